// Stencil correctness (issue 5, "Tests"): the CPU reference of the
// Kautz-Seidel stencil algorithm (verify/reference.h) agrees with the GPU's
// stencil, accumulated colour and first-surface depth buffers bit for bit,
// for seeded random depth maps and views, both slicing families, three
// resolutions, and the boundary cases (depth exactly on a slice, pixels
// reaching N on the last slice, ties in the best-axis choice).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstdio>
#include <random>

#include "core/image_io.h"
#include "ibr/depth_object.h"
#include "tests/ibr/scenes.h"
#include "tests/support/gl_test.h"
#include "verify/reference.h"

namespace ibr {
namespace {

using testing::Sphere;

struct Mismatches {
  int64_t stencil = 0, color = 0, depth = 0, pixels = 0;
  int64_t total() const { return stencil + color + depth; }
};

class StencilReferenceTest : public test_support::GlTest {
 protected:
  struct Outcome {
    Mismatches mismatches;
    ReferenceBuffers reference;
    int64_t finished_pixels = 0;
  };

  // Renders one frame on the GPU (slice passes only) and on the CPU, compares.
  Outcome Compare(DepthObjectRenderer& renderer, const ViewCamera& view,
                  const DepthObjectOptions& options, const std::string& name) {
    const FrameParams frame = PrepareFrame(renderer.maps(), view, options);
    render::RenderTarget accum(DepthObjectRenderer::AccumTargetOptions(frame.width, frame.height));
    renderer.DrawSlices(frame, options, accum);
    const core::Image8 stencil = accum.ReadStencil();
    const core::ImageF color = accum.ReadColorF(0);
    const core::ImageF depth = accum.ReadColorF(1);
    const std::vector<core::Image8> coverage = renderer.SliceCoverage(frame);
    Outcome out;
    out.reference = RenderReference(frame, renderer.tables(options.method),
                                    ReferenceVariant::From(options), coverage);
    const ReferenceBuffers& ref = out.reference;
    core::Image8 diff(frame.width, frame.height, 1, 0);
    for (int y = 0; y < frame.height; ++y) {
      for (int x = 0; x < frame.width; ++x) {
        bool bad = false;
        if (stencil.at(x, y) != ref.stencil.at(x, y)) ++out.mismatches.stencil, bad = true;
        for (int c = 0; c < 4; ++c) {
          if (std::bit_cast<uint32_t>(color.at(x, y, c)) !=
              std::bit_cast<uint32_t>(ref.color.at(x, y, c))) {
            ++out.mismatches.color, bad = true;
          }
        }
        for (int c = 0; c < 2; ++c) {
          if (std::bit_cast<uint32_t>(depth.at(x, y, c)) !=
              std::bit_cast<uint32_t>(ref.depth.at(x, y, c))) {
            ++out.mismatches.depth, bad = true;
          }
        }
        if (bad) ++out.mismatches.pixels, diff.at(x, y) = 255;
        if (ref.depth.at(x, y, 1) > 0) ++out.finished_pixels;
      }
    }
    if (out.mismatches.total() > 0) {
      test_support::WriteDebugImage(name + "_gpu_stencil.png", stencil);
      test_support::WriteDebugImage(name + "_cpu_stencil.png", ref.stencil);
      test_support::WriteDebugImage(name + "_diff.png", diff);
    }
    return out;
  }
};

// Random blobby object inside [-1, 1]^3 plus texel noise and holes, so
// decisions fall on every side of every comparison.
std::vector<Sphere> RandomSpheres(std::mt19937& rng) {
  std::uniform_real_distribution<double> pos(-0.55, 0.55), rad(0.2, 0.5);
  std::vector<Sphere> s;
  for (int i = 0; i < 5; ++i) s.push_back({{pos(rng), pos(rng), pos(rng)}, rad(rng)});
  return s;
}

void AddNoiseAndHoles(std::mt19937& rng, ImageMap& m) {
  std::uniform_real_distribution<float> u(0, 1);
  for (int y = 0; y < m.depth.height(); ++y) {
    for (int x = 0; x < m.depth.width(); ++x) {
      const float r = u(rng);
      if (r < 0.05f) {
        m.depth.at(x, y) = 0.0f;  // hole (invalid)
      } else if (r < 0.15f) {
        m.depth.at(x, y) = 2.0f * u(rng);  // noise anywhere in the cube
        m.mask.at(x, y) = 255;
      }
    }
  }
}

MapSet RandomCubeMaps(std::mt19937& rng, int map_size) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = CubeRigMaps({0, 0, 0}, 1.0, map_size);
  const auto spheres = RandomSpheres(rng);
  for (ImageMap& m : set.maps) {
    testing::RenderSpheres(spheres, m);
    AddNoiseAndHoles(rng, m);
  }
  return set;
}

MapSet RandomRingMaps(std::mt19937& rng, int map_size) {
  MapSet set;
  set.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  set.maps = testing::RingMaps(5, 3.5, 1.2, map_size);
  const auto spheres = RandomSpheres(rng);
  for (ImageMap& m : set.maps) {
    testing::RenderSpheres(spheres, m);
    AddNoiseAndHoles(rng, m);
  }
  return set;
}

ViewCamera RandomView(std::mt19937& rng, int size, bool orthographic) {
  const glm::dvec3 dir = testing::RandomUnit(rng);
  std::uniform_real_distribution<double> dist(2.6, 4.5), jitter(-0.2, 0.2);
  const glm::dvec3 target(jitter(rng), jitter(rng), jitter(rng));
  glm::dvec3 up = std::abs(dir.z) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
  if (orthographic) return testing::OrthographicView(target + 3.0 * dir, target, up, size, 1.8);
  return testing::PerspectiveView(target + dist(rng) * dir, target, up, size);
}

TEST_F(StencilReferenceTest, RandomMapsAndViewsAgreeBitForBit) {
  std::mt19937 rng(20010607);
  int cases = 0;
  int64_t fragments = 0, finished = 0;
  Mismatches total;
  const int sizes[3] = {64, 97, 160};  // three resolutions, one odd
  for (int scene = 0; scene < 2; ++scene) {
    const bool ring = scene == 1;
    DepthObjectRenderer renderer(programs(),
                                 ring ? RandomRingMaps(rng, 48) : RandomCubeMaps(rng, 40));
    for (int size : sizes) {
      for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
        for (int variant = 0; variant < 4; ++variant) {
          DepthObjectOptions o;
          o.slicing = slicing;
          o.slices = 24 + 8 * variant;
          o.method = variant == 3 ? Method::kVisualHull : Method::kDepthObject;
          o.robust_k = variant == 2 ? 1 : 0;
          o.outside = variant == 1 ? OutsidePolicy::kFail : OutsidePolicy::kPass;
          o.invalid_depth =
              variant == 1 ? InvalidDepthPolicy::kNoConstraint : InvalidDepthPolicy::kEmpty;
          const ViewCamera view = RandomView(rng, size, variant == 0 && size == 97);
          const std::string name = fmt::format("{}_{}_{}_v{}", ring ? "ring" : "cube", size,
                                               SlicingName(slicing), variant);
          const Outcome out = Compare(renderer, view, o, name);
          EXPECT_EQ(out.mismatches.total(), 0)
              << name << ": stencil " << out.mismatches.stencil << ", colour "
              << out.mismatches.color << ", depth " << out.mismatches.depth << " over "
              << out.mismatches.pixels << " pixels";
          total.stencil += out.mismatches.stencil;
          total.color += out.mismatches.color;
          total.depth += out.mismatches.depth;
          fragments += out.reference.fragments;
          finished += out.finished_pixels;
          ++cases;
        }
      }
    }
  }
  std::printf(
      "stencil reference: %d cases, %lld map-pass fragments, %lld object pixels, "
      "mismatches: stencil %lld, colour %lld, depth %lld\n",
      cases, static_cast<long long>(fragments), static_cast<long long>(finished),
      static_cast<long long>(total.stencil), static_cast<long long>(total.color),
      static_cast<long long>(total.depth));
  EXPECT_GT(finished, 1000) << "the random scenes must actually draw objects";
  EXPECT_NO_GL_ERROR();
}

// Boundary cases, constructed so they certainly occur: the view looks exactly
// along -z (orthographic and perspective), the map facing the same way gets,
// for every texel it shows, exactly the map depth of the LAST slice's point
// (a depth exactly on a slice, and every object pixel reaching N on the last
// slice), the other maps impose no constraint; then views on the cube's
// diagonals, where the best-axis choice ties.
TEST_F(StencilReferenceTest, BoundaryCasesAgreeBitForBit) {
  std::mt19937 rng(5);
  int cases = 0;
  for (bool orthographic : {true, false}) {
    for (int size : {64, 97, 160}) {
      MapSet set = RandomCubeMaps(rng, 40);
      const ViewCamera view =
          orthographic ? testing::OrthographicView({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, size, 1.3)
                       : testing::PerspectiveView({0, 0, 3.5}, {0, 0, 0}, {0, 1, 0}, size, 1.5);
      DepthObjectOptions o;
      o.slicing = Slicing::kOrthogonal;
      o.slices = 32;
      o.invalid_depth = InvalidDepthPolicy::kNoConstraint;
      // Points a float rounding outside the box at slice edges fall outside the
      // facing map's image: carve them, so only the constructed texels pass.
      o.outside = OutsidePolicy::kFail;
      const FrameParams frame = PrepareFrame(set, view, o);
      ASSERT_EQ(frame.stack.axis, 2);
      // Map 5 ("face-z") sits on the z = -1 face looking +z; map 4 ("face+z")
      // on z = +1 looking -z, the view's direction.
      const int facing = 4;
      for (int m = 0; m < 6; ++m) {
        set.maps[m].depth = core::ImageF(40, 40, 1, 0.0f);
        // The facing map's texels no last-slice point uses stay empty.
        set.maps[m].mask = core::Image8(40, 40, 1, m == facing ? 0 : 255);
      }
      const int last = static_cast<int>(frame.planes.size()) - 1;
      for (int row = 0; row < size; ++row) {
        for (int col = 0; col < size; ++col) {
          const glm::vec2 uv(col + 0.5f, frame.view_height - ((size - 1 - row) + 0.5f));
          const glm::vec3 p = ReferenceViewPointOnPlane(frame, uv, frame.planes[last]);
          glm::vec3 q;
          glm::ivec3 texel;
          // Several pixels can share a texel: keep the largest, so no pixel
          // passes before the last slice (earlier slices are nearer: smaller z).
          if (ReferenceMapLookup(frame.maps[facing], p, q, texel) && q.z > 0) {
            float& d = set.maps[facing].depth.at(texel.x, texel.y);
            d = std::max(d, q.z);
            set.maps[facing].mask.at(texel.x, texel.y) = 255;
          }
        }
      }
      DepthObjectRenderer renderer(programs(), std::move(set));
      const Outcome out =
          Compare(renderer, view, o, fmt::format("last_slice_{}_{}", orthographic, size));
      EXPECT_EQ(out.mismatches.total(), 0) << "along -z, size " << size;
      EXPECT_GT(out.reference.ties, 100) << "depths exactly on a slice must occur";
      EXPECT_GT(out.reference.finished_on_last_slice, 100)
          << "pixels must reach N on the last slice";
      EXPECT_EQ(out.reference.finished_on_last_slice, out.finished_pixels)
          << "every object pixel finishes on the last slice (orthographic " << orthographic
          << ", size " << size << ")";
      ++cases;
    }
  }
  // Ties in the best-axis choice: views along diagonals; the lowest tied
  // axis wins (render::ChooseOrthogonalAxis), on both sides.
  const glm::dvec3 diagonals[3] = {{1, 1, 1}, {1, 1, 0}, {0, -1, -1}};
  for (const glm::dvec3& d : diagonals) {
    for (int size : {64, 97, 160}) {
      DepthObjectRenderer renderer(programs(), RandomCubeMaps(rng, 40));
      const ViewCamera view =
          testing::PerspectiveView(3.0 * glm::normalize(d), {0, 0, 0},
                                   d.z == 0 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0), size);
      DepthObjectOptions o;
      o.slices = 40;
      const FrameParams frame = PrepareFrame(renderer.maps(), view, o);
      EXPECT_EQ(frame.stack.axis, d.x != 0 ? 0 : 1) << "lowest tied axis";
      const Outcome out =
          Compare(renderer, view, o, fmt::format("diag_{}_{}_{}_{}", d.x, d.y, d.z, size));
      EXPECT_EQ(out.mismatches.total(), 0) << "diagonal view, size " << size;
      EXPECT_GT(out.finished_pixels, 50);
      ++cases;
    }
  }
  std::printf("stencil reference boundary cases: %d, all without mismatches if this test passed\n",
              cases);
  EXPECT_NO_GL_ERROR();
}

// The property behind the paper's remark (sec. 4.1): a pixel whose stencil
// reached N stays N, so it keeps the colour and depth of the FRONT-MOST slice
// where every map accepted it. Checked directly, without emulating the
// stencil: for each pixel, the first slice (front to back) covering it where
// all maps accept its point, evaluated with the mirrored map test.
TEST_F(StencilReferenceTest, FinishedPixelsKeepTheFrontMostSlice) {
  std::mt19937 rng(77);
  for (Slicing slicing : {Slicing::kOrthogonal, Slicing::kScreen}) {
    DepthObjectRenderer renderer(programs(), RandomCubeMaps(rng, 40));
    const ViewCamera view = RandomView(rng, 97, false);
    DepthObjectOptions o;
    o.slicing = slicing;
    o.slices = 48;
    const FrameParams f = PrepareFrame(renderer.maps(), view, o);
    render::RenderTarget accum(DepthObjectRenderer::AccumTargetOptions(f.width, f.height));
    renderer.DrawSlices(f, o, accum);
    const core::ImageF color = accum.ReadColorF(0);
    const core::ImageF depth = accum.ReadColorF(1);
    const core::Image8 stencil = accum.ReadStencil();
    const std::vector<core::Image8> coverage = renderer.SliceCoverage(f);
    const MapTables& tables = renderer.tables(o.method);
    const ReferenceVariant variant = ReferenceVariant::From(o);
    int64_t finished = 0, wrong = 0, later_accepts = 0;
    for (int row = 0; row < f.height; ++row) {
      for (int col = 0; col < f.width; ++col) {
        const glm::vec2 uv(col + 0.5f, f.view_height - ((f.height - 1 - row) + 0.5f));
        int first = -1, accepted = 0;
        for (size_t s = 0; s < coverage.size(); ++s) {
          if (coverage[s].at(col, row) == 0) continue;
          const glm::vec3 p = ReferenceViewPointOnPlane(f, uv, f.planes[s]);
          bool all = true;
          for (int a : f.active) {
            glm::ivec3 texel;
            all = all && ReferenceMapAccepts(tables, f.maps[a], variant, p, texel);
          }
          if (!all) continue;
          ++accepted;
          if (first < 0) first = static_cast<int>(s);
        }
        if (first < 0) {
          wrong += stencil.at(col, row) != 0 || depth.at(col, row, 1) != 0;
          continue;
        }
        ++finished;
        later_accepts += accepted > 1;
        const glm::vec3 p = ReferenceViewPointOnPlane(f, uv, f.planes[first]);
        wrong += stencil.at(col, row) != f.active.size() || depth.at(col, row, 0) != p.z;
        // Its colour is the weighted sum of the maps' texels at that point.
        float expected[4] = {0, 0, 0, 0};
        for (int a : f.active) {
          glm::ivec3 texel;
          ReferenceMapAccepts(tables, f.maps[a], variant, p, texel);
          if (texel.x < 0) continue;
          for (int c = 0; c < 4; ++c) {
            const float cc =
                static_cast<float>(tables.color[tables.Index(texel.z, texel.x, texel.y) * 4 + c]) *
                f.inv255;
            expected[c] = expected[c] + cc * f.maps[a].extra.x;
          }
        }
        for (int c = 0; c < 4; ++c) wrong += color.at(col, row, c) != expected[c];
      }
    }
    EXPECT_EQ(wrong, 0) << SlicingName(slicing);
    EXPECT_GT(finished, 500);
    EXPECT_GT(later_accepts, finished / 2)
        << "deeper slices accept these pixels too, and must not win";
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
