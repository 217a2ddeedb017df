// Runs a shell command for CLI tests, capturing exit code, stdout and stderr.
#pragma once

#include <string>

namespace test_support {

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

CommandResult RunCommand(const std::string& command);

// Number of newline-terminated lines in `text` (an error message must be one).
int CountLines(const std::string& text);

// The `ibr` binary under test (IBR_BINARY, set by ctest).
std::string IbrBinary();

}  // namespace test_support
