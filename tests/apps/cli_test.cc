// The `ibr` tool as a user runs it: subcommands exist, the demo writes a
// decodable image, bad options give one clear line, a non-zero exit and no
// output.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::RunCommand;

TEST(Cli, HelpListsTheSubcommands) {
  const auto r = RunCommand(IbrBinary() + " --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* name : {"info", "demo", "bench"}) {
    EXPECT_NE(r.out.find(name), std::string::npos) << name << "\n" << r.out;
  }
}

TEST(Cli, DemoWritesAnImageAndSaysWhere) {
  const fs::path out = test_support::TestOutputDir() / "demo";
  const auto r = RunCommand(IbrBinary() + " demo --size 64 --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find((out / "color.png").string()), std::string::npos) << r.out;
  const core::Image8 color = core::ReadImage<uint8_t>(out / "color.png");
  EXPECT_EQ(color.width(), 64);
  int covered = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) covered += color.at(x, y, 3) == 255;
  EXPECT_GT(covered, 300);  // the torus covers a good part of the frame
}

TEST(Cli, AbsurdOptionGivesOneLineAndNoOutput) {
  const fs::path out = test_support::TestOutputDir() / "never";
  const auto r = RunCommand(IbrBinary() + " demo --size 3 --out '" + out.string() + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, UnknownSubcommandFails) {
  const auto r = RunCommand(IbrBinary() + " no-such-command");
  EXPECT_NE(r.exit_code, 0);
}

}  // namespace
