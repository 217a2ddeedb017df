// Composite deformations (Correa 2006 Fig. 5, eq. 9-10) in a scene: one
// volume and one deform mesh, each with a "deformations" list of two, each
// placed in its own half of the object (the same vocabulary and placement on
// both kinds). The scene renders, and each of the four deformations changes
// the picture where it is placed: dropping it changes enough pixels, and the
// pixels each one changes are (almost) disjoint from the other three's.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/volume_io.h"
#include "ibr/scene_renderer.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {
namespace fs = std::filesystem;

constexpr int kSize = 128;

// Two deformations per object: a clip whose box is moved by half a box to
// -x (it removes z > 0.6 of the object's left half) and a downward pull whose
// box is scaled by 0.5 about the centre and moved to the top of the right half
// (x in [0.5, 1], z in [0.5, 1]: a dent in the top at x = 0.75). Each entry
// can be left out.
std::string Deformations(bool clip, bool pull) {
  std::vector<std::string> list;
  if (clip) list.push_back(R"({"name": "clip", "amount": 0.6, "placement": "-0.5,0,0"})");
  if (pull) {
    list.push_back(R"({"name": "pull", "amount": -0.8, "width": 0.35,)"
                   R"( "placement": [0.25, 0, 0.25, 0, 0, 0, 0.5]})");
  }
  if (list.empty()) return R"("deformation": "none")";
  std::string text;
  for (const std::string& d : list) text += (text.empty() ? "" : ", ") + d;
  return R"("deformations": [)" + text + "]";
}

class SceneCompositeTest : public test_support::GlTest {
 protected:
  void SetUp() override {
    test_support::GlTest::SetUp();
    dir_ = fs::temp_directory_path() / fmt::format("ibr_scene_composite_{}", ::getpid());
    fs::create_directories(dir_);
    // A ball of density falling off from the centre (uint8, 32^3).
    const int n = 32;
    core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kUint8);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const double r = std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0, z + 0.5 - n / 2.0);
          v.SetValue(x, y, z, std::clamp(255 * (1 - r / (0.45 * n)), 0.0, 255.0));
        }
    core::WriteQVis(dir_ / "ball.dat", v);
  }
  void TearDown() override {
    fs::remove_all(dir_);
    test_support::GlTest::TearDown();
  }

  // The volume (2 units wide) left of x = 0, the sphere (radius 1) right of
  // it, seen from world -y with z up: image x = world x, image up = world z.
  core::Image8 Render(bool volume_clip, bool volume_pull, bool mesh_clip, bool mesh_pull) {
    const std::string volume =
        R"({"name": "ball", "type": "volume", "volume": "ball.dat", "mode": "iso:100", )" +
        Deformations(volume_clip, volume_pull) +
        R"(, "transform": {"translate": [-1.1, 0, 0], "scale": 0.0625}})";
    const std::string mesh = R"({"name": "sphere", "type": "deform", "mesh": {"shape": "sphere"},)"
                             R"( "cut": "solid", "resolution": 48, )" +
                             Deformations(mesh_clip, mesh_pull) +
                             R"(, "transform": {"translate": [1.1, 0, 0]}})";
    std::istringstream in(
        R"({"version": 1, "cameras": {"list": [{"name": "v", "width": 128, "height": 128,)"
        R"( "fx": 160, "fy": 160, "cx": 64, "cy": 64,)"
        R"( "cam_from_world": [[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 6]]}]}, "objects": [)" +
        volume + ", " + mesh + "]}");
    scene::ReadOptions options;
    options.base_dir = dir_;
    const scene::Scene s = scene::ReadScene(in, (dir_ / "s.json").string(), options);
    const LoadedScene loaded = LoadScene(programs(), s);
    SceneRenderer renderer(programs(), loaded);
    return renderer.Render(loaded.views.front().view).color;
  }

  fs::path dir_;
};

// Pixels whose colour differs by more than a rounding step.
std::vector<bool> Changed(const core::Image8& a, const core::Image8& b) {
  std::vector<bool> changed(static_cast<size_t>(kSize) * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      int diff = 0;
      for (int c = 0; c < 4; ++c) diff += std::abs(a.at(x, y, c) - b.at(x, y, c));
      changed[static_cast<size_t>(y) * kSize + x] = diff > 24;
    }
  return changed;
}

TEST_F(SceneCompositeTest, EachPlacedDeformationChangesThePictureWhereItIsPlaced) {
  const core::Image8 all = Render(true, true, true, true);
  test_support::WriteDebugImage("composite_all.png", all);
  int covered = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) covered += all.at(x, y, 3) > 0;
  ASSERT_GT(covered, kSize * kSize / 10) << "the scene drew little";
  const char* names[] = {"volume clip", "volume pull", "mesh clip", "mesh pull"};
  std::vector<std::vector<bool>> changes;
  for (int d = 0; d < 4; ++d) {
    const core::Image8 without = Render(d != 0, d != 1, d != 2, d != 3);
    changes.push_back(Changed(all, without));
  }
  for (int d = 0; d < 4; ++d) {
    const int n = static_cast<int>(std::count(changes[d].begin(), changes[d].end(), true));
    // Where its changes are: the mean image x (the volume is left, the mesh
    // right; the clips are in each object's left half, the pulls in its right).
    double mean_x = 0;
    for (size_t i = 0; i < changes[d].size(); ++i) mean_x += changes[d][i] ? i % kSize : 0;
    mean_x /= std::max(n, 1);
    std::printf("%s: %d pixels changed, mean image x %.1f\n", names[d], n, mean_x);
    EXPECT_GT(n, 40) << names[d];  // a notch of a few pixels wide at least
    // Image x = 64 + 160 x / 6 (world x at depth 6): the volume spans 8..61,
    // the sphere 67..120; each range is the deformed part with some margin.
    const double lo[] = {4, 36, 62, 94}, hi[] = {40, 62, 98, 124};
    EXPECT_GT(mean_x, lo[d]) << names[d];
    EXPECT_LT(mean_x, hi[d]) << names[d];
    for (int e = d + 1; e < 4; ++e) {
      int both = 0;
      for (size_t i = 0; i < changes[d].size(); ++i) both += changes[d][i] && changes[e][i];
      EXPECT_LE(both, n / 10) << names[d] << " and " << names[e];
    }
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
