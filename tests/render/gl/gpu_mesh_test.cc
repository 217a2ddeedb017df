// GpuMesh's vertex-cache order (render/gl/gpu_mesh.h): every triangle kept
// with its winding, every used vertex once, fewer vertices shaded than a
// scrambled order, and the same picture whatever order the mesh came in.
#include "render/gl/gpu_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <deque>
#include <random>
#include <vector>

#include "core/mesh.h"
#include "core/projection.h"
#include "render/passes/mesh_pass.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

using Triangle = std::array<uint32_t, 3>;

// A triangle rotated to start at its smallest index: equal for the same
// triangle with the same winding, different for the flipped one.
Triangle Canonical(Triangle t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

std::vector<Triangle> Triangles(const std::vector<uint32_t>& indices) {
  std::vector<Triangle> out;
  for (size_t i = 0; i + 2 < indices.size(); i += 3)
    out.push_back({indices[i], indices[i + 1], indices[i + 2]});
  return out;
}

// The sphere with its triangles shuffled, each rotated at random, and three
// vertices no triangle uses (the worst order a file can bring).
core::TriangleMesh Scrambled(const core::TriangleMesh& mesh, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Triangle> tris = Triangles(mesh.indices);
  std::shuffle(tris.begin(), tris.end(), rng);
  core::TriangleMesh out = mesh;
  out.indices.clear();
  for (Triangle t : tris) {
    std::rotate(t.begin(), t.begin() + rng() % 3, t.end());
    out.indices.insert(out.indices.end(), t.begin(), t.end());
  }
  for (int k = 0; k < 3; ++k) {
    out.positions.push_back(glm::vec3(5.0f + k));
    out.normals.push_back(glm::vec3(0, 0, 1));
    if (!out.uvs.empty()) out.uvs.push_back(glm::vec2(0));
  }
  return out;
}

// Vertices shaded per triangle by a FIFO post-transform cache of `size`
// entries (the average cache miss ratio, ACMR).
double Acmr(const std::vector<uint32_t>& indices, size_t size) {
  std::deque<uint32_t> cache;
  size_t misses = 0;
  for (uint32_t i : indices) {
    if (std::find(cache.begin(), cache.end(), i) != cache.end()) continue;
    ++misses;
    cache.push_back(i);
    if (cache.size() > size) cache.pop_front();
  }
  return static_cast<double>(misses) / (indices.size() / 3.0);
}

TEST(VertexCacheOrderTest, KeepsEveryTriangleWithItsWindingAndEveryUsedVertexOnce) {
  const core::TriangleMesh mesh = Scrambled(core::MakeSphere(1.0f, 24, 48), 7);
  const VertexOrder order = VertexCacheOrder(mesh.indices, mesh.positions.size());
  const size_t used = mesh.positions.size() - 3;
  ASSERT_EQ(order.vertex_count, used);
  ASSERT_EQ(order.new_from_old.size(), mesh.positions.size());
  // new_from_old is a bijection of the used vertices onto [0, used).
  std::vector<uint32_t> old_from_new(used, VertexOrder::kUnused);
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const uint32_t j = order.new_from_old[i];
    if (i >= used) {
      EXPECT_EQ(j, VertexOrder::kUnused) << "vertex " << i << " is used by no triangle";
      continue;
    }
    ASSERT_LT(j, used);
    EXPECT_EQ(old_from_new[j], VertexOrder::kUnused) << "two vertices share number " << j;
    old_from_new[j] = static_cast<uint32_t>(i);
  }
  // The same triangles, each with its own winding.
  std::vector<Triangle> before, after;
  for (const Triangle& t : Triangles(mesh.indices)) before.push_back(Canonical(t));
  for (const Triangle& t : Triangles(order.indices))
    after.push_back(Canonical({old_from_new[t[0]], old_from_new[t[1]], old_from_new[t[2]]}));
  std::sort(before.begin(), before.end());
  std::sort(after.begin(), after.end());
  EXPECT_EQ(before, after);
}

TEST(VertexCacheOrderTest, ShadesFewerVerticesThanAScrambledOrder) {
  const core::TriangleMesh mesh = Scrambled(core::MakeSphere(1.0f, 64, 128), 11);
  const VertexOrder order = VertexCacheOrder(mesh.indices, mesh.positions.size());
  const double before = Acmr(mesh.indices, 16), after = Acmr(order.indices, 16);
  std::printf("FIFO-16 vertices shaded per triangle: scrambled %.3f, ordered %.3f\n", before,
              after);
  EXPECT_GT(before, 2.5);  // a scrambled order shades nearly every corner
  EXPECT_LT(after, 0.8);   // a closed mesh has about 0.5 vertices a triangle
}

TEST(VertexCacheOrderTest, EmptyMeshHasNoTriangles) {
  const VertexOrder order = VertexCacheOrder({}, 4);
  EXPECT_TRUE(order.indices.empty());
  EXPECT_EQ(order.vertex_count, 0u);
}

TEST(ClustersOfTest, TileTheTrianglesAndBoundThem) {
  const core::TriangleMesh sphere = core::MakeSphere(0.8f, 48, 96);
  const VertexOrder order = VertexCacheOrder(sphere.indices, sphere.positions.size());
  std::vector<glm::vec3> positions(order.vertex_count);
  for (size_t v = 0; v < sphere.positions.size(); ++v)
    if (order.new_from_old[v] != VertexOrder::kUnused)
      positions[order.new_from_old[v]] = sphere.positions[v];
  const ClusterOrder clusters = ClustersOf(order.indices, positions);
  std::vector<Triangle> a = Triangles(order.indices), b = Triangles(clusters.indices);
  for (Triangle& t : a) t = Canonical(t);
  for (Triangle& t : b) t = Canonical(t);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);  // every triangle once, with its winding
  GLsizei next = 0;
  for (const MeshCluster& c : clusters.clusters) {
    EXPECT_EQ(c.first_index, next);  // contiguous runs, in order
    EXPECT_GT(c.index_count, 0);
    EXPECT_LE(c.index_count, 3 * 124);
    next += c.index_count;
    for (GLsizei i = c.first_index; i < c.first_index + c.index_count; ++i) {
      const glm::vec3& p = positions[clusters.indices[i]];
      EXPECT_TRUE(glm::all(glm::lessThanEqual(c.lo, p)) && glm::all(glm::lessThanEqual(p, c.hi)));
      EXPECT_LE(glm::length(p - c.center), c.radius * (1 + 1e-5f));
    }
  }
  EXPECT_EQ(next, static_cast<GLsizei>(clusters.indices.size()));
  EXPECT_GT(clusters.clusters.size(), 50u);
}

TEST(ClustersOfTest, ConeTestsAreConservative) {
  // For random eyes (outside and inside the sphere) and view directions:
  // a cluster said to face away has every triangle facing away, one said to
  // face the eye every triangle facing it (exactly, in double).
  const core::TriangleMesh mesh = core::MakeTorus(0.6f, 0.25f, 64, 32);
  const ClusterOrder clusters = ClustersOf(mesh.indices, mesh.positions);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int away = 0, towards = 0, wrong = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const glm::dvec3 direction = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    const glm::dvec3 eye = -direction * (0.2 + 4.0 * std::abs(u(rng)));
    const bool orthographic = trial % 4 == 3;
    for (const MeshCluster& c : clusters.clusters) {
      const bool a = orthographic ? c.FacesAwayAlong(direction) : c.FacesAwayFrom(eye);
      const bool t = orthographic ? c.FacesTowardsAlong(direction) : c.FacesTowards(eye);
      away += a;
      towards += t;
      if (!a && !t) continue;
      for (GLsizei i = c.first_index; i < c.first_index + c.index_count; i += 3) {
        const glm::dvec3 p0(mesh.positions[clusters.indices[i]]);
        const glm::dvec3 p1(mesh.positions[clusters.indices[i + 1]]);
        const glm::dvec3 p2(mesh.positions[clusters.indices[i + 2]]);
        const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
        if (glm::length(n) == 0.0) continue;
        for (const glm::dvec3& p : {p0, p1, p2}) {
          const double facing = glm::dot(n, orthographic ? direction : p - eye);
          wrong += a ? !(facing > 0) : !(facing < 0);
        }
      }
    }
  }
  std::printf("cone tests: %d clusters facing away, %d facing the eye, %d wrong corners\n", away,
              towards, wrong);
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(away, 300);
  EXPECT_GT(towards, 300);
}

class GpuMeshTest : public test_support::GlTest {};

TEST_F(GpuMeshTest, DrawsTheSamePictureWhateverTheTriangleOrder) {
  const core::TriangleMesh sphere = core::MakeSphere(0.8f, 32, 64);
  const core::TriangleMesh scrambled = Scrambled(sphere, 3);
  constexpr int kSize = 128;
  ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt({1.5, 1.0, 3.5}, {0, 0, 0}, {0, 1, 0});
  view.clip_from_cam =
      core::ClipFromCamPerspective(150.0, 150.0, kSize / 2.0, kSize / 2.0, kSize, kSize, 0.5, 10.0);
  MeshPassOptions options;
  options.base_color = {0.9f, 0.5f, 0.2f, 1.0f};
  const Frame a = RenderMesh(programs(), GpuMesh(sphere), view, kSize, kSize, options);
  const Frame b = RenderMesh(programs(), GpuMesh(scrambled), view, kSize, kSize, options);
  // The same triangles grouped into clusters (GpuMesh::Clustered).
  const Frame c =
      RenderMesh(programs(), GpuMesh::Clustered(scrambled), view, kSize, kSize, options);
  int covered = 0, colour_off = 0;
  float depth_off = 0.0f;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      covered += a.Covered(x, y);
      ASSERT_EQ(a.Covered(x, y), b.Covered(x, y)) << x << "," << y;
      ASSERT_EQ(a.Covered(x, y), c.Covered(x, y)) << x << "," << y;
      for (const Frame* f : {&b, &c}) {
        for (int k = 0; k < 4; ++k) {
          colour_off = std::max(colour_off, std::abs(a.color.at(x, y, k) - f->color.at(x, y, k)));
        }
        depth_off = std::max(depth_off, std::abs(a.depth.at(x, y) - f->depth.at(x, y)));
      }
    }
  }
  EXPECT_GT(covered, 3000);
  // A triangle's corners in another rotation interpolate in another order:
  // float rounding, nothing more.
  EXPECT_LE(colour_off, 1);
  EXPECT_LT(depth_off, 1e-5f);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace render
