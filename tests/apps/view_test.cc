// `ibr view` under a virtual X server (xvfb-run), as a user would run it:
// the window shows the depth object and the control panel; bad input and a
// missing display give one clear line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

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

// A scene with a deform object (a knife-cut sphere, left) and a DVR volume
// (a ball of density in a 24^3 QVis volume, right) at `path`, its cameras
// `cameras` (JSON).
void WriteCutAndBallScene(const fs::path& path, const std::string& cameras) {
  const fs::path dir = path.parent_path();
  std::ofstream(dir / "ball.dat") << "ObjectFileName: ball.raw\nResolution: 24 24 24\n"
                                     "SliceThickness: 1 1 1\nFormat: UCHAR\n";
  std::string voxels;
  for (int z = 0; z < 24; ++z)
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x)
        voxels += std::hypot(x - 11.5, y - 11.5, z - 11.5) < 10 ? '\xff' : '\0';
  std::ofstream(dir / "ball.raw", std::ios::binary) << voxels;
  std::ofstream(path)
      << R"({"version": 1, "cameras": )" << cameras << R"(, "objects": [)"
      << R"({"name": "cut", "type": "deform", "mesh": {"shape": "sphere"}, "deformation": "knife",)"
         R"( "cut": "solid", "resolution": 48, "transform": {"translate": [-1.6, 0, 0]}},)"
         R"({"name": "ball", "type": "volume", "volume": "ball.dat", "transfer": "ramp",)"
         R"( "transform": {"translate": [1.6, 0, 0], "scale": 0.05}}]})";
}

// `ibr view INPUT` at rest under xvfb-run: the screenshot, the exact frame
// (DIR/frame.png) and its camera (DIR/cameras/dataset.json, a cameras-only
// dataset).
test_support::CommandResult ViewAtRest(const fs::path& input, const std::string& flags,
                                       const fs::path& dir) {
  fs::create_directories(dir / "cameras");
  return RunCommand("xvfb-run -a -s '-screen 0 1024x768x24' " + IbrBinary() + " view " +
                    test_support::Quote(input) + " " + flags + " --frames 3 --screenshot " +
                    test_support::Quote(dir / "shot.png") + " --frame-out " +
                    test_support::Quote(dir / "frame.png") + " --camera-out " +
                    test_support::Quote(dir / "cameras" / "dataset.json"));
}

// Pixels where the viewer's exact frame (RGBA: the frame target) and the
// view `ibr render` wrote into `rendered` (color/view.png RGB, mask/view.png)
// differ in colour or coverage; `covered` counts the frame's covered pixels.
int64_t DifferingPixels(const fs::path& frame_png, const fs::path& rendered, int64_t& covered) {
  const core::Image8 frame = core::ReadImage<uint8_t>(frame_png, 4);
  const core::Image8 color = core::ReadImage<uint8_t>(rendered / "color" / "view.png", 3);
  const core::Image8 mask = core::ReadImage<uint8_t>(rendered / "mask" / "view.png", 1);
  EXPECT_EQ(frame.width(), color.width());
  EXPECT_EQ(frame.height(), color.height());
  if (frame.width() != color.width() || frame.height() != color.height()) return -1;
  int64_t differing = 0;
  covered = 0;
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < frame.width(); ++x) {
      covered += frame.at(x, y, 3) == 255;
      bool same = (frame.at(x, y, 3) == 255) == (mask.at(x, y, 0) > 127);
      for (int c = 0; c < 3; ++c) same = same && frame.at(x, y, c) == color.at(x, y, c);
      differing += !same;
    }
  return differing;
}

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

// --no-panel: the same screenshot without the control panel: the panel's
// corner shows the background, the sphere is still drawn.
TEST_F(ViewTest, ScreenshotWithoutThePanel) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path shot = test_support::TestOutputDir() / "view_no_panel.png";
  const auto r = RunCommand("xvfb-run -a -s '-screen 0 1024x768x24' " + IbrBinary() + " view '" +
                            (*dir_ / "sphere").string() +
                            "' --window 800x600 --frames 2 --azimuth 10 --no-panel --screenshot '" +
                            shot.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const core::Image8 image = core::ReadImage<uint8_t>(shot);
  ASSERT_EQ(image.width(), 800);
  int bright = 0;
  for (int y = 300; y < 340; ++y)
    for (int x = 380; x < 420; ++x) bright += image.at(x, y, 1) > 80;
  EXPECT_GT(bright, 40 * 40 * 9 / 10);
  // Where the panel's title bar and text were: background only (0.12 * 255 = 31).
  int background = 0;
  for (int y = 10; y < 60; ++y)
    for (int x = 20; x < 200; ++x) background += std::abs(image.at(x, y, 1) - 31) <= 2;
  EXPECT_EQ(background, 50 * 180);
}

// `ibr view SCENE.json`: a scene with a deform object (a knife-cut sphere,
// left) and a DVR volume (a ball of density, right) through
// ibr::SceneRenderer; both show, the gap between them is background, and the
// panel (left, clear of the objects in a wide window) holds the deform and
// volume objects' controls below the object and pass lists.
TEST_F(ViewTest, ScreenshotOfASceneShowsTheDeformObjectAndTheVolume) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path dir = *dir_ / "scene";
  fs::create_directories(dir);
  WriteCutAndBallScene(dir / "s.json", R"({"orbit": {"count": 1, "size": 64}})");
  const fs::path shot = test_support::TestOutputDir() / "view_scene.png";
  const auto r = RunCommand("xvfb-run -a -s '-screen 0 1700x800x24' " + IbrBinary() + " view '" +
                            (dir / "s.json").string() +
                            "' --window 1600x700 --frames 2 --azimuth 0 --elevation 0 "
                            "--screenshot '" +
                            shot.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("view: wrote"), std::string::npos) << r.out;
  const core::Image8 image = core::ReadImage<uint8_t>(shot);
  ASSERT_EQ(image.width(), 1600);
  ASSERT_EQ(image.height(), 700);
  // Right of the panel: object pixels left and right of the centre, none in
  // the gap at the centre column.
  auto lit = [&](int x0, int x1) {
    int n = 0;
    for (int y = 0; y < 700; ++y)
      for (int x = x0; x < x1; ++x) n += image.at(x, y, 0) + image.at(x, y, 1) > 80;
    return n;
  };
  EXPECT_GT(lit(450, 780), 2000) << "the deform object (left)";
  EXPECT_GT(lit(820, 1300), 800) << "the volume (right)";
  EXPECT_EQ(lit(795, 805), 0) << "the gap between them";
  // The panel's bottom: the lowest row of a column inside it (x = 200, left
  // of every object) that is not the viewer's background (0.12, 0.12, 0.14).
  // The lists alone end near y = 300; the deform controls (amount, width,
  // cut, step, step voxels, skip, implicit) and the volume's (effect, lighting,
  // mode, spacing) take it further down.
  int bottom = 0;
  for (int y = 0; y < 700; ++y) {
    if (std::abs(image.at(200, y, 0) - 31) > 2 || std::abs(image.at(200, y, 2) - 36) > 2)
      bottom = y;
  }
  EXPECT_GT(bottom, 480) << "the panel holds no object controls";
}

// The frame at rest is exact: the viewer's frame (--frame-out) equals, pixel
// for pixel, what `ibr render --cameras` writes from the camera the viewer
// saved (--camera-out), for a dataset's depth object (DepthObjectRenderer)
// and for a scene file's deform object and volume (SceneRenderer).
TEST_F(ViewTest, RestedFrameEqualsRenderOfADataset) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path dir = test_support::Scratch("view_exact_dataset");
  const auto v = ViewAtRest(*dir_ / "sphere", "--window 320x240 --azimuth 37 --elevation 15", dir);
  ASSERT_EQ(v.exit_code, 0) << v.err;
  const auto r = RunCommand(IbrBinary() + " render " + test_support::Quote(*dir_ / "sphere") +
                            " --cameras " + test_support::Quote(dir / "cameras") + " --out " +
                            test_support::Quote(dir / "rendered"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int64_t covered = 0;
  EXPECT_EQ(DifferingPixels(dir / "frame.png", dir / "rendered", covered), 0);
  EXPECT_GT(covered, 320 * 240 / 20) << "the sphere fills the middle of the frame";
}

TEST_F(ViewTest, RestedFrameEqualsRenderOfASceneWithADeformObjectAndAVolume) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path dir = test_support::Scratch("view_exact_scene");
  WriteCutAndBallScene(dir / "s.json", R"({"orbit": {"count": 1, "size": 64}})");
  const auto v = ViewAtRest(dir / "s.json", "--window 400x200 --azimuth 10 --elevation 5", dir);
  ASSERT_EQ(v.exit_code, 0) << v.err;
  // The same scene whose cameras are the viewer's.
  WriteCutAndBallScene(dir / "r.json", R"({"dataset": "cameras"})");
  const auto r = RunCommand(IbrBinary() + " render " + test_support::Quote(dir / "r.json") +
                            " --out " + test_support::Quote(dir / "rendered"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int64_t covered = 0;
  EXPECT_EQ(DifferingPixels(dir / "frame.png", dir / "rendered", covered), 0);
  // The deform object (left) is opaque; the DVR ball (right) blends alpha.
  const core::Image8 frame = core::ReadImage<uint8_t>(dir / "frame.png", 4);
  int64_t left = 0, right = 0;
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < frame.width(); ++x) {
      left += x < frame.width() / 2 && frame.at(x, y, 3) == 255;
      right += x >= frame.width() / 2 && frame.at(x, y, 3) > 0;
    }
  EXPECT_GT(left, 1000) << "the deform object shows";
  EXPECT_GT(right, 200) << "the volume (a ball about 26 px across) shows";
}

// Without a screenshot the frame and camera outputs have nothing to save.
TEST_F(ViewTest, FrameOutWithoutScreenshotIsOneLine) {
  const auto r = RunCommand(IbrBinary() + " view " + test_support::Quote(*dir_ / "sphere") +
                            " --frame-out x.png");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("screenshot"), std::string::npos) << r.err;
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
