// The slicing core (CPU side) against geometry computed independently here:
// screen slices lie on the box and on their plane and cover the box's exact
// cross-section (area vs a Sutherland-Hodgman clip of a large square against
// the six half-spaces), the orthogonal axis choice (incl. exact ties), the
// front-to-back order along every ray (incl. an eye inside the box), and the
// slice-count rules of Kautz-Seidel 2001 sec. 3.4.
#include "render/cores/slicing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "core/error.h"
#include "core/projection.h"

namespace render {
namespace {

// A random non-degenerate affine box: rotation, non-uniform scale, shear, offset.
SliceBox RandomBox(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1, 1), s(0.3f, 2.0f);
  glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(u(rng), u(rng), u(rng)));
  m = glm::rotate(m, 3.0f * u(rng),
                  glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.01f)));
  m = glm::scale(m, glm::vec3(s(rng), s(rng), s(rng)));
  m[1][0] += 0.3f * u(rng);  // shear
  return {m};
}

glm::vec3 BoxCentreWorld(const SliceBox& box) {
  return glm::vec3(box.world_from_box * glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
}

SliceView RandomView(std::mt19937& rng, const SliceBox& box, bool orthographic, float distance) {
  std::uniform_real_distribution<float> u(-1, 1);
  glm::vec3 dir = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.001f));
  const glm::vec3 centre = BoxCentreWorld(box);
  const glm::vec3 up = std::abs(dir.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  return {core::CamFromWorldLookAt(centre + distance * dir, centre, up), orthographic};
}

// Independent reference: Sutherland-Hodgman of a large square in the plane
// dot(n, p) = d against the six half-spaces of [0,1]^3.
std::vector<glm::dvec3> ReferenceCrossSection(glm::dvec3 n, double d) {
  const glm::dvec3 nn = glm::normalize(n);
  const glm::dvec3 origin = nn * (d / glm::length(n));
  const glm::dvec3 helper = std::abs(nn.x) < 0.5 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 a = glm::normalize(glm::cross(nn, helper)), b = glm::cross(nn, a);
  std::vector<glm::dvec3> poly = {origin - 10.0 * a - 10.0 * b, origin + 10.0 * a - 10.0 * b,
                                  origin + 10.0 * a + 10.0 * b, origin - 10.0 * a + 10.0 * b};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      // Keep p[axis] >= 0 (side 0) or p[axis] <= 1 (side 1).
      auto inside = [&](const glm::dvec3& p) { return side == 0 ? p[axis] >= 0 : p[axis] <= 1; };
      std::vector<glm::dvec3> out;
      for (size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 p = poly[i], q = poly[(i + 1) % poly.size()];
        const double bound = side == 0 ? 0.0 : 1.0;
        if (inside(p)) out.push_back(p);
        if (inside(p) != inside(q))
          out.push_back(p + (q - p) * ((bound - p[axis]) / (q[axis] - p[axis])));
      }
      poly = out;
    }
  }
  return poly;
}

double Area(const std::vector<glm::dvec3>& poly) {
  glm::dvec3 sum(0);
  for (size_t i = 1; i + 1 < poly.size(); ++i)
    sum += glm::cross(poly[i] - poly[0], poly[i + 1] - poly[0]);
  return 0.5 * glm::length(sum);
}

TEST(Slicing, ScreenSliceVerticesLieOnTheBoxAndOnTheirPlane) {
  std::mt19937 rng(4);
  int vertices = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const SliceBox box = RandomBox(rng);
    const SliceView view = RandomView(rng, box, trial % 2 == 0, 6.0f);
    SlicingOptions options;
    options.family = SliceFamily::kScreen;
    options.count = 17;
    const SliceStack stack = MakeSlices(box, view, options);
    ASSERT_FALSE(stack.slices.empty());
    const glm::mat4 cam_from_box = view.cam_from_world * box.world_from_box;
    for (const Slice& slice : stack.slices) {
      ASSERT_GE(slice.p_in_box.size(), 3u);
      ASSERT_LE(slice.p_in_box.size(), 6u);
      const float z0 = (cam_from_box * glm::vec4(slice.p_in_box[0], 1.0f)).z;
      for (const glm::vec3& p : slice.p_in_box) {
        ++vertices;
        float to_face = 1;
        for (int k = 0; k < 3; ++k) {
          EXPECT_GE(p[k], -1e-5f);
          EXPECT_LE(p[k], 1 + 1e-5f);
          to_face = std::min({to_face, std::abs(p[k]), std::abs(p[k] - 1)});
        }
        EXPECT_LT(to_face, 1e-5f) << "vertex not on a face of the box";
        EXPECT_NEAR(glm::dot(stack.normal_in_box, p), slice.offset_in_box, 1e-4f);
        // Screen-parallel: every vertex at the same camera z.
        EXPECT_NEAR((cam_from_box * glm::vec4(p, 1.0f)).z, z0,
                    1e-4f * std::max(1.0f, std::abs(z0)));
      }
    }
  }
  EXPECT_GT(vertices, 5000);
}

TEST(Slicing, ScreenSliceAreaEqualsAnIndependentClipper) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const SliceBox box = RandomBox(rng);
    const SliceView view = RandomView(rng, box, trial % 2 == 1, 5.0f);
    SlicingOptions options;
    options.family = SliceFamily::kScreen;
    options.count = 9;
    const SliceStack stack = MakeSlices(box, view, options);
    for (const Slice& slice : stack.slices) {
      const auto reference =
          ReferenceCrossSection(glm::dvec3(stack.normal_in_box), slice.offset_in_box);
      const double want = Area(reference);
      EXPECT_NEAR(PolygonArea(slice.p_in_box), want, 1e-4 * std::max(1.0, want))
          << "trial " << trial;
    }
  }
  // Random planes straight through ClipPlaneToUnitBox, including misses.
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const glm::vec3 n(u(rng), u(rng), u(rng));
    const float d = 1.5f * u(rng);
    const auto poly = ClipPlaneToUnitBox(n, d);
    const double want = Area(ReferenceCrossSection(glm::dvec3(n), d));
    hits += !poly.empty();
    EXPECT_NEAR(PolygonArea(poly), want, 1e-4) << n.x << " " << n.y << " " << n.z << " " << d;
    // Counter-clockwise around +n.
    if (poly.size() >= 3) {
      glm::vec3 twice(0);
      for (size_t i = 1; i + 1 < poly.size(); ++i)
        twice += glm::cross(poly[i] - poly[0], poly[i + 1] - poly[0]);
      EXPECT_GT(glm::dot(twice, n), 0);
    }
  }
  EXPECT_GT(hits, 500);
}

TEST(Slicing, PlaneAlongABoxFaceAndThroughACornerAreExact) {
  EXPECT_NEAR(PolygonArea(ClipPlaneToUnitBox({0, 0, 1}, 0)), 1.0f, 1e-6f);
  EXPECT_NEAR(PolygonArea(ClipPlaneToUnitBox({0, 0, 1}, 1)), 1.0f, 1e-6f);
  // The regular hexagon through the centre, normal (1,1,1): area 3 sqrt(3) / 4.
  const auto hexagon = ClipPlaneToUnitBox({1, 1, 1}, 1.5f);
  EXPECT_EQ(hexagon.size(), 6u);
  EXPECT_NEAR(PolygonArea(hexagon), 3 * std::sqrt(3.0f) / 4, 1e-5f);
  // Touching a single corner is no polygon.
  EXPECT_TRUE(ClipPlaneToUnitBox({1, 1, 1}, 3.0f).empty());
  EXPECT_TRUE(ClipPlaneToUnitBox({1, 1, 1}, 0.0f).empty());
  EXPECT_TRUE(ClipPlaneToUnitBox({0, 0, 0}, 0.5f).empty());
}

TEST(Slicing, HalfSpaceClipCutsTheBoxQuadToATriangle) {
  const std::vector<glm::vec3> quad = {{0, 0, 0.5f}, {1, 0, 0.5f}, {1, 1, 0.5f}, {0, 1, 0.5f}};
  const auto triangle = ClipPolygonToHalfSpace(quad, {1, 1, 0}, 1.0f);
  EXPECT_NEAR(PolygonArea(triangle), 0.5f, 1e-6f);
  for (const auto& p : triangle) EXPECT_LE(p.x + p.y, 1.0f + 1e-6f);
  EXPECT_TRUE(ClipPolygonToHalfSpace(quad, {1, 1, 0}, -0.5f).empty());
  EXPECT_NEAR(PolygonArea(ClipPolygonToHalfSpace(quad, {1, 1, 0}, 5.0f)), 1.0f, 1e-6f);
}

TEST(Slicing, OrthogonalAxisIsTheOneMostParallelToTheView) {
  const SliceBox unit{};
  for (int k = 0; k < 3; ++k) {
    for (float sign : {-1.0f, 1.0f}) {
      glm::vec3 dir(0);
      dir[k] = sign;
      const glm::vec3 up = k == 2 ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1);
      const SliceView view{
          core::CamFromWorldLookAt(glm::vec3(0.5f) - 4.0f * dir, glm::vec3(0.5f), up), false};
      EXPECT_EQ(ChooseOrthogonalAxis(unit, view), k);
    }
  }
  // Exact ties go to the lowest axis: (1,1,1) ties all three, (0,1,1) ties y and z.
  const SliceView diagonal{core::CamFromWorldLookAt({3.5f, 3.5f, 3.5f}, glm::vec3(0.5f), {0, 0, 1}),
                           true};
  EXPECT_EQ(ChooseOrthogonalAxis(unit, diagonal), 0);
  const SliceView yz{core::CamFromWorldLookAt({0.5f, -2.5f, -2.5f}, glm::vec3(0.5f), {1, 0, 0}),
                     true};
  EXPECT_EQ(ChooseOrthogonalAxis(unit, yz), 1);
  // A box stretched 4x along x: its x planes are as far apart in world but the
  // planes' normals are what counts, so a view 30 degrees off x still picks x.
  const SliceBox stretched{glm::scale(glm::mat4(1.0f), glm::vec3(4, 1, 1))};
  const glm::vec3 c(2, 0.5f, 0.5f);
  const glm::vec3 dir(std::cos(0.5236f), std::sin(0.5236f), 0);
  const SliceView view{core::CamFromWorldLookAt(c - 10.0f * dir, c, {0, 0, 1}), true};
  EXPECT_EQ(ChooseOrthogonalAxis(stretched, view), 0);
}

// Ray (box coordinates) against a convex planar polygon; t or -1.
double HitT(const std::vector<glm::vec3>& poly, glm::dvec3 o, glm::dvec3 d) {
  const glm::dvec3 p0(poly[0]);
  glm::dvec3 n(0);
  for (size_t i = 1; i + 1 < poly.size(); ++i)
    n += glm::cross(glm::dvec3(poly[i]) - p0, glm::dvec3(poly[i + 1]) - p0);
  const double denom = glm::dot(n, d);
  if (std::abs(denom) < 1e-12) return -1;
  const double t = glm::dot(n, p0 - o) / denom;
  if (t <= 0) return -1;
  const glm::dvec3 x = o + t * d;
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 a(poly[i]), b(poly[(i + 1) % poly.size()]);
    if (glm::dot(glm::cross(b - a, x - a), n) < -1e-12) return -1;
  }
  return t;
}

void ExpectOrderAlongRays(const SliceBox& box, const SliceView& view, SliceFamily family,
                          SliceOrder order, std::mt19937& rng) {
  SlicingOptions options;
  options.family = family;
  options.count = 24;
  options.order = order;
  const SliceStack stack = MakeSlices(box, view, options);
  const glm::mat4 box_from_world = glm::inverse(box.world_from_box);
  const glm::mat4 world_from_cam = glm::inverse(view.cam_from_world);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  int checked = 0;
  for (int ray = 0; ray < 200; ++ray) {
    // Through a random point of the box, from the eye (or along camera z).
    const glm::dvec3 target(u(rng), u(rng), u(rng));
    glm::dvec3 origin, dir;
    if (view.orthographic) {
      dir =
          glm::dvec3(glm::mat3(box_from_world) * glm::vec3(world_from_cam * glm::vec4(0, 0, 1, 0)));
      origin = target - 100.0 * dir;
    } else {
      origin = glm::dvec3(box_from_world * (world_from_cam * glm::vec4(0, 0, 0, 1)));
      dir = target - origin;
    }
    double last = order == SliceOrder::kFrontToBack ? -1 : 1e30;
    int hits = 0;
    for (const Slice& slice : stack.slices) {
      const double t = HitT(slice.p_in_box, origin, dir);
      if (t < 0) continue;
      ++hits;
      if (order == SliceOrder::kFrontToBack) {
        EXPECT_GT(t, last) << "ray " << ray;
      } else {
        EXPECT_LT(t, last) << "ray " << ray;
      }
      last = t;
    }
    checked += hits > 1;
  }
  EXPECT_GT(checked, 100);
}

TEST(Slicing, SlicesAreOrderedAlongEveryRay) {
  std::mt19937 rng(11);
  for (SliceFamily family :
       {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
    for (SliceOrder order : {SliceOrder::kFrontToBack, SliceOrder::kBackToFront}) {
      for (int trial = 0; trial < 6; ++trial) {
        const SliceBox box = RandomBox(rng);
        ExpectOrderAlongRays(box, RandomView(rng, box, false, 5.0f), family, order, rng);
        ExpectOrderAlongRays(box, RandomView(rng, box, true, 5.0f), family, order, rng);
      }
    }
  }
}

TEST(Slicing, EyeInsideTheBoxKeepsEveryRayOrdered) {
  std::mt19937 rng(12);
  const SliceBox box{glm::scale(glm::mat4(1.0f), glm::vec3(2, 3, 1.5f))};
  for (SliceFamily family : {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal}) {
    // Eye at box (0.3, 0.6, 0.45), looking at random directions.
    const glm::vec3 eye = glm::vec3(box.world_from_box * glm::vec4(0.3f, 0.6f, 0.45f, 1.0f));
    for (const glm::vec3 look :
         {glm::vec3(1, 0.2f, 0.1f), glm::vec3(-0.3f, 1, -0.5f), glm::vec3(0.1f, 0.1f, -1)}) {
      const SliceView view{core::CamFromWorldLookAt(eye, eye + look, glm::vec3(0.3f, 0.2f, 1)),
                           false};
      ExpectOrderAlongRays(box, view, family, SliceOrder::kFrontToBack, rng);
    }
  }
}

TEST(Slicing, CountRules) {
  EXPECT_EQ(SliceCountForSpacing(1.0f, 0.1f), 10);
  EXPECT_EQ(SliceCountForSpacing(1.0f, 0.3f), 4);
  EXPECT_EQ(SliceCountForSpacing(1e-9f, 1.0f), 1);
  EXPECT_THROW(SliceCountForSpacing(1.0f, 0.0f), core::InputError);
  EXPECT_THROW(SliceCountForSpacing(-1.0f, 0.1f), core::InputError);
  // Sec. 3.4: edge 2, displacement 0.5 -> 4 times the slices.
  EXPECT_EQ(OrthogonalSliceCount(16, 2.0f, 0.5f), 64);
  EXPECT_THROW(OrthogonalSliceCount(0, 2.0f, 0.5f), core::InputError);
  // A unit cube face-on in an orthographic view at 100 px per unit: the
  // longest projected corner distance is the face diagonal, 100 sqrt 2 px.
  const SliceBox unit{};
  const SliceView view{core::CamFromWorldLookAt({0.5f, 0.5f, -5}, {0.5f, 0.5f, 0.5f}, {0, -1, 0}),
                       true};
  const glm::mat4 clip = core::ClipFromCamOrthographic(100, 100, 200, 200, 400, 400, 0.1, 20);
  EXPECT_EQ(ScreenSliceCount(unit, view, clip, 400, 400),
            static_cast<int>(std::ceil(100 * std::sqrt(2.0))));
}

TEST(Slicing, SpacingAndPlanePositions) {
  const SliceBox box{glm::scale(glm::mat4(1.0f), glm::vec3(2, 2, 0.25f))};
  const SliceView top{core::CamFromWorldLookAt({1, 1, 5}, {1, 1, 0}, {0, 1, 0}), true};
  for (int count : {1, 7, 4096}) {
    SlicingOptions options;
    options.family = SliceFamily::kSurfaceAligned;
    options.count = count;
    const SliceStack stack = MakeSlices(box, top, options);
    ASSERT_EQ(static_cast<int>(stack.slices.size()), count);
    EXPECT_EQ(stack.axis, 2);
    EXPECT_FLOAT_EQ(stack.spacing_world, 0.25f / count);
    // Front to back from above: the top slice first, at (n - 0.5) / n.
    EXPECT_FLOAT_EQ(stack.slices.front().p_in_box[0].z, (count - 0.5f) / count);
    EXPECT_FLOAT_EQ(stack.slices.back().p_in_box[0].z, 0.5f / count);
    for (const Slice& s : stack.slices) {
      EXPECT_EQ(s.p_in_box.size(), 4u);
      EXPECT_NEAR(PolygonArea(s.p_in_box), 1.0f, 1e-6f);
    }
  }
  SlicingOptions bad;
  bad.count = 0;
  EXPECT_THROW(bad.Check(), core::InputError);
}

TEST(Slicing, DegenerateViewsGiveFiniteSlices) {
  const SliceBox box{glm::scale(glm::mat4(1.0f), glm::vec3(2, 2, 0.25f))};
  // Exactly along a box axis, and exactly in the base plane (z = 0.125, the
  // box's mid height), orthographic and perspective.
  const std::vector<SliceView> views = {
      {core::CamFromWorldLookAt({1, 1, 5}, {1, 1, 0.125f}, {0, 1, 0}), true},
      {core::CamFromWorldLookAt({1, 1, 5}, {1, 1, 0.125f}, {0, 1, 0}), false},
      {core::CamFromWorldLookAt({1, -5, 0.125f}, {1, 1, 0.125f}, {0, 0, 1}), true},
      {core::CamFromWorldLookAt({1, -5, 0.125f}, {1, 1, 0.125f}, {0, 0, 1}), false},
      {core::CamFromWorldLookAt({1, -5, 0.0f}, {1, 1, 0.0f}, {0, 0, 1}), false}};
  for (const SliceView& view : views) {
    for (SliceFamily family :
         {SliceFamily::kSurfaceAligned, SliceFamily::kOrthogonal, SliceFamily::kScreen}) {
      for (bool full : {false, true}) {
        SlicingOptions options;
        options.family = family;
        options.count = 33;
        options.full_size_screen_slices = full;
        const SliceStack stack = MakeSlices(box, view, options);
        EXPECT_FALSE(stack.slices.empty());
        EXPECT_TRUE(std::isfinite(stack.spacing_world));
        for (const Slice& s : stack.slices) {
          for (const glm::vec3& p : s.p_in_box) {
            ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
          }
        }
        if (family == SliceFamily::kScreen && !full) {
          // Along an axis the cross-sections are the box's face: area 1 each.
          if (&view == &views[0]) {
            for (const Slice& s : stack.slices) EXPECT_NEAR(PolygonArea(s.p_in_box), 1.0f, 1e-5f);
          }
        }
      }
    }
  }
}

TEST(Slicing, FullSizeScreenSlicesContainTheExactOnes) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const SliceBox box = RandomBox(rng);
    const SliceView view = RandomView(rng, box, trial % 2 == 0, 6.0f);
    SlicingOptions options;
    options.family = SliceFamily::kScreen;
    options.count = 8;
    const SliceStack exact = MakeSlices(box, view, options);
    options.full_size_screen_slices = true;
    const SliceStack full = MakeSlices(box, view, options);
    ASSERT_EQ(full.slices.size(), 8u);
    ASSERT_EQ(exact.slices.size(), 8u);  // no plane grazes a corner for these random boxes
    for (size_t i = 0; i < full.slices.size(); ++i) {
      EXPECT_NEAR(full.slices[i].offset_in_box, exact.slices[i].offset_in_box, 1e-4f);
      EXPECT_GE(PolygonArea(full.slices[i].p_in_box),
                PolygonArea(exact.slices[i].p_in_box) * (1 - 1e-4f));
      for (const glm::vec3& p : full.slices[i].p_in_box) {
        EXPECT_NEAR(glm::dot(full.normal_in_box, p), full.slices[i].offset_in_box,
                    1e-3f * std::max(1.0f, glm::length(p)));
      }
    }
  }
}

// ---- a slice split by a box (the volume pass's support box) ----

// Whether q lies in the convex polygon (any orientation, plane normal n),
// more than `margin` inside every edge.
bool InsideConvex(const std::vector<glm::vec3>& poly, const glm::vec3& n, const glm::vec3& q,
                  float margin) {
  int sign = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::vec3 a = poly[i], b = poly[(i + 1) % poly.size()];
    if (glm::length(b - a) < 1e-9f) continue;
    const float side = glm::dot(glm::cross(b - a, q - a), n) / glm::length(b - a);
    if (std::abs(side) <= margin) return false;
    const int s = side > 0 ? 1 : -1;
    if (sign != 0 && s != sign) return false;
    sign = s;
  }
  return true;
}

float DistanceToSegment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, float* t) {
  const glm::vec3 ab = b - a;
  *t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
  return glm::length(p - (a + *t * ab));
}

// No T-junction: no vertex of one part lies inside an edge of another (it
// must be that edge's end point, bit for bit, or further than `tolerance`
// from it).
template <typename V>
void ExpectNoTJunctions(const std::vector<std::vector<V>>& parts, float tolerance, int trial) {
  for (size_t i = 0; i < parts.size(); ++i)
    for (size_t j = 0; j < parts.size(); ++j) {
      if (i == j) continue;
      for (size_t k = 0; k < parts[i].size(); ++k) {
        const V a = parts[i][k], b = parts[i][(k + 1) % parts[i].size()];
        for (const V& v : parts[j]) {
          if (v == a || v == b) continue;
          float t = 0;
          const float d = DistanceToSegment(glm::vec3(v), glm::vec3(a), glm::vec3(b), &t);
          EXPECT_FALSE(d < tolerance && t > 0 && t < 1)
              << "trial " << trial << ": a vertex of part " << j << " inside an edge of part " << i;
        }
      }
    }
}

TEST(Slicing, PolygonSplitByABoxTilesThePolygonWithoutTJunctions) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 1), w(-0.3f, 1.3f), dir(-1, 1);
  int split_cases = 0, inside_cases = 0, snapped_cases = 0;
  for (int trial = 0; trial < 400; ++trial) {
    // A plane through the unit box (every 5th parallel to a box face, as a
    // screen slice of an axis-aligned view).
    glm::vec3 n = glm::normalize(glm::vec3(dir(rng), dir(rng), dir(rng)) + glm::vec3(1e-3f));
    if (trial % 5 == 0) n = glm::vec3(0, 0, 0), n[trial % 3] = 1;
    const glm::vec3 c(u(rng), u(rng), u(rng));
    const std::vector<glm::vec3> polygon = ClipPlaneToUnitBox(n, glm::dot(n, c));
    if (polygon.size() < 3) continue;
    glm::vec3 lo(w(rng), w(rng), w(rng)), hi(w(rng), w(rng), w(rng));
    for (int a = 0; a < 3; ++a) {
      if (lo[a] > hi[a]) std::swap(lo[a], hi[a]);
    }
    if (trial % 7 == 0) {  // a box face through a polygon vertex
      lo.x = polygon[0].x;
      ++snapped_cases;
    }
    if (trial % 11 == 0 && trial % 5 == 0) lo.z = hi.z = polygon[0].z;  // a face on the plane
    // The box's tree (inside 1, outside 0), as the volume pass splits slices
    // at its support box.
    std::vector<glm::vec3> inside;
    std::vector<std::vector<glm::vec3>> parts;
    size_t outside_parts = 0;
    for (const LabelledPolygon& part :
         PartitionPolygon(std::vector<glm::dvec3>(polygon.begin(), polygon.end()),
                          BoxTreeOfBox(lo, hi, 1, 0), 1e-6)) {
      parts.emplace_back(part.polygon.begin(), part.polygon.end());
      if (part.label == 1) {
        ASSERT_TRUE(inside.empty()) << trial;
        inside = parts.back();
      } else {
        ++outside_parts;
      }
    }
    inside_cases += !inside.empty();
    split_cases += parts.size() > 1;
    ASSERT_LE(outside_parts, 6u);
    // 1. The parts' areas add up to the polygon's; the inside part's is the
    //    clip of the polygon by the box's six half-spaces.
    const float area = PolygonArea(polygon);
    float sum = 0;
    for (const auto& part : parts) sum += PolygonArea(part);
    EXPECT_NEAR(sum, area, 1e-4f * area + 1e-6f) << trial;
    std::vector<glm::vec3> clipped = polygon;
    for (int a = 0; a < 3 && !clipped.empty(); ++a) {
      glm::vec3 e(0.0f);
      e[a] = 1;
      clipped = ClipPolygonToHalfSpace(clipped, -e, -lo[a]);
      if (!clipped.empty()) clipped = ClipPolygonToHalfSpace(clipped, e, hi[a]);
    }
    const float inside_area = inside.empty() ? 0 : PolygonArea(inside);
    const float clipped_area = clipped.empty() ? 0 : PolygonArea(clipped);
    EXPECT_NEAR(inside_area, clipped_area, 1e-4f * area + 2e-6f) << trial;
    // 2. Every vertex lies on the plane; the inside part in the box.
    for (const auto& part : parts) {
      EXPECT_GE(part.size(), 3u);
      for (const glm::vec3& v : part) EXPECT_NEAR(glm::dot(n, v), glm::dot(n, c), 1e-5f);
    }
    for (const glm::vec3& v : inside) {
      EXPECT_TRUE(glm::all(glm::greaterThanEqual(v, lo - 2e-6f)) &&
                  glm::all(glm::lessThanEqual(v, hi + 2e-6f)))
          << trial;
    }
    // 3. No T-junction.
    ExpectNoTJunctions(parts, 1e-5f, trial);
    // 4. Random points of the polygon away from every edge lie in exactly one
    //    part, the inside one iff in the box.
    for (int q = 0; q < 50; ++q) {
      glm::vec3 p(0.0f);
      float total = 0;
      for (const glm::vec3& v : polygon) {
        const float weight = u(rng);
        p += weight * v;
        total += weight;
      }
      p /= total;
      int in_parts = 0, margin_hits = 0;
      for (const auto& part : parts) {
        in_parts += InsideConvex(part, n, p, 1e-4f);
        margin_hits += InsideConvex(part, n, p, -1e-4f) && !InsideConvex(part, n, p, 1e-4f);
      }
      if (margin_hits > 0) continue;  // on an edge: a tie
      EXPECT_EQ(in_parts, 1) << trial;
      if (!inside.empty() && InsideConvex(inside, n, p, 1e-4f)) {
        EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, lo - 1e-5f)) &&
                    glm::all(glm::lessThanEqual(p, hi + 1e-5f)));
      }
    }
  }
  EXPECT_GT(split_cases, 100);
  EXPECT_GT(inside_cases, 50);
  EXPECT_GT(snapped_cases, 20);
}

// ---- a slice partitioned by a kd-tree of labelled grid cells (the volume pass's bricks) ----

// The label of the grid cell holding p (background outside the grid), by
// search of the edges: independent of the tree.
int GridLabel(const glm::ivec3& grid, const std::vector<uint8_t>& labels,
              const std::array<std::vector<double>, 3>& edges, int background,
              const glm::dvec3& p) {
  glm::ivec3 cell;
  for (int a = 0; a < 3; ++a) {
    if (p[a] < edges[a].front() || p[a] > edges[a].back()) return background;
    cell[a] = static_cast<int>(std::upper_bound(edges[a].begin(), edges[a].end(), p[a]) -
                               edges[a].begin()) -
              1;
    cell[a] = std::min(cell[a], grid[a] - 1);
  }
  return labels[(static_cast<size_t>(cell.z) * grid.y + cell.y) * grid.x + cell.x];
}

TEST(Slicing, BoxTreeOfGridLabelsEveryPointAsItsCell) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 60; ++trial) {
    const glm::ivec3 grid(1 + trial % 7, 1 + (trial / 2) % 5, 1 + (trial / 3) % 6);
    std::array<std::vector<double>, 3> edges;
    for (int a = 0; a < 3; ++a) {
      double x = -0.2 + 0.2 * u(rng);
      for (int i = 0; i <= grid[a]; ++i) edges[a].push_back(x), x += 0.05 + 0.3 * u(rng);
    }
    // Blocks of labels (0 the background, most common), some cells noise.
    std::vector<uint8_t> labels(static_cast<size_t>(grid.x) * grid.y * grid.z);
    const glm::dvec3 c(u(rng) * grid.x, u(rng) * grid.y, u(rng) * grid.z);
    for (int z = 0; z < grid.z; ++z)
      for (int y = 0; y < grid.y; ++y)
        for (int x = 0; x < grid.x; ++x) {
          uint8_t l = glm::length(glm::dvec3(x, y, z) - c) < 2 ? 2 : 0;
          if (x > c.x + 1) l = 1;
          if (u(rng) < 0.1) l = static_cast<uint8_t>(rng() % 3);
          labels[(static_cast<size_t>(z) * grid.y + y) * grid.x + x] = l;
        }
    const BoxTree tree = BoxTreeOfGrid(grid, labels, edges, 0);
    EXPECT_LE(tree.Leaves(), static_cast<int>(labels.size()) + 6) << trial;
    for (int q = 0; q < 400; ++q) {
      const glm::dvec3 p(-0.5 + 3 * u(rng), -0.5 + 3 * u(rng), -0.5 + 3 * u(rng));
      EXPECT_EQ(tree.LabelAt(p), GridLabel(grid, labels, edges, 0, p)) << trial;
    }
  }
  // One label everywhere: one leaf, or the background's six around one.
  const glm::ivec3 grid(4, 4, 4);
  std::array<std::vector<double>, 3> edges;
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i <= 4; ++i) edges[a].push_back(0.25 * i);
  EXPECT_EQ(BoxTreeOfGrid(grid, std::vector<uint8_t>(64, 0), edges, 0).Leaves(), 1);
  EXPECT_EQ(BoxTreeOfGrid(grid, std::vector<uint8_t>(64, 3), edges, 0).Leaves(), 7);
}

TEST(Slicing, PolygonPartitionByABoxTreeTilesThePolygonWithoutTJunctions) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0, 1), dir(-1, 1);
  std::uniform_real_distribution<double> ud(0, 1);
  int many_parts = 0;
  size_t most_parts = 0;
  for (int trial = 0; trial < 300; ++trial) {
    glm::vec3 n = glm::normalize(glm::vec3(dir(rng), dir(rng), dir(rng)) + glm::vec3(1e-3f));
    if (trial % 5 == 0) n = glm::vec3(0, 0, 0), n[trial % 3] = 1;  // parallel to cell faces
    const glm::vec3 c(u(rng), u(rng), u(rng));
    const std::vector<glm::vec3> slice = ClipPlaneToUnitBox(n, glm::dot(n, c));
    if (slice.size() < 3) continue;
    const std::vector<glm::dvec3> polygon(slice.begin(), slice.end());
    // A random grid over (part of) the box, cell edges sometimes through a
    // polygon vertex or on the plane.
    const glm::ivec3 grid(2 + trial % 5, 2 + (trial / 5) % 4, 2 + (trial / 7) % 3);
    std::array<std::vector<double>, 3> edges;
    for (int a = 0; a < 3; ++a) {
      double x = -0.1 + 0.3 * ud(rng);
      for (int i = 0; i <= grid[a]; ++i) edges[a].push_back(x), x += 0.05 + 0.35 * ud(rng);
    }
    if (trial % 7 == 0) edges[0][1] = polygon[0].x;
    if (trial % 5 == 0 && trial % 3 == 2) edges[2][1] = polygon[0].z;  // a cell face on the plane
    for (int a = 0; a < 3; ++a) std::sort(edges[a].begin(), edges[a].end());
    std::vector<uint8_t> labels(static_cast<size_t>(grid.x) * grid.y * grid.z);
    for (auto& l : labels) l = static_cast<uint8_t>(rng() % 3);
    const BoxTree tree = BoxTreeOfGrid(grid, labels, edges, 0);
    const std::vector<LabelledPolygon> parts = PartitionPolygon(polygon, tree);
    many_parts += parts.size() > 4;
    most_parts = std::max(most_parts, parts.size());
    // 1. Areas add up; every part is a convex polygon on the plane.
    std::vector<std::vector<glm::vec3>> fparts;
    for (const auto& part : parts) fparts.emplace_back(part.polygon.begin(), part.polygon.end());
    const float area = PolygonArea(slice);
    float sum = 0;
    for (const auto& part : fparts) {
      ASSERT_GE(part.size(), 3u);
      sum += PolygonArea(part);
      for (const glm::vec3& v : part) EXPECT_NEAR(glm::dot(n, v), glm::dot(n, c), 1e-5f);
    }
    EXPECT_NEAR(sum, area, 1e-4f * area + 1e-6f) << trial;
    // 2. No T-junction.
    std::vector<std::vector<glm::dvec3>> dparts;
    for (const auto& part : parts) dparts.push_back(part.polygon);
    ExpectNoTJunctions(dparts, 1e-6f, trial);
    // 3. Random points of the polygon away from every edge lie in exactly one
    //    part, whose label is the grid's there.
    for (int q = 0; q < 60; ++q) {
      glm::vec3 p(0.0f);
      float total = 0;
      for (const glm::vec3& v : slice) {
        const float weight = u(rng);
        p += weight * v;
        total += weight;
      }
      p /= total;
      int in_parts = 0, margin_hits = 0, label = -1;
      for (size_t k = 0; k < fparts.size(); ++k) {
        if (InsideConvex(fparts[k], n, p, 1e-4f)) ++in_parts, label = parts[k].label;
        margin_hits +=
            InsideConvex(fparts[k], n, p, -1e-4f) && !InsideConvex(fparts[k], n, p, 1e-4f);
      }
      if (margin_hits > 0) continue;  // on an edge: a tie
      EXPECT_EQ(in_parts, 1) << trial;
      // On a cell face (the plane lying in one): a tie, either side's label.
      bool on_face = false;
      for (int a = 0; a < 3; ++a)
        for (double e : edges[a]) on_face = on_face || std::abs(p[a] - e) < 1e-5;
      if (!on_face) {
        EXPECT_EQ(label, GridLabel(grid, labels, edges, 0, glm::dvec3(p))) << trial;
      }
    }
  }
  std::printf("partition: %d of 300 slices in more than 4 parts, at most %zu parts\n", many_parts,
              most_parts);
  EXPECT_GT(many_parts, 100);
}

TEST(Slicing, CentroidFanCoversAPolygonWithCollinearVertices) {
  // A square with a vertex in the middle of each edge, one of them 1e-7
  // outside, one 1e-7 inside: a fan from its first vertex would hold
  // zero-area triangles of either orientation.
  const std::vector<glm::vec3> square = {{0, 0, 0}, {0.5f, -1e-7f, 0},    {1, 0, 0}, {1, 0.5f, 0},
                                         {1, 1, 0}, {0.5f, 1 - 1e-7f, 0}, {0, 1, 0}, {0, 0.5f, 0}};
  const std::vector<glm::vec3> fan = CentroidFan(square);
  ASSERT_EQ(fan.size(), square.size() + 2);
  EXPECT_EQ(fan[1], square[0]);
  EXPECT_EQ(fan.back(), square[0]);
  float sum = 0;
  for (size_t i = 1; i + 1 < fan.size(); ++i) {
    const float signed_area = 0.5f * glm::cross(fan[i] - fan[0], fan[i + 1] - fan[0]).z;
    EXPECT_GT(signed_area, 0.1f) << i;  // every triangle the same way round
    sum += signed_area;
  }
  EXPECT_NEAR(sum, 1.0f, 1e-5f);
}

}  // namespace
}  // namespace render
