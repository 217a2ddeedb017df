// The reference rasteriser against analytic truth: a sphere's orthographic
// silhouette and depth, a tilted plane's perspective depth and normal.
#include "render/passes/mesh_pass.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "core/projection.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

class MeshPassTest : public test_support::GlTest {};

TEST_F(MeshPassTest, OrthographicSphereMatchesAnalyticDiscAndDepth) {
  constexpr int kSize = 256;
  constexpr double kScale = kSize / 2.5;  // pixels per unit
  const GpuMesh sphere(core::MakeSphere(1.0f, 128, 256));
  ViewSetup view;
  view.orthographic = true;
  view.cam_from_world = core::CamFromWorldLookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
  view.clip_from_cam = core::ClipFromCamOrthographic(kScale, kScale, kSize / 2.0, kSize / 2.0,
                                                     kSize, kSize, 0.5, 10.0);
  const Frame frame = RenderMesh(programs(), sphere, view, kSize, kSize);
  // The mesh is inscribed: its silhouette is inside the true circle by at most
  // 1 - cos(pi / 256) = 7.5e-5 units = 0.008 px. Pixels whose centre lies within
  // 0.05 px of the circle are ambiguous and skipped.
  const double margin = 0.05 / kScale;
  int mismatches = 0, checked = 0, depth_bad = 0;
  double max_depth_error = 0;
  for (int row = 0; row < kSize; ++row) {
    for (int col = 0; col < kSize; ++col) {
      const double x = (col + 0.5 - kSize / 2.0) / kScale;
      const double y = (row + 0.5 - kSize / 2.0) / kScale;
      const double r = std::sqrt(x * x + y * y);
      const bool covered = frame.color.at(col, row, 3) == 255;
      if (std::abs(r - 1.0) > margin) {
        ++checked;
        if (covered != (r < 1.0)) ++mismatches;
      }
      if (r < 0.95) {
        // Camera at z=5 looking down -z: depth of the front surface.
        const double truth = 5.0 - std::sqrt(1.0 - r * r);
        const double err = std::abs(frame.depth.at(col, row) - truth);
        max_depth_error = std::max(max_depth_error, err);
        // Facet sag for 128 rings is < 1e-4 units; 1e-3 leaves float headroom.
        if (err > 1e-3) ++depth_bad;
      } else if (r > 1.0 + margin) {
        EXPECT_EQ(frame.depth.at(col, row), 0.0f);
      }
    }
  }
  EXPECT_GT(checked, kSize * kSize - 200);
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(depth_bad, 0) << "max depth error " << max_depth_error;
  if (mismatches || depth_bad) test_support::WriteDebugImage("sphere.png", frame.color);
}

TEST_F(MeshPassTest, PerspectiveTiltedPlaneDepthAndNormalAreExact) {
  constexpr int kW = 160, kH = 120;
  const double f = 150, cx = 80.0, cy = 60.0;
  const GpuMesh plane(core::MakePlane(1.0f, 4));
  MeshPassOptions options;
  options.world_from_object = glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(1, 0, 0));
  ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt({0, 0, 3}, {0, 0, 0}, {0, 1, 0});
  view.clip_from_cam = core::ClipFromCamPerspective(f, f, cx, cy, kW, kH, 0.1, 10.0);
  const Frame frame = RenderMesh(programs(), plane, view, kW, kH, options);
  // Plane through the world origin with normal n: in the camera, through p0
  // (origin in cam) with normal n_cam; the ray through pixel centre (u, v) has
  // direction d = ((u - cx)/f, (v - cy)/f, 1) and meets it at depth n.p0 / n.d.
  const glm::vec3 n_world = glm::mat3(options.world_from_object) * glm::vec3(0, 0, 1);
  const glm::vec3 n_cam = glm::mat3(view.cam_from_world) * n_world;
  const glm::vec3 p0 = glm::vec3(view.cam_from_world * glm::vec4(0, 0, 0, 1));
  int covered = 0;
  for (int row = 10; row < kH - 10; ++row) {
    for (int col = 10; col < kW - 10; ++col) {
      if (frame.color.at(col, row, 3) != 255) continue;
      const glm::dvec3 d((col + 0.5 - cx) / f, (row + 0.5 - cy) / f, 1.0);
      const double truth =
          glm::dot(glm::dvec3(n_cam), glm::dvec3(p0)) / glm::dot(glm::dvec3(n_cam), d);
      ASSERT_NEAR(frame.depth.at(col, row), truth, 2e-5 * truth) << col << "," << row;
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(frame.normal.at(col, row, c), n_world[c], 2e-3);
      ++covered;
    }
  }
  EXPECT_GT(covered, 5000);
}

}  // namespace
}  // namespace render
