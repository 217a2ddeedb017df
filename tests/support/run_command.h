// Runs a shell command for CLI tests, capturing exit code, stdout and stderr.
#pragma once

#include <filesystem>
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

// `p` in single quotes, for a shell command line.
std::string Quote(const std::filesystem::path& p);

// A file's bytes (empty if it cannot be read), and a file written with
// `bytes` (its folders created).
std::string Slurp(const std::filesystem::path& p);
void Spit(const std::filesystem::path& p, const std::string& bytes);

// A fresh, empty directory TestOutputDir()/name for one test's files.
std::filesystem::path Scratch(const std::string& name);

}  // namespace test_support
