// Empty-space skipping for the depth-object / visual-hull ray path
// (ibr/empty_space.h): the chessboard distance against brute force, the
// occupancy proof against the CPU mirror of the map test on random points
// (no point of a voxel called empty is accepted by enough maps), and on the
// GPU the skipping march against the fine march on random views (same first
// surface within the refinement tolerance).
#include "ibr/empty_space.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/error.h"
#include "ibr/depth_object.h"
#include "tests/ibr/scenes.h"
#include "tests/support/gl_test.h"
#include "verify/reference.h"

namespace ibr {
namespace {

using testing::Sphere;

TEST(ChessboardDistanceTest, MatchesBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    const int n = 9 + trial;
    std::vector<uint8_t> g(static_cast<size_t>(n) * n * n, 1);
    std::vector<glm::ivec3> occupied;
    std::uniform_int_distribution<int> pick(0, n - 1);
    for (int k = 0; k < 1 + trial; ++k) {
      const glm::ivec3 c(pick(rng), pick(rng), pick(rng));
      g[(static_cast<size_t>(c.z) * n + c.y) * n + c.x] = 0;
      occupied.push_back(c);
    }
    ChessboardDistance(n, g);
    for (int z = 0; z < n; ++z) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          int best = 255;
          for (const glm::ivec3& c : occupied) {
            best =
                std::min(best, std::max({std::abs(c.x - x), std::abs(c.y - y), std::abs(c.z - z)}));
          }
          ASSERT_EQ(g[(static_cast<size_t>(z) * n + y) * n + x], best) << x << " " << y << " " << z;
        }
      }
    }
  }
  // No occupied voxel at all: everything is as far as the cap.
  std::vector<uint8_t> g(27, 1);
  ChessboardDistance(3, g);
  for (uint8_t v : g) EXPECT_EQ(v, 255);
}

struct Rig {
  std::string name;
  MapSet maps;
  DepthObjectOptions options;
};

std::vector<Rig> Rigs() {
  const std::vector<Sphere> spheres = {{{-0.3, 0.1, 0.0}, 0.45}, {{0.35, -0.2, 0.15}, 0.3}};
  std::vector<Rig> rigs;
  MapSet cube;
  cube.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  cube.maps = CubeRigMaps({0, 0, 0}, 1.0, 96);
  for (ImageMap& m : cube.maps) testing::RenderSpheres(spheres, m);
  MapSet ring;
  ring.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  ring.maps = testing::RingMaps(7, 3.0, 0.8, 80);
  for (ImageMap& m : ring.maps) testing::RenderSpheres(spheres, m);
  DepthObjectOptions o;
  rigs.push_back({"cube depth object", cube, o});
  o.robust_k = 1;
  rigs.push_back({"ring depth object robust k=1", ring, o});
  o.robust_k = 0;
  o.method = Method::kVisualHull;
  rigs.push_back({"ring visual hull", ring, o});
  o.outside = OutsidePolicy::kFail;
  rigs.push_back({"ring visual hull, outside fails", ring, o});
  return rigs;
}

SkipGridPolicy PolicyOf(const DepthObjectOptions& o) {
  SkipGridPolicy p;
  p.visual_hull = o.method == Method::kVisualHull;
  p.outside_passes = o.outside == OutsidePolicy::kPass;
  p.invalid_depth_passes = o.invalid_depth == InvalidDepthPolicy::kNoConstraint;
  p.rejections_needed = o.robust_k + 1;
  return p;
}

// Every random point of a voxel the grid calls empty is rejected by at least
// k + 1 active maps under the CPU mirror of the GPU map test, and the grid
// proves a good part of the box empty (it is not vacuous).
TEST(SkipGridTest, EmptyVoxelsHoldNoAcceptedPoint) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Rig& rig : Rigs()) {
    const MapTables tables = MakeMapTables(rig.maps, rig.options.method);
    ViewCamera world;  // identity pose: view camera space = world space
    world.camera = MapCamera::Pinhole(8, 8, 8, 8, 4, 4);
    DepthObjectOptions o = rig.options;
    o.hull_skip_opposite = false;
    const FrameParams f = PrepareFrame(rig.maps, world, o);
    const SkipGrid grid = BuildSkipGrid(rig.maps, tables.depth, tables.width, tables.height,
                                        f.active, PolicyOf(o), 32);
    const int n = grid.resolution;
    const double empty_fraction = static_cast<double>(grid.empty_voxels) / (double(n) * n * n);
    std::printf("%s: %.1f %% of the voxels proven empty\n", rig.name.c_str(), 100 * empty_fraction);
    EXPECT_GT(empty_fraction, 0.3) << rig.name;
    const ReferenceVariant variant = ReferenceVariant::From(o);
    int64_t checked = 0;
    for (int z = 0; z < n; ++z) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          if (grid.distance[grid.Index(x, y, z)] == 0) continue;
          for (int s = 0; s < 6; ++s) {
            // Corners and faces included: s = 0 is the voxel's low corner.
            const glm::dvec3 jitter =
                s == 0 ? glm::dvec3(0) : glm::dvec3(unit(rng), unit(rng), unit(rng));
            const glm::dvec3 pb = (glm::dvec3(x, y, z) + jitter) / double(n);
            const glm::vec3 p(rig.maps.world_from_box * glm::dvec4(pb, 1.0));
            int rejected = 0;
            for (int a : f.active) {
              glm::ivec3 texel;
              rejected += !ReferenceMapAccepts(tables, f.maps[a], variant, p, texel);
            }
            ASSERT_GE(rejected, o.robust_k + 1)
                << rig.name << " voxel " << x << " " << y << " " << z;
            ++checked;
          }
        }
      }
    }
    EXPECT_GT(checked, 0);
  }
}

TEST(SkipGridTest, RejectsBadResolution) {
  MapSet set;
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, 8);
  const MapTables tables = MakeMapTables(set, Method::kVisualHull);
  EXPECT_THROW(BuildSkipGrid(set, tables.depth, tables.width, tables.height, {0}, {}, 0),
               core::InputError);
  EXPECT_THROW(BuildSkipGrid(set, tables.depth, tables.width, tables.height, {0}, {}, 256),
               core::InputError);
}

class SkipRayTest : public test_support::GlTest {};

// The skipping march finds the fine march's first surface: on random
// perspective and orthographic views of every rig, the same pixels are
// covered and the depths agree within the refinement tolerance (the
// bisection brackets the crossing to step / 2^(refine_steps + 1); the two
// marches sample the same lattice of t, up to float rounding of its sums).
// Where one step holds several crossings of the nearest-texel field (a
// texel terrace edge), a bracket shifted by rounding may bisect to another
// of them: allowed on at most 0.5 % of the pixels, and never beyond the one
// step both brackets share.
TEST_F(SkipRayTest, SameFirstSurfaceAsTheFineMarch) {
  std::mt19937 rng(23);
  for (const Rig& rig : Rigs()) {
    DepthObjectRenderer renderer(programs(), rig.maps);
    for (int v = 0; v < 4; ++v) {
      const glm::dvec3 dir = testing::RandomUnit(rng);
      const glm::dvec3 up = std::abs(dir.z) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
      const ViewCamera view =
          v == 3 ? testing::OrthographicView(3.0 * dir, {0, 0, 0}, up, 160, 1.2)
                 : testing::PerspectiveView((2.6 + 0.5 * v) * dir, {0, 0, 0}, up, 160);
      DepthObjectOptions o = rig.options;
      o.slicing = Slicing::kRay;
      o.slices = 128;
      o.texturing = Texturing::kNone;
      o.skip_grid = 0;
      const render::Frame fine = renderer.RenderFrame(view, o);
      o.skip_grid = 48;
      const render::Frame skip = renderer.RenderFrame(view, o);
      const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
      const double tolerance = frame.stack.spacing_world / std::pow(2.0, o.refine_steps + 1) + 1e-5;
      int64_t covered = 0, mismatched = 0, far = 0, beyond_step = 0;
      double worst = 0;
      for (int y = 0; y < 160; ++y) {
        for (int x = 0; x < 160; ++x) {
          const bool a = fine.Covered(x, y), b = skip.Covered(x, y);
          covered += a;
          if (a != b) {
            ++mismatched;
            continue;
          }
          if (!a) continue;
          const double e = std::abs(fine.depth.at(x, y) - skip.depth.at(x, y));
          worst = std::max(worst, e);
          far += e > tolerance;
          beyond_step += e > frame.stack.spacing_world * 1.001;
        }
      }
      std::printf(
          "%s view %d: %lld covered, %lld coverage mismatches, %lld depths beyond %.2g (worst "
          "%.2g)\n",
          rig.name.c_str(), v, static_cast<long long>(covered), static_cast<long long>(mismatched),
          static_cast<long long>(far), tolerance, worst);
      EXPECT_GT(covered, 500) << rig.name << " view " << v;
      EXPECT_EQ(mismatched, 0) << rig.name << " view " << v;
      EXPECT_LE(far, covered / 200) << rig.name << " view " << v;
      EXPECT_EQ(beyond_step, 0) << rig.name << " view " << v;
    }
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
