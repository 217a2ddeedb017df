// The independent double-precision reference (verify/independent_reference.h)
// against analytic truth (an axis-aligned box: its depth object and visual
// hull are the box itself; a sphere: empty far outside, every map agreeing
// inside, depth near the true surface) and against the GPU's stencil and
// first-surface depth (DepthObjectRenderer::DrawSlices), where the two agree
// outside the stated tolerance band; its own view-dependent weights against
// the setup's (and the analytic cases: a view along a map gives that map
// weight 1), the accumulated colour, and the one-pass ray path (DrawRay)
// against its march (analytic on the aligned box; the GPU within the band).
#include "verify/independent_reference.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <random>

#include "ibr/depth_object.h"
#include "tests/ibr/scenes.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

using testing::Sphere;

// Entry and exit parameters of the ray o + t d through the box [-a, a]^3
// (t0 > t1 when it misses).
void AlignedBoxInterval(double a, const glm::dvec3& o, const glm::dvec3& d, double& t0,
                        double& t1) {
  t0 = -INFINITY;
  t1 = INFINITY;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (std::abs(o[k]) > a) t0 = INFINITY;
      continue;
    }
    const double ta = (-a - o[k]) / d[k], tb = (a - o[k]) / d[k];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
}

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
      double t0, t1;
      AlignedBoxInterval(a, ow, dw, t0, t1);
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

// Calls fn(col, row, pixel, ray origin, ray direction in world space) for
// every pixel of `f` outside the tolerance band; returns the band's count.
int64_t ForEachPixelOutsideBand(
    const IndependentFrame& f, const ViewCamera& view,
    const std::function<void(int, int, const IndependentPixel&, const glm::dvec3&,
                             const glm::dvec3&)>& fn) {
  int64_t band = 0;
  for (int row = 0; row < f.height; ++row) {
    for (int col = 0; col < f.width; ++col) {
      const IndependentPixel& px = f.at(col, row);
      if (px.band) {
        ++band;
        continue;
      }
      glm::dvec3 o_w, d_w;
      ViewRay(view, col, row, o_w, d_w);
      fn(col, row, px, o_w, d_w);
    }
  }
  return band;
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
        band += ForEachPixelOutsideBand(
            f, view,
            [&](int col, int row, const IndependentPixel& px, const glm::dvec3& o_w,
                const glm::dvec3& d_w) {
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
              EXPECT_EQ(px.front_slice, expected)
                  << MethodName(method) << " " << SlicingName(slicing) << " pixel " << col << ","
                  << row;
              if (expected >= 0) {
                EXPECT_EQ(px.stencil, n);
                EXPECT_DOUBLE_EQ(px.depth, best_z);
              } else {
                EXPECT_EQ(px.stencil, 0);
              }
            });
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
  // Totals of the slice path and of the ray path (DrawRay with the same
  // options and Slicing::kRay), and the weights' largest difference.
  IndependentComparison slices, ray;
  double worst_weight = 0;
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
      const IndependentComparison c = CompareWithIndependent(
          ref, accum.ReadStencil(), accum.ReadColorF(0), accum.ReadColorF(1));
      const std::string name = fmt::format("scene{}_variant{}", scene, variant);
      EXPECT_EQ(c.real_errors, 0) << name;
      if (c.real_errors > 0) test_support::WriteDebugImage(name + "_diff.png", c.diff);
      slices.Add(c);
      // The weights the GPU blends with (PrepareFrame, ibr/view_weights.h)
      // against the reference's own, from the poses.
      ASSERT_EQ(ref.weights.size(), frame.weights.size());
      for (size_t i = 0; i < ref.weights.size(); ++i)
        worst_weight = std::max(worst_weight, std::abs(ref.weights[i] - frame.weights[i]));
      // The ray path (empty-space skipping on every other variant).
      DepthObjectOptions ro = o;
      ro.slicing = Slicing::kRay;
      ro.skip_grid = variant % 2 == 0 ? 64 : 0;
      ro.refine_steps = variant % 4;
      const FrameParams ray_frame = PrepareFrame(renderer.maps(), view, ro);
      render::RenderTarget ray_accum(
          DepthObjectRenderer::AccumTargetOptions(ray_frame.width, ray_frame.height));
      renderer.DrawRay(ray_frame, ro, ray_accum);
      const IndependentComparison rc =
          CompareWithIndependent(RenderIndependent(renderer.maps(), view, ro, io), {},
                                 ray_accum.ReadColorF(0), ray_accum.ReadColorF(1));
      EXPECT_EQ(rc.real_errors, 0) << name << " ray";
      if (rc.real_errors > 0) test_support::WriteDebugImage(name + "_ray_diff.png", rc.diff);
      ray.Add(rc);
    }
  }
  std::printf(
      "independent vs GPU slices: %lld pixels, %lld agree, %lld object pixels, band %lld (%.3f "
      "%%), band disagreements %lld, real errors %lld, worst depth error / bound %.3g\n",
      static_cast<long long>(slices.pixels), static_cast<long long>(slices.agree),
      static_cast<long long>(slices.covered), static_cast<long long>(slices.band),
      100.0 * slices.band / slices.pixels, static_cast<long long>(slices.band_disagree),
      static_cast<long long>(slices.real_errors), slices.max_depth_error_over_bound);
  std::printf(
      "  colour: %lld object pixels compared (%lld with a texel-choice interval), %lld outside "
      "the bound, worst distance from the interval %.3g; weights: worst |GPU - independent| "
      "%.3g\n",
      static_cast<long long>(slices.color_checked), static_cast<long long>(slices.color_interval),
      static_cast<long long>(slices.color_errors), slices.max_color_error, worst_weight);
  std::printf(
      "ray path vs independent march: %lld pixels, %lld agree, %lld object pixels, band %lld "
      "(%.3f %%), band disagreements %lld, pixels with alternative outcomes %lld (%lld took "
      "one), real errors %lld, worst depth error / bound %.3g; colour on %lld pixels, %lld "
      "outside the bound, worst %.3g\n",
      static_cast<long long>(ray.pixels), static_cast<long long>(ray.agree),
      static_cast<long long>(ray.covered), static_cast<long long>(ray.band),
      100.0 * ray.band / ray.pixels, static_cast<long long>(ray.band_disagree),
      static_cast<long long>(ray.alternative_pixels), static_cast<long long>(ray.alternative_taken),
      static_cast<long long>(ray.real_errors), ray.max_depth_error_over_bound,
      static_cast<long long>(ray.color_checked), static_cast<long long>(ray.color_errors),
      ray.max_color_error);
  EXPECT_GT(slices.covered, 5000);
  EXPECT_LT(slices.band, slices.pixels / 20) << "the band must stay a thin set of pixels";
  EXPECT_EQ(slices.color_errors, 0);
  EXPECT_GT(slices.color_checked, slices.covered * 9 / 10) << "colour is compared on the object";
  EXPECT_LT(worst_weight, 1e-6);
  EXPECT_EQ(ray.real_errors, 0);
  EXPECT_GT(ray.covered, 5000);
  EXPECT_LT(ray.band, ray.pixels / 20) << "the ray path's band must stay a thin set of pixels";
  // Alternatives are checked strictly (the GPU must match one listed
  // outcome); measured here, about 60 % come from the march's first sample
  // on the box face, where the cube rig's image borders lie, the rest from
  // samples on texel edges between differing texels (silhouettes, holes).
  EXPECT_LT(ray.alternative_pixels, ray.pixels / 5);
  // Colour is compared where the GPU took the nominal outcome and the hit
  // point is known to its float bound (not after an uncertain bisection step).
  EXPECT_GT(ray.color_checked, ray.covered * 4 / 5);
  EXPECT_NO_GL_ERROR();
}

// The comparison can fail: a colour off by one 8-bit step on one pixel, a
// weight swapped between two maps, a ray depth one refinement step off and a
// missing ray hit are each reported as real errors.
TEST_F(IndependentGpuTest, InjectedColourAndRayFaultsAreRealErrors) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = testing::RingMaps(5, 3.5, 1.2, 48);
  const std::vector<Sphere> spheres = {{{0.1, 0, -0.1}, 0.6}, {{-0.3, 0.2, 0.3}, 0.35}};
  for (ImageMap& m : set.maps) testing::RenderSpheres(spheres, m);
  DepthObjectRenderer renderer(programs(), std::move(set));
  const ViewCamera view = testing::PerspectiveView({2.4, 1.1, 2.0}, {0, 0, 0}, {0, 1, 0}, 48);
  DepthObjectOptions o;
  o.slicing = Slicing::kScreen;
  o.slices = 40;
  const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
  render::RenderTarget accum(DepthObjectRenderer::AccumTargetOptions(frame.width, frame.height));
  renderer.DrawSlices(frame, o, accum);
  const IndependentFrame ref = RenderIndependent(renderer.maps(), view, o);
  const core::Image8 stencil = accum.ReadStencil();
  const core::ImageF color = accum.ReadColorF(0), depth = accum.ReadColorF(1);
  ASSERT_EQ(CompareWithIndependent(ref, stencil, color, depth).real_errors, 0);
  // One object pixel outside the band, its red one 8-bit step off.
  int fx = -1, fy = -1;
  for (int y = 0; y < ref.height && fx < 0; ++y) {
    for (int x = 0; x < ref.width && fx < 0; ++x) {
      if (ref.at(x, y).count > 0 && !ref.at(x, y).band) fx = x, fy = y;
    }
  }
  ASSERT_GE(fx, 0);
  core::ImageF bad_color = color;
  bad_color.at(fx, fy, 0) += 1.0f / 255.0f;
  EXPECT_EQ(CompareWithIndependent(ref, stencil, bad_color, depth).color_errors, 1);
  // A setup bug in the weights: the GPU drawn with the two largest weights swapped.
  std::vector<int> by_weight(ref.weights.size());
  std::iota(by_weight.begin(), by_weight.end(), 0);
  std::sort(by_weight.begin(), by_weight.end(),
            [&](int a, int b) { return ref.weights[a] > ref.weights[b]; });
  ASSERT_GT(ref.weights[by_weight[0]], ref.weights[by_weight[1]] + 0.05);
  FrameParams swapped = frame;
  std::swap(swapped.maps[by_weight[0]].extra.x, swapped.maps[by_weight[1]].extra.x);
  renderer.DrawSlices(swapped, o, accum);
  const IndependentComparison sw =
      CompareWithIndependent(ref, accum.ReadStencil(), accum.ReadColorF(0), accum.ReadColorF(1));
  std::printf("swapped weights: %lld of %lld object pixels' colours outside the bound\n",
              static_cast<long long>(sw.color_errors), static_cast<long long>(sw.covered));
  EXPECT_GT(sw.color_errors, sw.covered / 2);
  // The ray path: the GPU with 2 refinement steps against a reference with
  // 5 (depths up to a quarter step apart), and one hit removed.
  DepthObjectOptions ro = o;
  ro.slicing = Slicing::kRay;
  ro.refine_steps = 2;
  const FrameParams ray_frame = PrepareFrame(renderer.maps(), view, ro);
  render::RenderTarget ray_accum(
      DepthObjectRenderer::AccumTargetOptions(ray_frame.width, ray_frame.height));
  renderer.DrawRay(ray_frame, ro, ray_accum);
  const core::ImageF ray_color = ray_accum.ReadColorF(0);
  core::ImageF ray_depth = ray_accum.ReadColorF(1);
  const IndependentFrame ray_ref = RenderIndependent(renderer.maps(), view, ro);
  const IndependentComparison ok = CompareWithIndependent(ray_ref, {}, ray_color, ray_depth);
  EXPECT_EQ(ok.real_errors, 0);
  for (int y = 0; y < ray_ref.height; ++y) {
    for (int x = 0; x < ray_ref.width; ++x) {
      if (ok.diff.at(x, y) != 255) continue;
      const IndependentPixel& px = ray_ref.at(x, y);
      std::printf(
          "real error at %d,%d: gpu covered %g z %.9g | ref count %d z %.9g bound %.3g step %d "
          "alts %zu",
          x, y, ray_depth.at(x, y, 1), ray_depth.at(x, y, 0), px.count, px.depth, px.depth_bound,
          px.front_slice, px.alternatives.size());
      for (auto a : px.alternatives) std::printf(" (%.9g %.3g)", a.x, a.y);
      std::printf(" colour gpu %g %g %g %g ref lo %g %g %g %g hi %g %g %g %g b %g\n",
                  ray_color.at(x, y, 0), ray_color.at(x, y, 1), ray_color.at(x, y, 2),
                  ray_color.at(x, y, 3), px.color_lo[0], px.color_lo[1], px.color_lo[2],
                  px.color_lo[3], px.color_hi[0], px.color_hi[1], px.color_hi[2], px.color_hi[3],
                  px.color_bound);
    }
  }
  EXPECT_GT(ok.covered, 300);
  DepthObjectOptions finer = ro;
  finer.refine_steps = 5;
  const IndependentComparison off = CompareWithIndependent(
      RenderIndependent(renderer.maps(), view, finer), {}, ray_color, ray_depth);
  EXPECT_GT(off.real_errors, ok.covered / 2) << "depths a refinement step apart must fail";
  int hx = -1, hy = -1;
  for (int y = 0; y < ray_ref.height && hx < 0; ++y) {
    for (int x = 0; x < ray_ref.width && hx < 0; ++x) {
      if (ray_ref.at(x, y).count > 0 && !ray_ref.at(x, y).band) hx = x, hy = y;
    }
  }
  ASSERT_GE(hx, 0);
  ray_depth.at(hx, hy, 0) = ray_depth.at(hx, hy, 1) = 0.0f;
  EXPECT_EQ(CompareWithIndependent(ray_ref, {}, ray_color, ray_depth).real_errors, 1);
  EXPECT_NO_GL_ERROR();
}

// Weights analytically: a view looking along a map's direction gives that
// map weight 1; otherwise at most three are non-zero, they sum to 1 and the
// nearest map's is the largest.
TEST(IndependentReferenceTest, ViewDependentWeights) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = testing::RingMaps(6, 3.0, 0.8, 16);
  for (ImageMap& m : set.maps) m.depth = core::ImageF(16, 16, 1, 1.0f);
  DepthObjectOptions o;
  o.slices = 4;
  // From map 2's centre towards the box centre.
  const glm::dvec3 c2 = CameraCentre(set.maps[2].cam_from_world);
  ViewCamera along = testing::PerspectiveView(1.3 * c2, {0, 0, 0}, {0, 1, 0}, 8);
  const IndependentFrame f = RenderIndependent(set, along, o);
  // (1e-6: the view's pose is rounded, so its direction is 1e-8 off map 2's.)
  for (size_t i = 0; i < f.weights.size(); ++i) EXPECT_NEAR(f.weights[i], i == 2 ? 1.0 : 0.0, 1e-6);
  const ViewCamera between = testing::PerspectiveView({0.4, 2.0, 2.9}, {0, 0, 0}, {0, 1, 0}, 8);
  const IndependentFrame g = RenderIndependent(set, between, o);
  double sum = 0;
  int nonzero = 0;
  for (double w : g.weights) {
    sum += w;
    nonzero += w > 0;
    EXPECT_GE(w, 0);
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_LE(nonzero, 3);
  EXPECT_GE(nonzero, 2);
  int nearest = 0;
  double best = -2;
  for (size_t i = 0; i < set.maps.size(); ++i) {
    const glm::dvec3 d = glm::normalize(-CameraCentre(set.maps[i].cam_from_world));
    const double cosine = glm::dot(d, glm::normalize(glm::dvec3(-0.4, -2.0, -2.9)));
    if (cosine > best) best = cosine, nearest = static_cast<int>(i);
  }
  EXPECT_EQ(std::max_element(g.weights.begin(), g.weights.end()) - g.weights.begin(), nearest);
}

// The ray march on the aligned box (faces on texel boundaries): every pixel
// whose ray crosses the box [-0.5, 0.5]^3 by more than a step is a hit, its
// depth within half the final bisection bracket (dz / 2^refine_steps) of the
// true entry, plus the float bound; rays missing it are empty.
TEST(IndependentReferenceTest, RayMarchOnTheAlignedBox) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, 64);
  for (ImageMap& m : set.maps) RenderAlignedBox(0.5, m);
  int64_t hits = 0, misses = 0, band = 0;
  for (const ViewCamera& view : AnalyticViews(40)) {
    DepthObjectOptions o;
    o.slicing = Slicing::kRay;
    o.slices = 50;
    o.refine_steps = 5;
    const IndependentFrame f = RenderIndependent(set, view, o);
    ASSERT_TRUE(f.ray);
    band += ForEachPixelOutsideBand(
        f, view,
        [&](int col, int row, const IndependentPixel& px, const glm::dvec3& o_w,
            const glm::dvec3& d_w) {
          double t0, t1;
          AlignedBoxInterval(0.5, o_w, d_w, t0, t1);
          // Camera z of o_w + t d_w is z(o_w) + t (d_w has camera z 1).
          const double z_o = glm::dvec3(view.cam_from_world * glm::dvec4(o_w, 1.0)).z;
          if (!(t0 < t1)) {
            ++misses;
            EXPECT_EQ(px.count, 0) << col << "," << row;
            return;
          }
          if (t1 - t0 < 1.01 * f.ray_step) return;  // a sample may skip a thin corner
          ++hits;
          EXPECT_EQ(px.count, 1) << col << "," << row;
          const double z_true = z_o + t0;
          // The midpoint of the last bracket, which holds the true entry: within half of it.
          EXPECT_LE(std::abs(px.depth - z_true), f.ray_step / 64 + px.depth_bound + 1e-12)
              << col << "," << row;
        });
  }
  std::printf("ray march on the aligned box: %lld hits, %lld misses, %lld in the band\n",
              static_cast<long long>(hits), static_cast<long long>(misses),
              static_cast<long long>(band));
  EXPECT_GT(hits, 500);
  EXPECT_GT(misses, 1000);
  EXPECT_LT(band, (hits + misses) / 20);
}

}  // namespace
}  // namespace ibr
