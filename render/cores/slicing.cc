#include "render/cores/slicing.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/error.h"

namespace render {

SliceFamily SliceFamilyFromName(const std::string& name) {
  if (name == "surface" || name == "surface-aligned") return SliceFamily::kSurfaceAligned;
  if (name == "orthogonal") return SliceFamily::kOrthogonal;
  if (name == "screen") return SliceFamily::kScreen;
  core::ThrowInputError("SliceFamilyFromName",
                        "unknown slicing family '{}' (surface, orthogonal, screen)", name);
}

std::string SliceFamilyName(SliceFamily family) {
  switch (family) {
    case SliceFamily::kSurfaceAligned:
      return "surface";
    case SliceFamily::kOrthogonal:
      return "orthogonal";
    case SliceFamily::kScreen:
      return "screen";
  }
  return "unknown";
}

void SlicingOptions::Check() const {
  // 16384 slices at 1 px each is already far beyond any viewport's depth extent.
  if (count < 1 || count > 16384) {
    core::ThrowInputError("SlicingOptions", "slice count {} outside 1..16384", count);
  }
}

namespace {

struct ViewFrame {
  glm::vec3 eye_world{0};         // perspective centre (unused for orthographic)
  glm::vec3 axis_world{0, 0, 1};  // camera +z in the world
};

ViewFrame FrameOf(const SliceView& view) {
  const glm::mat3 r(view.cam_from_world);
  const glm::vec3 t(view.cam_from_world[3]);
  ViewFrame f;
  f.axis_world = glm::transpose(r) * glm::vec3(0, 0, 1);
  f.eye_world = -(glm::transpose(r) * t);
  return f;
}

// Direction the viewer looks at the box (unit, world), robust for an eye at
// the box centre (falls back to the camera axis).
glm::vec3 ViewDirectionToBox(const SliceBox& box, const SliceView& view) {
  const ViewFrame f = FrameOf(view);
  if (view.orthographic) return f.axis_world;
  const glm::vec3 centre = glm::vec3(box.world_from_box * glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  const glm::vec3 d = centre - f.eye_world;
  const float len = glm::length(d);
  return len > 1e-12f ? d / len : f.axis_world;
}

// Gradient of box coordinate k with respect to world position.
glm::vec3 BoxAxisGradientWorld(const SliceBox& box, int k) {
  const glm::mat3 inv = glm::inverse(glm::mat3(box.world_from_box));
  return glm::vec3(inv[0][k], inv[1][k], inv[2][k]);  // row k of the inverse
}

glm::vec3 EyeInBox(const SliceBox& box, const SliceView& view) {
  return glm::vec3(glm::inverse(box.world_from_box) * glm::vec4(FrameOf(view).eye_world, 1.0f));
}

glm::vec3 DirectionInBox(const SliceBox& box, glm::vec3 d_world) {
  return glm::inverse(glm::mat3(box.world_from_box)) * d_world;
}

// A planar quad for axis-aligned slices, CCW around `toward_viewer`.
std::vector<glm::vec3> AxisQuad(int axis, float c, float sign_toward_viewer) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis
  std::vector<glm::vec3> quad(4, glm::vec3(c));
  const float corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 4; ++i) {
    quad[i][u] = corners[i][0];
    quad[i][v] = corners[i][1];
  }
  if (sign_toward_viewer < 0) std::reverse(quad.begin(), quad.end());
  return quad;
}

}  // namespace

int ChooseOrthogonalAxis(const SliceBox& box, const SliceView& view) {
  const glm::vec3 d = ViewDirectionToBox(box, view);
  int best = 0;
  float best_score = -1;
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 g = BoxAxisGradientWorld(box, k);
    const float len = glm::length(g);
    const float score = len > 0 ? std::abs(glm::dot(g / len, d)) : 0.0f;
    // Near-ties (1e-6) keep the lower axis, so the choice is deterministic.
    if (score > best_score + 1e-6f) {
      best_score = score;
      best = k;
    }
  }
  return best;
}

std::vector<glm::vec3> ClipPlaneToUnitBox(glm::vec3 n, float d) {
  std::vector<glm::vec3> points;
  if (!(glm::dot(n, n) > 0) || !std::isfinite(d)) return points;
  const glm::vec3 corner[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                            {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  auto add = [&](glm::vec3 p) {
    for (const auto& q : points) {
      if (glm::length(q - p) < 1e-6f) return;
    }
    points.push_back(p);
  };
  for (const auto& e : edges) {
    const glm::vec3 a = corner[e[0]], b = corner[e[1]];
    const float sa = glm::dot(n, a) - d, sb = glm::dot(n, b) - d;
    if (sa == 0) add(a);
    if (sb == 0) add(b);
    if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) add(a + (b - a) * (sa / (sa - sb)));
  }
  if (points.size() < 3) return {};
  glm::vec3 centre(0);
  for (const auto& p : points) centre += p;
  centre /= static_cast<float>(points.size());
  const glm::vec3 nn = glm::normalize(n);
  const glm::vec3 helper = std::abs(nn.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::vec3 u = glm::normalize(glm::cross(helper, nn));
  const glm::vec3 v = glm::cross(nn, u);
  std::sort(points.begin(), points.end(), [&](const glm::vec3& a, const glm::vec3& b) {
    return std::atan2(glm::dot(a - centre, v), glm::dot(a - centre, u)) <
           std::atan2(glm::dot(b - centre, v), glm::dot(b - centre, u));
  });
  return points;
}

std::vector<glm::vec3> ClipPolygonToHalfSpace(const std::vector<glm::vec3>& polygon, glm::vec3 n,
                                              float d) {
  std::vector<glm::vec3> out;
  const size_t count = polygon.size();
  for (size_t i = 0; i < count; ++i) {
    const glm::vec3 a = polygon[i], b = polygon[(i + 1) % count];
    const float sa = glm::dot(n, a) - d, sb = glm::dot(n, b) - d;
    if (sa <= 0) out.push_back(a);
    if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) out.push_back(a + (b - a) * (sa / (sa - sb)));
  }
  if (out.size() < 3) return {};
  return out;
}

PolygonBoxSplit SplitPolygonByBox(const std::vector<glm::vec3>& polygon, const glm::vec3& lo,
                                  const glm::vec3& hi) {
  constexpr float kOnPlane = 1e-6f;
  PolygonBoxSplit split;
  std::vector<glm::vec3> rest = polygon;  // what is still inside every plane so far
  for (int plane = 0; plane < 6 && !rest.empty(); ++plane) {
    const int axis = plane / 2;
    const bool upper = (plane % 2) == 1;
    const float value = upper ? hi[axis] : lo[axis];
    // s > 0: outside this plane.
    std::vector<float> s(rest.size());
    bool any_out = false, any_in = false;
    for (size_t i = 0; i < rest.size(); ++i) {
      s[i] = upper ? rest[i][axis] - value : value - rest[i][axis];
      if (std::abs(s[i]) <= kOnPlane) s[i] = 0;
      any_out = any_out || s[i] > 0;
      any_in = any_in || s[i] < 0;
    }
    if (!any_out) continue;  // wholly inside (or on) this plane
    if (!any_in) {
      split.outside.push_back(std::move(rest));
      rest.clear();
      break;
    }
    std::vector<glm::vec3> in, out;
    const size_t n = rest.size();
    for (size_t i = 0; i < n; ++i) {
      const glm::vec3 a = rest[i], b = rest[(i + 1) % n];
      const float sa = s[i], sb = s[(i + 1) % n];
      if (sa <= 0) in.push_back(a);
      if (sa >= 0) out.push_back(a);
      if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) {
        glm::vec3 v = a + (b - a) * (sa / (sa - sb));
        v[axis] = value;  // exactly on the plane
        in.push_back(v);
        out.push_back(v);
        // An earlier outside part sharing the edge a-b gets v too.
        for (auto& part : split.outside) {
          for (size_t j = 0; j < part.size(); ++j) {
            const glm::vec3& p = part[j];
            const glm::vec3& q = part[(j + 1) % part.size()];
            if ((p == a && q == b) || (p == b && q == a)) {
              part.insert(part.begin() + static_cast<std::ptrdiff_t>(j + 1), v);
              break;
            }
          }
        }
      }
    }
    split.outside.push_back(std::move(out));
    rest = std::move(in);
  }
  split.inside = std::move(rest);
  return split;
}

std::vector<glm::vec3> CentroidFan(const std::vector<glm::vec3>& polygon) {
  glm::vec3 mean(0.0f);
  for (const glm::vec3& v : polygon) mean += v;
  mean /= static_cast<float>(polygon.size());
  std::vector<glm::vec3> fan = {mean};
  fan.insert(fan.end(), polygon.begin(), polygon.end());
  fan.push_back(polygon.front());
  return fan;
}

float PolygonArea(const std::vector<glm::vec3>& polygon) {
  glm::vec3 twice_area(0);
  for (size_t i = 1; i + 1 < polygon.size(); ++i) {
    twice_area += glm::cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
  }
  return 0.5f * glm::length(twice_area);
}

SliceStack MakeSlices(const SliceBox& box, const SliceView& view, const SlicingOptions& options) {
  options.Check();
  IBR_CHECK(std::abs(glm::determinant(glm::mat3(box.world_from_box))) > 0);
  SliceStack stack;
  stack.family = options.family;
  const int n = options.count;
  const glm::vec3 d_world = ViewDirectionToBox(box, view);

  if (options.family != SliceFamily::kScreen) {
    const int axis =
        options.family == SliceFamily::kSurfaceAligned ? 2 : ChooseOrthogonalAxis(box, view);
    stack.axis = axis;
    stack.spacing_in_box = 1.0f / n;
    stack.spacing_world = stack.spacing_in_box / glm::length(BoxAxisGradientWorld(box, axis));
    // Order key: how far along the view a plane c is. Orthographic: c times the
    // view direction's sign along the axis. Perspective: |c - eye| (planes on
    // the eye's side first; valid for every ray, also with the eye inside).
    const glm::vec3 eye = EyeInBox(box, view);
    const float dir_k = DirectionInBox(box, d_world)[axis];
    std::vector<float> planes(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) planes[k] = (k + 0.5f) / n;
    auto key = [&](float c) {
      if (view.orthographic) return dir_k >= 0 ? c : -c;
      return std::abs(c - eye[axis]);
    };
    std::stable_sort(planes.begin(), planes.end(),
                     [&](float a, float b) { return key(a) < key(b); });
    if (options.order == SliceOrder::kBackToFront) std::reverse(planes.begin(), planes.end());
    // The viewer is on the side the view direction comes from.
    const float toward = dir_k >= 0 ? -1.0f : 1.0f;
    stack.normal_in_box = glm::vec3(0);
    stack.normal_in_box[axis] = toward;
    for (float c : planes) {
      const float sign = view.orthographic ? toward : (eye[axis] >= c ? 1.0f : -1.0f);
      stack.slices.push_back({AxisQuad(axis, c, sign), toward * c});
    }
    return stack;
  }

  // Screen-space: planes camera z = const. In box coordinates camera z is
  // dot(g, p) + g0 with g = row 2 of (cam_from_world * world_from_box).
  stack.axis = -1;
  const glm::mat4 cam_from_box = view.cam_from_world * box.world_from_box;
  const glm::vec3 g(cam_from_box[0][2], cam_from_box[1][2], cam_from_box[2][2]);
  const float g0 = cam_from_box[3][2];
  float zmin = INFINITY, zmax = -INFINITY;
  std::vector<glm::vec3> corners_cam;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    const glm::vec3 p = glm::vec3(cam_from_box * glm::vec4(c, 1.0f));
    corners_cam.push_back(p);
    zmin = std::min(zmin, p.z);
    zmax = std::max(zmax, p.z);
  }
  // Perspective: slices at or behind the eye can never be seen.
  if (!view.orthographic) zmin = std::max(zmin, 0.0f);
  const float range = std::max(zmax - zmin, 0.0f);
  stack.spacing_world = range / n;
  stack.normal_in_box = -g;  // toward the viewer: camera z decreases
  const glm::mat4 box_from_cam = glm::inverse(cam_from_box);
  // Full-size slices: the box's screen rectangle (orthographic: in camera x/y;
  // perspective: in x/z, y/z), placed at each plane's depth.
  glm::vec2 lo(INFINITY), hi(-INFINITY);
  for (const auto& p : corners_cam) {
    const glm::vec2 q = view.orthographic ? glm::vec2(p) : glm::vec2(p) / std::max(p.z, 1e-6f);
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  for (int k = 0; k < n; ++k) {
    const int i = options.order == SliceOrder::kFrontToBack ? k : n - 1 - k;
    const float z = zmin + (i + 0.5f) * range / n;
    Slice slice;
    slice.offset_in_box = -(z - g0);
    if (options.full_size_screen_slices) {
      const glm::vec2 rect[4] = {{lo.x, lo.y}, {lo.x, hi.y}, {hi.x, hi.y}, {hi.x, lo.y}};
      for (const auto& r : rect) {
        const glm::vec3 p_cam = view.orthographic ? glm::vec3(r, z) : glm::vec3(r * z, z);
        slice.p_in_box.push_back(glm::vec3(box_from_cam * glm::vec4(p_cam, 1.0f)));
      }
      // The rectangle is counter-clockwise around camera -z; a mirroring box
      // map flips that in box coordinates, where exact slices are CCW.
      if (glm::determinant(glm::mat3(cam_from_box)) < 0) {
        std::reverse(slice.p_in_box.begin(), slice.p_in_box.end());
      }
    } else {
      slice.p_in_box = ClipPlaneToUnitBox(-g, -(z - g0));
      if (slice.p_in_box.empty()) continue;  // the plane grazes a corner
    }
    stack.slices.push_back(std::move(slice));
  }
  return stack;
}

int SliceCountForSpacing(float extent_world, float spacing_world) {
  if (!(extent_world > 0) || !(spacing_world > 0) || !std::isfinite(extent_world / spacing_world)) {
    core::ThrowInputError("SliceCountForSpacing",
                          "extent {} / spacing {} must be positive and finite", extent_world,
                          spacing_world);
  }
  return std::clamp(static_cast<int>(std::ceil(extent_world / spacing_world)), 1, 16384);
}

int OrthogonalSliceCount(int count_surface_aligned, float edge_length, float max_displacement) {
  if (count_surface_aligned < 1 || !(edge_length > 0) || !(max_displacement > 0)) {
    core::ThrowInputError("OrthogonalSliceCount",
                          "need count >= 1, edge > 0, displacement > 0 "
                          "(got {}, {}, {})",
                          count_surface_aligned, edge_length, max_displacement);
  }
  const double count =
      std::ceil(static_cast<double>(count_surface_aligned) * edge_length / max_displacement);
  return static_cast<int>(std::clamp(count, 1.0, 16384.0));
}

int ScreenSliceCount(const SliceBox& box, const SliceView& view, const glm::mat4& clip_from_cam,
                     int viewport_width, int viewport_height) {
  const glm::mat4 clip_from_box = clip_from_cam * view.cam_from_world * box.world_from_box;
  glm::vec2 px[8];
  for (int i = 0; i < 8; ++i) {
    const glm::vec4 c = clip_from_box * glm::vec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0f);
    const float w = std::max(std::abs(c.w), 1e-6f);
    px[i] = glm::vec2(c.x / w * 0.5f * viewport_width, c.y / w * 0.5f * viewport_height);
  }
  float longest = 0;
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) longest = std::max(longest, glm::length(px[i] - px[j]));
  }
  return std::clamp(static_cast<int>(std::ceil(longest)), 1, 16384);
}

}  // namespace render
