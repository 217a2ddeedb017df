// render/passes/deform_pass against the independent CPU reference
// (core/deform_reference.h: sphere tracing in double with the exact mesh
// distance and the analytic deformation and cut), and the two-stage
// composite against the plain mesh pass (a zero deformation must reproduce
// the mesh).
#include "render/passes/deform_pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <random>

#include "core/deform_reference.h"
#include "core/error.h"
#include "core/projection.h"
#include "render/passes/mesh_pass.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

constexpr int kSize = 96;
// Focal length in pixels of MakeView and Compare (the narrow pull zooms in).
double g_focal = 110.0;

struct Scene {
  core::TriangleMesh mesh;
  core::DeformationSum deformation;
  core::Placement placement;
  int sdf_resolution = 64;
  int deformation_resolution = 64;
};

ViewSetup MakeView(const glm::vec3& eye, const glm::vec3& target = glm::vec3(0.0f)) {
  ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt(eye, target, {0, 0, 1});
  view.clip_from_cam = core::ClipFromCamPerspective(g_focal, g_focal, kSize / 2.0, kSize / 2.0,
                                                    kSize, kSize, 0.1, 20);
  return view;
}

// Pixel classes: 0 nothing, 1 the mesh surface, 2 a cut face.
int GpuClass(const Frame& frame, int x, int y) {
  if (!frame.Covered(x, y)) return 0;
  return (frame.outcome.at(x, y) & kDeformCutFaceBit) ? 2 : 1;
}

// Pixels where two frames' classes (GpuClass) differ.
int ClassDiffer(const Frame& a, const Frame& b) {
  int differ = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) differ += GpuClass(a, x, y) != GpuClass(b, x, y);
  return differ;
}

struct Agreement {
  int compared = 0, agree = 0, band = 0;
  double worst_cut_normal_deg = 0.0;
  int cut_normals = 0;
  int cut_normals_off = 0;  // cut-face normals more than 1 degree off
  int crease = 0;           // of those, beside an edge between two cut faces
};

// Traces every pixel centre on the CPU inside the box and compares the class
// (and cut-face normals) with the GPU frame, outside a one-pixel band around
// the reference's class boundaries. Beside the reference's creases
// (neighbouring cut-face normals more than 10 degrees apart: an edge between
// two cut faces) the GPU normal may be either face's.
Agreement Compare(const Frame& frame, const ViewSetup& view, const core::DeformReference& reference,
                  const core::Placement& placement) {
  glm::dmat4 world_from_cam = glm::inverse(glm::dmat4(view.cam_from_world));
  glm::dvec3 eye(world_from_cam * glm::dvec4(0, 0, 0, 1));
  glm::dmat4 box_from_object = placement.BoxFromObject();
  std::vector<int> cls(kSize * kSize);
  std::vector<glm::dvec3> normals(kSize * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      glm::dvec3 d_cam((x + 0.5 - kSize / 2.0) / g_focal, (y + 0.5 - kSize / 2.0) / g_focal, 1.0);
      glm::dvec3 dir = glm::normalize(glm::dmat3(world_from_cam) * d_cam);
      // Box interval (slab test in box coordinates; the same t).
      glm::dvec3 o = glm::dvec3(box_from_object * glm::dvec4(eye, 1)),
                 d = glm::dmat3(box_from_object) * dir;
      double t0 = 0, t1 = 1e30;
      for (int a = 0; a < 3; ++a) {
        double ta = (0 - o[a]) / d[a], tb = (1 - o[a]) / d[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
      }
      int c = 0;
      if (t0 < t1) {
        core::DeformReferenceHit hit = reference.Trace(eye, dir, t0, t1);
        if (hit.hit) c = hit.cut_face ? 2 : 1;
        normals[y * kSize + x] = hit.normal;
      }
      cls[y * kSize + x] = c;
    }
  Agreement a;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      int c = cls[y * kSize + x];
      bool band = false, crease = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int xx = std::clamp(x + dx, 0, kSize - 1), yy = std::clamp(y + dy, 0, kSize - 1);
          band |= cls[yy * kSize + xx] != c;
          // Beside an edge where two cut faces meet the pixel sees both.
          crease |= c == 2 && glm::dot(normals[yy * kSize + xx], normals[y * kSize + x]) <
                                  std::cos(glm::radians(10.0));
        }
      if (band) {
        ++a.band;
        continue;
      }
      ++a.compared;
      int g = GpuClass(frame, x, y);
      a.agree += g == c;
      if (c != 2 || g != 2) continue;
      // A pixel beside a crease may show either face: its normal is checked
      // against the nearest of its neighbours' (all of them cut faces).
      glm::dvec3 n_gpu(frame.normal.at(x, y, 0), frame.normal.at(x, y, 1),
                       frame.normal.at(x, y, 2));
      n_gpu = glm::length(n_gpu) > 0.5 ? glm::normalize(n_gpu) : glm::dvec3(0.0);
      double cosine = glm::dot(n_gpu, normals[y * kSize + x]);
      for (int dy = -1; crease && dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int xx = std::clamp(x + dx, 0, kSize - 1), yy = std::clamp(y + dy, 0, kSize - 1);
          cosine = std::max(cosine, glm::dot(n_gpu, normals[yy * kSize + xx]));
        }
      const double deg = glm::degrees(std::acos(std::clamp(cosine, -1.0, 1.0)));
      a.worst_cut_normal_deg = std::max(a.worst_cut_normal_deg, deg);
      a.cut_normals_off += deg > 1.0;
      a.crease += crease;
      ++a.cut_normals;
    }
  return a;
}

class DeformPassTest : public test_support::GlTest {
 protected:
  Frame Render(const Scene& scene, const DeformPassOptions& options, const ViewSetup& view,
               const core::MeshDistance& distance, const DepthCube* cube = nullptr) {
    double grow = core::MaxObjectDisplacement(scene.deformation, scene.placement,
                                              scene.deformation_resolution);
    core::DistanceFieldOptions sdf_options;
    sdf_options.resolution = scene.sdf_resolution;
    sdf_ = core::BuildDistanceField(distance, scene.placement.ObjectBounds().Grown(grow + 0.02),
                                    sdf_options);
    texture_ = core::SampleDeformation(scene.deformation, scene.deformation_resolution);
    DeformInputs inputs{&scene.mesh, &sdf_, &texture_, scene.placement, cube};
    DeformPass pass(programs(), inputs, options);
    return RenderFrame(pass, view, kSize, kSize);
  }
  core::DistanceField sdf_;
  core::DeformationTexture texture_;
};

core::Deformation Make(core::DeformationKind kind, double amount, double width) {
  core::Deformation d;
  d.kind = kind;
  d.amount = amount;
  d.width = width;
  return d;
}

// The depth-map cube (DepthCube) of a sphere of `radius` at the origin, in
// closed form: face i looks inwards along -/+ axis i/2 from the cube
// [-half, half]^3, half = 1.05 radius; depth at a texel centre = half - the
// sphere's height there, 0 where the ray misses it.
DepthCube AnalyticSphereCube(double radius, int n) {
  const double half = 1.05 * radius, scale = n / (2 * half);
  DepthCube cube;
  cube.far = 2 * half;
  cube.texel = 1.0 / scale;
  for (int f = 0; f < 6; ++f) {
    const int axis = f / 2, a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double s = f % 2 == 0 ? 1.0 : -1.0;  // the face sits at s * half on its axis
    DepthCubeFace face{core::ImageF(n, n, 1), glm::dmat4(0.0)};
    // u = scale p_a + n/2, v = scale p_b + n/2, z = half - s p_axis.
    face.map_from_object[a][0] = scale;
    face.map_from_object[b][1] = scale;
    face.map_from_object[axis][2] = -s;
    face.map_from_object[3] = glm::dvec4(n / 2.0, n / 2.0, half, 1.0);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double pa = (x + 0.5 - n / 2.0) / scale, pb = (y + 0.5 - n / 2.0) / scale;
        const double h2 = radius * radius - pa * pa - pb * pb;
        face.depth.at(x, y) = h2 > 0 ? static_cast<float>(half - std::sqrt(h2)) : 0.0f;
      }
    cube.faces.push_back(std::move(face));
  }
  return cube;
}

TEST_F(DeformPassTest, TwistedBoxAgreesWithTheReference) {
  Scene scene;
  scene.mesh = core::MakeBox(glm::vec3(0.3f, 0.3f, 0.4f));
  scene.deformation.terms = {Make(core::DeformationKind::kTwist, 1.2, 0.45)};
  scene.placement = core::Placement::FromRegion({{-0.5, -0.5, -0.6}, {0.5, 0.5, 0.5}});
  core::MeshDistance distance(scene.mesh, false, "box");
  DeformPassOptions options;
  options.step_voxels = 0.5f;
  ViewSetup view = MakeView({2.2f, 1.4f, 1.3f});
  Frame frame = Render(scene, options, view, distance);
  test_support::WriteDebugImage("twisted_box.png", frame.color);
  core::DeformReference reference(distance, scene.deformation, scene.placement,
                                  core::CutMode::kNone, 0);
  Agreement a = Compare(frame, view, reference, scene.placement);
  std::printf("twisted box: %d/%d pixels agree (%.3f %%), %d in the band\n", a.agree, a.compared,
              100.0 * a.agree / a.compared, a.band);
  EXPECT_GE(a.agree, 0.995 * a.compared);
  EXPECT_GT(a.compared, kSize * kSize / 2);
  EXPECT_NO_GL_ERROR();
}

// A sphere cut by the knife through its middle.
Scene KnifedSphere() {
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 48, 96);
  scene.deformation.terms = {Make(core::DeformationKind::kKnife, 0.25, 0.7)};
  scene.placement = core::Placement::FromRegion({{-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}});
  return scene;
}

TEST_F(DeformPassTest, SolidKnifeCutAgreesWithTheReference) {
  const Scene scene = KnifedSphere();
  core::MeshDistance distance(scene.mesh, false, "sphere");
  // Solid and thick by the CSG field and by the paper's two-field search
  // (sec. 5.1.2): the same surface.
  const std::pair<CutMode, bool> cases[] = {{CutMode::kSolid, false},
                                            {CutMode::kSolid, true},
                                            {CutMode::kHollow, false},
                                            {CutMode::kThick, false},
                                            {CutMode::kThick, true}};
  for (const auto& [cut, search] : cases) {
    DeformPassOptions options;
    options.cut = cut;
    options.solid_search = search;
    options.thickness = 0.08f;
    options.step_voxels = 0.5f;
    ViewSetup view = MakeView({0.9f, -2.0f, 2.0f});
    Frame frame = Render(scene, options, view, distance);
    const std::string name = core::CutModeName(cut) + (search ? " search" : "");
    test_support::WriteDebugImage(
        "knife_" + core::CutModeName(cut) + (search ? "_search" : "") + ".png", frame.color);
    core::DeformReference reference(distance, scene.deformation, scene.placement, cut,
                                    options.thickness);
    Agreement a = Compare(frame, view, reference, scene.placement);
    std::printf(
        "knife %s: %d/%d pixels agree (%.3f %%), %d in the band; cut-face normals: %d, worst %.3f "
        "deg\n",
        name.c_str(), a.agree, a.compared, 100.0 * a.agree / a.compared, a.band, a.cut_normals,
        a.worst_cut_normal_deg);
    // (worst printed with more digits below)
    std::printf("  worst cut-face normal angle %.6f deg\n", a.worst_cut_normal_deg);
    EXPECT_GE(a.agree, 0.995 * a.compared) << name;
    if (cut == CutMode::kSolid) {
      EXPECT_GT(a.cut_normals, 50) << name;
    }
    if (cut != CutMode::kHollow) {
      EXPECT_LT(a.worst_cut_normal_deg, 1.0) << name;
    }
  }
  EXPECT_NO_GL_ERROR();
}

// Changed pixels: another class, or the same class at another depth (the
// hollow cut shows the sphere's inside where its outside was).
int ChangedPixels(const Frame& frame, const Frame& plain) {
  int changed = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      changed += GpuClass(frame, x, y) != GpuClass(plain, x, y) ||
                 std::abs(frame.depth.at(x, y) - plain.depth.at(x, y)) > 0.01f;
    }
  return changed;
}

// The cut-aways (clip, cutaway, wedge: D = 0, material removed) on a
// sphere, the box enclosing it: the pass agrees with the double reference,
// the solid cut shows its planar faces with their planes' normals, and the
// cut removes what it should (pixels that change against the uncut sphere).
TEST_F(DeformPassTest, CutAwaysAgreeWithTheReference) {
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 48, 96);
  scene.placement = core::Placement::FromRegion({{-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}});
  core::MeshDistance distance(scene.mesh, false, "sphere");
  const ViewSetup view = MakeView({2.0f, 0.9f, 1.6f});
  Scene uncut = scene;
  uncut.deformation.terms = {Make(core::DeformationKind::kTwist, 0.0, 0.3)};
  const Frame plain = Render(uncut, DeformPassOptions{}, view, distance);
  const std::pair<core::DeformationKind, double> cases[] = {
      {core::DeformationKind::kClip, 0.6},
      {core::DeformationKind::kCutaway, 0.5},
      {core::DeformationKind::kWedge, M_PI / 2}};
  for (const auto& [kind, amount] : cases) {
    scene.deformation.terms = {Make(kind, amount, 0.0)};
    for (CutMode cut : {CutMode::kSolid, CutMode::kHollow}) {
      DeformPassOptions options;
      options.cut = cut;
      options.step_voxels = 0.5f;
      const Frame frame = Render(scene, options, view, distance);
      const std::string tag = core::DeformationKindName(kind) + "_" + core::CutModeName(cut);
      test_support::WriteDebugImage("cutaway_" + tag + ".png", frame.color);
      core::DeformReference reference(distance, scene.deformation, scene.placement, cut, 0.0);
      const Agreement a = Compare(frame, view, reference, scene.placement);
      const int changed = ChangedPixels(frame, plain);
      std::printf(
          "%s: %d/%d pixels agree (%.3f %%), %d in the band, %d changed by the cut; cut-face "
          "normals %d (%d beside creases), %d more than 1 deg off (worst %.3f deg)\n",
          tag.c_str(), a.agree, a.compared, 100.0 * a.agree / a.compared, a.band, changed,
          a.cut_normals, a.crease, a.cut_normals_off, a.worst_cut_normal_deg);
      EXPECT_GE(a.agree, 0.995 * a.compared) << tag;
      EXPECT_GT(changed, kSize * kSize / 50) << tag;
      if (cut == CutMode::kSolid) {
        EXPECT_GT(a.cut_normals, 50) << tag;
        // One plane: exact. Where planes meet, the sampled alpha's minimum
        // is rounded within a deformation texel of the edge and its gradient
        // blends the faces' normals there (the peel's exact components are
        // not used for cut-aways): a bounded share of the face pixels.
        if (kind == core::DeformationKind::kClip) {
          EXPECT_EQ(a.cut_normals_off, 0) << tag;
        } else {
          EXPECT_LE(a.cut_normals_off, a.cut_normals / 5) << tag;
        }
      }
    }
  }
  EXPECT_NO_GL_ERROR();
}

// The names the mesh took from the volume paper (slices, seam, wave; one
// vocabulary, core::kDeformationTable) on a sphere, the box enclosing it with
// room at +x for the slices: the pass agrees with the double reference as the
// cut-aways do, and each deformation changes the picture.
TEST_F(DeformPassTest, SlicesSeamAndWaveAgreeWithTheReference) {
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 48, 96);
  scene.placement = core::Placement::FromRegion({{-0.6, -0.6, -0.6}, {0.8, 0.6, 0.6}});
  core::MeshDistance distance(scene.mesh, false, "sphere");
  const ViewSetup view = MakeView({2.0f, 0.9f, 1.6f});
  Scene plain_scene = scene;
  plain_scene.deformation.terms = {Make(core::DeformationKind::kTwist, 0.0, 0.3)};
  const Frame plain = Render(plain_scene, DeformPassOptions{}, view, distance);
  const core::Deformation cases[] = {Make(core::DeformationKind::kSlices, 0.06, 0.25),
                                     Make(core::DeformationKind::kSeam, 0.2, 0.7),
                                     Make(core::DeformationKind::kWave, 0.05, 0.5)};
  for (const core::Deformation& d : cases) {
    scene.deformation.terms = {d};
    const CutMode cut = d.HasCut() ? CutMode::kSolid : CutMode::kNone;
    DeformPassOptions options;
    options.cut = cut;
    options.step_voxels = 0.5f;
    const Frame frame = Render(scene, options, view, distance);
    const std::string tag = core::DeformationKindName(d.kind) + "_" + core::CutModeName(cut);
    test_support::WriteDebugImage("vocabulary_" + tag + ".png", frame.color);
    core::DeformReference reference(distance, scene.deformation, scene.placement, cut, 0.0);
    const Agreement a = Compare(frame, view, reference, scene.placement);
    const int changed = ChangedPixels(frame, plain);
    std::printf(
        "%s: %d/%d pixels agree (%.3f %%), %d in the band, %d changed; cut-face normals %d\n",
        tag.c_str(), a.agree, a.compared, 100.0 * a.agree / a.compared, a.band, changed,
        a.cut_normals);
    EXPECT_GE(a.agree, 0.995 * a.compared) << tag;
    EXPECT_GT(changed, kSize * kSize / 50) << tag;
    if (cut == CutMode::kSolid) {
      EXPECT_GT(a.cut_normals, 50) << tag;
    }
  }
  EXPECT_NO_GL_ERROR();
}

// Mean field samples per cast ray of a frame (bits 16..31 of the outcome).
double MeanSamples(const Frame& frame) {
  double samples = 0, rays = 0;
  for (int y = 0; y < frame.outcome.height(); ++y)
    for (int x = 0; x < frame.outcome.width(); ++x) {
      const uint32_t o = frame.outcome.at(x, y);
      const uint32_t n = o >> kDeformSamplesShift;
      if (n == 0) continue;
      samples += n;
      rays += 1;
    }
  return rays > 0 ? samples / rays : 0.0;
}

// Skipping by the object's distance field (the default) and by the cut alpha
// draw what the plain march draws (the reference agreement holds either way)
// with fewer samples; per mode: none (twist), solid CSG, solid search, hollow.
TEST_F(DeformPassTest, SkippingKeepsTheSurfaceAndSavesSamples) {
  struct Case {
    std::string name;
    Scene scene;
    CutMode cut;
    bool search;
  };
  // A gentle twist (a small warp Lipschitz bound) of a sphere small in its
  // box: room for the distance-field skip. A wide knife: room for the cut's.
  Scene twisted;
  twisted.mesh = core::MakeSphere(0.3f, 48, 96);
  twisted.deformation.terms = {Make(core::DeformationKind::kTwist, 0.5, 0.1)};
  twisted.placement = core::Placement::FromRegion({{-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}});
  Scene wide = KnifedSphere();
  wide.deformation.terms = {Make(core::DeformationKind::kKnife, 0.45, 0.8)};
  const std::vector<Case> cases = {{"twist", twisted, CutMode::kNone, false},
                                   {"wide knife solid csg", wide, CutMode::kSolid, false},
                                   {"wide knife solid search", wide, CutMode::kSolid, true},
                                   {"wide knife hollow", wide, CutMode::kHollow, false}};
  for (const Case& c : cases) {
    core::MeshDistance distance(c.scene.mesh, false, c.name);
    const ViewSetup view = MakeView({0.9f, -2.0f, 2.0f});
    core::DeformReference reference(distance, c.scene.deformation, c.scene.placement, c.cut, 0.08);
    DeformPassOptions options;
    options.cut = c.cut;
    options.solid_search = c.search;
    options.step_voxels = 0.5f;
    options.skip_object = false;
    const Frame plain = Render(c.scene, options, view, distance);
    // The cut's skip alone (its alpha from the march's own evaluation; no
    // fallback lookup where that is stale, a skip of 0 there).
    if (c.cut != CutMode::kNone) {
      options.skip_empty = true;
      const Frame cut_only = Render(c.scene, options, view, distance);
      const Agreement a_cut = Compare(cut_only, view, reference, c.scene.placement);
      const int cut_differ = ClassDiffer(plain, cut_only);
      std::printf(
          "%s: the cut's skip alone %.2f samples per ray; agreement %d/%d; %d pixels of "
          "another class\n",
          c.name.c_str(), MeanSamples(cut_only), a_cut.agree, a_cut.compared, cut_differ);
      EXPECT_GE(a_cut.agree, 0.995 * a_cut.compared) << c.name;
      EXPECT_LE(cut_differ, kSize * kSize / 500) << c.name;
      EXPECT_LT(MeanSamples(cut_only), MeanSamples(plain)) << c.name;
    }
    options.skip_object = true;
    options.skip_empty = c.cut != CutMode::kNone;
    const Frame skipped = Render(c.scene, options, view, distance);
    const Agreement a_plain = Compare(plain, view, reference, c.scene.placement);
    const Agreement a_skip = Compare(skipped, view, reference, c.scene.placement);
    const int differ = ClassDiffer(plain, skipped);
    const double s_plain = MeanSamples(plain), s_skip = MeanSamples(skipped);
    std::printf(
        "%s: samples per ray %.2f plain, %.2f skipping; agreement %d/%d vs %d/%d; %d pixels of "
        "another class\n",
        c.name.c_str(), s_plain, s_skip, a_plain.agree, a_plain.compared, a_skip.agree,
        a_skip.compared, differ);
    EXPECT_GE(a_skip.agree, 0.995 * a_skip.compared) << c.name;
    EXPECT_LE(differ, kSize * kSize / 500) << c.name;  // silhouette pixels at most
    EXPECT_LT(s_skip, s_plain) << c.name;
  }
  EXPECT_NO_GL_ERROR();
}

// The same knife through the sphere's depth-map cube (IMPLICIT_DEPTH_CUBE,
// maps in closed form): a convex object, which the six maps describe up to
// their texels, so the reference of the true mesh still holds.
TEST_F(DeformPassTest, SolidKnifeCutOnADepthCubeAgreesWithTheReference) {
  const Scene scene = KnifedSphere();
  core::MeshDistance distance(scene.mesh, false, "sphere");
  const DepthCube cube = AnalyticSphereCube(0.5, 128);
  DeformPassOptions options;
  options.cut = CutMode::kSolid;
  options.implicit = DeformImplicit::kDepthCube;
  options.step_voxels = 0.5f;
  ViewSetup view = MakeView({0.9f, -2.0f, 2.0f});
  Frame frame = Render(scene, options, view, distance, &cube);
  test_support::WriteDebugImage("knife_depth_cube.png", frame.color);
  core::DeformReference reference(distance, scene.deformation, scene.placement, CutMode::kSolid,
                                  0.0);
  Agreement a = Compare(frame, view, reference, scene.placement);
  std::printf("knife on the depth cube: %d/%d pixels agree (%.3f %%), %d in the band\n", a.agree,
              a.compared, 100.0 * a.agree / a.compared, a.band);
  EXPECT_GE(a.agree, 0.995 * a.compared);
  EXPECT_GT(a.compared, kSize * kSize / 2);
  EXPECT_GT(a.cut_normals, 50);
  EXPECT_LT(a.worst_cut_normal_deg, 1.0);
  EXPECT_NO_GL_ERROR();
}

// Isolated pixels: a pixel whose class (GpuClass) differs from all eight
// neighbours' while those agree among themselves (specks in a surface,
// holes in it, single pixels in empty space). Border pixels are skipped.
int IsolatedPixels(const Frame& frame) {
  int isolated = 0;
  for (int y = 1; y + 1 < kSize; ++y)
    for (int x = 1; x + 1 < kSize; ++x) {
      const int c = GpuClass(frame, x, y), n = GpuClass(frame, x + 1, y);
      bool speck = n != c;
      for (int dy = -1; dy <= 1 && speck; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          speck &= GpuClass(frame, x + dx, y + dy) == (dx || dy ? n : c);
      isolated += speck;
    }
  return isolated;
}

// A sphere peeled: the flap (the layer 0.7 <= z <= 0.85 of the box, x >= 0.5)
// turned about its hinge by `angle`; the vacated slab is cut. The flap's
// D and the rest's are two continuous pieces (core/deformation.h "Pieces"),
// so its faces are found where the union's field changes sign and are cut
// faces in every mode.
Scene PeeledSphere(double angle) {
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 48, 96);
  scene.deformation.terms = {Make(core::DeformationKind::kPeel, angle, 0.15)};
  scene.placement = core::Placement::FromRegion({{-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}});
  return scene;
}

TEST_F(DeformPassTest, PeelAgreesWithTheReferenceWithoutSpecks) {
  for (double angle : {0.9, 2.4}) {
    const Scene scene = PeeledSphere(angle);
    core::MeshDistance distance(scene.mesh, false, "sphere");
    for (CutMode cut : {CutMode::kSolid, CutMode::kNone, CutMode::kHollow}) {
      DeformPassOptions options;
      options.cut = cut;
      options.step_voxels = 0.5f;
      for (glm::vec3 eye : {glm::vec3(0.9f, -2.0f, 2.0f), glm::vec3(2.3f, 1.2f, 0.8f)}) {
        ViewSetup view = MakeView(eye);
        Frame frame = Render(scene, options, view, distance);
        const std::string tag = "peel_" + std::to_string(static_cast<int>(angle * 10)) + "_" +
                                core::CutModeName(cut) + "_" + std::to_string(int(eye.x * 10));
        test_support::WriteDebugImage(tag + ".png", frame.color);
        core::DeformReference reference(distance, scene.deformation, scene.placement, cut, 0.0);
        Agreement a = Compare(frame, view, reference, scene.placement);
        const int isolated = IsolatedPixels(frame);
        std::printf(
            "peel %.1f %s eye (%.1f, %.1f, %.1f): %d/%d pixels agree (%.3f %%), %d in the band; "
            "cut-face normals %d (%d beside creases), %d more than 1 deg off (worst "
            "%.3f); %d isolated pixels\n",
            angle, core::CutModeName(cut).c_str(), eye.x, eye.y, eye.z, a.agree, a.compared,
            100.0 * a.agree / a.compared, a.band, a.cut_normals, a.crease, a.cut_normals_off,
            a.worst_cut_normal_deg, isolated);
        EXPECT_GE(a.agree, 0.995 * a.compared) << tag;
        EXPECT_GT(a.compared, kSize * kSize / 2) << tag;
        EXPECT_EQ(isolated, 0) << tag;
        // The flap's faces (and the slab's, in the solid modes) are seen; their
        // normals are each face's own plane (DeformationSum::AlphaComponents),
        // also beside the edges where two cut faces meet and where the box
        // clips the turned flap.
        EXPECT_GE(a.cut_normals, 5) << tag;
        EXPECT_EQ(a.cut_normals_off, 0) << tag;
        EXPECT_LT(a.worst_cut_normal_deg, 1.0) << tag;
      }
    }
  }
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, ZeroDeformationCompositeReproducesTheMesh) {
  // The box covers the top of the sphere: stage 1 draws the rest, stage 2
  // ray casts the top from the distance field; together they are the mesh.
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 64, 128);
  scene.deformation.terms = {Make(core::DeformationKind::kTwist, 0.0, 0.3)};
  scene.placement = core::Placement::FromRegion({{-0.3, -0.35, 0.1}, {0.4, 0.35, 0.7}});
  scene.sdf_resolution = 64;
  core::MeshDistance distance(scene.mesh, false, "sphere");
  ViewSetup view = MakeView({1.6f, -1.7f, 1.2f});
  Frame frame = Render(scene, DeformPassOptions{}, view, distance);
  test_support::WriteDebugImage("composite.png", frame.color);
  GpuMesh gpu_mesh(scene.mesh);
  Frame truth = RenderMesh(programs(), gpu_mesh, view, kSize, kSize);
  int both = 0, differ = 0, rays = 0;
  double worst = 0.0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      bool a = frame.Covered(x, y), b = truth.color.at(x, y, 3) == 255;
      differ += a != b;
      if (a && b) {
        ++both;
        worst = std::max(worst, std::abs(double(frame.depth.at(x, y)) - truth.depth.at(x, y)));
        rays += (frame.outcome.at(x, y) & OutcomeBit(RayOutcome::kHit)) != 0;
      }
    }
  double iou = double(both) / (both + differ);
  std::printf(
      "composite vs mesh: IoU %.4f, %d ray-cast pixels, max depth difference %.4g (voxel %.4g)\n",
      iou, rays, worst, sdf_.spacing);
  EXPECT_GT(rays, 200);  // both stages really drew
  EXPECT_GE(iou, 0.99);
  // Trilinear interpolation of the distance to a curved surface and the
  // mesh's own facets: well under a voxel.
  EXPECT_LT(worst, 0.5 * sdf_.spacing);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, EachStageAloneCompositesToTheFrame) {
  // draw_rays off draws stage 1 alone, draw_mesh off stage 2 alone (what the
  // bench times separately): the nearer of the two at each pixel is the
  // whole frame's pixel (colour, camera z), and each really drew.
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 64, 128);
  scene.deformation.terms = {Make(core::DeformationKind::kTwist, 1.5, 0.1)};
  scene.placement = core::Placement::FromRegion({{-0.3, -0.35, 0.1}, {0.4, 0.35, 0.7}});
  scene.sdf_resolution = 64;
  core::MeshDistance distance(scene.mesh, false, "sphere");
  const ViewSetup view = MakeView({1.6f, -1.7f, 1.2f});
  DeformPassOptions mesh_only, ray_only;
  mesh_only.draw_rays = false;
  ray_only.draw_mesh = false;
  const Frame whole = Render(scene, DeformPassOptions{}, view, distance);
  const Frame mesh = Render(scene, mesh_only, view, distance);
  const Frame rays = Render(scene, ray_only, view, distance);
  int mesh_pixels = 0, ray_pixels = 0, compared = 0, differ = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const bool m = mesh.Covered(x, y), r = rays.Covered(x, y);
      mesh_pixels += m, ray_pixels += r;
      const Frame* nearer = m && (!r || mesh.depth.at(x, y) <= rays.depth.at(x, y)) ? &mesh
                            : r                                                     ? &rays
                                                                                    : nullptr;
      ++compared;
      if (!nearer) {
        differ += whole.Covered(x, y);
        continue;
      }
      bool same = whole.Covered(x, y) && whole.depth.at(x, y) == nearer->depth.at(x, y);
      for (int c = 0; c < 4; ++c)
        same = same && whole.color.at(x, y, c) == nearer->color.at(x, y, c);
      differ += !same;
    }
  std::printf("stages alone: %d mesh pixels, %d ray pixels, %d of %d differ from the frame\n",
              mesh_pixels, ray_pixels, differ, compared);
  EXPECT_GT(mesh_pixels, 1000);
  EXPECT_GT(ray_pixels, 200);
  // Equal depths from the two stages at the box's faces may resolve either
  // way in the frame (depth test LESS): a handful of pixels at most.
  EXPECT_LE(differ, compared / 1000);
  DeformPassOptions neither;
  neither.draw_mesh = neither.draw_rays = false;
  EXPECT_THROW(neither.Check(), core::InputError);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, CullingBackFacesDrawsTheSamePixels) {
  // Stage 1 culls the back faces of a closed, outward mesh and draws them
  // only in the box's screen footprint (DeformPass::Draw). Against drawing
  // both sides everywhere, over random boxes, deformations, cuts that open
  // the mesh and views (mirrored ones, and ones with the near plane in the
  // mesh, where the pass must not cull): the same colour, camera z, normal
  // and outcome bits at every pixel.
  const core::MeshDistance distance(core::MakeTorus(0.4f, 0.18f, 96, 48), false, "torus");
  Scene scene;
  scene.mesh = distance.closed_mesh();
  core::SetAreaWeightedNormals(scene.mesh);  // the back-face count below reads them
  ASSERT_TRUE(core::IsClosedOutward(scene.mesh));
  scene.sdf_resolution = 40;
  scene.deformation_resolution = 32;
  std::mt19937 rng(71);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * u01(rng); };
  const core::DeformationKind kinds[] = {
      core::DeformationKind::kKnife, core::DeformationKind::kPeel, core::DeformationKind::kTwist};
  const CutMode cuts[] = {CutMode::kHollow, CutMode::kNone, CutMode::kSolid};
  int culled = 0, differing = 0, back_face_pixels = 0;
  size_t clusters_left_out = 0;
  const int kConfigs = 30;
  for (int i = 0; i < kConfigs; ++i) {
    const core::DeformationKind kind = kinds[i % 3];
    const double amount = kind == core::DeformationKind::kKnife  ? uniform(0.1, 0.4)
                          : kind == core::DeformationKind::kPeel ? uniform(1.0, 3.0)
                                                                 : uniform(0.5, 2.5);
    scene.deformation.terms = {Make(kind, amount, uniform(0.2, 0.5))};
    const glm::dvec3 centre(uniform(-0.45, 0.45), uniform(-0.45, 0.45), uniform(-0.15, 0.15));
    const glm::dvec3 half(uniform(0.05, 0.3), uniform(0.05, 0.3), uniform(0.05, 0.25));
    scene.placement = core::Placement::FromRegion({centre - half, centre + half});
    // Mostly outside the torus's bounds; every fifth view close enough for
    // the near plane (0.1) to cut it.
    const double theta = uniform(0.0, 2 * M_PI), z = uniform(-0.9, 0.9);
    const glm::dvec3 direction(std::sqrt(1 - z * z) * std::cos(theta),
                               std::sqrt(1 - z * z) * std::sin(theta), z);
    const double range = i % 5 == 4 ? uniform(0.3, 0.7) : uniform(1.2, 2.5);
    ViewSetup view = MakeView(glm::vec3(range * direction));
    if (i % 3 == 1)
      view.cam_from_world = glm::scale(glm::mat4(1.0f), glm::vec3(-1, 1, 1)) *
                            view.cam_from_world;  // a mirrored camera
    DeformPassOptions options;
    options.cut = cuts[(i / 3) % 3];
    options.cull_back_faces = false;
    const Frame both = Render(scene, options, view, distance);
    options.cull_back_faces = true;
    DeformPass pass(programs(), {&scene.mesh, &sdf_, &texture_, scene.placement}, options);
    const Frame frame = RenderFrame(pass, view, kSize, kSize);
    culled += pass.last_culled_back_faces();
    clusters_left_out += pass.last_culled_clusters();
    int differ = 0;
    const glm::mat3 cam_from_world(view.cam_from_world);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        bool same = frame.outcome.at(x, y) == both.outcome.at(x, y) &&
                    std::bit_cast<uint32_t>(frame.depth.at(x, y)) ==
                        std::bit_cast<uint32_t>(both.depth.at(x, y));
        for (int c = 0; c < 4; ++c) same &= frame.color.at(x, y, c) == both.color.at(x, y, c);
        for (int c = 0; c < 3; ++c) {
          same &= std::bit_cast<uint32_t>(frame.normal.at(x, y, c)) ==
                  std::bit_cast<uint32_t>(both.normal.at(x, y, c));
        }
        differ += !same;
        // A back face of the rasterised mesh seen: its normal (camera
        // frame) points away from the eye along the pixel's ray.
        if (pass.last_culled_back_faces() && both.Covered(x, y) &&
            !(both.outcome.at(x, y) & OutcomeBit(RayOutcome::kHit))) {
          const glm::vec3 n =
              cam_from_world *
              glm::vec3(both.normal.at(x, y, 0), both.normal.at(x, y, 1), both.normal.at(x, y, 2));
          const glm::vec3 ray((x + 0.5 - kSize / 2.0) / g_focal, (y + 0.5 - kSize / 2.0) / g_focal,
                              1.0);  // as Compare
          back_face_pixels += glm::dot(n, ray) > 0.05f * glm::length(ray);
        }
      }
    if (differ) std::printf("configuration %d: %d pixels differ\n", i, differ);
    differing += differ;
  }
  std::printf(
      "back-face culling: %d of %d configurations culled, %zu clusters left out whole, %d "
      "back-face pixels seen, %d pixels differ\n",
      culled, kConfigs, clusters_left_out, back_face_pixels, differing);
  EXPECT_EQ(differing, 0);
  EXPECT_GE(culled, kConfigs / 2);   // the culling path ran
  EXPECT_LT(culled, kConfigs);       // and near views did not cull
  EXPECT_GT(clusters_left_out, 0u);  // whole back-facing clusters were not drawn
  // Back faces were seen through the boxes where the pass culled.
  EXPECT_GT(back_face_pixels, 50);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, ForwardTruthForTwistAndBend) {
  // A standing torus (ring in the y-z plane), finely tessellated, deformed
  // forward in closed form and rasterised by the mesh pass, against the
  // ray-cast inverse deformation of its distance field.
  core::TriangleMesh torus = core::MakeTorus(0.3f, 0.12f, 192, 48);
  for (glm::vec3& p : torus.positions) p = glm::vec3(p.z, p.x, p.y);
  for (glm::vec3& n : torus.normals) n = glm::vec3(n.z, n.x, n.y);
  for (const core::Deformation& d : {Make(core::DeformationKind::kTwist, 1.5, 0.45),
                                     Make(core::DeformationKind::kBend, 0.6, 0.0)}) {
    Scene scene;
    scene.mesh = torus;
    scene.deformation.terms = {d};
    scene.placement = core::Placement::FromRegion({{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}});
    scene.sdf_resolution = 128;
    core::MeshDistance distance(scene.mesh, false, "torus");
    // Zoomed so the torus fills most of the image (IoU counts silhouette
    // pixels: a small footprint would measure pixel sampling).
    g_focal = 330.0;
    ViewSetup view = MakeView({1.9f, -1.6f, 0.9f});
    Frame frame = Render(scene, DeformPassOptions{}, view, distance);
    core::TriangleMesh forward = torus;
    const glm::dmat4 box_from_object = scene.placement.BoxFromObject();
    for (glm::vec3& p : forward.positions) {
      glm::dvec3 u(box_from_object * glm::dvec4(glm::dvec3(p), 1.0));
      p = glm::vec3(scene.placement.object_from_box * glm::dvec4(d.Forward(u), 1.0));
    }
    GpuMesh gpu_forward(forward);
    Frame truth = RenderMesh(programs(), gpu_forward, view, kSize, kSize);
    test_support::WriteDebugImage("forward_" + core::DeformationKindName(d.kind) + "_ray.png",
                                  frame.color);
    test_support::WriteDebugImage("forward_" + core::DeformationKindName(d.kind) + "_truth.png",
                                  truth.color);
    int both = 0, differ = 0;
    std::vector<double> errors;
    // Grey where both cover, red: ray cast only, blue: forward mesh only.
    core::Image8 diff(kSize, kSize, 4, 0);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        bool a = frame.Covered(x, y), b = truth.color.at(x, y, 3) == 255;
        differ += a != b;
        if (a || b) {
          diff.at(x, y, 0) = a ? (b ? 128 : 255) : 0;
          diff.at(x, y, 1) = a && b ? 128 : 0;
          diff.at(x, y, 2) = b ? (a ? 128 : 255) : 0;
          diff.at(x, y, 3) = 255;
        }
        if (a && b) {
          ++both;
          errors.push_back(std::abs(double(frame.depth.at(x, y)) - truth.depth.at(x, y)));
        }
      }
    test_support::WriteDebugImage("forward_" + core::DeformationKindName(d.kind) + "_diff.png",
                                  diff);
    std::sort(errors.begin(), errors.end());
    double iou = double(both) / (both + differ);
    double p95 = errors[static_cast<size_t>(0.95 * (errors.size() - 1))];
    std::printf(
        "forward truth, %s: IoU %.4f (%d pixels differ), p95 depth error %.3g = %.3f voxel\n",
        core::DeformationKindName(d.kind).c_str(), iou, differ, p95, p95 / sdf_.spacing);
    EXPECT_GE(iou, 0.995) << core::DeformationKindName(d.kind);
    EXPECT_LE(p95, 0.5 * sdf_.spacing) << core::DeformationKindName(d.kind);
  }
  g_focal = 110.0;
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, NarrowPullMissesPerStepPolicy) {
  // Fig. 3 analogue: a flat top (box face at box z = 0.4) pulled into a
  // spike of amplitude 0.5 and width 0.03 of the region; base step one voxel.
  Scene scene;
  scene.mesh = core::MakeBox(glm::vec3(0.45f, 0.45f, 0.3f));
  for (glm::vec3& p : scene.mesh.positions) p.z -= 0.22f;  // top face at z = -0.02 (box z 0.4)
  scene.deformation.terms = {Make(core::DeformationKind::kPull, 0.5, 0.03)};
  scene.placement = core::Placement::FromRegion({{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}});
  scene.deformation_resolution = 128;
  core::MeshDistance distance(scene.mesh, false, "box");
  // Zoomed onto the spike's upper half (it reaches z = 0.46), seen from the
  // side: its tip is thinner than one step there.
  g_focal = 600.0;
  ViewSetup view = MakeView({2.4f, 0.9f, 0.35f}, {0.0f, 0.0f, 0.33f});
  core::DeformReference reference(distance, scene.deformation, scene.placement, CutMode::kNone, 0);
  double fixed_mean = 0.0;
  for (RayStepPolicy policy :
       {RayStepPolicy::kFixed, RayStepPolicy::kThreshold, RayStepPolicy::kJacobian}) {
    DeformPassOptions options;
    options.step_policy = policy;
    options.threshold = 0.04f;
    options.step_voxels = 1.0f;
    options.draw_mesh = false;
    Frame frame = Render(scene, options, view, distance);
    test_support::WriteDebugImage("pull_" + RayStepPolicyName(policy) + ".png", frame.color);
    Agreement a = Compare(frame, view, reference, scene.placement);
    // Misses: the reference hits, the shader found nothing (outside the band).
    int misses = a.compared - a.agree;
    double samples = 0;
    int rays = 0;
    std::map<int, int> histogram;  // samples per ray, in bins of 16
    for (uint32_t bits : frame.outcome.values()) {
      uint32_t n = bits >> kDeformSamplesShift;
      if (n == 0) continue;
      samples += n;
      ++rays;
      ++histogram[static_cast<int>(n / 16) * 16];
    }
    double mean = samples / std::max(rays, 1);
    if (policy == RayStepPolicy::kFixed) fixed_mean = mean;
    std::printf(
        "narrow pull, %s: %d misses of %d compared pixels, %.1f samples per ray (%.2fx fixed)\n  "
        "histogram:",
        RayStepPolicyName(policy).c_str(), misses, a.compared, mean, mean / fixed_mean);
    for (auto [bin, count] : histogram) std::printf(" %d-%d:%d", bin, bin + 15, count);
    std::printf("\n");
    if (policy == RayStepPolicy::kJacobian) {
      EXPECT_EQ(misses, 0);
      EXPECT_LE(mean, 2.0 * fixed_mean);
    }
  }
  g_focal = 110.0;
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, HardCaseSweepIsFiniteAndConsistent) {
  // Random deformations (sums, folds from large amounts), cuts, step
  // policies, regions (tiny, containing the whole mesh, missing it),
  // placements (rotated, scaled 0.2-3x, far off), cameras (inside the box,
  // grazing); every 8th configuration gets a NaN or infinite parameter,
  // which must be a clear InputError. Every other configuration samples the
  // sphere's depth-map cube instead of its distance field.
  core::TriangleMesh mesh = core::MakeSphere(0.5f, 12, 24);
  const DepthCube cube = AnalyticSphereCube(0.5, 20);
  core::MeshDistance distance(mesh, false, "sphere");
  std::mt19937 rng(2007);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * u01(rng); };
  const core::DeformationKind kinds[] = {
      core::DeformationKind::kTwist,   core::DeformationKind::kBend,
      core::DeformationKind::kPull,    core::DeformationKind::kKnife,
      core::DeformationKind::kPeel,    core::DeformationKind::kClip,
      core::DeformationKind::kCutaway, core::DeformationKind::kWedge,
      core::DeformationKind::kSlices,  core::DeformationKind::kSeam,
      core::DeformationKind::kWave};
  const CutMode cuts[] = {CutMode::kNone, CutMode::kHollow, CutMode::kSolid, CutMode::kThick};
  const RayStepPolicy policies[] = {RayStepPolicy::kFixed, RayStepPolicy::kThreshold,
                                    RayStepPolicy::kJacobian};
  constexpr int kConfigs = 208, kPixels = 24;
  int rendered = 0, refused = 0, bad_pixels = 0, inconsistent = 0, covered = 0;
  int failed_by[4] = {0, 0, 0, 0};
  for (int c = 0; c < kConfigs; ++c) {
    Scene scene;
    scene.mesh = mesh;
    int terms = 1 + (u01(rng) < 0.3);
    for (int t = 0; t < terms; ++t) {
      core::DeformationKind kind = kinds[rng() % std::size(kinds)];
      core::Deformation d = Make(kind, 0, 0);
      switch (kind) {
        case core::DeformationKind::kTwist:
          d.amount = uniform(-8, 8), d.width = uniform(0, 0.5);
          break;
        case core::DeformationKind::kBend:
          d.amount = uniform(-3, 3), d.width = 0;
          break;
        case core::DeformationKind::kPull:
          d.amount = uniform(-1, 1), d.width = uniform(0.01, 0.5);
          break;
        case core::DeformationKind::kKnife:
          d.amount = uniform(0.01, 0.5), d.width = uniform(0.05, 1);
          break;
        case core::DeformationKind::kPeel:
          d.amount = uniform(0, M_PI), d.width = uniform(0.02, 0.5);
          break;
        case core::DeformationKind::kClip:
        case core::DeformationKind::kCutaway:
          d.amount = uniform(0, 1), d.width = 0;
          break;
        case core::DeformationKind::kWedge:
          d.amount = uniform(0.01, M_PI), d.width = uniform(0, 1);
          break;
        case core::DeformationKind::kSlices:
          d.width = uniform(0.05, 1), d.amount = uniform(0, 0.9) * d.width;
          break;
        case core::DeformationKind::kSeam:
          d.amount = uniform(0.01, 0.5), d.width = uniform(0.05, 1);
          break;
        case core::DeformationKind::kWave:
          d.amount = uniform(-0.5, 0.5), d.width = uniform(0.05, 4);
          break;
      }
      scene.deformation.terms.push_back(d);
    }
    const bool poisoned = c % 8 == 7;
    if (poisoned) scene.deformation.terms[0].amount = (c % 16 == 7) ? NAN : INFINITY;
    glm::dvec3 centre(uniform(-0.8, 0.8), uniform(-0.8, 0.8), uniform(-0.8, 0.8));
    glm::dvec3 half(uniform(0.02, 1.2), uniform(0.02, 1.2), uniform(0.02, 1.2));
    if (c % 5 == 0) centre = glm::dvec3(0.0), half = glm::dvec3(0.7);  // contains the whole mesh
    if (c % 7 == 0) centre = glm::dvec3(3.0, 0, 0);                    // misses it
    glm::dvec3 rotation(uniform(-180, 180), uniform(-180, 180), uniform(-180, 180));
    if (c % 3 == 0) rotation = glm::dvec3(0.0);
    scene.placement = core::Placement::FromRegion({centre - half, centre + half}, rotation,
                                                  uniform(0.2, 3.0), glm::dvec3(0.0));
    scene.sdf_resolution = 20;
    scene.deformation_resolution = 16;
    DeformPassOptions options;
    options.cut = cuts[rng() % 4];
    options.thickness = static_cast<float>(uniform(0.01, 0.3));
    options.step_policy = policies[rng() % 3];
    options.skip_empty = u01(rng) < 0.5;
    options.max_steps = 256;
    if (c % 2 == 1) options.implicit = DeformImplicit::kDepthCube;
    glm::vec3 eye =
        glm::normalize(glm::vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) + 1e-3f);
    eye *= static_cast<float>(c % 6 == 0 ? uniform(0.05, 0.4)
                                         : uniform(1.2, 4.0));  // some inside the box
    ViewSetup view;
    view.cam_from_world = core::CamFromWorldLookAt(eye, {0.01f, 0.02f, 0.0f}, {0, 0, 1});
    view.clip_from_cam = core::ClipFromCamPerspective(kPixels, kPixels, kPixels / 2.0,
                                                      kPixels / 2.0, kPixels, kPixels, 0.01, 20);
    Frame frame;
    try {
      double grow = core::MaxObjectDisplacement(scene.deformation, scene.placement,
                                                scene.deformation_resolution);
      core::DistanceFieldOptions sdf_options;
      sdf_options.resolution = scene.sdf_resolution;
      sdf_ = core::BuildDistanceField(distance, scene.placement.ObjectBounds().Grown(grow + 0.01),
                                      sdf_options);
      texture_ = core::SampleDeformation(scene.deformation, scene.deformation_resolution);
      DeformPass pass(programs(), {&scene.mesh, &sdf_, &texture_, scene.placement, &cube}, options);
      frame = RenderFrame(pass, view, kPixels, kPixels);
    } catch (const core::InputError& e) {
      ++refused;
      EXPECT_TRUE(poisoned) << "config " << c << ": " << e.what();
      continue;
    }
    EXPECT_FALSE(poisoned) << "config " << c << " accepted a non-finite parameter";
    ++rendered;
    const uint32_t ray_bits = (1u << 1) | (1u << 2) | (1u << 3);
    for (int y = 0; y < kPixels; ++y)
      for (int x = 0; x < kPixels; ++x) {
        float z = frame.depth.at(x, y);
        bool finite = std::isfinite(z);
        for (int k = 0; k < 3; ++k) finite &= std::isfinite(frame.normal.at(x, y, k));
        bad_pixels += !finite;
        uint32_t bits = frame.outcome.at(x, y);
        bool hit = bits & OutcomeBit(RayOutcome::kHit);
        // A hit hidden behind the rasterised mesh still ORs its bit (every
        // ray reports, pass.h), so hit and mesh bits may both be set.
        bool mesh_px = bits & kDeformMeshBit;
        int ray_outcomes = std::popcount(bits & ray_bits);
        // Several rays may reach one pixel (outcomes OR, pass.h), so a pixel
        // may carry more than one ray outcome; samples are counted iff a ray ran.
        const bool checks[4] = {frame.Covered(x, y) == (hit || mesh_px),
                                (!(bits & kDeformCutFaceBit) || hit),
                                (frame.Covered(x, y) ? z >= 0 : z == 0),
                                ((bits >> kDeformSamplesShift) > 0) == (ray_outcomes >= 1)};
        bool ok = true;
        for (int k = 0; k < 4; ++k) {
          ok &= checks[k];
          if (!checks[k] && failed_by[k]++ < 3) {
            std::printf("config %d pixel (%d, %d): check %d fails: bits %#x covered %d z %g\n", c,
                        x, y, k, bits, frame.Covered(x, y), z);
          }
        }
        inconsistent += !ok;
        covered += frame.Covered(x, y);
      }
  }
  std::printf(
      "hard cases: %d configurations rendered, %d refused (non-finite parameters), %d covered "
      "pixels, "
      "%d non-finite pixels, %d inconsistent outcome flags\n",
      rendered, refused, covered, bad_pixels, inconsistent);
  EXPECT_EQ(rendered + refused, kConfigs);
  EXPECT_EQ(refused, kConfigs / 8);
  EXPECT_EQ(bad_pixels, 0);
  EXPECT_EQ(inconsistent, 0);
  EXPECT_NO_GL_ERROR();
}

// Seam blending (Correa, Silver, Chen 2007 sec. 3; DeformPassOptions::
// seam_blend). A coarse sphere, whose interpolated vertex normals differ from
// its distance field's gradient (the faceted surface), under a box with a
// zero deformation over its top: where the rasterised mesh meets the ray-cast
// box the shading jumps. Measured on the frame as the mean colour difference
// of neighbouring pixels across the seam (one drawn by the mesh stage alone,
// the other by a ray hit alone): blending must reduce it. Pixels whose
// surface point (unprojected from the frame's camera z) lies farther from
// the box than the band, and every ray-cast pixel, are unchanged bit for bit.
TEST_F(DeformPassTest, SeamBlendingReducesTheJumpAndLeavesTheRestAlone) {
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 9, 18);
  scene.deformation.terms = {Make(core::DeformationKind::kTwist, 0.0, 0.3)};
  scene.placement = core::Placement::FromRegion({{-0.6, -0.6, 0.1}, {0.6, 0.6, 0.7}});
  scene.sdf_resolution = 64;
  core::MeshDistance distance(scene.mesh, false, "coarse sphere");
  const ViewSetup view = MakeView({1.9f, -1.4f, 0.5f});
  DeformPassOptions off;
  off.seam_blend = false;
  const Frame plain = Render(scene, off, view, distance);
  const Frame blended = Render(scene, DeformPassOptions{}, view, distance);
  test_support::WriteDebugImage("seam_off.png", plain.color);
  test_support::WriteDebugImage("seam_on.png", blended.color);
  const double band = DeformPassOptions{}.seam_band_voxels * sdf_.spacing;

  // Which stage drew a pixel, from where its surface point lies (the frame's
  // camera z unprojected): inside the box the ray stage, outside the mesh's.
  const glm::dmat4 world_from_cam = glm::inverse(glm::dmat4(view.cam_from_world));
  const glm::dmat4 box_from_object = scene.placement.BoxFromObject();
  const glm::dmat3 object_from_box(scene.placement.object_from_box);
  const auto box_point = [&](const Frame& f, int x, int y) {
    const double z = f.depth.at(x, y);
    const glm::dvec3 p_cam((x + 0.5 - kSize / 2.0) / g_focal * z,
                           (y + 0.5 - kSize / 2.0) / g_focal * z, z);
    return glm::dvec3(box_from_object * world_from_cam * glm::dvec4(p_cam, 1.0));
  };
  const auto in_box = [&](const Frame& f, int x, int y) {
    const glm::dvec3 u = box_point(f, x, y);
    return u == glm::clamp(u, 0.0, 1.0);
  };
  const auto mesh_only = [&](const Frame& f, int x, int y) {
    return f.Covered(x, y) && !in_box(f, x, y);
  };
  const auto ray_only = [&](const Frame& f, int x, int y) {
    return f.Covered(x, y) && in_box(f, x, y);
  };
  // Mean over the seam's neighbour pairs of the largest channel difference.
  const auto seam_jump = [&](const Frame& f, int& pairs) {
    double sum = 0;
    pairs = 0;
    for (int y = 0; y + 1 < kSize; ++y)
      for (int x = 0; x + 1 < kSize; ++x)
        for (const glm::ivec2 q : {glm::ivec2(x + 1, y), glm::ivec2(x, y + 1)}) {
          const bool across = (mesh_only(f, x, y) && ray_only(f, q.x, q.y)) ||
                              (ray_only(f, x, y) && mesh_only(f, q.x, q.y));
          // The same surface on both sides (not a silhouette).
          if (!across || std::abs(f.depth.at(x, y) - f.depth.at(q.x, q.y)) > 0.05) continue;
          int jump = 0;
          for (int c = 0; c < 3; ++c)
            jump = std::max(jump, std::abs(f.color.at(x, y, c) - f.color.at(q.x, q.y, c)));
          sum += jump;
          ++pairs;
        }
    return pairs > 0 ? sum / pairs : 0.0;
  };
  int pairs_off = 0, pairs_on = 0;
  const double jump_off = seam_jump(plain, pairs_off), jump_on = seam_jump(blended, pairs_on);
  std::printf("seam: mean jump %.2f -> %.2f (8-bit levels) over %d / %d pixel pairs\n", jump_off,
              jump_on, pairs_off, pairs_on);
  EXPECT_GT(pairs_off, 30) << "the seam crosses the sphere in view";
  EXPECT_GT(jump_off, 4.0) << "a seam to blend: the coarse mesh's normals differ";
  EXPECT_LT(jump_on, 0.5 * jump_off);

  // Away from the seam: the same pixels.
  // A pixel's footprint at the sphere is about 0.025 units: two of them on
  // top of the band for the unprojection's rounding and the pixel's extent.
  const double margin = 2 * 2.6 / g_focal;
  int far_pixels = 0, changed = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      if (!plain.Covered(x, y)) continue;
      bool same = blended.Covered(x, y);
      for (int c = 0; c < 4; ++c)
        same = same && plain.color.at(x, y, c) == blended.color.at(x, y, c);
      changed += !same;
      const glm::dvec3 u = box_point(plain, x, y);
      const double d = glm::length(object_from_box * (u - glm::clamp(u, 0.0, 1.0)));
      if (d > band + margin || ray_only(plain, x, y)) {
        ++far_pixels;
        EXPECT_TRUE(same) << x << "," << y << " at " << d << " from the box";
      }
    }
  EXPECT_GT(far_pixels, 1000);
  EXPECT_GT(changed, 0);
  DeformPassOptions bad;
  bad.seam_band_voxels = 0;
  EXPECT_THROW(bad.Check(), core::InputError);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformPassTest, BadOptionsAreClearErrors) {
  DeformPassOptions options;
  options.step_voxels = NAN;
  EXPECT_THROW(options.Check(), core::InputError);
  options = {};
  options.thickness = -1;
  EXPECT_THROW(options.Check(), core::InputError);
  EXPECT_THROW(core::CutModeFromName("thin"), core::InputError);
}

}  // namespace
}  // namespace render
