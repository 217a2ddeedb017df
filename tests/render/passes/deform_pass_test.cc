// render/passes/deform_pass against the independent CPU reference
// (core/deform_reference.h: sphere tracing in double with the exact mesh
// distance and the analytic deformation and cut), and the two-stage
// composite against the plain mesh pass (a zero deformation must reproduce
// the mesh).
#include "render/passes/deform_pass.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/deform_reference.h"
#include "core/error.h"
#include "core/projection.h"
#include "render/passes/mesh_pass.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

constexpr int kSize = 96;
constexpr double kFocal = 110.0;

struct Scene {
  core::TriangleMesh mesh;
  core::DeformationSum deformation;
  core::Placement placement;
  int sdf_resolution = 64;
  int deformation_resolution = 64;
};

ViewSetup MakeView(const glm::vec3& eye) {
  ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt(eye, {0, 0, 0}, {0, 0, 1});
  view.clip_from_cam =
      core::ClipFromCamPerspective(kFocal, kFocal, kSize / 2.0, kSize / 2.0, kSize, kSize, 0.1, 20);
  return view;
}

// Pixel classes: 0 nothing, 1 the mesh surface, 2 a cut face.
int GpuClass(const Frame& frame, int x, int y) {
  if (!frame.Covered(x, y)) return 0;
  return (frame.outcome.at(x, y) & kDeformCutFaceBit) ? 2 : 1;
}

struct Agreement {
  int compared = 0, agree = 0, band = 0;
  double worst_cut_normal_deg = 0.0;
  int cut_normals = 0;
};

// Traces every pixel centre on the CPU inside the box and compares the class
// (and cut-face normals) with the GPU frame, outside a one-pixel band around
// the reference's class boundaries.
Agreement Compare(const Frame& frame, const ViewSetup& view, const core::DeformReference& reference,
                  const core::Placement& placement) {
  glm::dmat4 world_from_cam = glm::inverse(glm::dmat4(view.cam_from_world));
  glm::dvec3 eye(world_from_cam * glm::dvec4(0, 0, 0, 1));
  glm::dmat4 box_from_object = placement.BoxFromObject();
  std::vector<int> cls(kSize * kSize);
  std::vector<glm::dvec3> normals(kSize * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      glm::dvec3 d_cam((x + 0.5 - kSize / 2.0) / kFocal, (y + 0.5 - kSize / 2.0) / kFocal, 1.0);
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
      bool band = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int xx = std::clamp(x + dx, 0, kSize - 1), yy = std::clamp(y + dy, 0, kSize - 1);
          band |= cls[yy * kSize + xx] != c;
        }
      if (band) {
        ++a.band;
        continue;
      }
      ++a.compared;
      int g = GpuClass(frame, x, y);
      a.agree += g == c;
      if (c == 2 && g == 2) {
        glm::dvec3 n_gpu(frame.normal.at(x, y, 0), frame.normal.at(x, y, 1),
                         frame.normal.at(x, y, 2));
        double cosine = glm::length(n_gpu) > 0.5
                            ? glm::dot(glm::normalize(n_gpu), normals[y * kSize + x])
                            : -1.0;
        a.worst_cut_normal_deg = std::max(a.worst_cut_normal_deg,
                                          glm::degrees(std::acos(std::clamp(cosine, -1.0, 1.0))));
        ++a.cut_normals;
      }
    }
  return a;
}

class DeformPassTest : public test_support::GlTest {
 protected:
  Frame Render(const Scene& scene, const DeformPassOptions& options, const ViewSetup& view,
               const core::MeshDistance& distance) {
    double grow = core::MaxObjectDisplacement(scene.deformation, scene.placement,
                                              scene.deformation_resolution);
    core::DistanceFieldOptions sdf_options;
    sdf_options.resolution = scene.sdf_resolution;
    sdf_ = core::BuildDistanceField(distance, scene.placement.ObjectBounds().Grown(grow + 0.02),
                                    sdf_options);
    texture_ = core::SampleDeformation(scene.deformation, scene.deformation_resolution);
    DeformInputs inputs{&scene.mesh, &sdf_, &texture_, scene.placement};
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

TEST_F(DeformPassTest, SolidKnifeCutAgreesWithTheReference) {
  Scene scene;
  scene.mesh = core::MakeSphere(0.5f, 48, 96);
  scene.deformation.terms = {Make(core::DeformationKind::kKnife, 0.25, 0.7)};
  scene.placement = core::Placement::FromRegion({{-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}});
  core::MeshDistance distance(scene.mesh, false, "sphere");
  for (CutMode cut : {CutMode::kSolid, CutMode::kHollow, CutMode::kThick}) {
    DeformPassOptions options;
    options.cut = cut;
    options.thickness = 0.08f;
    options.step_voxels = 0.5f;
    ViewSetup view = MakeView({0.9f, -2.0f, 2.0f});
    Frame frame = Render(scene, options, view, distance);
    test_support::WriteDebugImage("knife_" + core::CutModeName(cut) + ".png", frame.color);
    core::DeformReference reference(distance, scene.deformation, scene.placement, cut,
                                    options.thickness);
    Agreement a = Compare(frame, view, reference, scene.placement);
    std::printf(
        "knife %s: %d/%d pixels agree (%.3f %%), %d in the band; cut-face normals: %d, worst %.3f "
        "deg\n",
        core::CutModeName(cut).c_str(), a.agree, a.compared, 100.0 * a.agree / a.compared, a.band,
        a.cut_normals, a.worst_cut_normal_deg);
    EXPECT_GE(a.agree, 0.995 * a.compared) << core::CutModeName(cut);
    if (cut == CutMode::kSolid) {
      EXPECT_GT(a.cut_normals, 50);
    }
    if (cut != CutMode::kHollow) {
      EXPECT_LT(a.worst_cut_normal_deg, 1.0) << core::CutModeName(cut);
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
  MeshFrame truth = RenderMesh(programs(), gpu_mesh, view, kSize, kSize);
  int both = 0, differ = 0, rays = 0;
  double worst = 0.0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      bool a = frame.Covered(x, y), b = truth.color.at(x, y, 3) == 255;
      differ += a != b;
      if (a && b) {
        ++both;
        worst = std::max(worst, std::abs(double(frame.depth.at(x, y)) - truth.depth.at(x, y)));
        rays += (frame.outcome.at(x, y) & (1u << static_cast<int>(RayOutcome::kHit))) != 0;
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
