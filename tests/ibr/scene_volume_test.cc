// Volume objects in scene files (ibr/volume_object.h, ibr/scene_renderer.h):
// a DVR volume composited with opaque meshes by depth, against the analytic
// transmittance of a homogeneous volume (Beer-Lambert in slice steps).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/volume_io.h"
#include "ibr/scene_renderer.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {
namespace fs = std::filesystem;

constexpr int kVoxels = 32;               // the volume is 32^3 voxels ...
constexpr double kVoxelWorld = 1.0 / 16;  // ... scaled to the world box [-1, 1]^3
constexpr double kOpacity = 0.1;          // per voxel (transfer function, constant)
constexpr int kSize = 96;                 // pixels
constexpr double kCamZ = 6;               // camera at world z = -6 looking +z: cam z = world z + 6

class SceneVolumeTest : public test_support::GlTest {
 protected:
  void SetUp() override {
    test_support::GlTest::SetUp();
    dir_ = fs::temp_directory_path() / fmt::format("ibr_scene_volume_{}", ::getpid());
    fs::create_directories(dir_);
    // Density 1 everywhere (float), so every sample classifies the same.
    core::Volume v = core::Volume::Zeros({kVoxels, kVoxels, kVoxels}, core::ScalarType::kFloat32);
    for (int z = 0; z < kVoxels; ++z)
      for (int y = 0; y < kVoxels; ++y)
        for (int x = 0; x < kVoxels; ++x) v.SetValue(x, y, z, 1.0);
    core::WriteQVis(dir_ / "block.dat", v);
    std::ofstream(dir_ / "white.json")
        << fmt::format(R"({{"points": [[0, 1, 0, 0, {0}], [1, 1, 0, 0, {0}]]}})", kOpacity);
  }
  void TearDown() override {
    fs::remove_all(dir_);
    test_support::GlTest::TearDown();
  }

  render::Frame Render(const std::vector<std::string>& objects) {
    std::string list;
    for (const std::string& o : objects) list += (list.empty() ? "" : ", ") + o;
    std::istringstream in(
        R"({"version": 1, "cameras": {"list": [{"name": "v", "width": 96, "height": 96,)"
        R"( "fx": 40, "fy": 40, "cx": 48, "cy": 48, "orthographic": true,)"
        R"( "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 6]]}]}, "objects": [)" +
        list + "]}");
    scene::ReadOptions options;
    options.base_dir = dir_;
    const scene::Scene s = scene::ReadScene(in, (dir_ / "s.json").string(), options);
    const LoadedScene loaded = LoadScene(programs(), s);
    SceneRenderer renderer(programs(), loaded);
    passes_ = renderer.PassNames();
    return renderer.Render(loaded.views.front().view);
  }

  fs::path dir_;
  std::vector<std::string> passes_;
};

// The volume, red, opacity 0.1 per voxel, no lighting.
const std::string kVolume =
    R"({"name": "block", "type": "volume", "volume": "block.dat", "transfer": "white.json",)"
    R"( "lighting": "none", "transform": {"scale": 0.0625}})";
// Boxes (half extents 0.3 x 0.21 x 0.15): one inside the volume (front face
// at world z = -0.15), one wholly in front of it (z in [-1.75, -1.45]).
const std::string kInside = R"({"name": "inside", "type": "mesh", "mesh": {"shape": "box"},)"
                            R"( "transform": {"translate": [-0.45, 0, 0], "scale": 0.3}})";
const std::string kFront = R"({"name": "front", "type": "mesh", "mesh": {"shape": "box"},)"
                           R"( "transform": {"translate": [0.45, 0, -1.6], "scale": 0.3}})";

// Transmittance of `length_voxels` of the volume drawn as slices at most one
// voxel apart, each with the opacity corrected for its spacing s: n slices
// fall in the interval with n s in [L - s, L + s], so T = (1 - a)^(n s) lies
// between these two.
std::pair<double, double> TransmittanceBounds(double length_voxels) {
  return {std::pow(1 - kOpacity, length_voxels + 1), std::pow(1 - kOpacity, length_voxels - 1)};
}

TEST_F(SceneVolumeTest, DvrVolumeCompositesWithOpaqueMeshesByDepth) {
  // The meshes alone (the volume named but disabled): their colour and depth.
  const auto off = [](std::string o) { return o.insert(o.size() - 1, R"(, "enabled": false)"), o; };
  const render::Frame meshes = Render({off(kVolume), kInside, kFront});
  const render::Frame volume_alone = Render({kVolume});
  EXPECT_EQ(passes_, std::vector<std::string>{"volume:dvr"});
  const render::Frame both = Render({kVolume, kInside, kFront});
  EXPECT_EQ(passes_, (std::vector<std::string>{"volume:dvr", "mesh", "mesh"}));
  // The scene order does not matter: DVR volumes are drawn after opaque objects.
  const render::Frame reversed = Render({kFront, kInside, kVolume});
  EXPECT_EQ(reversed.color, both.color);
  EXPECT_EQ(reversed.depth, both.depth);
  test_support::WriteDebugImage("meshes.png", meshes.color);
  test_support::WriteDebugImage("volume_and_meshes.png", both.color);

  // RGBA8 blending rounds after every slice; the error decays by (1 - a) a
  // slice, so it stays below 0.5 / a = 5 levels.
  const double tolerance = 0.5 / kOpacity + 1;
  int inside = 0, front = 0, open = 0, separated = 0;
  for (int y = 1; y < kSize - 1; ++y)
    for (int x = 1; x < kSize - 1; ++x) {
      // Away from mesh silhouettes: the 3x3 neighbourhood shares the depth.
      const float z = meshes.depth.at(x, y);
      bool interior = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          interior = interior && std::abs(meshes.depth.at(x + dx, y + dy) - z) < 1e-3f;
      if (!interior) continue;
      // The camera z written is the opaque mesh's (DVR writes none).
      ASSERT_NEAR(both.depth.at(x, y), z, 1e-5f) << x << "," << y;
      const double world_z = z - kCamZ;
      if (z > 0 && world_z < -1) {
        // Mesh in front of the volume: every slice behind it fails the depth test.
        ++front;
        for (int c = 0; c < 4; ++c)
          ASSERT_NEAR(both.color.at(x, y, c), meshes.color.at(x, y, c), 1) << x << "," << y;
      } else if (z > 0) {
        // Mesh inside: only the slices between the volume's front (z = -1)
        // and the mesh are drawn over it: C (1 - T) + T M, alpha 255.
        ++inside;
        const auto [t_lo, t_hi] = TransmittanceBounds((world_z + 1) / kVoxelWorld);
        for (int c = 0; c < 3; ++c) {
          const double m = meshes.color.at(x, y, c), volume = c == 0 ? 255 : 0;
          const double at_lo = volume * (1 - t_lo) + t_lo * m,
                       at_hi = volume * (1 - t_hi) + t_hi * m;
          const double lo = std::min(at_lo, at_hi), hi = std::max(at_lo, at_hi);
          const double got = both.color.at(x, y, c);
          ASSERT_GE(got, lo - tolerance) << x << "," << y << " c" << c;
          ASSERT_LE(got, hi + tolerance) << x << "," << y << " c" << c;
          // The test can fail: with the whole volume over the mesh (no depth
          // test) green and blue would be T_total M, far below the band.
          if (c == 1) {
            const auto [total_lo, total_hi] = TransmittanceBounds(2 / kVoxelWorld);
            (void)total_lo;
            separated += total_hi * m + tolerance < lo - tolerance;
          }
        }
        ASSERT_EQ(both.color.at(x, y, 3), 255);
      } else if (volume_alone.color.at(x, y, 3) > 0) {
        // No mesh: the whole depth of the volume, premultiplied red.
        ++open;
        const auto [t_lo, t_hi] = TransmittanceBounds(2 / kVoxelWorld);
        const double got = both.color.at(x, y, 3);
        ASSERT_GE(got, 255 * (1 - t_hi) - tolerance) << x << "," << y;
        ASSERT_LE(got, 255 * (1 - t_lo) + tolerance) << x << "," << y;
        ASSERT_EQ(both.color.at(x, y, 0), both.color.at(x, y, 3));  // red, premultiplied
        ASSERT_EQ(both.color.at(x, y, 1), 0);
      }
    }
  std::printf("volume + meshes: %d px mesh in front, %d px mesh inside, %d px volume only\n", front,
              inside, open);
  // 0.6 x 0.42 world units at 40 px per unit, less the borders.
  EXPECT_GT(front, 250);
  EXPECT_GT(inside, 250);
  EXPECT_GT(open, 2000);
  EXPECT_EQ(separated, inside);
  EXPECT_NO_GL_ERROR();
}

TEST_F(SceneVolumeTest, IsoVolumeIsOpaqueAndWritesDepth) {
  const std::string iso =
      R"({"name": "block", "type": "volume", "volume": "block.dat", "mode": "iso:1",)"
      R"( "lighting": "none", "transform": {"scale": 0.0625}})";
  const render::Frame f = Render({iso, kFront});
  EXPECT_EQ(passes_, (std::vector<std::string>{"volume:iso", "mesh"}));
  // The block's front face at world z = -1 (cam z 5), except where the box
  // in front (cam z 4.25) hides it.
  int face = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float z = f.depth.at(x, y);
      if (z == 0) continue;
      if (std::abs(z - 5.0f) < 0.05f) {
        ++face;
        EXPECT_EQ(f.color.at(x, y, 3), 255);
      } else {
        EXPECT_NEAR(z, 4.25f, 0.01f) << x << "," << y;
      }
    }
  EXPECT_GT(face, 5000);
  EXPECT_NO_GL_ERROR();
}

TEST_F(SceneVolumeTest, BadVolumeSettingsNameFileAndPointer) {
  struct Case {
    std::string object, expect;
  };
  const std::vector<Case> cases = {
      {R"({"type": "volume", "volume": "block.dat", "effect": "melt"})", "/objects/0/effect"},
      {R"({"type": "volume", "volume": "block.dat", "mode": "iso:2"})", "/objects/0/mode"},
      {R"({"type": "volume", "volume": "block.dat", "lighting": "spot"})", "/objects/0/lighting"},
      {R"({"type": "volume", "volume": "block.dat", "map_size": 0, "effect": "peel"})",
       "/objects/0/map_size"},
      {R"({"type": "volume", "volume": "block.dat", "spacing": 0})", "/objects/0/spacing"},
      {R"({"type": "volume", "volume": "block.dat", "transfer": "nope.json"})",
       "/objects/0/transfer"},
      {R"({"type": "volume", "volume": "missing.dat"})", "/objects/0/volume"},
  };
  for (const Case& c : cases) {
    try {
      Render({c.object});
      ADD_FAILURE() << c.object << ": accepted";
    } catch (const core::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("s.json"), std::string::npos) << what;
      EXPECT_NE(what.find(c.expect), std::string::npos) << c.object << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace ibr
