// `ibr render` end to end: a cube capture of the analytic sphere, rendered as
// a depth object / visual hull / ray variant from a turntable and from the
// capture's own cameras; bad input gives one error line and no output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace ibr {
namespace {

namespace fs = std::filesystem;

class RenderCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_support::TestOutputDir().parent_path() / "render_cli";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const auto r = test_support::RunCommand(test_support::IbrBinary() +
                                            " capture --shape sphere --rig cube --size 64 --out " +
                                            (dir_ / "sphere").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static fs::path dir_;
};
fs::path RenderCliTest::dir_;

TEST_F(RenderCliTest, RendersEveryMethodAndSlicing) {
  const std::string in = (dir_ / "sphere").string();
  for (const std::string& args : std::vector<std::string>{
           "--method depth-object --slicing orthogonal --orbit 3",
           "--method visual-hull --slicing screen --texturing none --orbit 2",
           "--method depth-object --slicing ray --texturing visibility --robust 1 --orbit 2",
           "--method depth-object --slicing screen --cameras " + in}) {
    const fs::path out = dir_ / "out";
    fs::remove_all(out);
    const auto r = test_support::RunCommand(test_support::IbrBinary() + " render " + in + " " +
                                            args + " --slices 64 --size 64 --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    EXPECT_NE(r.out.find("render: view 1/"), std::string::npos) << "progress lines";
    const capture::Dataset rendered = capture::ReadDataset(out);
    ASSERT_GE(rendered.views.size(), 2u);
    for (size_t i = 0; i < rendered.views.size(); ++i) {
      const core::Image8 mask = rendered.LoadMask(i);
      const core::ImageF depth = rendered.LoadDepth(i);
      int64_t object = 0;
      for (size_t p = 0; p < mask.pixel_count(); ++p) {
        object += mask.data()[p] > 127;
        EXPECT_EQ(mask.data()[p] > 127, depth.data()[p] > 0) << "depth is 0 exactly where empty";
      }
      EXPECT_GT(object, 200) << args << " view " << rendered.views[i].name;
    }
  }
}

// Issue 13: a perspective dataset rendered from a cube rig's (orthographic)
// cameras: the torus's ring from the cube of the (smaller) sphere, whose
// cameras sit inside the torus's box. An orthographic view also sees what lies
// behind its image plane (camera z < 0) within its clip range: a valid
// request, written with invalid depth (0) at those pixels ("DatasetWriter::
// AddView: negative depth" before).
TEST_F(RenderCliTest, RendersAPerspectiveDatasetFromACubeRigsCameras) {
  const fs::path ring = dir_ / "torus_ring";
  fs::remove_all(ring);
  const auto c = test_support::RunCommand(test_support::IbrBinary() +
                                          " capture --shape torus --rig ring:4 --size 32 --out " +
                                          ring.string());
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const fs::path out = dir_ / "torus_from_sphere_cube";
  fs::remove_all(out);
  const auto r = test_support::RunCommand(test_support::IbrBinary() + " render " + ring.string() +
                                          " --cameras " + (dir_ / "sphere").string() +
                                          " --slicing orthogonal --outside pass --size 32 --out " +
                                          out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const capture::Dataset rendered = capture::ReadDataset(out, /*check_pixels=*/true);
  ASSERT_EQ(rendered.views.size(), 6u);
  int64_t object = 0, positive = 0, behind = 0;
  for (size_t i = 0; i < rendered.views.size(); ++i) {
    const core::Image8 mask = rendered.LoadMask(i);
    const core::ImageF depth = rendered.LoadDepth(i);
    for (size_t p = 0; p < mask.pixel_count(); ++p) {
      EXPECT_GE(depth.data()[p], 0.0f);
      if (mask.data()[p] <= 127) {
        EXPECT_EQ(depth.data()[p], 0.0f) << "depth is 0 where empty";
        continue;
      }
      ++object;
      positive += depth.data()[p] > 0;
      behind += depth.data()[p] == 0;
    }
  }
  EXPECT_GT(behind, 0) << "no pixel lay behind a cube camera: the case is not exercised";
  EXPECT_GT(positive, object / 2) << "most of the torus is in front of the cameras";
}

TEST_F(RenderCliTest, BadInputLeavesNoOutput) {
  const std::string in = (dir_ / "sphere").string();
  const fs::path out = dir_ / "bad";
  for (const std::string& args : std::vector<std::string>{
           "--method hull --orbit 2", "--slicing diagonal --orbit 2", "--orbit 2 --slices 0",
           "--cameras " + (dir_ / "missing").string(), ""}) {
    const auto r = test_support::RunCommand(test_support::IbrBinary() + " render " + in + " " +
                                            args + " --out " + out.string());
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_NE(r.err.find("ibr: error:"), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

// `ibr render SCENE.json`: a depth object of the captured sphere beside a
// displaced torus; every camera of the scene becomes a view of the output.
TEST_F(RenderCliTest, RendersASceneFile) {
  const fs::path scene = dir_ / "two.json";
  std::ofstream(scene)
      << R"({"version": 1, "cameras": {"orbit": {"count": 2, "size": 64}}, "objects": [
    {"type": "depth-object", "images": {"dataset": "sphere"}, "slicing": "ray", "slices": 64,
     "transform": {"translate": [-1.5, 0, 0]}},
    {"type": "displaced-mesh", "mesh": {"shape": "torus"}, "height": {"generator": "bumps", "texels": 32},
     "method": "slices-orthogonal", "slices": 16, "transform": {"translate": [1.5, 0, 0]}}]})";
  const fs::path out = dir_ / "scene_out";
  fs::remove_all(out);
  const auto r = test_support::RunCommand(test_support::IbrBinary() + " render " + scene.string() +
                                          " --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("passes [depth-object, displacement:slices-orthogonal]"), std::string::npos)
      << r.out;
  const capture::Dataset rendered = capture::ReadDataset(out);
  ASSERT_EQ(rendered.views.size(), 2u);
  for (size_t i = 0; i < rendered.views.size(); ++i) {
    const core::Image8 mask = rendered.LoadMask(i);
    const core::ImageF depth = rendered.LoadDepth(i);
    int64_t object = 0;
    for (size_t p = 0; p < mask.pixel_count(); ++p) {
      object += mask.data()[p] > 127;
      EXPECT_EQ(mask.data()[p] > 127, depth.data()[p] > 0) << "depth is 0 exactly where empty";
    }
    EXPECT_GT(object, 300) << rendered.views[i].name;
  }
}

TEST_F(RenderCliTest, BadSceneNamesFileAndPointerAndLeavesNoOutput) {
  const fs::path out = dir_ / "bad_scene";
  struct Case {
    const char* text;
    const char* expect;
  };
  const Case cases[] = {
      {R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "depth-object", "images": {"dataset": "sphere"}, "slices": "many"}]})",
       "/objects/0/slices"},
      {R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "mesh", "mesh": {"file": "gone.obj"}}]})",
       "/objects/0/mesh/file"},
      {R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "volume", "volume": "gone.dat"}]})",
       "/objects/0/volume"},
  };
  for (const Case& c : cases) {
    const fs::path scene = dir_ / "bad.json";
    std::ofstream(scene) << c.text;
    const auto r = test_support::RunCommand(test_support::IbrBinary() + " render " +
                                            scene.string() + " --out " + out.string());
    EXPECT_NE(r.exit_code, 0) << c.text;
    EXPECT_NE(r.err.find("ibr: error:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.text;
  }
}

}  // namespace
}  // namespace ibr
