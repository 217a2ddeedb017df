// The bunny figures of issue 3: capture ../shared/data/meshes/stanford-bunny.obj
// with sphere:26 at 512 px, export the dataset as a COLMAP dense workspace,
// run the real `colmap stereo_fusion`, and measure the fused points' distance
// to the true mesh as a fraction of the scene size; the 6-view cube capture
// (orthographic: COLMAP has no such camera, so export must refuse it) is
// measured by back-projecting its own depth maps. Prints the figures and
// capture times; asserts accuracy bounds, never speed.
//
// Distance to the mesh: exact point-to-triangle distance (Ericson, Real-Time
// Collision Detection, 5.1.5) over the true triangles, accelerated by a
// uniform grid: triangles are binned by their bounding boxes and a query
// visits shells of cells around the point until no unvisited cell can hold a
// closer triangle. Exact rather than sampled, so tiny errors are not hidden by
// the measuring stick (a rendered-depth comparison would be limited by the
// rasteriser's own float depth and by the pixel grid along rays).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "capture/colmap_dataset.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/metrics.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace capture {
namespace {
namespace fs = std::filesystem;

bool HaveColmap() { return std::system("command -v colmap > /dev/null 2>&1") == 0; }

// Closest point on triangle abc to p (Ericson 2005, sec. 5.1.5).
glm::dvec3 ClosestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                             const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

class MeshDistance {
 public:
  explicit MeshDistance(const core::TriangleMesh& mesh, int cells = 64) : mesh_(mesh) {
    glm::vec3 lo, hi;
    mesh.Bounds(lo, hi);
    lo_ = glm::dvec3(lo);
    const glm::dvec3 extent = glm::dvec3(hi) - lo_;
    cell_ = std::max({extent.x, extent.y, extent.z}) / cells * 1.0001;
    for (int k = 0; k < 3; ++k) n_[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / cell_)));
    bins_.resize(static_cast<size_t>(n_[0]) * n_[1] * n_[2]);
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      glm::dvec3 tlo(1e300), thi(-1e300);
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 v(mesh.positions[mesh.indices[3 * t + k]]);
        tlo = glm::min(tlo, v);
        thi = glm::max(thi, v);
      }
      const glm::ivec3 a = Cell(tlo), b = Cell(thi);
      for (int z = a.z; z <= b.z; ++z)
        for (int y = a.y; y <= b.y; ++y)
          for (int x = a.x; x <= b.x; ++x) bins_[Index({x, y, z})].push_back(t);
    }
  }

  double operator()(const glm::dvec3& p) const {
    // Cells in the Chebyshev shell r around p's (clamped) cell differ from it
    // by r indices along some axis, so they lie at least (r - 1) cells from p
    // (farther still if p is outside the grid): stop once the best distance
    // found is within that bound.
    const glm::ivec3 c = Cell(p);
    double best = 1e300;
    const int max_ring = std::max({n_[0], n_[1], n_[2]});
    for (int r = 0; r <= max_ring; ++r) {
      if (best <= (r - 1) * cell_) break;
      for (int z = c.z - r; z <= c.z + r; ++z) {
        for (int y = c.y - r; y <= c.y + r; ++y) {
          for (int x = c.x - r; x <= c.x + r; ++x) {
            if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) != r)
              continue;  // shell only
            if (x < 0 || y < 0 || z < 0 || x >= n_[0] || y >= n_[1] || z >= n_[2]) continue;
            for (uint32_t t : bins_[Index({x, y, z})]) {
              const glm::dvec3 a(mesh_.positions[mesh_.indices[3 * t]]),
                  b(mesh_.positions[mesh_.indices[3 * t + 1]]),
                  cc(mesh_.positions[mesh_.indices[3 * t + 2]]);
              best = std::min(best, glm::length(p - ClosestOnTriangle(p, a, b, cc)));
            }
          }
        }
      }
    }
    return best;
  }

 private:
  glm::ivec3 Cell(const glm::dvec3& p) const {
    glm::ivec3 c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(std::floor((p[k] - lo_[k]) / cell_)), 0, n_[k] - 1);
    return c;
  }
  size_t Index(const glm::ivec3& c) const {
    return (static_cast<size_t>(c.z) * n_[1] + c.y) * n_[0] + c.x;
  }

  const core::TriangleMesh& mesh_;
  glm::dvec3 lo_{0.0};
  double cell_ = 1;
  int n_[3] = {1, 1, 1};
  std::vector<std::vector<uint32_t>> bins_;
};

// The grid search against brute force, for points inside and outside the grid.
TEST(MeshDistance, AgreesWithBruteForce) {
  const core::TriangleMesh mesh = core::MakeTorus(1.0f, 0.4f, 24, 12);
  const MeshDistance distance(mesh, 16);
  uint32_t state = 12345;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1 << 24);
  };
  for (int i = 0; i < 300; ++i) {
    const glm::dvec3 p(4 * next() - 2, 4 * next() - 2, 2 * next() - 1);
    double brute = 1e300;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      brute = std::min(
          brute,
          glm::length(p - ClosestOnTriangle(p, glm::dvec3(mesh.positions[mesh.indices[3 * t]]),
                                            glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]),
                                            glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]]))));
    }
    ASSERT_DOUBLE_EQ(distance(p), brute) << i;
  }
}

std::vector<glm::dvec3> ReadFusedPly(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  size_t n = 0;
  bool binary_le = false;
  while (std::getline(in, line)) {
    if (line.rfind("format binary_little_endian", 0) == 0) binary_le = true;
    if (line.rfind("element vertex", 0) == 0) n = std::stoul(line.substr(15));
    if (line == "end_header") break;
  }
  EXPECT_TRUE(binary_le) << path;
  std::vector<glm::dvec3> xyz;
  for (size_t i = 0; i < n; ++i) {
    float v[6];  // x y z nx ny nz
    uint8_t rgb[3];
    in.read(reinterpret_cast<char*>(v), sizeof v);
    in.read(reinterpret_cast<char*>(rgb), sizeof rgb);
    if (!in) break;
    xyz.emplace_back(v[0], v[1], v[2]);
  }
  EXPECT_EQ(xyz.size(), n) << path;
  return xyz;
}

struct ErrorStats {
  size_t count = 0;
  double mean = 0, median = 0, p95 = 0, max = 0;  // fractions of the scene size
};

ErrorStats Measure(const MeshDistance& distance, std::vector<glm::dvec3> points,
                   double scene_size) {
  std::vector<double> e;
  e.reserve(points.size());
  for (const auto& p : points) e.push_back(distance(p) / scene_size);
  ErrorStats s;
  s.count = e.size();
  if (e.empty()) return s;
  const core::ErrorStats stats = core::SummarizeErrors(e);
  s.mean = stats.mean;
  s.median = core::Median(e);
  s.p95 = stats.p95;
  s.max = stats.max;
  return s;
}

void Print(const char* what, const ErrorStats& s) {
  std::printf(
      "%s: %zu points, distance to the mesh / scene size: mean %.2e, median %.2e, p95 %.2e, max "
      "%.2e\n",
      what, s.count, s.mean, s.median, s.p95, s.max);
}

// Every depth pixel of a dataset, back-projected into the world.
std::vector<glm::dvec3> BackProject(const Dataset& d) {
  std::vector<glm::dvec3> points;
  for (size_t v = 0; v < d.views.size(); ++v) {
    const Camera& cam = d.camera(d.views[v]);
    const Rigid3 world_from_cam = d.views[v].cam_from_world.Inverse();
    const core::ImageF depth = d.LoadDepth(v);
    for (int row = 0; row < depth.height(); ++row)
      for (int col = 0; col < depth.width(); ++col)
        if (const float z = depth.at(col, row); z > 0)
          points.push_back(world_from_cam * cam.UnprojectPixel(col, row, z));
  }
  return points;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

class BunnyFusionTest : public test_support::GlTest {};

TEST_F(BunnyFusionTest, SphereRigFusesNearTheMeshCubeRigCannotBeExported) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap is not installed";
  const fs::path bunny = test_support::SharedData("meshes/stanford-bunny.obj");
  if (bunny.empty())
    GTEST_SKIP() << "../shared/data/meshes/stanford-bunny.obj is absent (IBR_SHARED_DATA)";
  const fs::path root = test_support::TestOutputDir();
  fs::remove_all(root);
  fs::create_directories(root);
  const SceneMesh scene = LoadSceneMesh(bunny);
  glm::vec3 lo, hi;
  scene.mesh.Bounds(lo, hi);
  const glm::dvec3 extent = glm::dvec3(hi) - glm::dvec3(lo);
  const double scene_size = std::max({extent.x, extent.y, extent.z});  // largest bounding-box side
  const MeshDistance distance(scene.mesh, 96);

  // 26 perspective views at 512 px.
  CaptureOptions options;
  options.size = 512;
  options.rig = "sphere:26";
  auto start = std::chrono::steady_clock::now();
  CaptureDataset(programs(), scene, options, root / "sphere26");
  const double capture_sphere_s = Seconds(start);
  const Dataset sphere = ReadDataset(root / "sphere26");
  ASSERT_EQ(sphere.views.size(), 26u);
  const ErrorStats sphere_depth = Measure(distance, BackProject(sphere), scene_size);

  start = std::chrono::steady_clock::now();
  ExportColmapWorkspace(sphere, root / "ws");
  const double export_s = Seconds(start);
  start = std::chrono::steady_clock::now();
  const auto r = test_support::RunCommand(
      "colmap stereo_fusion --workspace_path " + (root / "ws").string() + " --output_path " +
      (root / "ws/fused.ply").string() + " --input_type geometric --StereoFusion.num_threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const double fusion_s = Seconds(start);
  const ErrorStats fused = Measure(distance, ReadFusedPly(root / "ws/fused.ply"), scene_size);

  // The six orthographic cube faces at 512 px.
  options.rig = "cube";
  start = std::chrono::steady_clock::now();
  CaptureDataset(programs(), scene, options, root / "cube");
  const double capture_cube_s = Seconds(start);
  const Dataset cube = ReadDataset(root / "cube");
  ASSERT_EQ(cube.views.size(), 6u);
  const ErrorStats cube_depth = Measure(distance, BackProject(cube), scene_size);
  try {
    ExportColmapWorkspace(cube, root / "ws_cube");
    ADD_FAILURE() << "an orthographic dataset was exported to COLMAP";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("orthographic"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(root / "ws_cube"));

  std::printf("bunny (%zu triangles), scene size %.4g (largest bounding-box side)\n",
              scene.mesh.triangle_count(), scene_size);
  std::printf(
      "capture sphere:26 at 512 px: %.2f s; export colmap: %.2f s; colmap stereo_fusion (1 "
      "thread): %.2f s\n",
      capture_sphere_s, export_s, fusion_s);
  std::printf("capture cube (6 orthographic views) at 512 px: %.2f s\n", capture_cube_s);
  Print("sphere:26 depth maps back-projected", sphere_depth);
  Print("sphere:26 colmap stereo_fusion", fused);
  Print("cube depth maps back-projected", cube_depth);
  std::printf(
      "cube: no colmap figures: COLMAP has no orthographic camera model, export refuses the rig\n");

  // Bounds (measured on this machine, see the printout): the rasterised
  // depth is float camera z of the true triangles, so back-projected pixels
  // sit on the mesh to float precision; fusion averages consistent pixels
  // over a small cluster, which on the bunny's curved, creased surface pulls
  // points off it by far more than on the box (colmap_binary_test).
  // Measured: back-projected p95 2.3e-7 (sphere) and 5e-8 (cube); fusion
  // 32412 points (each fused point absorbs the consistent pixels of ~13
  // views), median 9.5e-5, p95 4.4e-4, max 2.2e-3. Bounds with ~5x margin.
  EXPECT_LT(sphere_depth.p95, 1e-5);
  EXPECT_LT(cube_depth.p95, 1e-5);
  EXPECT_GT(fused.count, 10000u) << "fusion found too few consistent points";
  EXPECT_LT(fused.median, 5e-4);
  EXPECT_LT(fused.p95, 3e-3);
}

}  // namespace
}  // namespace capture
