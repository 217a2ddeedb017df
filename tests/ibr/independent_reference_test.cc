// The independent double-precision reference (ibr/independent_reference.h)
// against analytic truth (an axis-aligned box: its depth object and visual
// hull are the box itself; a sphere: empty far outside, every map agreeing
// inside, depth near the true surface) and against the GPU's stencil and
// first-surface depth (DepthObjectRenderer::DrawSlices), where the two agree
// outside the stated tolerance band.
#include "ibr/independent_reference.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "ibr/depth_object.h"
#include "tests/ibr/scenes.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

using testing::Sphere;

// Depth and mask of the axis-aligned box [-a, a]^3 seen by `map` (exact ray cast).
void RenderAlignedBox(double a, ImageMap& map) {
  const MapCamera& cam = map.camera;
  map.depth = core::ImageF(cam.width, cam.height, 1, 0.0f);
  map.mask = core::Image8(cam.width, cam.height, 1, 0);
  const glm::dmat4 world_from_cam = glm::inverse(map.cam_from_world);
  for (int row = 0; row < cam.height; ++row) {
    for (int col = 0; col < cam.width; ++col) {
      glm::dvec3 o, d;
      testing::PixelRay(cam, col, row, o, d);
      const glm::dvec3 ow(world_from_cam * glm::dvec4(o, 1.0)),
          dw(world_from_cam * glm::dvec4(d, 0.0));
      double t0 = -INFINITY, t1 = INFINITY;
      for (int k = 0; k < 3; ++k) {
        if (dw[k] == 0) {
          if (std::abs(ow[k]) > a) t0 = INFINITY;
          continue;
        }
        const double ta = (-a - ow[k]) / dw[k], tb = (a - ow[k]) / dw[k];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
      }
      if (!(t0 <= t1) || t1 <= 0) continue;
      map.depth.at(col, row) = static_cast<float>(o.z + std::max(t0, 0.0) * d.z);
      map.mask.at(col, row) = 255;
    }
  }
}

// The view ray through pixel (col, row) in world space.
void ViewRay(const ViewCamera& v, int col, int row, glm::dvec3& o, glm::dvec3& d) {
  testing::PixelRay(v.camera, col, row, o, d);
  const glm::dmat4 world_from_cam = glm::inverse(v.cam_from_world);
  o = glm::dvec3(world_from_cam * glm::dvec4(o, 1.0));
  d = glm::dvec3(world_from_cam * glm::dvec4(d, 0.0));  // camera z of o + t d is z(o) + t
}

std::vector<ViewCamera> AnalyticViews(int size) {
  return {testing::PerspectiveView({2.2, 1.4, 3.1}, {0, 0, 0}, {0, 1, 0}, size),
          testing::OrthographicView({-3, 2, -1.5}, {0.05, -0.02, 0}, {0, 1, 0}, size, 1.5),
          testing::PerspectiveView({0.3, -3.5, 0.4}, {0, 0, 0}, {0, 0, 1}, size)};
}

// Box [-0.5, 0.5]^3 inside the cube rig [-1, 1]^3, maps 64 px: the box's faces
// fall on texel boundaries, so the maps describe it without quantisation and
// the depth object and the visual hull are exactly the box. Truth per pixel:
// the first slice plane (front to back along the ray) whose point lies in it.
TEST(IndependentReferenceTest, AlignedBoxIsReproducedExactly) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, 64);
  for (ImageMap& m : set.maps) RenderAlignedBox(0.5, m);
  int64_t checked = 0, band = 0, object = 0;
  for (const ViewCamera& view : AnalyticViews(48)) {
    for (Method method : {Method::kDepthObject, Method::kVisualHull}) {
      for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
        DepthObjectOptions o;
        o.method = method;
        o.slicing = slicing;
        o.slices = 37;
        const IndependentFrame f = RenderIndependent(set, view, o);
        const int n = static_cast<int>(f.active.size());
        EXPECT_EQ(n, method == Method::kDepthObject ? 6 : 3);
        for (int row = 0; row < f.height; ++row) {
          for (int col = 0; col < f.width; ++col) {
            const IndependentPixel& px = f.at(col, row);
            if (px.band) {
              ++band;
              continue;
            }
            glm::dvec3 o_w, d_w;
            ViewRay(view, col, row, o_w, d_w);
            // Truth: nearest slice whose point is in the box (and in the rig's cube).
            int expected = -1;
            double best_z = INFINITY;
            for (size_t s = 0; s < f.plane_values.size(); ++s) {
              const double z = f.SliceDepth(col, row, static_cast<int>(s));
              if (!std::isfinite(z)) continue;
              const glm::dvec3 p =
                  o_w + (z - glm::dvec3(view.cam_from_world * glm::dvec4(o_w, 1.0)).z) * d_w;
              const bool inside =
                  std::abs(p.x) <= 0.5 && std::abs(p.y) <= 0.5 && std::abs(p.z) <= 0.5;
              if (inside && z < best_z) best_z = z, expected = static_cast<int>(s);
            }
            ++checked;
            object += expected >= 0;
            ASSERT_EQ(px.front_slice, expected) << MethodName(method) << " " << SlicingName(slicing)
                                                << " pixel " << col << "," << row;
            if (expected >= 0) {
              EXPECT_EQ(px.stencil, n);
              EXPECT_DOUBLE_EQ(px.depth, best_z);
            } else {
              EXPECT_EQ(px.stencil, 0);
            }
          }
        }
      }
    }
  }
  std::printf(
      "aligned box: %lld pixels checked against the box, %lld object pixels, %lld in the band\n",
      static_cast<long long>(checked), static_cast<long long>(object),
      static_cast<long long>(band));
  EXPECT_GT(object, 3000);
  EXPECT_LT(band, checked / 20) << "the band must stay a thin set of pixels";
}

// A sphere of radius 0.7 in the cube rig (maps 128 px): rays missing the
// sphere by more than two texels are empty; rays that hit it have every map
// agreeing (count 6) at a depth no nearer than the surface minus the maps'
// quantisation and no farther than one slice spacing plus it. The
// quantisation of a discrete depth map near a map's silhouette rim is
// O(sqrt(r h)) (h the texel size), so that is the bound; most pixels are far
// tighter, which the second check states.
TEST(IndependentReferenceTest, SphereCountsAndDepths) {
  const double r = 0.7;
  const std::vector<Sphere> spheres = {{{0, 0, 0}, r}};
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, 128);
  for (ImageMap& m : set.maps) testing::RenderSpheres(spheres, m);
  const double h = 2.0 / 128;
  for (const ViewCamera& view : AnalyticViews(64)) {
    for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
      DepthObjectOptions o;
      o.slicing = slicing;
      o.slices = 96;
      const IndependentFrame f = RenderIndependent(set, view, o);
      int64_t hits = 0, tight = 0, misses = 0;
      for (int row = 0; row < f.height; ++row) {
        for (int col = 0; col < f.width; ++col) {
          const IndependentPixel& px = f.at(col, row);
          glm::dvec3 o_w, d_w;
          ViewRay(view, col, row, o_w, d_w);
          const auto t = testing::HitSpheres(spheres, o_w, d_w);
          // Distance of the ray from the centre (closest approach).
          const glm::dvec3 dn = glm::normalize(d_w);
          const double miss = glm::length(o_w - glm::dot(o_w, dn) * dn) - r;
          if (miss > 2.5 * h) {
            ++misses;
            EXPECT_EQ(px.stencil, 0)
                << "ray " << miss << " outside the sphere at " << col << "," << row;
            continue;
          }
          if (!t || miss > -3 * h) continue;  // the rim: quantised silhouettes decide
          ++hits;
          const double z_true = glm::dvec3(view.cam_from_world * glm::dvec4(o_w + *t * d_w, 1.0)).z;
          // Camera z spacing of the slices along this ray: at most the plane spacing
          // over the cosine between the plane normal and the ray (screen: exact).
          double spacing = 0;
          for (size_t s = 1; s < f.plane_values.size(); ++s) {
            const double a = f.SliceDepth(col, row, static_cast<int>(s) - 1),
                         b = f.SliceDepth(col, row, static_cast<int>(s));
            if (std::isfinite(a) && std::isfinite(b)) spacing = std::max(spacing, std::abs(b - a));
          }
          const double quant = std::sqrt(2 * r * h) + h;
          EXPECT_EQ(px.stencil, 6) << "inside the sphere's silhouette at " << col << "," << row;
          EXPECT_GE(px.depth, z_true - quant);
          EXPECT_LE(px.depth, z_true + spacing + quant);
          tight += std::abs(px.depth - z_true) <= spacing + 2 * h;
        }
      }
      EXPECT_GT(hits, 300);
      EXPECT_GT(misses, 300);
      EXPECT_GT(tight, hits * 9 / 10) << "most of the surface within a slice and two texels";
    }
  }
}

// Random blobby objects with noisy, holed maps (the stencil_reference_test
// scenes), random views, both slicings and methods, robust k and both
// policies: the GPU's stencil, front slice and first-surface depth agree with
// the independent reference on every pixel outside the band.
class IndependentGpuTest : public test_support::GlTest {};

TEST_F(IndependentGpuTest, GpuAgreesOutsideTheBand) {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> pos(-0.55, 0.55), rad(0.2, 0.5), u(0, 1);
  int64_t pixels = 0, agree = 0, band = 0, band_disagree = 0, real = 0, covered = 0;
  double worst_over_bound = 0;
  GLint subpixel_bits = 4;
  glGetIntegerv(GL_SUBPIXEL_BITS, &subpixel_bits);
  for (int scene = 0; scene < 4; ++scene) {
    MapSet set;
    set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
    set.maps =
        scene % 2 == 0 ? CubeRigMaps({0, 0, 0}, 1.0, 40) : testing::RingMaps(5, 3.5, 1.2, 48);
    std::vector<Sphere> spheres;
    for (int i = 0; i < 5; ++i) spheres.push_back({{pos(rng), pos(rng), pos(rng)}, rad(rng)});
    for (ImageMap& m : set.maps) {
      testing::RenderSpheres(spheres, m);
      for (float& d : m.depth.values()) {
        if (u(rng) < 0.05) d = 0.0f;  // holes
      }
    }
    DepthObjectRenderer renderer(programs(), std::move(set));
    for (int variant = 0; variant < 8; ++variant) {
      DepthObjectOptions o;
      o.slicing = variant % 2 == 0 ? Slicing::kOrthogonal : Slicing::kScreen;
      o.slices = 20 + 7 * variant;
      o.method = variant >= 6 ? Method::kVisualHull : Method::kDepthObject;
      o.robust_k = variant == 2 || variant == 3 ? 1 : 0;
      o.outside = variant == 4 ? OutsidePolicy::kFail : OutsidePolicy::kPass;
      o.invalid_depth =
          variant == 5 ? InvalidDepthPolicy::kNoConstraint : InvalidDepthPolicy::kEmpty;
      const glm::dvec3 dir = testing::RandomUnit(rng);
      const glm::dvec3 up = std::abs(dir.z) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
      const int size = 48 + 16 * (variant % 3);
      const ViewCamera view =
          variant == 1 ? testing::OrthographicView(3.0 * dir, {0, 0, 0}, up, size, 1.8)
                       : testing::PerspectiveView((2.8 + u(rng)) * dir, {0, 0, 0}, up, size);
      const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
      render::RenderTarget accum(
          DepthObjectRenderer::AccumTargetOptions(frame.width, frame.height));
      renderer.DrawSlices(frame, o, accum);
      IndependentOptions io;
      io.subpixel_bits = subpixel_bits;
      io.tie_axis = frame.stack.axis;
      const IndependentFrame ref = RenderIndependent(renderer.maps(), view, o, io);
      const IndependentComparison c =
          CompareWithIndependent(ref, accum.ReadStencil(), accum.ReadColorF(1));
      const std::string name = fmt::format("scene{}_variant{}", scene, variant);
      EXPECT_EQ(c.real_errors, 0) << name;
      if (c.real_errors > 0) test_support::WriteDebugImage(name + "_diff.png", c.diff);
      pixels += c.pixels;
      agree += c.agree;
      band += c.band;
      band_disagree += c.band_disagree;
      real += c.real_errors;
      covered += c.covered;
      worst_over_bound = std::max(worst_over_bound, c.max_depth_error_over_bound);
    }
  }
  std::printf(
      "independent vs GPU: %lld pixels, %lld agree, %lld object pixels, band %lld (%.3f %%), "
      "band disagreements %lld, real errors %lld, worst depth error / bound %.3g\n",
      static_cast<long long>(pixels), static_cast<long long>(agree),
      static_cast<long long>(covered), static_cast<long long>(band), 100.0 * band / pixels,
      static_cast<long long>(band_disagree), static_cast<long long>(real), worst_over_bound);
  EXPECT_GT(covered, 5000);
  EXPECT_LT(band, pixels / 20) << "the band must stay a thin set of pixels";
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
