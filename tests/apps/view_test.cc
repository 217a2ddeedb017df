// `ibr view` under a virtual X server (xvfb-run), as a user would run it:
// the window shows the depth object and the control panel; bad input and a
// missing display give one clear line.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

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
  // The gap: no grey (object) pixels; the gizmo's red x axis may cross it.
  int grey_in_gap = 0;
  for (int y = 0; y < 700; ++y) {
    for (int x = 795; x < 805; ++x) {
      const int red = image.at(x, y, 0), green = image.at(x, y, 1), blue = image.at(x, y, 2);
      grey_in_gap += red + green > 80 && std::abs(red - green) < 40 && std::abs(green - blue) < 40;
    }
  }
  EXPECT_EQ(grey_in_gap, 0) << "the gap between them";
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

// The pixels of `image` right of x0 whose colour `match` accepts.
template <typename Match>
std::vector<glm::dvec2> PixelsWhere(const core::Image8& image, int x0, Match match) {
  std::vector<glm::dvec2> pixels;
  for (int y = 0; y < image.height(); ++y)
    for (int x = x0; x < image.width(); ++x)
      if (match(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)))
        pixels.push_back({x + 0.5, y + 0.5});
  return pixels;
}

// The ends of a thin line of pixels: the extremes along their principal axis.
std::pair<glm::dvec2, glm::dvec2> LineEnds(const std::vector<glm::dvec2>& pixels) {
  glm::dvec2 mean(0.0);
  for (const glm::dvec2& p : pixels) mean += p / static_cast<double>(pixels.size());
  double xx = 0, xy = 0, yy = 0;
  for (const glm::dvec2& p : pixels) {
    xx += (p.x - mean.x) * (p.x - mean.x);
    xy += (p.x - mean.x) * (p.y - mean.y);
    yy += (p.y - mean.y) * (p.y - mean.y);
  }
  const double angle = 0.5 * std::atan2(2 * xy, xx - yy);
  const glm::dvec2 axis(std::cos(angle), std::sin(angle));
  glm::dvec2 lo = mean, hi = mean;
  for (const glm::dvec2& p : pixels) {
    if (glm::dot(p - mean, axis) < glm::dot(lo - mean, axis)) lo = p;
    if (glm::dot(p - mean, axis) > glm::dot(hi - mean, axis)) hi = p;
  }
  return {lo, hi};
}

// Issue 35 item 4: a recorded session (a drag of the knife's line across a
// deform object, then an orbit) replayed through the viewer's input
// handlers; the scene it saves renders, in `ibr render`, the viewer's final
// exact frame pixel for pixel; the saved placement is the drag's travel
// along the box's x axis and the saved camera the orbit's.
TEST_F(ViewTest, ReplayedDragAndOrbitSaveTheSceneThatRendersTheFrame) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path dir = test_support::Scratch("view_replay");
  std::ofstream(dir / "s.json")
      << R"({"version": 1, "cameras": {"orbit": {"count": 1, "size": 64}}, "objects": [)"
         R"({"name": "cut", "type": "deform", "mesh": {"shape": "sphere"}, "deformation": "knife",)"
         R"( "cut": "solid", "resolution": 48}]})";
  const std::string xvfb = "xvfb-run -a -s '-screen 0 1300x800x24' " + IbrBinary() + " view ";
  const std::string window = " --window 1200x700 --azimuth 30 --elevation 20";
  // Where the gizmo shows: the knife's line (yellow) and the x axis (red),
  // right of the panel (x < 420).
  const auto shot = RunCommand(xvfb + test_support::Quote(dir / "s.json") + window +
                               " --frames 2 --screenshot " + test_support::Quote(dir / "shot.png"));
  ASSERT_EQ(shot.exit_code, 0) << shot.err;
  const core::Image8 image = core::ReadImage<uint8_t>(dir / "shot.png", 4);
  const std::vector<glm::dvec2> knife =
      PixelsWhere(image, 420, [](int r, int g, int b) { return r > 200 && g > 180 && b < 90; });
  const std::vector<glm::dvec2> x_axis =
      PixelsWhere(image, 420, [](int r, int g, int b) { return r > 225 && g < 85 && b < 85; });
  ASSERT_GT(knife.size(), 100u) << "no knife line in the screenshot";
  ASSERT_GT(x_axis.size(), 100u) << "no x-axis handle in the screenshot";
  const auto [k0, k1] = LineEnds(knife);
  const glm::dvec2 press = glm::round(0.5 * (k0 + k1));
  const glm::dvec2 travel(60, 0);
  // The recorded session: move to the line's middle, press, drag right in
  // three steps, release; then orbit from the window's empty corner.
  std::ofstream(dir / "events.json") << fmt::format(
      R"({{"version": 1, "window": [1200, 700], "azimuth_deg": 30, "elevation_deg": 20,)"
      R"( "panel": true, "events": [)"
      R"({{"frame": 1, "t": 0.1, "type": "move", "x": {0}, "y": {1}}},)"
      R"({{"frame": 2, "t": 0.2, "type": "button", "button": 0, "action": "press", "mods": 0}},)"
      R"({{"frame": 3, "t": 0.3, "type": "move", "x": {2}, "y": {1}}},)"
      R"({{"frame": 4, "t": 0.4, "type": "move", "x": {3}, "y": {1}}},)"
      R"({{"frame": 5, "t": 0.5, "type": "move", "x": {4}, "y": {1}}},)"
      R"({{"frame": 6, "t": 0.6, "type": "button", "button": 0, "action": "release", "mods": 0}},)"
      R"({{"frame": 7, "t": 0.7, "type": "move", "x": 1150, "y": 650}},)"
      R"({{"frame": 8, "t": 0.8, "type": "button", "button": 0, "action": "press", "mods": 0}},)"
      R"({{"frame": 9, "t": 0.9, "type": "move", "x": 1125, "y": 650}},)"
      R"({{"frame": 10, "t": 1.0, "type": "move", "x": 1100, "y": 650}},)"
      R"({{"frame": 11, "t": 1.1, "type": "button", "button": 0, "action": "release", "mods": 0}})"
      R"(]}})",
      press.x, press.y, press.x + travel.x / 3, press.x + 2 * travel.x / 3, press.x + travel.x);
  fs::create_directories(dir / "cameras");
  const auto replay = RunCommand(xvfb + test_support::Quote(dir / "s.json") + " --replay " +
                                 test_support::Quote(dir / "events.json") + " --frame-out " +
                                 test_support::Quote(dir / "frame.png") + " --save-scene " +
                                 test_support::Quote(dir / "out.json") + " --record " +
                                 test_support::Quote(dir / "again.json"));
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  EXPECT_NE(replay.out.find("replayed 11 events"), std::string::npos) << replay.out;

  // `ibr render` of the saved scene draws the viewer's final frame.
  const auto render = RunCommand(IbrBinary() + " render " + test_support::Quote(dir / "out.json") +
                                 " --out " + test_support::Quote(dir / "rendered"));
  ASSERT_EQ(render.exit_code, 0) << render.err;
  int64_t covered = 0;
  EXPECT_EQ(DifferingPixels(dir / "frame.png", dir / "rendered", covered), 0);
  EXPECT_GT(covered, 20000) << "the sphere (about 240 px across) shows";

  const nlohmann::json saved = nlohmann::json::parse(std::ifstream(dir / "out.json"));
  // The placement: moved along the box's x axis alone (the knife's line is
  // dragged across the cut), by the travel projected on the x axis's image:
  // the red handle spans 0.75 of the box's x extent (1.1 normalised units: a
  // unit sphere's bounds grown by 0.05 a side). The screenshot's line ends
  // are within a few pixels: 10 %.
  const std::string placement = saved["objects"][0]["placement"].get<std::string>();
  std::vector<double> p;
  for (std::stringstream in(placement); in.good();) {
    std::string item;
    std::getline(in, item, ',');
    p.push_back(std::stod(item));
  }
  ASSERT_EQ(p.size(), 7u) << placement;
  const auto [a0, a1] = LineEnds(x_axis);
  const glm::dvec2 image_of_axis = a1 - a0;
  const double expected = std::abs(glm::dot(travel, image_of_axis)) /
                          glm::dot(image_of_axis, image_of_axis) * 0.75 * 1.1;
  EXPECT_NEAR(std::abs(p[0]), expected, 0.1 * expected) << placement;
  EXPECT_GT(expected, 0.05);
  for (int i = 1; i < 6; ++i) EXPECT_EQ(p[i], 0.0) << placement;
  EXPECT_EQ(p[6], 1.0) << placement;

  // The camera: the orbit turned the azimuth by 0.4 degrees a pixel (50 px:
  // 30 -> 50 degrees), the camera a screenshot at azimuth 50 saves.
  const auto at_50 =
      RunCommand(xvfb + test_support::Quote(dir / "s.json") +
                 " --window 1200x700 --azimuth 50 --elevation 20 --frames 1 --screenshot " +
                 test_support::Quote(dir / "shot50.png") + " --camera-out " +
                 test_support::Quote(dir / "cameras" / "dataset.json"));
  ASSERT_EQ(at_50.exit_code, 0) << at_50.err;
  const nlohmann::json expected_camera =
      nlohmann::json::parse(std::ifstream(dir / "cameras" / "dataset.json"));
  const nlohmann::json& camera = saved["cameras"]["list"][0];
  EXPECT_EQ(camera["width"], 1200);
  EXPECT_EQ(camera["height"], 700);
  const nlohmann::json& view = expected_camera["views"][0];
  SCOPED_TRACE(view.dump());
  SCOPED_TRACE(camera.dump());
  // A rotation stored as rows in the saved scene's 3x4 cam_from_world.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(camera["cam_from_world"][r][c].get<double>(),
                  view["cam_from_world"][r][c].get<double>(), 1e-6);

  // --record during the replay wrote the same events (the same handlers).
  const nlohmann::json given = nlohmann::json::parse(std::ifstream(dir / "events.json"));
  const nlohmann::json recorded = nlohmann::json::parse(std::ifstream(dir / "again.json"));
  ASSERT_EQ(recorded["events"].size(), given["events"].size());
  for (size_t i = 0; i < given["events"].size(); ++i) {
    nlohmann::json a = given["events"][i], b = recorded["events"][i];
    a.erase("t"), b.erase("t");
    EXPECT_EQ(a, b) << i;
  }
}

// A peeled volume's flap edge dragged (Correa 2006 Fig. 1's sweep): the
// saved scene holds the dragged angle in its "deformations" list, and
// `ibr render` of it draws the viewer's final frame pixel for pixel.
TEST_F(ViewTest, ReplayedVolumePeelSavesTheSceneThatRendersTheFrame) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path dir = test_support::Scratch("view_replay_peel");
  WriteCutAndBallScene(dir / "both.json", R"({"orbit": {"count": 1, "size": 64}})");
  std::ofstream(dir / "s.json")
      << R"({"version": 1, "cameras": {"orbit": {"count": 1, "size": 64}}, "objects": [)"
         R"({"name": "ball", "type": "volume", "volume": "ball.dat", "transfer": "ramp",)"
         R"( "effect": "peel", "transform": {"scale": 0.05}}]})";
  const std::string xvfb = "xvfb-run -a -s '-screen 0 1300x800x24' " + IbrBinary() + " view ";
  const auto shot = RunCommand(xvfb + test_support::Quote(dir / "s.json") +
                               " --window 1200x700 --azimuth 80 --elevation 10 --frames 2 "
                               "--screenshot " +
                               test_support::Quote(dir / "shot.png"));
  ASSERT_EQ(shot.exit_code, 0) << shot.err;
  const core::Image8 image = core::ReadImage<uint8_t>(dir / "shot.png", 4);
  // The flap edge: the orange pixel with the most orange neighbours (the
  // edge is drawn 3 px wide, the hinge 1 px).
  const auto orange = [&](int x, int y) {
    return image.at(x, y, 0) > 200 && image.at(x, y, 1) > 110 && image.at(x, y, 1) < 190 &&
           image.at(x, y, 2) < 90;
  };
  glm::ivec2 grab(-1);
  int best = 0;
  for (int y = 2; y < 698; ++y)
    for (int x = 422; x < 1198; ++x) {
      if (!orange(x, y)) continue;
      int n = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) n += orange(x + dx, y + dy);
      if (n > best) best = n, grab = {x, y};
    }
  ASSERT_GT(best, 10) << "no flap edge in the screenshot";
  std::ofstream(dir / "events.json") << fmt::format(
      R"({{"version": 1, "window": [1200, 700], "azimuth_deg": 80, "elevation_deg": 10,)"
      R"( "panel": true, "events": [{{"frame": 1, "type": "move", "x": {0}, "y": {1}}},)"
      R"({{"frame": 2, "type": "button", "button": 0, "action": "press"}},)"
      R"({{"frame": 3, "type": "move", "x": {0}, "y": {2}}},)"
      R"({{"frame": 4, "type": "button", "button": 0, "action": "release"}}]}})",
      grab.x, grab.y, grab.y + 40);
  const auto replay = RunCommand(xvfb + test_support::Quote(dir / "s.json") + " --replay " +
                                 test_support::Quote(dir / "events.json") + " --frame-out " +
                                 test_support::Quote(dir / "frame.png") + " --save-scene " +
                                 test_support::Quote(dir / "out.json"));
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  const nlohmann::json saved = nlohmann::json::parse(std::ifstream(dir / "out.json"));
  const nlohmann::json& object = saved["objects"][0];
  EXPECT_FALSE(object.contains("effect")) << object.dump();
  ASSERT_EQ(object["deformations"].size(), 1u) << object.dump();
  EXPECT_EQ(object["deformations"][0]["name"], "peel");
  const auto render = RunCommand(IbrBinary() + " render " + test_support::Quote(dir / "out.json") +
                                 " --out " + test_support::Quote(dir / "rendered"));
  ASSERT_EQ(render.exit_code, 0) << render.err;
  int64_t covered = 0;
  EXPECT_EQ(DifferingPixels(dir / "frame.png", dir / "rendered", covered), 0);
  // Without the drag (the file's default angle) the frame differs.
  nlohmann::json undragged = saved;
  undragged["objects"][0]["deformations"][0].erase("amount");
  std::ofstream(dir / "undragged.json") << undragged.dump();
  const auto plain =
      RunCommand(IbrBinary() + " render " + test_support::Quote(dir / "undragged.json") +
                 " --out " + test_support::Quote(dir / "plain"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_GT(DifferingPixels(dir / "frame.png", dir / "plain", covered), 0);
}

// Issue 35 item 5: a window/level drag (Control + left drag over the frame)
// replayed on a DVR volume whose density falls off from its centre; the
// saved scene holds the edited transfer function inline, its window the
// drag's (x widens, y moves the level, each pixel 1/500 of the data range),
// and `ibr render` of it draws the viewer's final frame pixel for pixel.
TEST_F(ViewTest, ReplayedWindowLevelSavesTheTransferThatRendersTheFrame) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  const fs::path dir = test_support::Scratch("view_replay_window");
  std::ofstream(dir / "fall.dat") << "ObjectFileName: fall.raw\nResolution: 24 24 24\n"
                                     "SliceThickness: 1 1 1\nFormat: UCHAR\n";
  std::string voxels;
  long data_max = 0;  // the data range is [0, data_max]
  for (int z = 0; z < 24; ++z)
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        const double r = std::hypot(x - 11.5, y - 11.5, z - 11.5);
        const long v = std::lround(255 * std::clamp(1 - r / 12, 0.0, 1.0));
        data_max = std::max(data_max, v);
        voxels += static_cast<char>(v);
      }
  std::ofstream(dir / "fall.raw", std::ios::binary) << voxels;
  std::ofstream(dir / "s.json")
      << R"({"version": 1, "cameras": {"orbit": {"count": 1, "size": 64}}, "objects": [)"
         R"({"name": "fall", "type": "volume", "volume": "fall.dat", "transfer": "ramp",)"
         R"( "transform": {"scale": 0.05}}]})";
  std::ofstream(dir / "events.json")
      << R"({"version": 1, "window": [640, 480], "azimuth_deg": 30, "elevation_deg": 20,)"
         R"( "panel": false, "events": [)"
         R"({"frame": 1, "type": "move", "x": 300, "y": 250},)"
         R"({"frame": 2, "type": "button", "button": 0, "action": "press", "mods": 2},)"
         R"({"frame": 3, "type": "move", "x": 340, "y": 240},)"
         R"({"frame": 4, "type": "move", "x": 380, "y": 210},)"
         R"({"frame": 5, "type": "button", "button": 0, "action": "release", "mods": 2}]})";
  const std::string xvfb = "xvfb-run -a -s '-screen 0 800x600x24' " + IbrBinary() + " view ";
  const auto replay = RunCommand(xvfb + test_support::Quote(dir / "s.json") + " --replay " +
                                 test_support::Quote(dir / "events.json") + " --frame-out " +
                                 test_support::Quote(dir / "frame.png") + " --save-scene " +
                                 test_support::Quote(dir / "out.json"));
  ASSERT_EQ(replay.exit_code, 0) << replay.err;

  // The ramp over the uint8 range [0, 255], dragged by (80, -40) px, each
  // pixel 1/500 of the data range.
  const nlohmann::json saved = nlohmann::json::parse(std::ifstream(dir / "out.json"));
  const nlohmann::json& transfer = saved["objects"][0]["transfer"];
  ASSERT_TRUE(transfer.is_object()) << saved.dump();
  EXPECT_EQ(transfer["units"], "data");
  ASSERT_EQ(transfer["points"].size(), 2u) << transfer.dump();
  const double per_px = data_max / 500.0, width = 255 + 80 * per_px, level = 127.5 - 40 * per_px;
  EXPECT_NEAR(transfer["points"][0][0].get<double>(), level - width / 2, 1e-9);
  EXPECT_NEAR(transfer["points"][1][0].get<double>(), level + width / 2, 1e-9);

  const auto render = RunCommand(IbrBinary() + " render " + test_support::Quote(dir / "out.json") +
                                 " --out " + test_support::Quote(dir / "rendered"));
  ASSERT_EQ(render.exit_code, 0) << render.err;
  int64_t covered = 0;
  EXPECT_EQ(DifferingPixels(dir / "frame.png", dir / "rendered", covered), 0);
  // The same camera with the file's ramp draws another picture: the edit shows.
  const core::Image8 frame = core::ReadImage<uint8_t>(dir / "frame.png", 4);
  int64_t lit = 0;
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < frame.width(); ++x) lit += frame.at(x, y, 3) > 0;
  EXPECT_GT(lit, 1000) << "the volume shows";
  nlohmann::json unedited = saved;
  unedited["objects"][0]["transfer"] = "ramp";
  std::ofstream(dir / "unedited.json") << unedited.dump();
  const auto plain =
      RunCommand(IbrBinary() + " render " + test_support::Quote(dir / "unedited.json") + " --out " +
                 test_support::Quote(dir / "plain"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_GT(DifferingPixels(dir / "frame.png", dir / "plain", covered), 1000);
}

// A recording that is not one: one line naming the file and the value.
TEST_F(ViewTest, BadRecordingIsOneLine) {
  const fs::path dir = test_support::Scratch("view_bad_replay");
  std::ofstream(dir / "s.json") << R"({"version": 1, "cameras": {"orbit": {}}, "objects": [)"
                                   R"({"type": "mesh", "mesh": {"shape": "sphere"}}]})";
  std::ofstream(dir / "e.json")
      << R"({"version": 1, "window": [640, 480], "azimuth_deg": 0,)"
         R"( "elevation_deg": 0, "events": [{"frame": 0, "type": "fly"}]})";
  const auto r = RunCommand(IbrBinary() + " view " + test_support::Quote(dir / "s.json") +
                            " --replay " + test_support::Quote(dir / "e.json"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/events/0/type"), std::string::npos) << r.err;
}

// `ibr view --help` names the replay flags.
TEST_F(ViewTest, HelpShowsReplayAndSaveScene) {
  const auto r = RunCommand(IbrBinary() + " view --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag : {"--replay", "--save-scene", "--record"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
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
