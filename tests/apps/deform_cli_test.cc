// `ibr deform` end to end on Spot: a PNG with its outcome counts printed; a
// dataset's cameras into a dataset folder, checked against a capture of the
// same mesh through the same cameras (a region beside the mesh leaves the
// composite = the mesh, so masks and camera z must match the capture's);
// bad parameters give one error line, a non-zero exit and no output.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "core/deformation.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace apps {
namespace {

namespace fs = std::filesystem;

class DeformCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_support::TestOutputDir().parent_path() / "deform_cli";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    spot_ = test_support::SharedData("meshes/spot.obj").string();
    const auto r = test_support::RunCommand(test_support::IbrBinary() + " capture --mesh " + spot_ +
                                            " --rig ring:3 --size 48 --out " +
                                            (dir_ / "spot_capture").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static std::string Deform(const std::string& args) {
    return test_support::IbrBinary() + " deform " + spot_ + " " + args;
  }
  static fs::path dir_;
  static std::string spot_;
};
fs::path DeformCliTest::dir_;
std::string DeformCliTest::spot_;

// The "pixels mesh M ray-hit H" counts of an output line, -1 if absent.
std::pair<long, long> Counts(const std::string& out, const std::string& what) {
  std::smatch m;
  const std::regex re(what + ": pixels mesh ([0-9]+) ray-hit ([0-9]+)");
  if (!std::regex_search(out, m, re)) return {-1, -1};
  return {std::stol(m[1]), std::stol(m[2])};
}

TEST_F(DeformCliTest, WritesAPngAndPrintsOutcomeCounts) {
  for (const std::string& args :
       std::vector<std::string>{"--deformation twist", "--deformation knife --cut solid --skip",
                                "--deformation knife --cut solid --solid search --skip",
                                "--deformation twist --skip-object false",
                                "--deformation peel --cut hollow --step jacobian",
                                "--deformation bend,pull --amount 0.5,0.2 --width 0,0.1",
                                "--deformation knife --cut solid --implicit depth-cube"}) {
    const fs::path out = dir_ / "one.png";
    fs::remove(out);
    const auto r =
        test_support::RunCommand(Deform(args + " --size 64 --resolution 32 --out " + out.string()));
    ASSERT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    EXPECT_TRUE(fs::exists(out)) << args;
    EXPECT_TRUE(fs::exists(dir_ / "one.depth.exr")) << args;
    const auto [mesh, hit] = Counts(r.out, "view deform");
    // The default region is the mesh's bounds grown: the whole object is ray cast.
    EXPECT_GE(mesh, 0) << r.out;
    EXPECT_GT(hit, 100) << args << "\n" << r.out;
    // The implicit's memory: the 32^3-ish field, or six 32^2 float maps.
    const bool cube = args.find("depth-cube") != std::string::npos;
    EXPECT_NE(
        r.out.find(cube ? "implicit depth-cube 6 x 32x32 R32F, 24576 bytes" : "implicit sdf "),
        std::string::npos)
        << r.out;
  }
}

// Every deformation of the one vocabulary (core::kDeformationTable, the
// names `ibr volume` takes) renders on a mesh with its default amount and
// width and a solid cut: the picture is not empty and differs from the
// undeformed mesh's (a twist of angle 0).
TEST_F(DeformCliTest, EveryDeformationNameRendersAndChangesThePicture) {
  const auto render = [&](const std::string& args, const std::string& name) {
    const fs::path out = dir_ / name;
    fs::remove(out);
    const auto r = test_support::RunCommand(
        Deform(args + " --cut solid --size 96 --resolution 48 --out " + out.string()));
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    return r.exit_code == 0 ? core::ReadImage<uint8_t>(out) : core::Image8(96, 96, 4);
  };
  const auto covered = [](const core::Image8& image) {
    int n = 0;
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x) n += image.at(x, y, 3) > 0;
    return n;
  };
  const core::Image8 none = render("--deformation twist --amount 0", "every_none.png");
  const int object = covered(none);
  ASSERT_GT(object, 1000);
  for (const core::DeformationInfo& info : core::kDeformationTable) {
    const std::string name = core::DeformationKindName(info.kind);
    const core::Image8 image = render("--deformation " + name, "every_" + name + ".png");
    int changed = 0;
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x) {
        int diff = 0;
        for (int c = 0; c < 4; ++c) diff += std::abs(image.at(x, y, c) - none.at(x, y, c));
        changed += diff > 24;
      }
    std::printf("mesh %s: %d of the object's %d pixels changed, %d covered\n", name.c_str(),
                changed, object, covered(image));
    EXPECT_GT(covered(image), object / 4) << name;
    EXPECT_GT(changed, object / 50) << name;
  }
}

// A cut-away is only its cut alpha: without --cut it is drawn solid (the new
// faces counted), never silently as the untouched mesh; an explicit --cut
// none is honoured.
TEST_F(DeformCliTest, ACutAwayWithoutCutIsDrawnSolid) {
  const auto cut_faces = [&](const std::string& args) {
    const fs::path out = dir_ / "cutaway.png";
    const auto r =
        test_support::RunCommand(Deform(args + " --size 64 --resolution 32 --out " + out.string()));
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    std::smatch m;
    const std::regex re("cut-face ([0-9]+)");
    return std::regex_search(r.out, m, re) ? std::stol(m[1]) : -1L;
  };
  for (const char* name : {"clip", "cutaway", "wedge"}) {
    const std::string deformation = std::string("--deformation ") + name;
    const long by_default = cut_faces(deformation);
    EXPECT_GT(by_default, 20) << name;
    EXPECT_EQ(by_default, cut_faces(deformation + " --cut solid")) << name;
    EXPECT_EQ(cut_faces(deformation + " --cut none"), 0) << name;
  }
  EXPECT_EQ(cut_faces("--deformation knife"), 0) << "a knife keeps the default none";
}

TEST_F(DeformCliTest, RendersADatasetsCamerasInItsFrame) {
  const fs::path capture_dir = dir_ / "spot_capture";
  const capture::Dataset captured = capture::ReadDataset(capture_dir);
  // Region beside the mesh (normalised units): nothing is deformed.
  const fs::path out = dir_ / "beside";
  fs::remove_all(out);
  auto r = test_support::RunCommand(Deform("--region 2,2,2,3,3,3 --resolution 16 --cameras " +
                                           capture_dir.string() + " --out " + out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const capture::Dataset rendered = capture::ReadDataset(out);
  ASSERT_EQ(rendered.views.size(), captured.views.size());
  EXPECT_NE(r.out.find("all 3 views"), std::string::npos) << r.out;
  for (size_t v = 0; v < rendered.views.size(); ++v) {
    const core::Image8 mask = rendered.LoadMask(v), truth_mask = captured.LoadMask(v);
    const core::ImageF depth = rendered.LoadDepth(v), truth_depth = captured.LoadDepth(v);
    ASSERT_EQ(mask.width(), truth_mask.width());
    int64_t both = 0, differ = 0;
    double worst = 0.0;
    for (int y = 0; y < mask.height(); ++y)
      for (int x = 0; x < mask.width(); ++x) {
        const bool a = mask.at(x, y) > 127, b = truth_mask.at(x, y) > 127;
        EXPECT_EQ(a, depth.at(x, y) > 0) << "depth is 0 exactly where empty";
        differ += a != b;
        if (a && b) {
          ++both;
          worst = std::max(worst, double(std::abs(depth.at(x, y) - truth_depth.at(x, y))));
        }
      }
    std::printf("view %zu: %lld pixels both, %lld differ, max camera-z difference %.3g\n", v,
                static_cast<long long>(both), static_cast<long long>(differ), worst);
    EXPECT_GT(both, 200);
    // The same mesh rasterised through the same camera: equal up to the
    // capture's own antialiasing of its mask at the silhouette.
    EXPECT_LE(differ, both / 50);
    EXPECT_LT(worst, 1e-3);
  }
  // A twist through the same cameras: every view rendered, counts per view.
  const fs::path twist = dir_ / "twist";
  fs::remove_all(twist);
  r = test_support::RunCommand(Deform("--deformation twist --resolution 32 --cameras " +
                                      capture_dir.string() + " --out " + twist.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(capture::ReadDataset(twist).views.size(), 3u);
  EXPECT_GT(Counts(r.out, "all 3 views").second, 300) << r.out;
}

TEST_F(DeformCliTest, BadParametersLeaveNoOutput) {
  const fs::path out = dir_ / "bad";
  const std::string png = (dir_ / "bad.png").string();
  for (const std::string& args : std::vector<std::string>{
           "--amount nan --out " + out.string(),
           "--amount inf --out " + out.string(),
           "--deformation knife --width -inf --out " + out.string(),
           "--deformation wobble --out " + out.string(),
           "--region 1,0,0,0,1,1 --out " + out.string(),
           "--region 0,0,nan,1,1,1 --out " + out.string(),
           "--region 1,2,3 --out " + out.string(),
           "--placement 0,0,inf --out " + out.string(),
           "--step-voxels nan --out " + out.string(),
           "--cut thick:nan --out " + out.string(),
           "--cut sliced --out " + out.string(),
           "--cut solid --solid mesh --out " + out.string(),
           "--skip-object maybe --out " + out.string(),
           "--implicit octree --out " + out.string(),
           "--cameras " + (dir_ / "missing").string() + " --out " + out.string(),
           "--cameras " + (dir_ / "spot_capture").string() + " --out " + png,
       }) {
    const auto r = test_support::RunCommand(Deform(args + " --size 32 --resolution 16"));
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_NE(r.err.find("ibr: error:"), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(test_support::CountLines(r.err), 1) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
    EXPECT_FALSE(fs::exists(png)) << args;
  }
}

}  // namespace
}  // namespace apps
