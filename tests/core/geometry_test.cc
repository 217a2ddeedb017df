// Camera projection helpers, analytic meshes and timing statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

#include "core/error.h"
#include "core/mesh.h"
#include "core/projection.h"
#include "core/summed_volume.h"
#include "core/timing.h"

namespace core {
namespace {

// Projects p_in_cam with clip_from_cam, returns image (u, v) and NDC z.
glm::vec3 ToImage(const glm::mat4& clip_from_cam, glm::vec3 p_in_cam, int w, int h) {
  const glm::vec4 clip = clip_from_cam * glm::vec4(p_in_cam, 1);
  const glm::vec3 ndc = glm::vec3(clip) / clip.w;
  return {(ndc.x + 1) * 0.5f * w, (1 - ndc.y) * 0.5f * h, ndc.z};
}

TEST(Projection, PerspectiveMatchesPinholeFormula) {
  const double fx = 500, fy = 480, cx = 320.5, cy = 239.25;
  const glm::mat4 m = ClipFromCamPerspective(fx, fy, cx, cy, 640, 480, 0.1, 100);
  for (glm::vec3 p : {glm::vec3(0.3f, -0.2f, 2.0f), glm::vec3(-1.0f, 0.7f, 5.0f)}) {
    const glm::vec3 uvz = ToImage(m, p, 640, 480);
    EXPECT_NEAR(uvz.x, fx * p.x / p.z + cx, 1e-3);
    EXPECT_NEAR(uvz.y, fy * p.y / p.z + cy, 1e-3);
  }
  EXPECT_NEAR(ToImage(m, {0, 0, 0.1f}, 640, 480).z, -1.0, 1e-5);
  EXPECT_NEAR(ToImage(m, {0, 0, 100.0f}, 640, 480).z, 1.0, 1e-5);
}

TEST(Projection, OrthographicMatchesAffineFormula) {
  const glm::mat4 m = ClipFromCamOrthographic(100, 100, 64, 64, 128, 128, -1, 3);
  const glm::vec3 p(0.25f, -0.5f, 1.0f);
  const glm::vec3 uvz = ToImage(m, p, 128, 128);
  EXPECT_NEAR(uvz.x, 100 * 0.25 + 64, 1e-4);
  EXPECT_NEAR(uvz.y, 100 * -0.5 + 64, 1e-4);
  EXPECT_NEAR(uvz.z, 0.0, 1e-6);
}

TEST(Projection, ClipRangeZInvertsBothProjections) {
  // The near and far planes come back from the matrices they were built into,
  // to float precision: the matrices are float, and the far plane divides by
  // P23 - P22 = 1 - 1.002, which keeps about 4 of float's 7 digits (5e-4 relative).
  const glm::dvec2 persp =
      ClipRangeZ(ClipFromCamPerspective(500, 500, 320, 240, 640, 480, 0.1, 100));
  EXPECT_NEAR(persp.x, 0.1, 1e-6);
  EXPECT_NEAR(persp.y, 100.0, 0.05);
  const glm::dvec2 ortho = ClipRangeZ(ClipFromCamOrthographic(100, 100, 64, 64, 128, 128, -1, 3));
  EXPECT_NEAR(ortho.x, -1.0, 1e-6);
  EXPECT_NEAR(ortho.y, 3.0, 1e-6);
}

TEST(Projection, LookAtAxesFollowTheOpenCvConvention) {
  // Camera on -y looking at the origin with world z up: camera z = +y world,
  // camera y (down) = -z world, camera x (right) = +x world.
  const glm::mat4 cam_from_world = CamFromWorldLookAt({0, -5, 0}, {0, 0, 0}, {0, 0, 1});
  const glm::vec3 origin_in_cam = glm::vec3(cam_from_world * glm::vec4(0, 0, 0, 1));
  EXPECT_NEAR(origin_in_cam.z, 5.0f, 1e-5);
  EXPECT_NEAR(glm::length(glm::vec2(origin_in_cam)), 0.0f, 1e-5);
  const glm::vec3 up_in_cam = glm::mat3(cam_from_world) * glm::vec3(0, 0, 1);
  EXPECT_NEAR(up_in_cam.y, -1.0f, 1e-5);
  const glm::vec3 x_in_cam = glm::mat3(cam_from_world) * glm::vec3(1, 0, 0);
  EXPECT_NEAR(x_in_cam.x, 1.0f, 1e-5);
  // Looking straight down the up vector still gives a valid rotation.
  const glm::mat3 r = glm::mat3(CamFromWorldLookAt({0, 0, 5}, {0, 0, 0}, {0, 0, 1}));
  EXPECT_NEAR(glm::determinant(r), 1.0f, 1e-5);
}

TEST(Mesh, AnalyticShapesLieOnTheirSurfaces) {
  const TriangleMesh sphere = MakeSphere(2.0f, 16, 32);
  for (const auto& p : sphere.positions) EXPECT_NEAR(glm::length(p), 2.0f, 1e-5);
  const TriangleMesh torus = MakeTorus(1.0f, 0.25f, 25, 25);
  EXPECT_EQ(torus.triangle_count(), 2u * 625u);  // the paper's 625-polygon donut
  for (const auto& p : torus.positions) {
    const float ring = std::sqrt(p.x * p.x + p.y * p.y) - 1.0f;
    EXPECT_NEAR(std::sqrt(ring * ring + p.z * p.z), 0.25f, 1e-5);
  }
  const TriangleMesh box = MakeBox({1, 2, 3});
  glm::vec3 lo, hi;
  box.Bounds(lo, hi);
  EXPECT_EQ(hi, glm::vec3(1, 2, 3));
  EXPECT_EQ(lo, glm::vec3(-1, -2, -3));
  // Winding: each triangle's geometric normal agrees with its vertex normals.
  for (const TriangleMesh* m : {&sphere, &torus, &box}) {
    for (size_t t = 0; t < m->triangle_count(); ++t) {
      const uint32_t a = m->indices[3 * t], b = m->indices[3 * t + 1], c = m->indices[3 * t + 2];
      const glm::vec3 n =
          glm::cross(m->positions[b] - m->positions[a], m->positions[c] - m->positions[a]);
      if (glm::length(n) < 1e-6f) continue;  // degenerate (zero-area) pole triangles
      EXPECT_GT(glm::dot(n, m->normals[a] + m->normals[b] + m->normals[c]), 0.0f);
    }
  }
}

TEST(Mesh, AreaWeightedNormalsOfASphereAreItsRadii) {
  core::TriangleMesh sphere = core::MakeSphere(2.0f, 24, 48);
  sphere.normals.clear();
  core::SetAreaWeightedNormals(sphere);
  ASSERT_EQ(sphere.normals.size(), sphere.positions.size());
  // Degrees, away from the poles and the seam column (its vertices are
  // repeated, each copy seeing one side's triangles only).
  double worst = 0.0;
  for (size_t i = 0; i < sphere.positions.size(); ++i) {
    const glm::vec3 radial = glm::normalize(sphere.positions[i]);
    EXPECT_NEAR(glm::length(sphere.normals[i]), 1.0f, 1e-5f);
    if (std::abs(radial.z) > 0.99f || sphere.uvs[i].x == 0.0f || sphere.uvs[i].x == 1.0f) continue;
    const double c = std::clamp(glm::dot(radial, sphere.normals[i]), -1.0f, 1.0f);
    worst = std::max(worst, std::acos(c) * 180.0 / 3.14159265358979);
  }
  EXPECT_LT(worst, 1.0);
  // A triangle with no area leaves its corners' normals at +z.
  core::TriangleMesh flat;
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.indices = {0, 1, 2};
  core::SetAreaWeightedNormals(flat);
  for (const glm::vec3& n : flat.normals) EXPECT_EQ(n, glm::vec3(0, 0, 1));
}

TEST(Mesh, ValidateRejectsBadMeshes) {
  TriangleMesh mesh = MakePlane(1.0f);
  mesh.indices.push_back(99);
  EXPECT_THROW(mesh.Validate("test"), InputError);
  mesh = MakePlane(1.0f);
  mesh.positions[0].x = NAN;
  EXPECT_THROW(mesh.Validate("test"), InputError);
}

TEST(Timing, SummarizeGivesMedianMinMax) {
  const TimingStats s = Summarize({5, 1, 3, 9, 7});
  EXPECT_EQ(s.median_ms, 5);
  EXPECT_EQ(s.min_ms, 1);
  EXPECT_EQ(s.max_ms, 9);
  EXPECT_EQ(s.mean_ms, 5);
  EXPECT_EQ(Summarize({4, 2}).median_ms, 3);
  EXPECT_EQ(Summarize({}).samples, 0);
}

// CPU time counts work done, not time waited: one thread busy until its CPU
// clock reads 30 ms took about that long on the wall clock (not less than
// 20 ms: in one make test run on the loaded 2-core VM the process CPU clock
// read 30 ms after 27.9 ms of wall clock); a 50 ms sleep costs almost no CPU.
TEST(Timing, CpuStopwatchCountsWorkNotWaiting) {
  CpuStopwatch cpu;
  Stopwatch wall;
  volatile double x = 0;
  while (cpu.ElapsedMs() < 30) x = x + 1;
  EXPECT_GE(wall.ElapsedMs(), 20.0);
  EXPECT_LT(cpu.ElapsedMs(), 1000.0);
  cpu.Restart();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_LT(cpu.ElapsedMs(), 10.0);
  EXPECT_GE(cpu.ElapsedMs(), 0.0);
}

// The summed-volume table against brute-force counts over random boxes.
TEST(SummedVolume, CountsMatchBruteForce) {
  std::mt19937 rng(7);
  const glm::ivec3 dims(7, 5, 9);
  std::vector<uint8_t> flags(static_cast<size_t>(dims.x) * dims.y * dims.z);
  for (auto& f : flags) f = static_cast<uint8_t>(rng() % 3 == 0 ? 1 + rng() % 4 : 0);
  const SummedVolume table(dims, flags);
  for (int trial = 0; trial < 500; ++trial) {
    glm::ivec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = static_cast<int>(rng() % (dims[a] + 1));
      hi[a] = static_cast<int>(rng() % (dims[a] + 1));
      if (lo[a] > hi[a]) std::swap(lo[a], hi[a]);
    }
    int expected = 0;
    for (int z = lo.z; z < hi.z; ++z)
      for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x)
          expected += flags[(static_cast<size_t>(z) * dims.y + y) * dims.x + x] != 0;
    EXPECT_EQ(table.Count(lo, hi), expected) << trial;
  }
}

}  // namespace
}  // namespace core
