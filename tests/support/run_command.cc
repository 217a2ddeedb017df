#include "tests/support/run_command.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/support/gl_test.h"

namespace test_support {

CommandResult RunCommand(const std::string& command) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("ibr-cmd-" + std::to_string(::getpid()) + "-" + std::to_string(std::rand()));
  std::filesystem::create_directories(dir);
  const std::string full = command + " > '" + (dir / "out").string() + "' 2> '" +
                           (dir / "err").string() + "' < /dev/null";
  const int status = std::system(full.c_str());
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = Slurp(dir / "out");
  result.err = Slurp(dir / "err");
  std::filesystem::remove_all(dir);
  return result;
}

int CountLines(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

std::string IbrBinary() {
  const char* path = std::getenv("IBR_BINARY");
  return path ? path : "ibr";
}

std::string Quote(const std::filesystem::path& p) {
  std::string quoted(1, '\'');  // built piecewise: GCC 12's -Wrestrict misfires on "'" + s
  quoted += p.string();
  quoted += '\'';
  return quoted;
}

std::filesystem::path Scratch(const std::string& name) {
  const std::filesystem::path dir = TestOutputDir() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string Slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void Spit(const std::filesystem::path& p, const std::string& bytes) {
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << bytes;
}

}  // namespace test_support
