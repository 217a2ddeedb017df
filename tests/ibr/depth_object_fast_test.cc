// The fast slice path (SlicePath::kFast, ibr/depth_object_fast.cc) against
// the exact stencil path and its CPU reference (verify/reference.h), on the
// test objects of depth_object_test and stencil_reference_test (a sphere and
// random blobs with noise and holes in the cube rig and a pinhole ring, the
// cup): the same coverage except for a stated share of pixels, the same
// first-slice depth within the slice spacing along the view, the same
// colour sum; and a sweep over view angles, grazing ones included, with
// finite results.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "capture/synthetic.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/scene_options.h"
#include "tests/ibr/scenes.h"
#include "tests/support/gl_test.h"
#include "verify/reference.h"

namespace ibr {
namespace {

using testing::Sphere;

// Share of the pixels either path covers that only one covers. The paths
// differ where a ray meets the slices out of drawing order (not in these
// views: the eye is outside the box) and where two slices' window depths tie
// in the 24-bit buffer (LESS keeps the first drawn, as the stencil does);
// measured 0 here, the bound leaves room for such ties along the rim.
constexpr double kCoverageTolerance = 1e-3;

// The depth step between neighbouring slices along the view's axis: screen
// slices are camera-z planes (their spacing); a ray crosses box-axis planes
// 1/cos apart.
double SpacingAlongView(const MapSet& maps, const FrameParams& frame, const ViewCamera& view) {
  double spacing = frame.stack.spacing_world;
  if (frame.stack.axis >= 0) {
    const glm::dvec3 n = glm::normalize(glm::dvec3(maps.world_from_box[frame.stack.axis]));
    spacing /= std::max(std::abs(glm::dot(n, CameraAxis(view.cam_from_world))), 1e-6);
  }
  return spacing;
}

struct Agreement {
  int64_t union_pixels = 0, only_one = 0, both = 0;
  int64_t depth_equal = 0;  // both covered, camera z bit-equal
  double max_depth_diff = 0;
  double max_color_diff = 0;  // accumulated sum w c and sum w, relative to sum w
  double coverage_share() const {
    return union_pixels ? static_cast<double>(only_one) / union_pixels : 0.0;
  }
};

// `a`, `b`: 4-channel colour (sum w c, sum w) and 2-channel (z, covered) images.
Agreement Agree(const core::ImageF& color_a, const core::ImageF& depth_a,
                const core::ImageF& color_b, const core::ImageF& depth_b) {
  Agreement g;
  for (int y = 0; y < depth_a.height(); ++y) {
    for (int x = 0; x < depth_a.width(); ++x) {
      const bool ca = depth_a.at(x, y, 1) > 0.5f, cb = depth_b.at(x, y, 1) > 0.5f;
      if (!ca && !cb) continue;
      ++g.union_pixels;
      if (ca != cb) {
        ++g.only_one;
        continue;
      }
      ++g.both;
      const double dz = std::abs(double(depth_a.at(x, y, 0)) - depth_b.at(x, y, 0));
      g.depth_equal += dz == 0;
      g.max_depth_diff = std::max(g.max_depth_diff, dz);
      if (dz == 0) {
        const double w = std::max<double>(color_a.at(x, y, 3), 1e-6);
        for (int c = 0; c < 4; ++c) {
          g.max_color_diff = std::max(
              g.max_color_diff, std::abs(double(color_a.at(x, y, c)) - color_b.at(x, y, c)) / w);
        }
      }
    }
  }
  return g;
}

class DepthObjectFastTest : public test_support::GlTest {
 protected:
  // The fast slice passes' accumulation target, read back: colour, depth.
  std::pair<core::ImageF, core::ImageF> Fast(DepthObjectRenderer& renderer,
                                             const FrameParams& frame,
                                             const DepthObjectOptions& options) {
    render::RenderTarget accum(DepthObjectRenderer::AccumTargetOptions(frame.width, frame.height));
    renderer.DrawSlicesFast(frame, options, accum);
    return {accum.ReadColorF(0), accum.ReadColorF(1)};
  }
};

MapSet SphereCube(int map_size, const std::vector<Sphere>& spheres) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, map_size);
  for (ImageMap& m : set.maps) testing::RenderSpheres(spheres, m);
  return set;
}

// Random blobs with texel noise and holes (stencil_reference_test's maps), so
// decisions fall on every side of every comparison.
MapSet NoisyBlobs(std::mt19937& rng, int map_size, bool ring) {
  std::uniform_real_distribution<double> pos(-0.55, 0.55), rad(0.2, 0.5);
  std::vector<Sphere> spheres;
  for (int i = 0; i < 5; ++i) spheres.push_back({{pos(rng), pos(rng), pos(rng)}, rad(rng)});
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps =
      ring ? testing::RingMaps(5, 3.5, 1.2, map_size) : CubeRigMaps({0, 0, 0}, 1.0, map_size);
  std::uniform_real_distribution<float> u(0, 1);
  for (ImageMap& m : set.maps) {
    testing::RenderSpheres(spheres, m);
    for (float& d : m.depth.values()) {
      const float r = u(rng);
      if (r < 0.05f)
        d = 0.0f;  // hole (invalid)
      else if (r < 0.1f)
        d = 2.0f * u(rng);  // noise anywhere in the box
    }
  }
  return set;
}

// The cup captured in the cube rig, through the dataset route the bench and
// `ibr render` take (capture, write, read, MapsFromDataset).
MapSet CupCube(render::ProgramCache& programs) {
  capture::CaptureOptions co;
  co.rig = "cube";
  co.size = 160;
  const std::filesystem::path dir = test_support::TestOutputDir() / "cup_cube";
  std::filesystem::remove_all(dir);
  capture::CaptureDataset(programs, capture::MakeShapeScene("cup"), co, dir);
  return MapsFromDataset(capture::ReadDataset(dir));
}

ViewCamera RandomView(std::mt19937& rng, int size, bool orthographic, double scale = 1.0) {
  const glm::dvec3 dir = testing::RandomUnit(rng);
  std::uniform_real_distribution<double> dist(2.6, 4.5);
  const glm::dvec3 up = std::abs(dir.z) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
  if (orthographic)
    return testing::OrthographicView(3.0 * scale * dir, {0, 0, 0}, up, size, 1.8 * scale);
  return testing::PerspectiveView(dist(rng) * scale * dir, {0, 0, 0}, up, size);
}

// Fast slice passes against the CPU reference of the exact ones, which
// tests/verify/stencil_reference_test holds bit-equal to the GPU's exact path.
TEST_F(DepthObjectFastTest, SlicePassesMatchTheReference) {
  std::mt19937 rng(120003);
  int cases = 0;
  for (int object = 0; object < 3; ++object) {
    const MapSet maps = object == 0 ? SphereCube(96, {{{0, 0, 0}, 0.8}})
                                    : NoisyBlobs(rng, 80, /*ring=*/object == 2);
    DepthObjectRenderer renderer(programs(), maps);
    for (Method method : {Method::kDepthObject, Method::kVisualHull}) {
      for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
        for (int robust_k : {0, 1}) {
          for (int v = 0; v < 2; ++v) {
            DepthObjectOptions o;
            o.method = method;
            o.slicing = slicing;
            o.slices = v == 0 ? 48 : 97;
            o.robust_k = robust_k;
            o.slice_path = SlicePath::kFast;
            const ViewCamera view = RandomView(rng, 72, /*orthographic=*/v == 1);
            const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
            const auto [color, depth] = Fast(renderer, frame, o);
            const ReferenceBuffers ref =
                RenderReference(frame, renderer.tables(method), ReferenceVariant::From(o),
                                renderer.SliceCoverage(frame));
            const Agreement g = Agree(color, depth, ref.color, ref.depth);
            const double spacing = SpacingAlongView(renderer.maps(), frame, view);
            const std::string what =
                fmt::format("object {} {} {} k={} view {}", object, MethodName(method),
                            SlicingName(slicing), robust_k, v);
            std::printf(
                "%s: %lld pixels, %lld covered by one path only, depth bit-equal %lld of %lld, "
                "max depth diff %.3g (spacing %.3g), max colour diff %.3g\n",
                what.c_str(), static_cast<long long>(g.union_pixels),
                static_cast<long long>(g.only_one), static_cast<long long>(g.depth_equal),
                static_cast<long long>(g.both), g.max_depth_diff, spacing, g.max_color_diff);
            EXPECT_GT(g.union_pixels, 0) << what;
            EXPECT_LE(g.coverage_share(), kCoverageTolerance) << what;
            EXPECT_LE(g.max_depth_diff, spacing * 1.0001) << what;
            // Same maps, same order, same float operations: the colour sum of
            // a pixel finished on the same slice differs by rounding at most.
            EXPECT_LE(g.max_color_diff, 1e-5) << what;
            ++cases;
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 48);
  EXPECT_NO_GL_ERROR();
}

// Whole frames (with the resolve pass and its refinement, texturing) by both
// paths on the cup: the cavity is kept, coverage and depth agree.
TEST_F(DepthObjectFastTest, CupFramesMatchTheExactPath) {
  DepthObjectRenderer renderer(programs(), CupCube(programs()));
  std::mt19937 rng(7);
  for (Method method : {Method::kDepthObject, Method::kVisualHull}) {
    for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
      for (int v = 0; v < 3; ++v) {
        // View 0 looks into the opening; the others are random.
        const ViewCamera view =
            v == 0 ? testing::PerspectiveView({0.3, -0.4, 4.0}, {0, 0, 0.2}, {0, 1, 0}, 128)
                   : RandomView(rng, 128, v == 2, 1.6);
        DepthObjectOptions o;
        o.method = method;
        o.slicing = slicing;
        o.slices = 128;
        const render::Frame exact = renderer.RenderFrame(view, o);
        o.slice_path = SlicePath::kFast;
        const render::Frame fast = renderer.RenderFrame(view, o);
        const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
        const double spacing = SpacingAlongView(renderer.maps(), frame, view);
        int64_t union_pixels = 0, only_one = 0, colour_off = 0, both = 0;
        double max_dz = 0;
        for (int y = 0; y < 128; ++y) {
          for (int x = 0; x < 128; ++x) {
            const bool a = exact.Covered(x, y), b = fast.Covered(x, y);
            union_pixels += a || b;
            only_one += a != b;
            if (!(a && b)) continue;
            ++both;
            max_dz = std::max(max_dz, double(std::abs(exact.depth.at(x, y) - fast.depth.at(x, y))));
            for (int c = 0; c < 3; ++c)
              colour_off += std::abs(int(exact.color.at(x, y, c)) - fast.color.at(x, y, c)) > 1;
          }
        }
        const std::string what =
            fmt::format("cup {} {} view {}", MethodName(method), SlicingName(slicing), v);
        std::printf(
            "%s: %lld pixels, %lld by one path only, max depth diff %.3g (spacing %.3g), "
            "%lld colour channels off by > 1/255\n",
            what.c_str(), static_cast<long long>(union_pixels), static_cast<long long>(only_one),
            max_dz, spacing, static_cast<long long>(colour_off));
        EXPECT_GT(union_pixels, 500) << what;
        EXPECT_LE(static_cast<double>(only_one), kCoverageTolerance * union_pixels) << what;
        // Refinement brackets the surface between the same two slices.
        EXPECT_LE(max_dz, spacing * 1.0001) << what;
        EXPECT_LE(colour_off, both / 1000) << what;
        if (v == 0 && method == Method::kDepthObject) {
          // The cavity (depth_object_test's check): the depth object's centre
          // sees the floor, the hull's the lid, about a cup height above it.
          DepthObjectOptions h = o;
          h.method = Method::kVisualHull;
          const render::Frame hull = renderer.RenderFrame(view, h);
          ASSERT_GT(fast.depth.at(64, 64), 0) << what;
          ASSERT_GT(hull.depth.at(64, 64), 0) << what;
          EXPECT_GT(fast.depth.at(64, 64) - hull.depth.at(64, 64), 0.8) << what;
          test_support::WriteDebugImage("fast_cup_" + SlicingName(slicing) + ".png", fast.color);
        }
      }
    }
  }
  EXPECT_NO_GL_ERROR();
}

// A sweep of view angles from above to grazing (elevation 90 to 0 degrees,
// and views whose axis lies in a box face plane, at 45 degrees between two
// box axes where the orthogonal family switches axis, and along the cube's
// diagonal), perspective and orthographic, and eyes inside the box: every
// frame finite, the object drawn, and (eye outside) the fast path's coverage
// and depth those of the exact path.
TEST_F(DepthObjectFastTest, ViewAngleSweepIncludingGrazingIsFinite) {
  const std::vector<Sphere> sphere = {{{0.1, -0.05, 0.0}, 0.7}};
  DepthObjectRenderer renderer(programs(), SphereCube(64, sphere));
  int views = 0;
  auto finite = [](const render::Frame& f) {
    for (float z : f.depth.values())
      if (!std::isfinite(z) || z < 0) return false;
    for (size_t p = 0; p < f.color.pixel_count(); ++p) {
      const uint8_t alpha = f.color.data()[p * 4 + 3];
      if (alpha != 0 && alpha != 255) return false;
    }
    return true;
  };
  for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
    for (double elevation : {90.0, 89.9, 60.0, 54.7356, 45.0, 30.0, 10.0, 1.0, 0.01, 0.0}) {
      for (double azimuth : {0.0, 22.5, 45.0, 45.001}) {
        for (bool ortho : {false, true}) {
          const double e = glm::radians(elevation), a = glm::radians(azimuth);
          const glm::dvec3 dir(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
          const glm::dvec3 up = elevation > 80 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
          const ViewCamera view = ortho
                                      ? testing::OrthographicView(3.0 * dir, {0, 0, 0}, up, 64, 1.2)
                                      : testing::PerspectiveView(3.0 * dir, {0, 0, 0}, up, 64);
          DepthObjectOptions o;
          o.slicing = slicing;
          o.slices = 64;
          o.texturing = Texturing::kNone;
          const render::Frame exact = renderer.RenderFrame(view, o);
          o.slice_path = SlicePath::kFast;
          const render::Frame fast = renderer.RenderFrame(view, o);
          const std::string what =
              fmt::format("{} elevation {} azimuth {} {}", SlicingName(slicing), elevation, azimuth,
                          ortho ? "ortho" : "persp");
          EXPECT_TRUE(finite(fast)) << what;
          int64_t covered = 0, only_one = 0, union_pixels = 0;
          double max_dz = 0;
          for (size_t i = 0; i < fast.color.pixel_count(); ++i) {
            const bool a2 = exact.color.data()[i * 4 + 3] == 255,
                       b2 = fast.color.data()[i * 4 + 3] == 255;
            covered += b2;
            union_pixels += a2 || b2;
            only_one += a2 != b2;
            if (a2 && b2)
              max_dz = std::max(max_dz,
                                double(std::abs(exact.depth.values()[i] - fast.depth.values()[i])));
          }
          const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
          EXPECT_GT(covered, 300) << what;
          EXPECT_LE(static_cast<double>(only_one), kCoverageTolerance * union_pixels + 1) << what;
          EXPECT_LE(max_dz, SpacingAlongView(renderer.maps(), frame, view) * 1.0001) << what;
          ++views;
        }
      }
    }
    // Eyes inside the box (inside and outside the sphere): the orders may
    // differ there (the fast path keeps the nearest slice), so only finite
    // output and a drawn object are required.
    for (glm::dvec3 eye :
         {glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(0.85, 0.9, 0.2), glm::dvec3(0.95, 0.0, 0.0)}) {
      DepthObjectOptions o;
      o.slicing = slicing;
      o.slices = 64;
      o.slice_path = SlicePath::kFast;
      const render::Frame f =
          renderer.RenderFrame(testing::PerspectiveView(eye, {0, 0, 0}, {0, 0, 1}, 64, 0.6), o);
      const int64_t covered = f.CoveredPixels();
      EXPECT_TRUE(finite(f)) << "eye inside at " << eye.x;
      EXPECT_GT(covered, 0) << "eye inside at " << eye.x;
      ++views;
    }
  }
  EXPECT_EQ(views, 2 * (10 * 4 * 2 + 3));
  EXPECT_NO_GL_ERROR();
}

TEST(DepthObjectFastOptions, NamesAndSettings) {
  EXPECT_EQ(SlicePathFromName("fast"), SlicePath::kFast);
  EXPECT_EQ(SlicePathFromName("exact"), SlicePath::kExact);
  EXPECT_EQ(SlicePathName(SlicePath::kFast), "fast");
  EXPECT_THROW(SlicePathFromName("quick"), core::InputError);
  EXPECT_EQ(DepthObjectOptions{}.slice_path, SlicePath::kExact) << "the paper's path by default";
  const DepthObjectOptions o =
      DepthObjectOptionsFromJson(nlohmann::json::parse(R"({"slice_path": "fast"})"), "s");
  EXPECT_EQ(o.slice_path, SlicePath::kFast);
  try {
    DepthObjectOptionsFromJson(nlohmann::json::parse(R"({"slice_path": "quick"})"), "scene.json");
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json /slice_path"), std::string::npos) << e.what();
  }
  DepthObjectFlags flags;
  flags.slice_path = "fast";
  EXPECT_EQ(DepthObjectOptionsFrom(SettingsFromFlags(flags)).slice_path, SlicePath::kFast);
}

}  // namespace
}  // namespace ibr
