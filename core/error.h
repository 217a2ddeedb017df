// The "bad input" error channel: files, formats, options, shader sources.
// The message names the function, the file (where there is one) and what was
// wrong; the CLI prints it as one line and exits non-zero.
#pragma once

#include <fmt/format.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace core {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws InputError("where: what").
template <typename... Args>
[[noreturn]] void ThrowInputError(std::string_view where, fmt::format_string<Args...> format,
                                  Args&&... args) {
  throw InputError(fmt::format("{}: {}", where, fmt::format(format, std::forward<Args>(args)...)));
}

// Throws InputError("where: 'path': what").
template <typename... Args>
[[noreturn]] void ThrowFileError(std::string_view where, const std::filesystem::path& path,
                                 fmt::format_string<Args...> format, Args&&... args) {
  throw InputError(fmt::format("{}: '{}': {}", where, path.string(),
                               fmt::format(format, std::forward<Args>(args)...)));
}

}  // namespace core
