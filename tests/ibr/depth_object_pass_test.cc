// Depth objects on the pass contract (ibr/depth_object_pass.h): drawn alone
// into a frame target the pass gives what DepthObjectRenderer gives, and two
// depth objects drawn into one frame composite by depth (each pixel shows
// the nearer one, coverage is the union), in either drawing order; and
// DepthObjectRenderer::RenderFrame, the one readback (render::Frame), holds
// exactly what the renderer's own output target holds.
#include "ibr/depth_object_pass.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/projection.h"
#include "render/passes/pass.h"
#include "tests/ibr/scenes.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

using testing::Sphere;

MapSet SphereCube(const Sphere& sphere, int map_size) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, map_size);
  for (ImageMap& m : set.maps) testing::RenderSpheres({sphere}, m);
  return set;
}

render::ViewSetup SetupOf(const ViewCamera& v, double near, double far) {
  render::ViewSetup s;
  s.cam_from_world = glm::mat4(v.cam_from_world);
  s.clip_from_cam = core::ClipFromCamPerspective(v.camera.fx, v.camera.fy, v.camera.cx, v.camera.cy,
                                                 v.camera.width, v.camera.height, near, far);
  s.orthographic = false;
  return s;
}

class DepthObjectPassTest : public test_support::GlTest {};

// The stages the exactness tests drive, into the resolve's own layout
// (attachment 0 RGBA8 colour, attachment 1 RG32F camera z and covered):
// PrepareFrame, the path's accumulation, DrawResolve.
core::Image8 StagesColor(DepthObjectRenderer& renderer, const ViewCamera& view,
                         const DepthObjectOptions& o, core::ImageF& z_covered) {
  const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
  const render::RenderTarget accum(
      DepthObjectRenderer::AccumTargetOptions(frame.width, frame.height));
  if (o.slicing == Slicing::kRay)
    renderer.DrawRay(frame, o, accum);
  else if (o.slice_path == SlicePath::kFast)
    renderer.DrawSlicesFast(frame, o, accum);
  else
    renderer.DrawSlices(frame, o, accum);
  const render::RenderTarget own({frame.width, frame.height, {GL_RGBA8, GL_RG32F}, true});
  own.Bind();
  renderer.DrawResolve(frame, o, accum);
  z_covered = own.ReadColorF(1);
  return own.ReadColor8(0);
}

TEST_F(DepthObjectPassTest, DrawsWhatTheRendererDrawsAndCompositesByDepth) {
  constexpr int kSize = 128;
  const ViewCamera view = testing::PerspectiveView({0.4, 0.9, 3.0}, {0, 0, 0}, {0, 1, 0}, kSize);
  const render::ViewSetup setup = SetupOf(view, 0.5, 8.0);
  // The camera is recovered from the projection.
  const ViewCamera back = ViewCameraFromSetup(setup, kSize, kSize);
  EXPECT_NEAR(back.camera.fx, view.camera.fx, 1e-3);
  EXPECT_NEAR(back.camera.cy, view.camera.cy, 1e-3);

  DepthObjectOptions o;
  o.slicing = Slicing::kRay;
  o.texturing = Texturing::kNone;
  DepthObjectPass a(programs(), SphereCube({{-0.25, 0.0, 0.0}, 0.5}, 96), o);
  DepthObjectPass b(programs(), SphereCube({{0.3, 0.1, 0.35}, 0.45}, 96), o);
  EXPECT_EQ(a.name(), "depth-object");

  // Alone: the renderer's image.
  const render::Frame fa = render::RenderFrame(a, setup, kSize, kSize);
  const render::Frame fb = render::RenderFrame(b, setup, kSize, kSize);
  // The renderer's stages: attachment 1 RG32F (camera z, covered).
  core::ImageF ra;
  StagesColor(a.renderer(), view, o, ra);
  int64_t covered_a = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      ASSERT_EQ(fa.Covered(x, y), ra.at(x, y, 1) > 0.5f) << x << " " << y;
      if (!fa.Covered(x, y)) continue;
      ++covered_a;
      EXPECT_NEAR(fa.depth.at(x, y), ra.at(x, y, 0), 1e-6);
      EXPECT_NE(fa.outcome.at(x, y), 0u);
    }
  }
  EXPECT_GT(covered_a, 1000);

  // Together, in both orders: the nearer surface wins. Where the two
  // surfaces are closer than the 24-bit window depth can tell apart, either.
  for (int order = 0; order < 2; ++order) {
    render::RenderTarget target(render::FrameTargetOptions(kSize, kSize));
    render::BeginFrame(target);
    (order == 0 ? a : b).Draw(target, setup);
    (order == 0 ? b : a).Draw(target, setup);
    const render::Frame f = render::ReadFrame(target);
    int64_t both = 0;
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        const bool ca = fa.Covered(x, y), cb = fb.Covered(x, y);
        ASSERT_EQ(f.Covered(x, y), ca || cb) << x << " " << y;
        if (!ca && !cb) continue;
        const float za = ca ? fa.depth.at(x, y) : INFINITY, zb = cb ? fb.depth.at(x, y) : INFINITY;
        both += ca && cb;
        if (ca && cb && std::abs(za - zb) < 1e-3f) continue;
        EXPECT_NEAR(f.depth.at(x, y), std::min(za, zb), 1e-6)
            << x << " " << y << " order " << order;
      }
    }
    EXPECT_GT(both, 200) << "the two objects overlap in the view";
  }
  EXPECT_NO_GL_ERROR();
}

// RenderFrame (the frame target, no depth test) against the renderer's
// stages into the resolve's own layout (RGBA8 colour, RG32F camera z +
// covered), for every
// path: the same pixels covered, the same colour bytes, the same camera z;
// empty pixels 0; a covered pixel has alpha 255 and the hit outcome bit.
TEST_F(DepthObjectPassTest, RenderFrameHoldsTheOwnOutputTarget) {
  constexpr int kSize = 96;
  DepthObjectRenderer renderer(programs(), SphereCube({{0.1, -0.05, 0.0}, 0.7}, 64));
  struct Case {
    Method method;
    Slicing slicing;
    SlicePath path;
    Texturing texturing;
  };
  const Case cases[] = {
      {Method::kDepthObject, Slicing::kOrthogonal, SlicePath::kExact, Texturing::kViewDependent},
      {Method::kDepthObject, Slicing::kScreen, SlicePath::kFast, Texturing::kNone},
      {Method::kDepthObject, Slicing::kRay, SlicePath::kExact, Texturing::kVisibility},
      {Method::kVisualHull, Slicing::kOrthogonal, SlicePath::kExact, Texturing::kPaperBlend},
  };
  for (bool ortho : {false, true}) {
    ViewCamera view = testing::PerspectiveView({0.6, 1.1, 2.8}, {0, 0, 0}, {0, 1, 0}, kSize);
    if (ortho)
      view.camera =
          MapCamera::Orthographic(kSize, kSize, kSize / 3.0, kSize / 3.0, kSize / 2.0, kSize / 2.0);
    for (const Case& c : cases) {
      DepthObjectOptions o;
      o.method = c.method;
      o.slicing = c.slicing;
      o.slice_path = c.path;
      o.texturing = c.texturing;
      o.slices = 64;
      const std::string what =
          fmt::format("{} {} {} {}", MethodName(c.method), SlicingName(c.slicing),
                      SlicePathName(c.path), ortho ? "ortho" : "persp");
      const render::Frame f = renderer.RenderFrame(view, o);
      core::ImageF zc;
      const core::Image8 color = StagesColor(renderer, view, o, zc);
      int64_t covered = 0, color_diff = 0;
      for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
          const bool own_covered = zc.at(x, y, 1) > 0.5f;
          ASSERT_EQ(f.Covered(x, y), own_covered) << what << " at " << x << " " << y;
          for (int k = 0; k < 4; ++k) color_diff += f.color.at(x, y, k) != color.at(x, y, k);
          if (!own_covered) {
            EXPECT_EQ(f.depth.at(x, y), 0.0f) << what;
            EXPECT_EQ(f.outcome.at(x, y), 0u) << what;
            continue;
          }
          ++covered;
          EXPECT_EQ(f.depth.at(x, y), zc.at(x, y, 0)) << what << " at " << x << " " << y;
          EXPECT_NE(f.outcome.at(x, y), 0u) << what;
        }
      }
      EXPECT_EQ(color_diff, 0) << what;
      EXPECT_EQ(f.CoveredPixels(), covered) << what;
      EXPECT_GT(covered, 500) << what;
    }
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
