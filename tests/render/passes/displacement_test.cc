// Displacement mapping by slicing (Kautz-Seidel 2001, sec. 3) against
// analytic truth (a constant height is a plane at a known, quantised height;
// a height of 0 draws nothing; the strict alpha test on both sides of a slice
// height) and against the tessellated ground truth (Figure 4 as a number: no
// see-through pixels for orthogonal and screen-space slicing at a grazing
// view where surface-aligned slicing has them; the donut).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/displacement_error.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/memory_budget.h"
#include "core/mesh.h"
#include "core/projection.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/displacement_pass.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {
using core::CompareToGroundTruth;
using core::DisplacementError;
using core::DisplacementErrorOptions;
using core::HeightTexelWorldSize;

constexpr float kMaxDisplacement = 0.25f;

struct Camera {
  ViewSetup view;
  double f, c;  // focal length and principal point (square image), pixels
};

// Perspective camera orbiting the origin at `elevation_deg` above z = 0.
Camera OrbitCamera(double elevation_deg, double azimuth_deg, int size, double distance = 4.0) {
  const double el = elevation_deg * std::numbers::pi / 180,
               az = azimuth_deg * std::numbers::pi / 180;
  const glm::vec3 horizontal(static_cast<float>(std::cos(az)), static_cast<float>(std::sin(az)), 0);
  const glm::vec3 to_eye = static_cast<float>(std::cos(el)) * horizontal +
                           glm::vec3(0, 0, static_cast<float>(std::sin(el)));
  const glm::vec3 up = -static_cast<float>(std::sin(el)) * horizontal +
                       glm::vec3(0, 0, static_cast<float>(std::cos(el)));
  Camera cam;
  cam.f = 1.3 * size;
  cam.c = size / 2.0;
  cam.view.cam_from_world =
      core::CamFromWorldLookAt(static_cast<float>(distance) * to_eye, {0, 0, 0}, up);
  cam.view.clip_from_cam =
      core::ClipFromCamPerspective(cam.f, cam.f, cam.c, cam.c, size, size, 0.5, 10.0);
  return cam;
}

core::ImageF ConstantHeight(float h, int texels = 8) { return core::ImageF(texels, texels, 1, h); }

Texture ExactTexture(const core::ImageF& height) {
  return UploadDisplacementTexture(MakeDisplacementTexels(height), {GL_RGBA32F, false});
}

// Camera z where the ray through pixel (col, row) meets the world plane z = height.
double PlaneDepth(const Camera& cam, int col, int row, double height) {
  const glm::dvec3 d((col + 0.5 - cam.c) / cam.f, (row + 0.5 - cam.c) / cam.f, 1.0);
  const glm::dvec3 n_cam = glm::dmat3(glm::mat3(cam.view.cam_from_world)) * glm::dvec3(0, 0, 1);
  const glm::dvec3 p0 =
      glm::dvec3(cam.view.cam_from_world * glm::vec4(0, 0, static_cast<float>(height), 1));
  return glm::dot(n_cam, p0) / glm::dot(n_cam, d);
}

// The world point of pixel (col, row) on the plane z = height.
glm::dvec3 PlanePoint(const Camera& cam, int col, int row, double height) {
  const double z = PlaneDepth(cam, col, row, height);
  const glm::dvec3 p_cam((col + 0.5 - cam.c) / cam.f * z, (row + 0.5 - cam.c) / cam.f * z, z);
  return glm::dvec3(glm::inverse(cam.view.cam_from_world) * glm::vec4(glm::vec3(p_cam), 1.0f));
}

int Covered(const Frame& frame) {
  int n = 0;
  for (int y = 0; y < frame.color.height(); ++y)
    for (int x = 0; x < frame.color.width(); ++x) n += frame.color.at(x, y, 3) == 255;
  return n;
}

void ExpectFinite(const Frame& frame) {
  for (int y = 0; y < frame.depth.height(); ++y) {
    for (int x = 0; x < frame.depth.width(); ++x) {
      const float z = frame.depth.at(x, y);
      ASSERT_TRUE(std::isfinite(z)) << x << "," << y;
      const uint8_t a = frame.color.at(x, y, 3);
      ASSERT_TRUE(a == 0 || a == 255);
      if (a == 255) {
        ASSERT_GT(z, 0.0f);
      } else {
        ASSERT_EQ(z, 0.0f);
      }
    }
  }
}

class DisplacementTest : public test_support::GlTest {
 protected:
  Frame RenderPlane(const core::ImageF& height, SliceFamily family, int count, const Camera& cam,
                    int size, const core::TriangleMesh& base = core::MakePlane(1.0f, 1),
                    bool linear = false) {
    DisplacementPassOptions options;
    options.slicing.family = family;
    options.slicing.count = count;
    options.max_displacement = kMaxDisplacement;
    const Texture texture =
        UploadDisplacementTexture(MakeDisplacementTexels(height), {GL_RGBA32F, linear});
    DisplacementPass pass(programs(), base, texture, options);
    return RenderFrame(pass, cam.view, size, size);
  }
};

// Surface-aligned slices are planes z = (k + 0.5) / n (times the max
// displacement); with a constant height h the strict alpha test keeps those
// below h, so the plane seen is the highest of them: exact, per pixel.
TEST_F(DisplacementTest, ConstantHeightIsThePlaneAtTheHighestSliceBelowIt) {
  constexpr int kSize = 128, kSlices = 16;
  const Camera cam = OrbitCamera(60, -60, kSize);
  for (float h : {0.3f, 0.5f, 0.77f, 1.0f}) {
    const Frame frame =
        RenderPlane(ConstantHeight(h), SliceFamily::kSurfaceAligned, kSlices, cam, kSize);
    ExpectFinite(frame);
    const double k = std::ceil(h * kSlices - 0.5) - 1;
    const double seen = (k + 0.5) / kSlices * kMaxDisplacement;
    // Seen height within one slice spacing below h (half a spacing when h is a cell boundary).
    ASSERT_GE(h * kMaxDisplacement - seen, 0.0);
    ASSERT_LE(h * kMaxDisplacement - seen, kMaxDisplacement / kSlices + 1e-7);
    int inside = 0, wrong_coverage = 0;
    for (int row = 0; row < kSize; ++row) {
      for (int col = 0; col < kSize; ++col) {
        const glm::dvec3 p = PlanePoint(cam, col, row, seen);
        const double edge = std::max(std::abs(p.x), std::abs(p.y));
        const bool covered = frame.color.at(col, row, 3) == 255;
        // Inside the top slice's square every pixel shows it; outside, the
        // lower slices' edges (the volume's side) may show.
        if (edge > 0.97) continue;
        if (!covered) {
          ++wrong_coverage;
          continue;
        }
        ++inside;
        const double truth = PlaneDepth(cam, col, row, seen);
        ASSERT_NEAR(frame.depth.at(col, row), truth, 2e-5 * truth)
            << "h " << h << " at " << col << "," << row;
      }
    }
    EXPECT_EQ(wrong_coverage, 0) << "h " << h;
    EXPECT_GT(inside, 3000);
  }
  EXPECT_NO_GL_ERROR();
}

// Orthogonal and screen slices: the surface seen lies behind the true plane
// at h by at most the distance along the ray to the next slice plane.
TEST_F(DisplacementTest, ConstantHeightIsWithinOneSliceOfThePlaneForEveryFamily) {
  constexpr int kSize = 128, kSlices = 24;
  const float h = 0.6f;
  const core::TriangleMesh base = core::MakePlane(1.0f, 1);
  const auto volumes = DisplacementVolumesFromMesh(base);
  ASSERT_EQ(volumes.size(), 1u);  // MakePlane's quad is one parallelogram volume
  const SliceBox box = DisplacementVolumeBox(volumes[0], kMaxDisplacement);
  for (double elevation : {20.0, 60.0}) {
    const Camera cam = OrbitCamera(elevation, -60, kSize);
    for (SliceFamily family :
         {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
      SlicingOptions slicing;
      slicing.family = family;
      slicing.count = kSlices;
      const SliceStack stack = MakeSlices(box, {cam.view.cam_from_world, false}, slicing);
      glm::dvec3 m_cam(0, 0, 1);  // screen planes: camera z = const
      if (family != SliceFamily::kScreen) {
        const glm::mat3 inv = glm::inverse(glm::mat3(box.world_from_box));
        const glm::vec3 g(inv[0][stack.axis], inv[1][stack.axis], inv[2][stack.axis]);
        m_cam = glm::normalize(glm::dvec3(glm::mat3(cam.view.cam_from_world) * g));
      }
      const Frame frame = RenderPlane(ConstantHeight(h), family, kSlices, cam, kSize);
      ExpectFinite(frame);
      int checked = 0;
      double worst = 0;
      for (int row = 0; row < kSize; ++row) {
        for (int col = 0; col < kSize; ++col) {
          const glm::dvec3 p = PlanePoint(cam, col, row, h * kMaxDisplacement);
          if (std::max(std::abs(p.x), std::abs(p.y)) > 0.95 || frame.color.at(col, row, 3) != 255)
            continue;
          const glm::dvec3 d = glm::normalize(
              glm::dvec3((col + 0.5 - cam.c) / cam.f, (row + 0.5 - cam.c) / cam.f, 1));
          const double bound = stack.spacing_world / std::abs(glm::dot(d, m_cam)) * d.z;
          const double truth = PlaneDepth(cam, col, row, h * kMaxDisplacement);
          const double behind = frame.depth.at(col, row) - truth;
          worst = std::max(worst, behind / bound);
          EXPECT_GE(behind, -2e-5 * truth) << SliceFamilyName(family) << " " << col << "," << row;
          EXPECT_LE(behind, bound + 2e-5 * truth)
              << SliceFamilyName(family) << " " << col << "," << row;
          ++checked;
        }
      }
      EXPECT_GT(checked, 2000) << SliceFamilyName(family) << " elevation " << elevation;
      RecordProperty(SliceFamilyName(family) + "_worst_fraction_of_bound", std::to_string(worst));
    }
  }
  EXPECT_NO_GL_ERROR();
}

// The alpha test is strict (sec. 3.2): a height exactly at a slice's height
// does not draw that slice; the next float above does.
TEST_F(DisplacementTest, HeightExactlyAtASliceHeightTestsBothSidesOfTheStrictInequality) {
  constexpr int kSize = 96;
  const Camera cam = OrbitCamera(70, -60, kSize);
  // Two slices, at heights 0.25 and 0.75.
  const float at = 0.75f, above = std::nextafter(0.75f, 1.0f);
  const Frame at_frame =
      RenderPlane(ConstantHeight(at), SliceFamily::kSurfaceAligned, 2, cam, kSize);
  const Frame above_frame =
      RenderPlane(ConstantHeight(above), SliceFamily::kSurfaceAligned, 2, cam, kSize);
  const int col = kSize / 2, row = kSize / 2;
  ASSERT_EQ(at_frame.color.at(col, row, 3), 255);
  ASSERT_EQ(above_frame.color.at(col, row, 3), 255);
  const double low = PlaneDepth(cam, col, row, 0.25 * kMaxDisplacement);
  const double high = PlaneDepth(cam, col, row, 0.75 * kMaxDisplacement);
  EXPECT_NEAR(at_frame.depth.at(col, row), low, 1e-5 * low);
  EXPECT_NEAR(above_frame.depth.at(col, row), high, 1e-5 * high);
  // Exactly the lowest slice's height: nothing at all.
  const Frame none =
      RenderPlane(ConstantHeight(0.25f), SliceFamily::kSurfaceAligned, 2, cam, kSize);
  EXPECT_EQ(Covered(none), 0);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DisplacementTest, HeightZeroRendersNothingForEveryFamilyAndBase) {
  constexpr int kSize = 96;
  const Camera cam = OrbitCamera(40, -60, kSize, 6.0);
  for (const core::TriangleMesh& base :
       {core::MakePlane(1.0f, 1), core::MakeTorus(1.0f, 0.4f, 25, 25)}) {
    for (SliceFamily family :
         {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
      const Frame frame = RenderPlane(ConstantHeight(0.0f), family, 16, cam, kSize, base, true);
      EXPECT_EQ(Covered(frame), 0) << SliceFamilyName(family);
      ExpectFinite(frame);
    }
  }
  // A positive height on the same setup does draw (the check above can fail).
  EXPECT_GT(Covered(RenderPlane(ConstantHeight(0.5f), SliceFamily::kOrthogonal, 16, cam, kSize)),
            1000);
  EXPECT_NO_GL_ERROR();
}

class GroundTruthTest : public DisplacementTest {
 protected:
  struct Result {
    DisplacementError error;
    Frame frame, truth;
  };
  // Bumps on a solid floor (every ground-truth pixel is surface), 128 texels.
  Result Compare(const core::TriangleMesh& base, SliceFamily family, int count, const Camera& cam,
                 int size, float tiling) {
    core::HeightMapOptions hm;
    hm.pattern = core::HeightPattern::kBumps;
    hm.size = 128;
    core::ImageF height = core::MakeHeightMap(hm);
    for (float& v : height.values()) v = 0.15f + 0.85f * v;
    const Texture texture = UploadDisplacementTexture(MakeDisplacementTexels(height));
    DisplacementPassOptions options;
    options.slicing.family = family;
    options.slicing.count = count;
    options.max_displacement = kMaxDisplacement;
    options.tiling = tiling;
    DisplacementPass pass(programs(), base, texture, options);
    Result r;
    r.frame = RenderFrame(pass, cam.view, size, size);
    const GpuMesh truth_mesh(MakeDisplacedGroundTruth(base, height, kMaxDisplacement, tiling));
    MeshPassOptions mesh_options;
    mesh_options.texture = &texture;
    mesh_options.shade = false;
    const Frame truth = RenderMesh(programs(), truth_mesh, cam.view, size, size, mesh_options);
    r.truth = {truth.color, truth.depth};
    DisplacementErrorOptions error_options;
    error_options.depth_unit = HeightTexelWorldSize(base, 128, tiling);
    r.error =
        CompareToGroundTruth(r.frame.color, r.frame.depth, truth.color, truth.depth, error_options);
    return r;
  }
};

// Kautz-Seidel 2001, Figure 4 vs Figure 7, as a number.
TEST_F(GroundTruthTest, AtAGrazingViewOnlySurfaceAlignedSlicesAreSeeThrough) {
  constexpr int kSize = 192;
  const Camera cam = OrbitCamera(8, -60, kSize, 3.2);
  const core::TriangleMesh plane = core::MakePlane(1.0f, 1);
  // 32 slices across the height; directions b, c and screen-space slices
  // cross the 2-unit edge, so they get 32 * edge / displacement = 256 (sec.
  // 3.4), the same spacing and about the same fill.
  const int across = OrthogonalSliceCount(32, 2.0f, kMaxDisplacement);
  ASSERT_EQ(across, 256);
  const Result surface = Compare(plane, SliceFamily::kSurfaceAligned, 32, cam, kSize, 1.0f);
  const Result orthogonal = Compare(plane, SliceFamily::kOrthogonal, across, cam, kSize, 1.0f);
  const Result screen = Compare(plane, SliceFamily::kScreen, across, cam, kSize, 1.0f);
  EXPECT_GT(surface.error.truth_pixels, 4000);
  EXPECT_GT(surface.error.see_through_pixels, 100);
  EXPECT_EQ(orthogonal.error.see_through_pixels, 0);
  EXPECT_EQ(screen.error.see_through_pixels, 0);
  RecordProperty("surface_see_through", surface.error.see_through_pixels);
  if (HasFailure()) {
    test_support::WriteDebugImage("truth.png", surface.truth.color);
    test_support::WriteDebugImage("surface.png", surface.frame.color);
    test_support::WriteDebugImage("orthogonal.png", orthogonal.frame.color);
    test_support::WriteDebugImage("screen.png", screen.frame.color);
  }
  EXPECT_NO_GL_ERROR();
}

TEST_F(GroundTruthTest, TheDonutMatchesItsTessellation) {
  constexpr int kSize = 160;
  const Camera cam = OrbitCamera(35, -60, kSize, 6.0);
  const core::TriangleMesh torus = core::MakeTorus(1.0f, 0.4f, 25, 25);
  ASSERT_EQ(DisplacementVolumesFromMesh(torus).size(),
            1225u);  // 1250 triangles; the inner equator's 25 quads are rectangles
  for (SliceFamily family :
       {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
    const Result r = Compare(torus, family, 32, cam, kSize, 2.0f);
    // Coverage differs only along silhouettes (a few % of the pixels at this size).
    EXPECT_GT(r.error.coverage_iou, 0.95) << SliceFamilyName(family);
    // 32 slices over 0.25 units of height is 0.0078 units per slice, ~1.2
    // height texels here (one texel is ~0.0068 units): the median pixel is
    // well under 2 texels off; silhouettes and the curved volumes' bilinear
    // approximation make the tail.
    EXPECT_LT(r.error.mean_depth_error, 2.0) << SliceFamilyName(family);
    EXPECT_TRUE(std::isfinite(r.error.p95_depth_error));
    RecordProperty(SliceFamilyName(family) + "_p95", std::to_string(r.error.p95_depth_error));
    if (HasFailure()) {
      test_support::WriteDebugImage("torus_truth.png", r.truth.color);
      test_support::WriteDebugImage("torus_" + SliceFamilyName(family) + ".png", r.frame.color);
    }
  }
  EXPECT_NO_GL_ERROR();
}

TEST_F(DisplacementTest, HardCasesAreFiniteAndNaNFree) {
  constexpr int kSize = 64;
  const core::TriangleMesh plane = core::MakePlane(1.0f, 1);
  // View exactly along the box's z axis, and exactly in the base plane.
  Camera top = OrbitCamera(90, -90, kSize);
  Camera edge_on = OrbitCamera(0, -90, kSize);
  for (SliceFamily family :
       {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
    ExpectFinite(RenderPlane(ConstantHeight(0.5f), family, 16, top, kSize));
    ExpectFinite(RenderPlane(ConstantHeight(0.5f), family, 16, edge_on, kSize));
    // 1 slice (at mid height) and 4096 slices, maximum height 1.0.
    const Frame one = RenderPlane(ConstantHeight(1.0f), family, 1, top, kSize);
    ExpectFinite(one);
    EXPECT_GT(Covered(one), 500);
    const Frame many = RenderPlane(ConstantHeight(1.0f), family, 4096, top, kSize);
    ExpectFinite(many);
    // The top of the volume, within one of the 4096 slices.
    const double truth = PlaneDepth(top, kSize / 2, kSize / 2, kMaxDisplacement);
    EXPECT_NEAR(many.depth.at(kSize / 2, kSize / 2), truth, kMaxDisplacement / 4096 + 1e-5 * truth);
  }
  // Edge-on, a constant height is seen only as the top slice's sliver: the
  // orthogonal family turns to vertical slices and shows the side.
  EXPECT_GT(
      Covered(RenderPlane(ConstantHeight(0.5f), SliceFamily::kOrthogonal, 16, edge_on, kSize)), 20);

  // Degenerate (zero-area) faces beside a good quad: dropped, same image.
  core::TriangleMesh mixed = plane;
  const uint32_t n = static_cast<uint32_t>(mixed.positions.size());
  mixed.positions.insert(mixed.positions.end(),
                         {{0.2f, 0.2f, 0}, {0.2f, 0.2f, 0}, {0.5f, 0.5f, 0}, {0.6f, 0.6f, 0}});
  mixed.normals.insert(mixed.normals.end(), 4, glm::vec3(0, 0, 1));
  mixed.uvs.insert(mixed.uvs.end(), {{0.1f, 0.1f}, {0.1f, 0.1f}, {0.2f, 0.3f}, {0.3f, 0.3f}});
  mixed.indices.insert(mixed.indices.end(),
                       {n, n + 1, n + 2, n + 2, n + 3, n + 1, n + 1, n + 1, n + 1});
  EXPECT_EQ(DisplacementVolumesFromMesh(mixed).size(), 1u);
  const Camera cam = OrbitCamera(50, -60, kSize);
  for (SliceFamily family :
       {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
    const Frame a = RenderPlane(ConstantHeight(0.5f), family, 16, cam, kSize, mixed);
    const Frame b = RenderPlane(ConstantHeight(0.5f), family, 16, cam, kSize, plane);
    ExpectFinite(a);
    EXPECT_EQ(a.depth, b.depth);
  }
  // A mesh of only degenerate faces renders nothing, without error.
  core::TriangleMesh flat_only;
  flat_only.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat_only.normals.assign(3, glm::vec3(0, 0, 1));
  flat_only.uvs = {{0, 0}, {0.5f, 0}, {1, 0}};
  flat_only.indices = {0, 1, 2};
  EXPECT_EQ(
      Covered(RenderPlane(ConstantHeight(0.5f), SliceFamily::kScreen, 16, cam, kSize, flat_only)),
      0);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DisplacementTest, FullSizeScreenSlicesDrawTheSamePixelsWithMoreFragments) {
  constexpr int kSize = 128;
  const Camera cam = OrbitCamera(30, -60, kSize);
  core::HeightMapOptions hm;
  hm.pattern = core::HeightPattern::kBumps;
  hm.size = 64;
  const core::ImageF height = core::MakeHeightMap(hm);
  const Texture texture = ExactTexture(height);
  DisplacementPassOptions options;
  options.slicing.family = SliceFamily::kScreen;
  options.slicing.count = 32;
  options.max_displacement = kMaxDisplacement;
  for (const core::TriangleMesh& base : {core::MakePlane(1.0f, 1)}) {  // affine volume: same planes
    DisplacementPass pass(programs(), base, texture, options);
    pass.CountFragments(true);
    const Frame exact = RenderFrame(pass, cam.view, kSize, kSize);
    const double exact_fragments = pass.last_stats().fragments;
    SlicingOptions full = options.slicing;
    full.full_size_screen_slices = true;
    pass.SetSlicing(full);
    const Frame padded = RenderFrame(pass, cam.view, kSize, kSize);
    const double full_fragments = pass.last_stats().fragments;
    DisplacementErrorOptions e;
    e.depth_unit = kMaxDisplacement / 32;
    const DisplacementError diff =
        CompareToGroundTruth(padded.color, padded.depth, exact.color, exact.depth, e);
    // Same planes, different triangulation: the interpolated ramp differs in
    // the last bits, which flips the strict test only where the height equals
    // the ramp (the rims of these small bumps, most of their 2-3k pixels).
    EXPECT_GT(diff.coverage_iou, 0.95);
    if (HasFailure()) {
      test_support::WriteDebugImage("exact.png", exact.color);
      test_support::WriteDebugImage("full.png", padded.color);
    }
    EXPECT_LT(diff.p95_depth_error, 1e-3);
    if (exact_fragments >= 0) {
      EXPECT_GT(full_fragments, 1.5 * exact_fragments);
    }
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace render

namespace render {
namespace {

// The tessellated truth is planned before anything is allocated: the plan's
// counts are the tessellation's exactly, the rule's subdivisions are kept
// when the budget allows them, and otherwise the largest count that fits is
// chosen (one more would not fit) or, when not even one fits, one line names
// the budget.
TEST(GroundTruthPlanTest, CountsExactlyAndFitsTheBudget) {
  const core::TriangleMesh torus = core::MakeTorus(1.0f, 0.4f, 25, 25);
  core::HeightMapOptions h;
  h.size = 32;
  const core::ImageF height = core::MakeHeightMap(h);

  core::SetMemoryBudget(std::uint64_t{1} << 40);
  const GroundTruthPlan ample = PlanDisplacedGroundTruth(torus, 32, 2.0f);
  // The torus's longest uv edge is the diagonal of a 1/25 x 1/25 cell:
  // sqrt(2) / 25 * 2 tilings * 32 texels = 3.62 -> 4.
  EXPECT_EQ(ample.wanted_subdivisions, 4);
  EXPECT_EQ(ample.subdivisions, 4);
  EXPECT_FALSE(ample.limited());
  const core::TriangleMesh mesh = MakeDisplacedGroundTruth(torus, height, 0.1f, 2.0f, ample, 2.0f);
  EXPECT_EQ(mesh.positions.size(), ample.vertices);
  EXPECT_EQ(mesh.triangle_count(), ample.triangles);
  EXPECT_EQ(ample.triangles, torus.triangle_count() * 16);
  EXPECT_LE(ample.texels_per_edge, 1.0f);

  // 512 per edge over 1250 faces: far over a 64 MiB budget.
  const std::uint64_t budget = 64ull << 20;
  core::SetMemoryBudget(budget);
  const GroundTruthPlan limited = PlanDisplacedGroundTruth(torus, 4096, 8.0f);
  EXPECT_EQ(limited.wanted_subdivisions, kMaxGroundTruthSubdivisions);
  EXPECT_TRUE(limited.limited());
  EXPECT_LE(limited.bytes, budget);
  EXPECT_GT(GroundTruthBytes(torus.triangle_count(), limited.subdivisions + 1), budget);
  EXPECT_GT(limited.texels_per_edge, 1.0f);
  EXPECT_NE(limited.Describe().find("memory budget"), std::string::npos) << limited.Describe();

  core::SetMemoryBudget(std::uint64_t{16} << 10);  // not even one subdivision per face
  try {
    PlanDisplacedGroundTruth(torus, 32, 2.0f);
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("memory budget"), std::string::npos) << e.what();
  }
  // The CPU tessellation checks its own allocation too (callers without a plan).
  core::DisplacedMeshOptions dm;
  dm.subdivisions = 1024;
  EXPECT_THROW(core::TessellateDisplaced(torus, height, dm), core::InputError);
  core::SetMemoryBudget(std::nullopt);
}

}  // namespace
}  // namespace render
