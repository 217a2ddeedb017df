// core/distance_field: the CGAL-backed signed distance field against brute
// force in double (closest point on every triangle, Ericson 2005 sec. 5.1.5;
// sign from the generalised winding number, Jacobson et al. 2013), which
// shares no code with CGAL's AABB tree or ray-cast inside test.
#include "core/distance_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>

#include "core/error.h"
#include "core/mesh.h"
#include "core/ply_io.h"

namespace core {
namespace {

glm::dvec3 ClosestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                             const glm::dvec3& c) {
  glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  glm::dvec3 bp = p - b;
  double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  glm::dvec3 cp = p - c;
  double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Brute-force signed distance: min over all triangles; sign from the winding
// number (sum of signed solid angles / 4 pi, Van Oosterom-Strackee).
double BruteSignedDistance(const TriangleMesh& mesh, const glm::dvec3& p) {
  double best = 1e300, winding = 0.0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]), b(mesh.positions[mesh.indices[3 * t + 1]]),
        c(mesh.positions[mesh.indices[3 * t + 2]]);
    best = std::min(best, glm::length(p - ClosestOnTriangle(p, a, b, c)));
    glm::dvec3 ra = a - p, rb = b - p, rc = c - p;
    double la = glm::length(ra), lb = glm::length(rb), lc = glm::length(rc);
    double num = glm::dot(ra, glm::cross(rb, rc));
    double den =
        la * lb * lc + glm::dot(ra, rb) * lc + glm::dot(rb, rc) * la + glm::dot(rc, ra) * lb;
    winding += 2.0 * std::atan2(num, den);
  }
  winding /= 4.0 * std::numbers::pi;
  return winding > 0.5 ? -best : best;
}

// Inside the exact band the field equals the brute-force distance (float
// rounding); beyond it the sign is exact and the value, an interpolation of
// exact block corners, lies beyond the band and within a block diagonal of
// the truth. band_voxels <= 0: every node exact.
void ExpectMatchesBruteForce(const TriangleMesh& mesh, const char* name, int resolution,
                             double band_voxels = 4.0) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  Box3d box{glm::dvec3(lo) - 0.2,
            glm::dvec3(hi) + 0.1};  // asymmetric: grid not centred on the mesh
  DistanceFieldOptions options;
  options.resolution = resolution;
  options.threads = 2;
  options.exact_band_voxels = band_voxels;
  DistanceField field = BuildDistanceField(mesh, box, options, name);
  ASSERT_EQ(field.values.size(), static_cast<size_t>(field.size.x) * field.size.y * field.size.z);
  const double diagonal = std::sqrt(3.0) * 4 * field.spacing;
  double max_diff = 0.0, max_far_diff = 0.0;
  int sign_errors = 0, band_errors = 0, far_nodes = 0;
  for (int k = 0; k < field.size.z; ++k)
    for (int j = 0; j < field.size.y; ++j)
      for (int i = 0; i < field.size.x; ++i) {
        glm::dvec3 p = field.origin + field.spacing * glm::dvec3(i, j, k);
        double truth = BruteSignedDistance(mesh, p);
        double got = field.At(i, j, k);
        if (std::abs(truth) <= field.exact_band) {
          max_diff = std::max(max_diff, std::abs(truth - got));
        } else {
          ++far_nodes;
          max_far_diff = std::max(max_far_diff, std::abs(truth - got));
          band_errors += !(std::abs(got) > field.exact_band);
        }
        // Points within float rounding of the surface may take either sign.
        if (std::abs(truth) > 1e-6 && (truth < 0) != (got < 0)) ++sign_errors;
      }
  std::printf(
      "%s: %dx%dx%d samples, %zu triangles, band %.3g voxels: max |sdf - brute force| = %.3g in "
      "the band; %d nodes beyond it, max difference %.3g (block diagonal %.3g); %lld distance "
      "queries\n",
      name, field.size.x, field.size.y, field.size.z, mesh.triangle_count(), band_voxels, max_diff,
      far_nodes, max_far_diff, diagonal, static_cast<long long>(field.distance_queries));
  EXPECT_EQ(sign_errors, 0) << name;
  EXPECT_EQ(band_errors, 0) << name;
  // Float storage: relative rounding of distances up to ~1.5 units.
  EXPECT_LT(max_diff, 1e-6) << name;
  EXPECT_LE(max_far_diff, diagonal) << name;
  if (band_voxels <= 0) {
    EXPECT_EQ(far_nodes, 0) << name;
  }
}

TEST(DistanceField, SphereMatchesBruteForce) {
  ExpectMatchesBruteForce(MakeSphere(0.8f, 8, 12), "sphere", 24);
}

TEST(DistanceField, TorusMatchesBruteForce) {
  ExpectMatchesBruteForce(MakeTorus(0.6f, 0.25f, 12, 8), "torus", 24);
}

TEST(DistanceField, CupMatchesBruteForce) {
  // Concave: the inside test must not be fooled by the cavity.
  ExpectMatchesBruteForce(MakeCup(0.7f, 0.9f, 0.15f, 12), "cup", 24);
}

TEST(DistanceField, BoxMatchesBruteForce) {
  // Grid nodes on the faces' planes and sharp edges (the twisted-box test's mesh).
  ExpectMatchesBruteForce(MakeBox(glm::vec3(0.3f, 0.3f, 0.4f)), "box", 40);
  ExpectMatchesBruteForce(MakeBox(glm::vec3(0.3f, 0.3f, 0.4f)), "box (no band)", 40, 0.0);
}

// Analytic truth, independent of any triangle code: a finely tessellated
// sphere against |p| - r and a box against the box's exact signed distance.
// In the band the error is the tessellation's (sphere: the inscribed
// polyhedron lies within r (1 - cos(pi / rings)) of the sphere) plus float
// rounding; beyond it within the block bound (half a 4^3 block's diagonal);
// every node's sign right where the truth is farther than that error.
struct AnalyticErrors {
  double band_max_voxels = 0, far_max_voxels = 0;
  int sign_errors = 0, band_nodes = 0;
};
template <typename Truth>
AnalyticErrors CompareAnalytic(const DistanceField& field, double surface_error,
                               const Truth& truth) {
  AnalyticErrors e;
  for (int k = 0; k < field.size.z; ++k)
    for (int j = 0; j < field.size.y; ++j)
      for (int i = 0; i < field.size.x; ++i) {
        const double t = truth(field.origin + field.spacing * glm::dvec3(i, j, k));
        const double got = field.At(i, j, k);
        const double error_voxels = std::abs(got - t) / field.spacing;
        if (std::abs(t) <= field.exact_band - surface_error) {
          ++e.band_nodes;
          e.band_max_voxels = std::max(e.band_max_voxels, error_voxels);
        } else if (std::abs(t) > field.exact_band + surface_error) {
          e.far_max_voxels = std::max(e.far_max_voxels, error_voxels);
        }
        if (std::abs(t) > surface_error + 1e-6 && (t < 0) != (got < 0)) ++e.sign_errors;
      }
  return e;
}

TEST(DistanceField, AnalyticSphereAndBoxWithinVoxelBounds) {
  const double half_block_diagonal_voxels = 0.5 * std::sqrt(3.0) * 4;
  {
    const float r = 0.5f;
    const int rings = 64;
    const TriangleMesh sphere = MakeSphere(r, rings, 2 * rings);
    DistanceFieldOptions options;
    options.resolution = 64;
    options.threads = 2;
    const DistanceField field =
        BuildDistanceField(sphere, Box3d{{-0.7, -0.65, -0.6}, {0.6, 0.7, 0.75}}, options, "sphere");
    const double tessellation = r * (1 - std::cos(std::numbers::pi / rings));
    const AnalyticErrors e = CompareAnalytic(
        field, tessellation, [&](const glm::dvec3& p) { return glm::length(p) - r; });
    const double bound_voxels = tessellation / field.spacing + 1e-4;
    std::printf(
        "analytic sphere r %.2f, %d rings, resolution %d: band max error %.4f voxels (bound "
        "%.4f) over %d nodes, beyond the band %.3f voxels (bound %.3f), %d sign errors\n",
        r, rings, options.resolution, e.band_max_voxels, bound_voxels, e.band_nodes,
        e.far_max_voxels, half_block_diagonal_voxels + bound_voxels, e.sign_errors);
    EXPECT_GT(e.band_nodes, 1000);
    EXPECT_LE(e.band_max_voxels, bound_voxels);
    EXPECT_LE(e.far_max_voxels, half_block_diagonal_voxels + bound_voxels);
    EXPECT_EQ(e.sign_errors, 0);
  }
  {
    const glm::dvec3 half(0.3, 0.2, 0.45);
    const TriangleMesh box = MakeBox(glm::vec3(half));
    DistanceFieldOptions options;
    options.resolution = 64;
    options.threads = 2;
    const DistanceField field =
        BuildDistanceField(box, Box3d{{-0.55, -0.5, -0.7}, {0.6, 0.45, 0.65}}, options, "box");
    // The exact signed distance of an axis-aligned box (Quilez).
    const AnalyticErrors e = CompareAnalytic(field, 0.0, [&](const glm::dvec3& p) {
      const glm::dvec3 q = glm::abs(p) - half;
      return glm::length(glm::max(q, 0.0)) + std::min(std::max({q.x, q.y, q.z}), 0.0);
    });
    std::printf(
        "analytic box: band max error %.2g voxels over %d nodes, beyond the band %.3f voxels, %d "
        "sign errors\n",
        e.band_max_voxels, e.band_nodes, e.far_max_voxels, e.sign_errors);
    EXPECT_GT(e.band_nodes, 1000);
    EXPECT_LE(e.band_max_voxels, 1e-4);  // float storage only
    EXPECT_LE(e.far_max_voxels, half_block_diagonal_voxels);
    EXPECT_EQ(e.sign_errors, 0);
  }
}

// A real scanner mesh (MeshLab's screwdriver.ply, closed: ../shared/data/tests-real/
// meshes/README.md): at band nodes and at nodes spread over the grid, the
// field's sign equals the generalised winding number's and its band values
// the brute-force distance.
TEST(DistanceField, RealScannerMeshSignsMatchWindingNumber) {
  const std::filesystem::path file =
      std::filesystem::path(IBR_REAL_DATA_DIR) / "meshes" / "screwdriver.ply";
  const TriangleMesh mesh = ReadPly(file).mesh;
  ASSERT_EQ(FindMeshBoundary(mesh).boundary_edges, 0u) << "the file must be closed";
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const double margin = 0.1 * glm::length(glm::dvec3(hi - lo));
  DistanceFieldOptions options;
  options.resolution = 64;
  options.threads = 2;
  const DistanceField field = BuildDistanceField(
      mesh, Box3d{glm::dvec3(lo), glm::dvec3(hi)}.Grown(margin), options, file.string());
  // Every 7th band node and as many nodes drawn over the grid.
  std::vector<glm::ivec3> nodes;
  for (int k = 0; k < field.size.z; ++k)
    for (int j = 0; j < field.size.y; ++j)
      for (int i = 0; i < field.size.x; ++i) {
        if (std::abs(field.At(i, j, k)) <= field.exact_band && (i + j + k) % 7 == 0)
          nodes.emplace_back(i, j, k);
      }
  const size_t band_nodes = nodes.size();
  std::mt19937 random(7);
  for (size_t n = 0; n < band_nodes; ++n) {
    nodes.emplace_back(std::uniform_int_distribution<int>(0, field.size.x - 1)(random),
                       std::uniform_int_distribution<int>(0, field.size.y - 1)(random),
                       std::uniform_int_distribution<int>(0, field.size.z - 1)(random));
  }
  int sign_errors = 0;
  double band_max_voxels = 0.0;
  for (size_t n = 0; n < nodes.size(); ++n) {
    const glm::ivec3 v = nodes[n];
    const double truth = BruteSignedDistance(mesh, field.origin + field.spacing * glm::dvec3(v));
    const double got = field.At(v.x, v.y, v.z);
    if (std::abs(truth) > 1e-6 && (truth < 0) != (got < 0)) ++sign_errors;
    if (n < band_nodes)
      band_max_voxels = std::max(band_max_voxels, std::abs(got - truth) / field.spacing);
  }
  std::printf(
      "screwdriver.ply: %zu triangles, %dx%dx%d field: %zu band and %zu spread nodes, band max "
      "error %.2g voxels, %d sign errors\n",
      mesh.triangle_count(), field.size.x, field.size.y, field.size.z, band_nodes, band_nodes,
      band_max_voxels, sign_errors);
  EXPECT_GT(band_nodes, 500u);
  EXPECT_EQ(sign_errors, 0);
  EXPECT_LE(band_max_voxels, 1e-4);  // float storage only
}

TEST(DistanceField, FarBlocksKeepTheSignAndStayBeyondTheBand) {
  // A small sphere in a large box: most 4^3 blocks are far from the surface
  // and interpolated from their corners (checked against brute force by
  // ExpectMatchesBruteForce: sign exact, |value| > band, error < diagonal).
  TriangleMesh sphere = MakeSphere(0.25f, 8, 12);
  Box3d box{{-1.2, -1.1, -1.0}, {1.3, 1.2, 1.1}};
  DistanceFieldOptions options;
  options.resolution = 48;
  options.threads = 2;
  DistanceField field = BuildDistanceField(sphere, box, options, "small sphere");
  const int64_t nodes = static_cast<int64_t>(field.values.size());
  std::printf("small sphere: %lld of %lld nodes queried exactly\n",
              static_cast<long long>(field.distance_queries), static_cast<long long>(nodes));
  EXPECT_LT(field.distance_queries, nodes / 3);
  double worst_far = 0.0;
  int sign_errors = 0, band_errors = 0, band_mismatch = 0;
  for (int k = 0; k < field.size.z; ++k)
    for (int j = 0; j < field.size.y; ++j)
      for (int i = 0; i < field.size.x; ++i) {
        glm::dvec3 p = field.origin + field.spacing * glm::dvec3(i, j, k);
        double truth = BruteSignedDistance(sphere, p), got = field.At(i, j, k);
        sign_errors += (truth < 0) != (got < 0);
        if (std::abs(truth) <= field.exact_band) {
          band_mismatch += std::abs(truth - got) > 1e-6;
        } else {
          band_errors += !(std::abs(got) > field.exact_band);
          worst_far = std::max(worst_far, std::abs(truth - got));
        }
      }
  std::printf("small sphere: beyond the band max |field - brute force| = %.4g (diagonal %.4g)\n",
              worst_far, std::sqrt(3.0) * 4 * field.spacing);
  EXPECT_EQ(sign_errors, 0);
  EXPECT_EQ(band_errors, 0);
  EXPECT_EQ(band_mismatch, 0);
  EXPECT_GT(worst_far, 1e-4);  // the far nodes really were interpolated
  EXPECT_LE(worst_far, std::sqrt(3.0) * 4 * field.spacing);
}

// The skip bound of the deform pass: at random points (not nodes) a
// trilinear lookup exceeds the true distance by at most LookupOverestimate,
// with the band (far blocks interpolated) and without it.
TEST(DistanceField, LookupOverestimateBoundsTheLookupsExcess) {
  TriangleMesh sphere = MakeSphere(0.25f, 8, 12);
  const Box3d box{{-1.2, -1.1, -1.0}, {1.3, 1.2, 1.1}};
  std::mt19937 rng(5);
  for (double band : {4.0, 0.0}) {
    DistanceFieldOptions options;
    options.resolution = 32;
    options.threads = 2;
    options.exact_band_voxels = band;
    const DistanceField field = BuildDistanceField(sphere, box, options, "small sphere");
    const double bound = field.LookupOverestimate();
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const Box3d grid = field.Bounds();
    double worst = -1e30;
    for (int n = 0; n < 4000; ++n) {
      const glm::dvec3 p = grid.lo + (grid.hi - grid.lo) * glm::dvec3(u01(rng), u01(rng), u01(rng));
      const double truth = std::abs(BruteSignedDistance(sphere, p));
      worst = std::max(worst, std::abs(field.Sample(p)) - truth);
    }
    std::printf("band %.0f voxels: largest |lookup| - |distance| %.4g, bound %.4g\n", band, worst,
                bound);
    EXPECT_LE(worst, bound) << "band " << band;
    EXPECT_GT(worst, 0.0);  // lookups do exceed it: the bound is not vacuous
  }
}

TEST(DistanceField, ExactEverywhereWithoutABand) {
  ExpectMatchesBruteForce(MakeTorus(0.6f, 0.25f, 12, 8), "torus (no band)", 24, 0.0);
  ExpectMatchesBruteForce(MakeCup(0.7f, 0.9f, 0.15f, 12), "cup (band 1 voxel)", 37, 1.0);
}

TEST(DistanceField, BoxWithSplitVerticesIsClosed) {
  // MakeBox duplicates corners per face (24 vertices); welding makes it closed.
  TriangleMesh box = MakeBox(glm::vec3(0.5f, 0.3f, 0.4f));
  EXPECT_EQ(FindMeshBoundary(box).boundary_edges, 0u);
  MeshDistance distance(box, false, "box");
  EXPECT_NEAR(distance.SignedDistance({0, 0, 0}), -0.3, 1e-7);  // 0.3f
  EXPECT_NEAR(distance.SignedDistance({1.5, 0, 0}), 1.0, 1e-7);
  glm::dvec3 closest, normal;
  distance.ClosestPoint({0, 2, 0}, &closest, &normal);
  EXPECT_NEAR(closest.y, 0.3, 1e-7);
  EXPECT_NEAR(normal.y, 1.0, 1e-12);  // outward
}

TEST(DistanceField, ClosedOutwardMeshesAreRecognised) {
  // Welded (CGAL's closed mesh) and outward: yes.
  const MeshDistance sphere(MakeSphere(0.5f, 12, 24), false, "sphere");
  const TriangleMesh closed = sphere.closed_mesh();
  EXPECT_TRUE(IsClosedOutward(closed));
  // Split vertices with bit-equal positions (MakeBox's 24 corners): yes.
  EXPECT_TRUE(IsClosedOutward(MakeBox(glm::vec3(0.5f, 0.3f, 0.4f))));
  // Two disjoint outward components: yes.
  TriangleMesh two = closed;
  for (const glm::vec3& p : closed.positions) two.positions.push_back(p + glm::vec3(2, 0, 0));
  for (uint32_t i : closed.indices) two.indices.push_back(i + uint32_t(closed.positions.size()));
  EXPECT_TRUE(IsClosedOutward(two));
  // Inside out: no.
  TriangleMesh inverted = closed;
  for (size_t t = 0; t < inverted.triangle_count(); ++t)
    std::swap(inverted.indices[3 * t + 1], inverted.indices[3 * t + 2]);
  EXPECT_FALSE(IsClosedOutward(inverted));
  // A cavity (an inward component inside): no (its component volume < 0).
  TriangleMesh cavity = closed;
  for (const glm::vec3& p : inverted.positions) cavity.positions.push_back(0.5f * p);
  for (uint32_t i : inverted.indices)
    cavity.indices.push_back(i + uint32_t(closed.positions.size()));
  EXPECT_FALSE(IsClosedOutward(cavity));
  // One triangle flipped (inconsistent orientation), one removed (a hole):
  // no.
  TriangleMesh flipped = closed;
  std::swap(flipped.indices[1], flipped.indices[2]);
  EXPECT_FALSE(IsClosedOutward(flipped));
  TriangleMesh open = closed;
  open.indices.resize(open.indices.size() - 3);
  EXPECT_FALSE(IsClosedOutward(open));
  // MakeSphere's seam column repeats with rounding differences: positions
  // that are not bit-equal leave cracks a rasteriser may show; no.
  EXPECT_FALSE(IsClosedOutward(MakeSphere(0.5f, 12, 24)));
  // A degenerate triangle (two equal corners) and the empty mesh: no.
  TriangleMesh degenerate = closed;
  degenerate.indices.insert(degenerate.indices.end(), {0, 0, 1});
  EXPECT_FALSE(IsClosedOutward(degenerate));
  EXPECT_FALSE(IsClosedOutward(TriangleMesh{}));
}

TEST(DistanceField, SampleIsTrilinearAndExactOnPlanes) {
  // The distance to a large box face is linear: trilinear interpolation is exact.
  TriangleMesh box = MakeBox(glm::vec3(10.0f));
  DistanceFieldOptions options;
  options.resolution = 9;
  DistanceField field = BuildDistanceField(box, {{-1, -1, 8}, {1, 1, 12}}, options, "box");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 100; ++n) {
    glm::dvec3 p(u(rng), u(rng), 10.0 + 2 * u(rng));
    EXPECT_NEAR(field.Sample(p), p.z - 10.0, 1e-5);
  }
}

TEST(DistanceField, OpenMeshIsRefusedUnlessCapped) {
  TriangleMesh cylinder = MakeCylinder(0.5f, 1.0f, 16, 4);
  MeshBoundary boundary = FindMeshBoundary(cylinder);
  EXPECT_EQ(boundary.boundary_edges, 32u);
  EXPECT_EQ(boundary.boundary_loops, 2u);
  try {
    MeshDistance distance(cylinder, false, "cylinder.obj");
    FAIL() << "open mesh accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("32 boundary edges"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cylinder.obj"), std::string::npos) << e.what();
  }
  MeshDistance capped(cylinder, true, "cylinder.obj");
  EXPECT_EQ(capped.capped_holes(), 2u);
  EXPECT_EQ(FindMeshBoundary(capped.closed_mesh()).boundary_edges, 0u);
  // The caps are planar (z = +-0.5): inside the can and distance to the caps.
  EXPECT_LT(capped.SignedDistance({0, 0, 0}), 0.0);
  EXPECT_NEAR(capped.SignedDistance({0, 0, 0.9}), 0.4, 1e-6);
  EXPECT_NEAR(capped.SignedDistance({0, 0, 0.45}), -0.05, 1e-6);
}

TEST(DistanceField, BadInput) {
  TriangleMesh sphere = MakeSphere(0.5f, 6, 8);
  DistanceFieldOptions options;
  options.resolution = 1;
  EXPECT_THROW(BuildDistanceField(sphere, {{-1, -1, -1}, {1, 1, 1}}, options, "s"), InputError);
  options.resolution = 8;
  EXPECT_THROW(BuildDistanceField(sphere, {{-1, -1, -1}, {1, -1, 1}}, options, "s"), InputError);
  EXPECT_THROW(BuildDistanceField(sphere, {{-1, -1, -1}, {1, NAN, 1}}, options, "s"), InputError);
  EXPECT_THROW(MeshDistance(TriangleMesh{}, false, "empty"), InputError);
}

}  // namespace
}  // namespace core
