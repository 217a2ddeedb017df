// Real captures through the command line (issue 34, classes 5 and 6):
// - y-down data renders upright: a cup captured y-up, then the same dataset
//   with its world turned upside down (cameras y-down, as COLMAP's and
//   RGB-D's worlds are): `ibr render --orbit` takes the cameras' mean up and
//   renders the same images as the upright original, the cup's known top at
//   the image top; `--up y` renders it upside down;
// - `--arc` keeps an orbit within an arc around the input views; `--cameras`
//   takes a cameras-only manifest and a scene file's camera list;
// - a single RGB-D view (the real TUM frame) gets `--outside fail` by default
//   and says why (no grey block); `--outside pass` fills the box;
// - the import messages: a sparse-only COLMAP model says it cannot be
//   rendered yet (and render then fails as it said), a depth scale of 1000
//   on the TUM frame warns at import and in `ibr info`, 5000 does not;
// - `ibr render DATASET` takes the ray path by default (same images as
//   --slicing ray).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/real_captures.h"
#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test_support::IbrBinary;
using test_support::RunCommand;

const fs::path kReal = test_support::RealCapturesDir();

std::string Quote(const fs::path& p) {
  std::string quoted(1, '\'');
  quoted += p.string();
  quoted += '\'';
  return quoted;
}

json ReadJson(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

void WriteJson(const fs::path& p, const json& j) { std::ofstream(p) << j.dump(2); }

class RealCapturesCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_support::TestOutputDir().parent_path() / "real_captures_cli";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const auto r = RunCommand(IbrBinary() + " capture --shape cup --rig ring:8 --size 64 --out " +
                              Quote(dir_ / "cup"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The same capture in a world turned 180 degrees about x (y -> -y,
    // z -> -z): cam_from_world' = cam_from_world * R, bounds mirrored; the
    // camera frames, and so the images and camera-z depth, are unchanged.
    fs::copy(dir_ / "cup", dir_ / "cup_ydown", fs::copy_options::recursive);
    json j = ReadJson(dir_ / "cup/dataset.json");
    for (json& v : j["views"]) {
      for (int row = 0; row < 3; ++row) {
        v["cam_from_world"][row][1] = -v["cam_from_world"][row][1].get<double>();
        v["cam_from_world"][row][2] = -v["cam_from_world"][row][2].get<double>();
      }
      v.erase("normal");  // world-frame normals would need turning too
    }
    json& b = j["bounds"];
    for (int k : {1, 2}) {
      const double lo = b["min"][k], hi = b["max"][k];
      b["min"][k] = -hi;
      b["max"][k] = -lo;
    }
    j.erase("up");
    WriteJson(dir_ / "cup_ydown/dataset.json", j);
    // Views from one side: the first three of the ring.
    fs::copy(dir_ / "cup_ydown", dir_ / "cup_ydown_side", fs::copy_options::recursive);
    j["views"] = json::array({j["views"][0], j["views"][1], j["views"][2]});
    WriteJson(dir_ / "cup_ydown_side/dataset.json", j);
  }
  static fs::path dir_;
};
fs::path RealCapturesCliTest::dir_;

// Mask IoU of two rendered datasets' views i.
double MaskIou(const capture::Dataset& a, const capture::Dataset& b, size_t i) {
  const core::Image8 ma = a.LoadMask(i), mb = b.LoadMask(i);
  int64_t both = 0, either = 0;
  for (size_t p = 0; p < ma.pixel_count(); ++p) {
    both += ma.data()[p] > 127 && mb.data()[p] > 127;
    either += ma.data()[p] > 127 || mb.data()[p] > 127;
  }
  return either ? static_cast<double>(both) / static_cast<double>(either) : 1.0;
}

// The image row of world point p in view i (camera y down).
double Row(const capture::Dataset& d, size_t i, const glm::dvec3& p) {
  const capture::DatasetView& v = d.views[i];
  return d.camera(v).Project(v.cam_from_world * p).y;
}

TEST_F(RealCapturesCliTest, YDownDataRendersUprightByDefault) {
  const auto render = [&](const std::string& in, const std::string& out, const std::string& args) {
    fs::remove_all(dir_ / out);
    const auto r = RunCommand(IbrBinary() + " render " + Quote(dir_ / in) +
                              " --orbit 4 --size 64 " + args + " --out " + Quote(dir_ / out));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out;
  };
  render("cup", "upright", "");
  const std::string out = render("cup_ydown", "ydown", "");
  EXPECT_NE(out.find("orbit up (0.000, -1.000, 0.000) from the input cameras' mean up"),
            std::string::npos)
      << out;
  render("cup_ydown", "ydown_up_y", "--up y");
  const capture::Dataset upright = capture::ReadDataset(dir_ / "upright");
  const capture::Dataset ydown = capture::ReadDataset(dir_ / "ydown");
  const capture::Dataset flipped = capture::ReadDataset(dir_ / "ydown_up_y");
  ASSERT_EQ(ydown.views.size(), 4u);
  // The cup's top and bottom in the turned world (its y-up top is at the
  // original box's max y, now at -max y).
  const capture::Bounds& b = *upright.bounds;
  const glm::dvec3 c = b.centre();
  const glm::dvec3 top(c.x, -b.max.y, -c.z), bottom(c.x, -b.min.y, -c.z);
  for (size_t i = 0; i < 4; ++i) {
    const double iou = MaskIou(upright, ydown, i);
    std::printf("view %zu: IoU vs the upright original %.4f\n", i, iou);
    // The same cameras up to the rounding of the turned poses.
    EXPECT_GT(iou, 0.98) << "view " << i;
    EXPECT_LT(Row(ydown, i, top), Row(ydown, i, bottom)) << "top above bottom, view " << i;
    EXPECT_GT(Row(flipped, i, top), Row(flipped, i, bottom)) << "--up y: upside down, view " << i;
  }
}

TEST_F(RealCapturesCliTest, ArcStaysAroundTheInputViews) {
  const fs::path out = dir_ / "arc";
  fs::remove_all(out);
  const auto r = RunCommand(IbrBinary() + " render " + Quote(dir_ / "cup_ydown_side") +
                            " --orbit 3 --arc 60 --size 32 --out " + Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("orbit arc 60 degrees"), std::string::npos) << r.out;
  const capture::Dataset in = capture::ReadDataset(dir_ / "cup_ydown_side");
  const capture::Dataset arc = capture::ReadDataset(out);
  ASSERT_EQ(arc.views.size(), 3u);
  const glm::dvec3 up(0, -1, 0);
  // The input views' mean direction from the object towards the cameras,
  // across up.
  glm::dvec3 towards(0.0);
  for (const auto& v : in.views) towards -= glm::transpose(v.cam_from_world.rotation)[2];
  towards -= glm::dot(towards, up) * up;
  towards = glm::normalize(towards);
  const glm::dvec3 centre = in.bounds->centre();
  std::vector<double> angles;
  for (const auto& v : arc.views) {
    glm::dvec3 d = v.cam_from_world.Centre() - centre;
    d = glm::normalize(d - glm::dot(d, up) * up);
    const double a = std::atan2(glm::dot(glm::cross(towards, d), up), glm::dot(towards, d));
    angles.push_back(a * 180 / M_PI);
  }
  std::printf("arc azimuths: %.3f %.3f %.3f degrees\n", angles[0], angles[1], angles[2]);
  EXPECT_NEAR(std::abs(angles[0]), 30, 1e-3);
  EXPECT_NEAR(angles[1], 0, 1e-3);
  EXPECT_NEAR(std::abs(angles[2]), 30, 1e-3);
  EXPECT_LT(angles[0] * angles[2], 0) << "both ends of the arc";
}

TEST_F(RealCapturesCliTest, CamerasFromACamerasOnlyManifestAndASceneList) {
  json j = ReadJson(dir_ / "cup/dataset.json");
  for (json& v : j["views"]) {
    v.erase("color");
    v.erase("depth");
    v.erase("mask");
    v.erase("normal");
  }
  WriteJson(dir_ / "cams.json", j);
  fs::remove_all(dir_ / "from_cams");
  auto r = RunCommand(IbrBinary() + " render " + Quote(dir_ / "cup") + " --cameras " +
                      Quote(dir_ / "cams.json") + " --size 32 --out " + Quote(dir_ / "from_cams"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(capture::ReadDataset(dir_ / "from_cams").views.size(), 8u);

  WriteJson(dir_ / "scene.json",
            json::parse(R"({"version": 1, "cameras": {"list": [{"name": "front", "width": 40,
              "height": 30, "fx": 40, "fy": 40, "cx": 20, "cy": 15,
              "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3]]}]},
              "objects": [{"type": "depth-object", "images": {"dataset": "cup"}}]})"));
  fs::remove_all(dir_ / "from_scene");
  r = RunCommand(IbrBinary() + " render " + Quote(dir_ / "cup") + " --cameras " +
                 Quote(dir_ / "scene.json") + " --out " + Quote(dir_ / "from_scene"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const capture::Dataset scene = capture::ReadDataset(dir_ / "from_scene");
  ASSERT_EQ(scene.views.size(), 1u);
  EXPECT_EQ(scene.views[0].name, "front");
  EXPECT_EQ(scene.camera(scene.views[0]).width, 40);
}

TEST_F(RealCapturesCliTest, DepthScaleWarnsAtImportAndInInfo) {
  const fs::path src = test_support::WriteTumRedwoodLayout(dir_ / "tum_src");
  for (const int scale : {5000, 1000}) {
    const fs::path out = dir_ / ("tum_" + std::to_string(scale));
    fs::remove_all(out);
    const auto r = RunCommand(IbrBinary() + " import redwood " + Quote(src) + " --depth-scale " +
                              std::to_string(scale) + " --out " + Quote(out));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto info = RunCommand(IbrBinary() + " info " + Quote(out));
    ASSERT_EQ(info.exit_code, 0) << info.err;
    std::printf("--depth-scale %d:\n%s%s", scale, r.out.c_str(), info.out.c_str());
    if (scale == 5000) {
      EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
      EXPECT_EQ(info.out.find("warning"), std::string::npos) << info.out;
    } else {
      EXPECT_NE(r.out.find("warning: depth scale looks wrong"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("--depth-scale 5000 instead of 1000"), std::string::npos) << r.out;
      EXPECT_NE(info.out.find("warning   depth scale looks wrong"), std::string::npos) << info.out;
    }
  }
}

TEST_F(RealCapturesCliTest, ASingleViewIsNotFilledWithAGreyBlock) {
  const fs::path src = test_support::WriteTumRedwoodLayout(dir_ / "tum_single_src");
  const fs::path tum = dir_ / "tum_single";
  fs::remove_all(tum);
  const auto imported = RunCommand(IbrBinary() + " import redwood " + Quote(src) +
                                   " --depth-scale 5000 --out " + Quote(tum));
  ASSERT_EQ(imported.exit_code, 0) << imported.err;
  // Object pixels over the orbit's views, and those of them that are grey
  // (R = G = B within 3: shaded but coloured by no map).
  struct Coverage {
    int64_t object = 0, grey = 0;
  };
  const auto covered = [&](const std::string& args, std::string* out_text) {
    const fs::path out = dir_ / "tum_orbit";
    fs::remove_all(out);
    const auto rr = RunCommand(IbrBinary() + " render " + Quote(tum) + " --orbit 3 --size 48 " +
                               args + " --out " + Quote(out));
    EXPECT_EQ(rr.exit_code, 0) << args << rr.err;
    if (out_text) *out_text = rr.out;
    const capture::Dataset d = capture::ReadDataset(out);
    Coverage c;
    for (size_t i = 0; i < d.views.size(); ++i) {
      const core::Image8 mask = d.LoadMask(i), color = d.LoadColor(i);
      for (int y = 0; y < mask.height(); ++y) {
        for (int x = 0; x < mask.width(); ++x) {
          if (mask.at(x, y) <= 127) continue;
          ++c.object;
          const int r = color.at(x, y, 0), g = color.at(x, y, 1), b = color.at(x, y, 2);
          c.grey += std::abs(r - g) <= 3 && std::abs(g - b) <= 3;
        }
      }
    }
    return c;
  };
  std::string said;
  const Coverage by_default = covered("", &said);
  const Coverage fail = covered("--outside fail", nullptr);
  const Coverage pass = covered("--outside pass", nullptr);
  std::printf(
      "object (grey) pixels over 3 orbit views: default %lld (%lld), fail %lld (%lld), pass %lld "
      "(%lld)\n%s",
      static_cast<long long>(by_default.object), static_cast<long long>(by_default.grey),
      static_cast<long long>(fail.object), static_cast<long long>(fail.grey),
      static_cast<long long>(pass.object), static_cast<long long>(pass.grey), said.c_str());
  EXPECT_NE(said.find("outside fail:"), std::string::npos) << said;
  EXPECT_NE(said.find("seen by no input view"), std::string::npos) << said;
  EXPECT_NE(said.find("--outside pass"), std::string::npos) << said;
  EXPECT_EQ(by_default.object, fail.object);
  EXPECT_EQ(by_default.grey, fail.grey);
  // pass fills the box outside the one view's frustum: more object, and
  // the block it adds is grey.
  EXPECT_GT(pass.object, by_default.object * 5 / 4);
  EXPECT_GT(pass.grey - by_default.grey, (pass.object - by_default.object) * 3 / 4);
}

TEST_F(RealCapturesCliTest, SparseOnlyImportSaysItCannotRenderAndRenderAgrees) {
  const fs::path out = dir_ / "maupertuis";
  fs::remove_all(out);
  auto r = RunCommand(IbrBinary() + " import colmap " + Quote(kReal / "maupertuis") + " --out " +
                      Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.out.find("import: sparse model only"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("import: bounds min"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("import: up ("), std::string::npos) << r.out;
  r = RunCommand(IbrBinary() + " render " + Quote(out) + " --orbit 1 --size 16 --out " +
                 Quote(dir_ / "maupertuis_render"));
  EXPECT_NE(r.exit_code, 0);
  // What the import said, not the first map's name.
  EXPECT_NE(r.err.find("its 4 views have poses and colour but no depth and no masks (a "
                       "sparse-only import)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("ibr render OTHER --cameras DATASET"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("map '"), std::string::npos) << r.err;
  EXPECT_EQ(test_support::CountLines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "maupertuis_render"));
}

// The new flags' bad values: one error line, no output.
TEST_F(RealCapturesCliTest, BadUpArcAndMasksGiveOneErrorLine) {
  const fs::path out = dir_ / "bad";
  const std::string cup = Quote(dir_ / "cup");
  for (const std::string& args :
       {"render " + cup + " --orbit 2 --up w", "render " + cup + " --orbit 2 --up 0,0,0",
        "render " + cup + " --orbit 2 --up 1,2", "render " + cup + " --orbit 2 --arc 0",
        "render " + cup + " --orbit 2 --arc 400",
        "render " + cup + " --cameras " + cup + " --arc 30",
        "render " + cup + " --cameras " + cup + " --up y",
        "render " + cup + " --cameras " + Quote(dir_ / "no_such.json"),
        "import colmap " + Quote(kReal / "maupertuis") + " --masks " + Quote(dir_ / "no_masks"),
        "import colmap " + Quote(kReal / "maupertuis") + " --bounds-percentile 60"}) {
    fs::remove_all(out);
    const auto r = RunCommand(IbrBinary() + " " + args + " --out " + Quote(out));
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(test_support::CountLines(r.err), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find("ibr: error:"), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

TEST_F(RealCapturesCliTest, RenderTakesTheRayPathByDefault) {
  for (const std::string name : {"default", "ray"}) {
    fs::remove_all(dir_ / ("path_" + name));
    const auto r = RunCommand(IbrBinary() + " render " + Quote(dir_ / "cup") +
                              " --orbit 2 --size 32 " + (name == "ray" ? "--slicing ray" : "") +
                              " --out " + Quote(dir_ / ("path_" + name)));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  for (const char* view : {"orbit_000", "orbit_001"}) {
    const std::string file = std::string("color/") + view + ".png";
    const core::Image8 a = core::ReadImage<uint8_t>(dir_ / "path_default" / file);
    const core::Image8 b = core::ReadImage<uint8_t>(dir_ / "path_ray" / file);
    EXPECT_TRUE(std::equal(a.values().begin(), a.values().end(), b.values().begin())) << view;
  }
}

}  // namespace
