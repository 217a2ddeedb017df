// Synthetic capture against analytic truth: depth of a sphere equals the
// ray-sphere intersection; back-projected depth pixels of every analytic
// shape lie on that shape's surface; the six cube faces agree where they see
// the same points; captures are deterministic; Spot is textured.
#include "capture/synthetic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/error.h"
#include "tests/support/gl_test.h"

namespace capture {
namespace {

class SyntheticTest : public test_support::GlTest {};

// Unsigned distance from p to each analytic shape (MakeShapeScene's sizes).
double SurfaceDistance(const std::string& shape, const glm::dvec3& p) {
  if (shape == "sphere") return std::abs(glm::length(p) - 1.0);
  if (shape == "torus") {
    const double q = std::hypot(std::hypot(p.x, p.y) - 1.0, p.z);
    return std::abs(q - 0.4);
  }
  if (shape == "box") {
    const glm::dvec3 h(1.0, 0.7, 0.5);
    const glm::dvec3 d = glm::abs(p) - h;
    const double outside = glm::length(glm::max(d, 0.0));
    const double inside = std::min(std::max({d.x, d.y, d.z}), 0.0);
    return std::abs(outside + inside);
  }
  // cup: distance in the (r, z) half plane to the closed profile polyline.
  const glm::dvec2 q(std::hypot(p.x, p.y), p.z);
  const glm::dvec2 prof[] = {{0, 0}, {1, 0}, {1, 1.2}, {0.88, 1.2}, {0.88, 0.12}, {0, 0.12}};
  double best = 1e30;
  for (int s = 0; s + 1 < 6; ++s) {
    const glm::dvec2 a = prof[s], ab = prof[s + 1] - prof[s];
    const double t = std::clamp(glm::dot(q - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    best = std::min(best, glm::length(q - (a + t * ab)));
  }
  return best;
}

TEST(Rig, ParseAndLayout) {
  EXPECT_EQ(RigSpec::Parse("cube").count, 6);
  EXPECT_EQ(RigSpec::Parse("ring:8").count, 8);
  EXPECT_EQ(RigSpec::Parse("sphere:26").kind, RigSpec::Kind::kSphere);
  for (const char* bad : {"ring", "ring:0", "ring:x", "sphere:-3", "cubes", "ring:8x", ""}) {
    EXPECT_THROW(RigSpec::Parse(bad), core::InputError) << bad;
  }
  CaptureOptions options;
  options.size = 64;
  const Bounds bounds{{-1, -2, -1}, {1, 2, 3}};
  const auto ring = MakeRig(RigSpec::Parse("ring:5"), bounds, options);
  ASSERT_EQ(ring.size(), 5u);
  for (const auto& v : ring) {
    // Every perspective view looks at the bounds centre and sees the whole bounding sphere.
    const glm::dvec3 c = v.cam_from_world * bounds.centre();
    EXPECT_NEAR(c.x, 0, 1e-9);
    EXPECT_NEAR(c.y, 0, 1e-9);
    EXPECT_GT(v.near, 0);
    EXPECT_LT(v.near, c.z - 0.5 * glm::length(bounds.extent()));
  }
  const auto cube = MakeRig(RigSpec::Parse("cube"), bounds, options);
  ASSERT_EQ(cube.size(), 6u);
  for (const auto& v : cube) {
    EXPECT_TRUE(v.camera.orthographic());
    // The bounds centre projects to the image centre at depth = half cube size.
    const glm::dvec3 c = v.cam_from_world * bounds.centre();
    EXPECT_NEAR(c.z, 2.0 * 1.05, 1e-9);
  }
}

TEST_F(SyntheticTest, SphereDepthEqualsRaySphereIntersection) {
  const double kSag = 1 - std::cos(3.14159265358979 / 256);
  const SceneMesh sphere = MakeShapeScene("sphere");
  CaptureOptions options;
  options.size = 128;
  const Bounds bounds{{-1, -1, -1}, {1, 1, 1}};
  std::vector<RigView> views = MakeRig(RigSpec::Parse("cube"), bounds, options);
  const auto ring = MakeRig(RigSpec::Parse("ring:3"), bounds, options);
  views.insert(views.end(), ring.begin(), ring.end());
  for (const RigView& view : views) {
    SCOPED_TRACE(view.name);
    const CapturedView cap = RenderView(programs(), sphere, view, options);
    const glm::dvec3 centre_in_cam = view.cam_from_world * glm::dvec3(0.0);
    int checked = 0, bad = 0, coverage_mismatch = 0;
    double max_err = 0;
    for (int row = 0; row < options.size; ++row) {
      for (int col = 0; col < options.size; ++col) {
        // Ray o + t d in the camera frame, with d.z = 1 so t is camera z.
        glm::dvec3 o(0.0), d;
        if (view.camera.orthographic()) {
          o = view.camera.UnprojectPixel(col, row, 0.0);
          d = {0, 0, 1};
        } else {
          d = view.camera.UnprojectPixel(col, row, 1.0);
        }
        const glm::dvec3 oc = o - centre_in_cam;
        const double a = glm::dot(d, d), b = 2 * glm::dot(oc, d), c = glm::dot(oc, oc) - 1.0;
        const double disc = b * b - 4 * a * c;
        const bool hit = disc > 0;
        const float depth = cap.depth.at(col, row);
        // Pixels whose ray grazes the silhouette (within ~0.05 px) are ambiguous.
        const double graze = disc / (4 * a * a);  // = (chord half-length)^2 in t units
        if (std::abs(graze) < 2e-3) continue;
        if (hit != (depth > 0)) ++coverage_mismatch;
        if (!hit || !(depth > 0)) continue;
        const double truth = (-b - std::sqrt(disc)) / (2 * a);
        // The tessellated sphere lies between radius 1 - sag and 1 (sag =
        // 1 - cos(pi / 256) = 7.5e-5 for 256 rings): its depth lies between
        // the intersections with those two spheres, plus float rounding.
        const double c_in = glm::dot(oc, oc) - (1.0 - kSag) * (1.0 - kSag);
        const double disc_in = b * b - 4 * a * c_in;
        const double deepest = disc_in > 0 ? (-b - std::sqrt(disc_in)) / (2 * a) : truth + 1.0;
        const double err = depth < truth ? truth - depth : std::max(0.0, depth - deepest);
        max_err = std::max(max_err, std::abs(depth - truth));
        ++checked;
        // 1e-4: the rasteriser snaps vertices to 1/256 px, which moves depth
        // on steep (near-silhouette) slopes; a half-pixel convention error
        // would be ~1e-2 here.
        if (err > 1e-4) ++bad;
      }
    }
    EXPECT_GT(checked, 2000);
    EXPECT_EQ(bad, 0) << "max |depth - sphere depth| " << max_err;
    EXPECT_EQ(coverage_mismatch, 0);
  }
}

TEST_F(SyntheticTest, BackProjectedDepthLiesOnEveryAnalyticSurface) {
  CaptureOptions options;
  options.size = 96;
  for (const std::string& shape : ShapeNames()) {
    SCOPED_TRACE(shape);
    const SceneMesh scene = MakeShapeScene(shape);
    glm::vec3 lo, hi;
    scene.mesh.Bounds(lo, hi);
    const Bounds bounds{glm::dvec3(lo), glm::dvec3(hi)};
    std::vector<RigView> views = MakeRig(RigSpec::Parse("cube"), bounds, options);
    const auto sph = MakeRig(RigSpec::Parse("sphere:4"), bounds, options);
    views.insert(views.end(), sph.begin(), sph.end());
    for (const RigView& view : views) {
      const CapturedView cap = RenderView(programs(), scene, view, options);
      const Rigid3 world_from_cam = view.cam_from_world.Inverse();
      int n = 0;
      double max_dist = 0;
      for (int row = 0; row < options.size; ++row) {
        for (int col = 0; col < options.size; ++col) {
          const float depth = cap.depth.at(col, row);
          EXPECT_EQ(depth > 0, cap.mask.at(col, row) == 255);
          if (!(depth > 0)) continue;
          const glm::dvec3 p = world_from_cam * view.camera.UnprojectPixel(col, row, depth);
          max_dist = std::max(max_dist, SurfaceDistance(shape, p));
          ++n;
          // The normal faces the camera and is unit length.
          const glm::dvec3 nw(cap.normal.at(col, row, 0), cap.normal.at(col, row, 1),
                              cap.normal.at(col, row, 2));
          EXPECT_NEAR(glm::length(nw), 1.0, 1e-5);
        }
      }
      EXPECT_GT(n, 300) << view.name;
      // Facet sag < 8e-5 for these tessellations; float depth ~1e-6 of 5 units.
      EXPECT_LT(max_dist, 2e-4) << view.name;
    }
  }
}

// Bilinear depth lookup at image coordinates uv (sparse convention); nullopt
// unless all four neighbours are valid.
std::optional<double> Bilinear(const core::ImageF& depth, glm::dvec2 uv) {
  const double x = uv.x - 0.5, y = uv.y - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= depth.width() || y0 + 1 >= depth.height()) return std::nullopt;
  const double fx = x - x0, fy = y - y0;
  double v[4];
  for (int k = 0; k < 4; ++k) {
    v[k] = depth.at(x0 + (k & 1), y0 + (k >> 1));
    if (!(v[k] > 0)) return std::nullopt;
  }
  return (v[0] * (1 - fx) + v[1] * fx) * (1 - fy) + (v[2] * (1 - fx) + v[3] * fx) * fy;
}

TEST_F(SyntheticTest, CubeFacesOfASphereAgreeAtSharedPoints) {
  const SceneMesh sphere = MakeShapeScene("sphere");
  CaptureOptions options;
  options.size = 128;
  const auto views = MakeRig(RigSpec::Parse("cube"), {{-1, -1, -1}, {1, 1, 1}}, options);
  std::vector<CapturedView> caps;
  for (const auto& v : views) caps.push_back(RenderView(programs(), sphere, v, options));
  int shared = 0;
  double max_diff = 0;
  for (size_t a = 0; a < views.size(); ++a) {
    const Rigid3 world_from_a = views[a].cam_from_world.Inverse();
    for (size_t b = 0; b < views.size(); ++b) {
      if (a == b) continue;
      for (int row = 0; row < options.size; row += 3) {
        for (int col = 0; col < options.size; col += 3) {
          const float da = caps[a].depth.at(col, row);
          if (!(da > 0)) continue;
          const glm::dvec3 p = world_from_a * views[a].camera.UnprojectPixel(col, row, da);
          // Seen by b only where the surface faces b clearly (no grazing).
          const glm::dvec3 view_dir_b =
              glm::transpose(views[b].cam_from_world.rotation) * glm::dvec3(0, 0, 1);
          if (glm::dot(glm::normalize(p), view_dir_b) > -0.3) continue;
          const glm::dvec3 p_in_b = views[b].cam_from_world * p;
          const auto db = Bilinear(caps[b].depth, views[b].camera.Project(p_in_b));
          if (!db) continue;
          max_diff = std::max(max_diff, std::abs(*db - p_in_b.z));
          ++shared;
        }
      }
    }
  }
  EXPECT_GT(shared, 5000);
  // Bilinear interpolation of a sphere cap at 64 px/unit (facing >= 0.3):
  // curvature error < 1e-3 units.
  EXPECT_LT(max_diff, 1.5e-3);
}

TEST_F(SyntheticTest, CaptureIsDeterministicAndWritesADataset) {
  const SceneMesh torus = MakeShapeScene("torus");
  CaptureOptions options;
  options.size = 48;
  options.rig = "ring:3";
  const auto root = test_support::TestOutputDir();
  const Dataset a = CaptureDataset(programs(), torus, options, root / "a");
  const Dataset b = CaptureDataset(programs(), torus, options, root / "b");
  EXPECT_EQ(a, b);
  const Dataset ra = ReadDataset(root / "a", true);
  const Dataset rb = ReadDataset(root / "b", true);
  ASSERT_EQ(ra.views.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(ra.LoadColor(i), rb.LoadColor(i));
    EXPECT_EQ(ra.LoadDepth(i), rb.LoadDepth(i));
    EXPECT_EQ(ra.LoadNormal(i), rb.LoadNormal(i));
  }
  ASSERT_TRUE(ra.bounds);
  EXPECT_NEAR(ra.bounds->max.x, 1.4, 1e-5);
}

TEST_F(SyntheticTest, SpotIsCapturedWithItsTexture) {
  const auto spot = test_support::SharedData("meshes/spot.obj");
  if (spot.empty()) GTEST_SKIP() << "../shared/data/meshes/spot.obj is absent";
  const SceneMesh scene = LoadSceneMesh(spot);
  ASSERT_FALSE(scene.texture.empty()) << "spot_texture.png not picked up";
  CaptureOptions options;
  options.size = 128;
  options.rig = "ring:2";
  options.shade = false;  // flat albedo: colours come from the texture only
  glm::vec3 lo, hi;
  scene.mesh.Bounds(lo, hi);
  const auto views =
      MakeRig(RigSpec::Parse(options.rig), {glm::dvec3(lo), glm::dvec3(hi)}, options);
  const CapturedView cap = RenderView(programs(), scene, views[0], options);
  std::set<int> colours;
  int covered = 0;
  for (int row = 0; row < options.size; ++row) {
    for (int col = 0; col < options.size; ++col) {
      if (cap.mask.at(col, row) != 255) continue;
      ++covered;
      colours.insert(cap.color.at(col, row, 0) << 16 | cap.color.at(col, row, 1) << 8 |
                     cap.color.at(col, row, 2));
    }
  }
  test_support::WriteDebugImage("spot.png", cap.color);
  EXPECT_GT(covered, 1000);
  // Unshaded and untextured would be one colour; Spot's texture has many.
  EXPECT_GT(colours.size(), 50u);
}

// The noise backdrop changes colour only (depth, mask, normals and the
// object's colour are those of the black capture), and it is world-fixed: two
// cameras at one centre, rotated 6 degrees apart, see the same backdrop colour
// along the same rays (pixels mapped by the rotation's homography).
TEST_F(SyntheticTest, NoiseBackdropIsColourOnlyAndWorldFixed) {
  const SceneMesh torus = MakeShapeScene("torus");
  CaptureOptions black;
  black.size = 96;
  black.rig = "ring:2";
  CaptureOptions noise = black;
  noise.background = "noise";
  glm::vec3 lo, hi;
  torus.mesh.Bounds(lo, hi);
  const auto views = MakeRig(RigSpec::Parse(black.rig), {glm::dvec3(lo), glm::dvec3(hi)}, black);
  const CapturedView a = RenderView(programs(), torus, views[0], black);
  const CapturedView b = RenderView(programs(), torus, views[0], noise);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.mask, b.mask);
  EXPECT_EQ(a.normal, b.normal);
  std::set<int> colours;
  for (int row = 0; row < 96; ++row) {
    for (int col = 0; col < 96; ++col) {
      for (int c = 0; c < 3; ++c) {
        if (a.mask.at(col, row)) {
          ASSERT_EQ(a.color.at(col, row, c), b.color.at(col, row, c));
        } else {
          ASSERT_EQ(a.color.at(col, row, c), 0);
        }
      }
      if (!a.mask.at(col, row))
        colours.insert(b.color.at(col, row, 0) << 16 | b.color.at(col, row, 1) << 8 |
                       b.color.at(col, row, 2));
    }
  }
  EXPECT_GT(colours.size(), 500u) << "the backdrop should be richly textured";
  EXPECT_THROW(
      [] {
        CaptureOptions bad;
        bad.background = "white";
        bad.Check();
      }(),
      core::InputError);

  // Pure rotation about the camera centre: view 2 looks 6 degrees to the side.
  RigView v1 = views[0], v2 = views[0];
  const glm::dvec3 eye = v1.cam_from_world.Centre();
  const glm::dvec3 forward = glm::transpose(v1.cam_from_world.rotation) * glm::dvec3(0, 0, 1);
  const glm::dvec3 side = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  v2.cam_from_world =
      LookAt(eye, eye + forward + std::tan(6 * 3.14159265358979 / 180) * side, {0, 1, 0});
  const CapturedView c1 = RenderView(programs(), torus, v1, noise);
  const CapturedView c2 = RenderView(programs(), torus, v2, noise);
  const Camera& cam = v1.camera;
  const glm::dmat3 r21 = v2.cam_from_world.rotation * glm::transpose(v1.cam_from_world.rotation);
  double same = 0, shifted = 0;
  int n = 0;
  for (int row = 8; row < 88; ++row) {
    for (int col = 8; col < 88; ++col) {
      if (c1.mask.at(col, row)) continue;
      const glm::dvec2 uv = cam.Project(r21 * cam.UnprojectPixel(col, row, 1.0));
      // Bilinear in view 2 (pixel centres at +0.5), and the same 2 px to the side.
      const double x = uv.x - 0.5, y = uv.y - 0.5;
      const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
      if (x0 < 3 || y0 < 1 || x0 >= 94 || y0 >= 94) continue;
      bool object = false;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = -2; dx < 2; ++dx) object = object || c2.mask.at(x0 + dx, y0 + dy);
      if (object) continue;
      const double fx = x - x0, fy = y - y0;
      auto sample = [&](int c, int offset) {
        auto at = [&](int px, int py) {
          return static_cast<double>(c2.color.at(px + offset, py, c));
        };
        return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
               fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
      };
      for (int c = 0; c < 3; ++c) {
        same += std::abs(c1.color.at(col, row, c) - sample(c, 0));
        shifted += std::abs(c1.color.at(col, row, c) - sample(c, -2));
      }
      ++n;
    }
  }
  ASSERT_GT(n, 2000);
  same /= 3.0 * n;
  shifted /= 3.0 * n;
  std::printf("backdrop: mean |difference| along the same ray %.2f, 2 px off %.2f (of 255)\n", same,
              shifted);
  // Resampling a minified texture (no mipmaps) leaves some; a wrong ray much more.
  EXPECT_LT(same, 0.5 * shifted);
}

}  // namespace
}  // namespace capture
