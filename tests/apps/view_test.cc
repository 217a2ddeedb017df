// `ibr view` under a virtual X server (xvfb-run), as a user would run it:
// the window shows the depth object and the control panel; bad input and a
// missing display give one clear line.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::RunCommand;

class ViewTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ =
        new fs::path(fs::temp_directory_path() / ("ibr-view-test-" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    const auto r = RunCommand(IbrBinary() + " capture --shape sphere --rig cube --size 64 --out '" +
                              (*dir_ / "sphere").string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static fs::path* dir_;
};
fs::path* ViewTest::dir_ = nullptr;

TEST_F(ViewTest, ScreenshotShowsTheObjectAndThePanel) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path shot = test_support::TestOutputDir() / "view.png";
  const auto r =
      RunCommand("xvfb-run -a -s '-screen 0 1024x768x24' " + IbrBinary() + " view '" +
                 (*dir_ / "sphere").string() +
                 "' --window 800x600 --frames 2 --azimuth 10 --screenshot '" + shot.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("view: wrote"), std::string::npos) << r.out;
  const core::Image8 image = core::ReadImage<uint8_t>(shot);
  ASSERT_EQ(image.width(), 800);
  ASSERT_EQ(image.height(), 600);
  // The sphere sits at the window centre (below the panel's bottom edge at
  // about y = 270): lit grey, far brighter than the background (0.12 * 255 = 31).
  int bright = 0;
  for (int y = 300; y < 340; ++y)
    for (int x = 380; x < 420; ++x) bright += image.at(x, y, 1) > 80;
  EXPECT_GT(bright, 40 * 40 * 9 / 10);
  int background = 0;
  for (int y = 580; y < 600; ++y)
    for (int x = 760; x < 800; ++x) background += std::abs(image.at(x, y, 1) - 31) <= 2;
  EXPECT_EQ(background, 20 * 40);
  // ImGui's title bar (blue) spans the panel's top.
  EXPECT_GT(image.at(60, 18, 2), image.at(60, 18, 0) + 40);
}

TEST_F(ViewTest, MissingDatasetIsOneLineAndNoWindow) {
  const auto r = RunCommand(IbrBinary() + " view '" + (*dir_ / "nope").string() + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
}

TEST_F(ViewTest, NoDisplayIsOneClearLine) {
  // ctest removes DISPLAY for this test: GLFW cannot open a window.
  ASSERT_EQ(std::getenv("DISPLAY"), nullptr);
  const auto r =
      RunCommand(IbrBinary() + " view '" + (*dir_ / "sphere").string() + "' --screenshot x.png");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("DISPLAY"), std::string::npos) << r.err;
}

}  // namespace
