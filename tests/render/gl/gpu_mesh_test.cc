// GpuMesh's vertex-cache order (render/gl/gpu_mesh.h): every triangle kept
// with its winding, every used vertex once, fewer vertices shaded than a
// scrambled order, and the same picture whatever order the mesh came in.
#include "render/gl/gpu_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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
  int covered = 0, colour_off = 0;
  float depth_off = 0.0f;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      covered += a.Covered(x, y);
      ASSERT_EQ(a.Covered(x, y), b.Covered(x, y)) << x << "," << y;
      for (int c = 0; c < 4; ++c)
        colour_off = std::max(colour_off, std::abs(a.color.at(x, y, c) - b.color.at(x, y, c)));
      depth_off = std::max(depth_off, std::abs(a.depth.at(x, y) - b.depth.at(x, y)));
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
