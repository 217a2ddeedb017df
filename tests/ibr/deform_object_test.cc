// The depth-map cube implicit of the deform pass (Correa, Silver, Chen 2007,
// sec. 6.1; ibr::MakeDepthCube, render::DepthCube) through the one path of
// `ibr deform` (ibr::MakeDeformObject), against the double sphere tracer of
// the true mesh's distance (core/deform_reference.h, bench::TraceDeformReference):
//  - convex shapes (a sphere cut by the solid knife, a twisted box), which six
//    depth maps describe exactly up to their texels (the deformation only
//    moves where the implicit is sampled, never the object's convexity): the
//    silhouette and camera z agree to bounds in map texels, and the error
//    shrinks when the maps' resolution doubles;
//  - Spot, which is not convex (horns, ears, leg junctions are surfaces no
//    face sees head-on or at all): the error is printed beside the distance
//    field's, and is larger (the `_off` debug image marks the pixels off by
//    more than a texel);
//  - memory (six R32F maps) and the implicit's name as an option.
#include "ibr/deform_object.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "bench/deform_bench.h"
#include "capture/synthetic.h"
#include "core/deform_reference.h"
#include "core/distance_field.h"
#include "core/error.h"
#include "core/mesh.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

constexpr int kSize = 128;

struct Measured {
  core::ViewMetrics metrics;  // depth errors in the depth cube's texels
  double texel = 0.0;         // normalised units
  int64_t bytes = 0;
  int64_t off_by_a_texel = 0;  // pixels both cover whose camera z is off by more than a texel
};

class DeformDepthCubeTest : public test_support::GlTest {
 protected:
  // `mesh` deformed by `deformation` (cut `cut`) through MakeDeformObject with
  // the given implicit and resolution, drawn from the bench's oblique view,
  // against the sphere tracer of the true mesh. Depth errors are reported in
  // texels of a depth cube of `resolution` (the mesh's cube: 1.05 / N).
  Measured Measure(const std::string& name, const core::TriangleMesh& mesh,
                   const core::Deformation& deformation, core::CutMode cut,
                   render::DeformImplicit implicit, int resolution) {
    DeformObjectOptions options;
    options.deformation.terms = {deformation};
    options.pass.cut = cut;
    options.pass.implicit = implicit;
    options.pass.step_voxels = 0.5f;
    options.sdf_resolution = resolution;
    const DeformObjectData data = MakeDeformObject(mesh, options, name, false, &programs());
    render::DeformPass pass(programs(), data.Inputs(), options.pass);
    const bench::DeformPinholeView view = bench::DeformObliqueView(kSize);
    const render::Frame frame = render::RenderFrame(pass, view.Setup(), kSize, kSize);
    const core::MeshDistance distance(data.mesh, false, name);
    const core::DeformReference reference(distance, options.deformation, data.placement, cut, 0.0);
    const bench::DeformReferenceFrame truth =
        bench::TraceDeformReference(reference, data.placement, view);
    Measured m;
    // The cube rig's texel: its cube is the mesh's bounding cube (longest
    // side 1) grown by 5 %.
    m.texel = 1.05 / resolution;
    m.metrics = core::CompareDepth(frame.depth, truth.depth, m.texel);
    m.bytes = data.ImplicitBytes();
    // Where the depth is off by more than a texel: the picture in grey, those
    // pixels red.
    core::Image8 off = frame.color;
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        const float z = frame.depth.at(x, y), t = truth.depth.at(x, y);
        if (z > 0 && t > 0 && std::abs(z - t) > m.texel) {
          ++m.off_by_a_texel;
          off.at(x, y, 0) = 255, off.at(x, y, 1) = off.at(x, y, 2) = 0;
        }
      }
    }
    const std::string tag =
        name + "_" + render::DeformImplicitName(implicit) + "_" + std::to_string(resolution);
    test_support::WriteDebugImage("deform_" + tag + ".png", frame.color);
    test_support::WriteDebugImage("deform_" + tag + "_truth.png", truth.color);
    test_support::WriteDebugImage("deform_" + tag + "_off.png", off);
    std::printf(
        "%s %s %d: %lld bytes; IoU %.5f, %lld wrong pixels; depth error (texels of 1.05/%d) mean "
        "%.3f p95 %.3f max %.3f; %lld pixels off by more than a texel\n",
        name.c_str(), render::DeformImplicitName(implicit).c_str(), resolution,
        static_cast<long long>(m.bytes), m.metrics.iou,
        static_cast<long long>(m.metrics.wrong_pixels), resolution, m.metrics.depth.mean,
        m.metrics.depth.p95, m.metrics.depth.max, static_cast<long long>(m.off_by_a_texel));
    EXPECT_NO_GL_ERROR();
    return m;
  }
};

TEST_F(DeformDepthCubeTest, ConvexShapesAgreeWithTheReferenceToTheMapsTexels) {
  struct Case {
    std::string name;
    core::TriangleMesh mesh;
    core::Deformation deformation;
    core::CutMode cut;
  };
  core::Deformation twist;
  twist.kind = core::DeformationKind::kTwist, twist.amount = 1.2, twist.width = 0.2;
  const Case cases[] = {
      {"sphere_knife", core::MakeSphere(0.5f, 64, 128), bench::KnifeCut(), core::CutMode::kSolid},
      {"box_twist", core::MakeBox(glm::vec3(0.5f, 0.35f, 0.3f)), twist, core::CutMode::kNone},
  };
  for (const Case& c : cases) {
    const Measured coarse =
        Measure(c.name, c.mesh, c.deformation, c.cut, render::DeformImplicit::kDepthCube, 64);
    const Measured fine =
        Measure(c.name, c.mesh, c.deformation, c.cut, render::DeformImplicit::kDepthCube, 128);
    Measure(c.name, c.mesh, c.deformation, c.cut, render::DeformImplicit::kSdf, 128);
    for (const Measured* m : {&coarse, &fine}) {
      EXPECT_GE(m->metrics.iou, 0.99) << c.name;
      EXPECT_GT(m->metrics.both_pixels, kSize * kSize / 8) << c.name;
      // Inside the silhouettes the bilinear maps hold a convex surface to a
      // fraction of a texel; the maps' own silhouettes (a blend of the
      // surface and the far face over one texel) carve up to about a texel,
      // seen along grazing rays.
      EXPECT_LE(m->metrics.depth.p95, 1.0) << c.name;
      EXPECT_LE(m->metrics.depth.mean, 0.25) << c.name;
    }
    // Resolution-limited: twice the texels, no larger an error in object
    // units (texels of the coarse cube are twice the fine one's).
    EXPECT_LE(fine.metrics.depth.p95 * fine.texel, coarse.metrics.depth.p95 * coarse.texel)
        << c.name;
    EXPECT_LE(fine.metrics.wrong_pixels, coarse.metrics.wrong_pixels) << c.name;
  }
}

TEST_F(DeformDepthCubeTest, SpotIsNotExactAndTheErrorIsPrinted) {
  const core::TriangleMesh spot =
      capture::LoadSceneMesh(test_support::SharedData("meshes/spot.obj")).mesh;
  const Measured cube = Measure("spot_knife", spot, bench::KnifeCut(), core::CutMode::kSolid,
                                render::DeformImplicit::kDepthCube, 128);
  const Measured sdf = Measure("spot_knife", spot, bench::KnifeCut(), core::CutMode::kSolid,
                               render::DeformImplicit::kSdf, 128);
  std::printf(
      "spot: depth cube %lld bytes, IoU %.5f, p95 %.3f texels; distance field %lld bytes, IoU "
      "%.5f, p95 %.3f texels\n",
      static_cast<long long>(cube.bytes), cube.metrics.iou, cube.metrics.depth.p95,
      static_cast<long long>(sdf.bytes), sdf.metrics.iou, sdf.metrics.depth.p95);
  // Still Spot where the tracer sees it...
  EXPECT_GE(cube.metrics.iou, 0.9);
  EXPECT_TRUE(std::isfinite(cube.metrics.depth.max));
  // ...but not exact: what no face sees is filled, so the error is above
  // the distance field's of the same resolution (the max is no measure here:
  // both share the odd silhouette pixel where a step misses a thin tip).
  EXPECT_GT(cube.metrics.depth.p95, sdf.metrics.depth.p95);
  EXPECT_GT(cube.metrics.depth.mean, sdf.metrics.depth.mean);
  EXPECT_GT(cube.off_by_a_texel, sdf.off_by_a_texel);
  EXPECT_EQ(cube.bytes, int64_t{6} * 128 * 128 * 4);
  EXPECT_LT(cube.bytes * 10, sdf.bytes);
}

// Pixel classes: 0 nothing, 1 the mesh's surface, 2 a cut face.
int GpuClass(const render::Frame& frame, int x, int y) {
  if (!frame.Covered(x, y)) return 0;
  return (frame.outcome.at(x, y) & render::kDeformCutFaceBit) ? 2 : 1;
}
// The reference's: TraceDeformReference tints cut faces (r != g), grey elsewhere.
int ReferenceClass(const bench::DeformReferenceFrame& truth, int x, int y) {
  if (!(truth.depth.at(x, y) > 0)) return 0;
  return truth.color.at(x, y, 0) != truth.color.at(x, y, 1) ? 2 : 1;
}

// Spot peeled as `ibr deform spot.obj --deformation peel` peels it (the
// default angle 2.4 and thickness 0.15, region the mesh's bounds grown by
// 0.05), seen from `ibr deform`'s orbit view at azimuth 30, elevation 20:
// which surface is hit (nothing, Spot, a cut face) agrees with the double
// sphere tracer outside a one-pixel band around its class boundaries, and
// no pixel is a speck (differs from all eight neighbours, which agree).
// Before the flap became its own piece, its faces were a jump of the sampled
// D interpolated over one texel: ragged edges and specks.
TEST_F(DeformDepthCubeTest, PeeledSpotAgreesWithTheReferenceWithoutSpecks) {
  const core::TriangleMesh spot =
      capture::LoadSceneMesh(test_support::SharedData("meshes/spot.obj")).mesh;
  for (core::CutMode cut : {core::CutMode::kSolid, core::CutMode::kNone}) {
    DeformObjectOptions options;
    core::Deformation peel;
    peel.kind = core::DeformationKind::kPeel;
    SetDeformationDefaults(peel);
    options.deformation.terms = {peel};
    options.pass.cut = cut;
    const DeformObjectData data = MakeDeformObject(spot, options, "spot", false, &programs());
    render::DeformPass pass(programs(), data.Inputs(), options.pass);
    // `ibr deform`'s default orbit of a normalised mesh.
    auto orbit = [](int size) { return bench::DeformOrbitView(size); };
    const std::string tag = "spot_peel_" + core::CutModeName(cut);
    // The picture at `ibr deform`'s size, to look at.
    test_support::WriteDebugImage(tag + "_384.png",
                                  render::RenderFrame(pass, orbit(384).Setup(), 384, 384).color);
    const bench::DeformPinholeView view = orbit(kSize);
    const render::Frame frame = render::RenderFrame(pass, view.Setup(), kSize, kSize);
    const core::MeshDistance distance(data.mesh, false, "spot");
    const core::DeformReference reference(distance, options.deformation, data.placement, cut, 0.0);
    const bench::DeformReferenceFrame truth =
        bench::TraceDeformReference(reference, data.placement, view);
    test_support::WriteDebugImage(tag + ".png", frame.color);
    test_support::WriteDebugImage(tag + "_truth.png", truth.color);
    int compared = 0, agree = 0, band = 0, cut_pixels = 0, isolated = 0;
    for (int y = 1; y + 1 < kSize; ++y) {
      for (int x = 1; x + 1 < kSize; ++x) {
        const int c = ReferenceClass(truth, x, y), g = GpuClass(frame, x, y);
        bool in_band = false;
        const int n = GpuClass(frame, x + 1, y);
        bool speck = n != g;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            in_band |= ReferenceClass(truth, x + dx, y + dy) != c;
            if (dx || dy) speck &= GpuClass(frame, x + dx, y + dy) == n;
          }
        }
        isolated += speck;
        if (in_band) {
          ++band;
          continue;
        }
        ++compared;
        agree += g == c;
        cut_pixels += c == 2;
      }
    }
    std::printf(
        "%s: %d/%d pixels agree (%.3f %%), %d in the band, %d cut-face pixels; %d isolated "
        "pixels\n",
        tag.c_str(), agree, compared, 100.0 * agree / compared, band, cut_pixels, isolated);
    EXPECT_GE(agree, 0.995 * compared) << tag;
    EXPECT_GT(compared, kSize * kSize / 2) << tag;
    EXPECT_GT(cut_pixels, 20) << tag;  // the flap's faces are seen
    EXPECT_EQ(isolated, 0) << tag;
  }
  EXPECT_NO_GL_ERROR();
}

// --cap-holes caps the rasterised part too (ibr::CappedMesh): a sphere with its
// top cap of triangles removed, capped, its deformation box at the bottom,
// seen from above: the hole shows the cap at the rim's height, not the
// sphere's inside.
TEST_F(DeformDepthCubeTest, CappedHolesAreCappedInTheRasterisedPartToo) {
  core::TriangleMesh sphere = core::MakeSphere(1.0f, 32, 64);
  for (glm::vec3& p : sphere.positions) p = glm::vec3(p.x, p.z, -p.y);  // poles on +-y
  for (glm::vec3& n : sphere.normals) n = glm::vec3(n.x, n.z, -n.y);
  core::TriangleMesh holed = sphere;
  holed.indices.clear();
  float rim = 1.0f;  // the lowest y of a removed triangle's corners
  for (size_t t = 0; t < sphere.triangle_count(); ++t) {
    const uint32_t* v = &sphere.indices[3 * t];
    float lowest = 1.0f;
    for (int k = 0; k < 3; ++k) lowest = std::min(lowest, sphere.positions[v[k]].y);
    if (lowest > 0.9f) {
      rim = std::min(rim, lowest);
      continue;
    }
    holed.indices.insert(holed.indices.end(), v, v + 3);
  }
  ASSERT_GT(core::FindMeshBoundary(holed).boundary_loops, 0u);
  DeformObjectOptions options;
  options.deformation.terms = {core::Deformation{}};                   // a twist
  options.region = core::Box3d{{-0.6, -0.6, -0.6}, {0.6, -0.2, 0.6}};  // the bottom
  options.cap_holes = true;
  const DeformObjectData data =
      MakeDeformObject(holed, options, "holed sphere", false, &programs());
  const core::MeshBoundary boundary = core::FindMeshBoundary(data.Drawn());
  EXPECT_EQ(boundary.boundary_edges, 0u);
  for (size_t i = 0; i < data.Drawn().positions.size(); ++i)  // outward, unit normals
    EXPECT_GT(glm::dot(data.Drawn().normals[i], data.Drawn().positions[i]), 0.0f) << i;

  // From straight above (normalised: radius 0.5, centre 0), the camera 3 up.
  render::ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt({0, 3, 0}, {0, 0, 0}, {0, 0, 1});
  view.clip_from_cam =
      core::ClipFromCamPerspective(300.0, 300.0, kSize / 2.0, kSize / 2.0, kSize, kSize, 0.5, 10.0);
  const auto centre_depth = [&](const core::TriangleMesh& drawn, uint32_t* outcome) {
    render::DeformInputs inputs = data.Inputs();
    inputs.mesh = &drawn;
    render::DeformPass pass(programs(), inputs, options.pass);
    const render::Frame frame = render::RenderFrame(pass, view, kSize, kSize);
    *outcome = frame.outcome.at(kSize / 2, kSize / 2);
    return frame.depth.at(kSize / 2, kSize / 2);
  };
  uint32_t outcome = 0;
  const float capped = centre_depth(data.Drawn(), &outcome);
  const float cap_plane = 3.0f - 0.5f * rim;  // camera z of the cap (a plane at the rim)
  std::printf("centre pixel: camera z %.4f, the cap's plane %.4f\n", capped, cap_plane);
  EXPECT_NEAR(capped, cap_plane, 0.01f);
  EXPECT_TRUE(outcome & render::kDeformMeshBit);
  // The mesh as given, open (as drawn before): the hole shows the inside,
  // down to the deformation box's top face (y = -0.2, camera z 3.2), where
  // the capped field's solid begins: the two stages disagreed.
  const float open = centre_depth(data.mesh, &outcome);
  std::printf("the open mesh drawn instead: camera z %.4f\n", open);
  EXPECT_GT(open, 3.1f);
  EXPECT_NO_GL_ERROR();
}

TEST(DeformDepthCubeOptions, ImplicitNamesAndTheCubesChecks) {
  EXPECT_EQ(render::DeformImplicitFromName("sdf"), render::DeformImplicit::kSdf);
  EXPECT_EQ(render::DeformImplicitFromName("depth-cube"), render::DeformImplicit::kDepthCube);
  try {
    render::DeformImplicitFromName("octree");
    ADD_FAILURE() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'octree'"), std::string::npos) << e.what();
  }
  scene::Settings settings;
  settings.Set("implicit", "depth-cube", "--implicit");
  EXPECT_EQ(DeformObjectOptionsFrom(settings).pass.implicit, render::DeformImplicit::kDepthCube);
  render::DepthCube cube;
  EXPECT_THROW(cube.Check("t"), core::InputError);  // no faces
  cube.faces.resize(6, {core::ImageF(8, 8, 1), glm::dmat4(1.0)});
  cube.far = 1.0, cube.texel = 0.125;
  cube.Check("t");
  EXPECT_EQ(cube.Bytes(), 6 * 8 * 8 * 4);
  cube.faces[3].depth = core::ImageF(8, 7, 1);
  EXPECT_THROW(cube.Check("t"), core::InputError);
}

}  // namespace
}  // namespace ibr
