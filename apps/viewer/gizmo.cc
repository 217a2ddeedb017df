#include "apps/viewer/gizmo.h"

#include <algorithm>
#include <cmath>

namespace viewer {
namespace {

// How far an axis handle reaches, in box units from the centre: past the
// face, so its end shows outside the box.
constexpr double kAxisReach = 0.75;
// Pixels of travel per degree (rotate) and per e-fold (scale).
constexpr double kDegreesPerPixel = 0.5;
constexpr double kScalePixels = 150;

constexpr uint32_t Rgba(uint32_t r, uint32_t g, uint32_t b, uint32_t a = 255) {
  return r | (g << 8) | (b << 16) | (a << 24);  // IM_COL32's packing
}
constexpr uint32_t kAxisColours[3] = {Rgba(235, 70, 70), Rgba(80, 220, 80), Rgba(80, 120, 255)};
constexpr uint32_t kEdgeColour = Rgba(230, 230, 230, 160);
constexpr uint32_t kKnifeColour = Rgba(255, 220, 40);
constexpr uint32_t kPeelColour = Rgba(255, 150, 40);

glm::dvec3 World(const GizmoBox& box, const glm::dvec3& u) {
  return glm::dvec3(box.world_from_norm * box.norm_from_box * glm::dvec4(u, 1.0));
}

// The flap's free edge at angle `a`: its far side turned about the hinge.
std::pair<glm::dvec3, glm::dvec3> PeelEdge(const GizmoBox& box, double a) {
  const double x = box.peel_hinge.x + box.peel_length * std::cos(a);
  const double z = box.peel_hinge.y + box.peel_length * std::sin(a);
  return {{x, 0, z}, {x, 1, z}};
}

// A handle's segment in box units.
std::pair<glm::dvec3, glm::dvec3> HandleSegment(const GizmoBox& box, int handle) {
  const glm::dvec3 centre(0.5);
  if (handle < 3) {
    glm::dvec3 end = centre;
    end[handle] += kAxisReach;
    return {centre, end};
  }
  if (handle == 3) return {{0.5, 0, 1}, {0.5, 1, 1}};
  return PeelEdge(box, box.peel_angle.value_or(0));
}

bool HasHandle(const GizmoBox& box, int handle) {
  return (handle < 3 && box.axes) || (handle == 3 && box.knife) ||
         (handle == 4 && box.peel_angle.has_value());
}

double DistanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
  const glm::dvec2 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

glm::dvec2 Xy(const glm::dvec3& v) { return {v.x, v.y}; }

}  // namespace

glm::dvec3 ProjectToWindow(const FrameCamera& camera, const glm::dvec3& p_world) {
  const glm::dvec3 p = glm::dvec3(glm::dmat4(camera.cam_from_world) * glm::dvec4(p_world, 1.0));
  if (!(p.z > 1e-9)) return {0, 0, p.z};
  return {camera.fx * p.x / p.z + camera.cx, camera.fy * p.y / p.z + camera.cy, p.z};
}

const char* GizmoModeName(GizmoMode mode) {
  switch (mode) {
    case GizmoMode::kTranslate:
      return "translate";
    case GizmoMode::kRotate:
      return "rotate";
    case GizmoMode::kScale:
      return "scale";
  }
  return "?";
}

HandleKind KindOfHandle(int handle) {
  return handle < 3    ? HandleKind::kAxis
         : handle == 3 ? HandleKind::kKnifeLine
                       : HandleKind::kPeelEdge;
}

std::vector<OverlayLine> GizmoLines(const GizmoBox& box, const FrameCamera& camera, GizmoMode mode,
                                    std::optional<int> active) {
  std::vector<OverlayLine> lines;
  const auto add = [&](const glm::dvec3& a_box, const glm::dvec3& b_box, uint32_t colour,
                       float thickness) {
    const glm::dvec3 a = ProjectToWindow(camera, World(box, a_box));
    const glm::dvec3 b = ProjectToWindow(camera, World(box, b_box));
    if (a.z <= 0 || b.z <= 0) return;  // behind the camera: not clipped, left out
    lines.push_back({glm::vec2(a), glm::vec2(b), colour, thickness});
  };
  // The 12 edges: from each corner with a 0 coordinate along that axis.
  for (int axis = 0; axis < 3; ++axis) {
    for (int c = 0; c < 4; ++c) {
      glm::dvec3 a(0.0);
      a[(axis + 1) % 3] = c & 1;
      a[(axis + 2) % 3] = (c >> 1) & 1;
      glm::dvec3 b = a;
      b[axis] = 1;
      add(a, b, kEdgeColour, 1.0f);
    }
  }
  for (int h = 0; h < 5; ++h) {
    if (!HasHandle(box, h)) continue;
    const auto [a, b] = HandleSegment(box, h);
    const float thickness = active == h ? 5.0f : 3.0f;
    const uint32_t colour = h < 3 ? kAxisColours[h] : h == 3 ? kKnifeColour : kPeelColour;
    add(a, b, colour, thickness);
    if (h < 3 && mode != GizmoMode::kTranslate) {
      // Rotate and scale modes mark the axis end with a cross bar.
      glm::dvec3 across(0.0);
      across[(h + 1) % 3] = 0.08;
      add(b - across, b + across, colour, thickness);
    }
  }
  if (box.peel_angle) {
    const glm::dvec2 h = box.peel_hinge;
    add({h.x, 0, h.y}, {h.x, 1, h.y}, kPeelColour, 1.0f);  // the hinge
  }
  return lines;
}

std::optional<int> PickHandle(const GizmoBox& box, const FrameCamera& camera,
                              const glm::dvec2& pixel, double radius_px) {
  std::optional<int> best;
  double best_distance = radius_px;
  for (int h = 0; h < 5; ++h) {
    if (!HasHandle(box, h)) continue;
    const auto [a_box, b_box] = HandleSegment(box, h);
    const glm::dvec3 a = ProjectToWindow(camera, World(box, a_box));
    const glm::dvec3 b = ProjectToWindow(camera, World(box, b_box));
    if (a.z <= 0 || b.z <= 0) continue;
    const double d = DistanceToSegment(pixel, Xy(a), Xy(b));
    if (d <= best_distance) {
      best_distance = d;
      best = h;
    }
  }
  return best;
}

GizmoPlacement DragHandle(const GizmoBox& box, const GizmoPlacement& start, GizmoMode mode,
                          int handle, const FrameCamera& camera, const glm::dvec2& from,
                          const glm::dvec2& to) {
  GizmoPlacement p = start;
  const glm::dvec2 travel = to - from;
  if (KindOfHandle(handle) == HandleKind::kPeelEdge) {
    // The mouse in the flap's plane: hinge + a X + b Z on the screen, X and
    // Z the images of the box's x and z about the hinge's middle.
    const glm::dvec3 hinge(box.peel_hinge.x, 0.5, box.peel_hinge.y);
    const glm::dvec2 h = Xy(ProjectToWindow(camera, World(box, hinge)));
    const glm::dvec2 x = Xy(ProjectToWindow(camera, World(box, hinge + glm::dvec3(0.5, 0, 0)))) - h;
    const glm::dvec2 z = Xy(ProjectToWindow(camera, World(box, hinge + glm::dvec3(0, 0, 0.5)))) - h;
    const double det = x.x * z.y - x.y * z.x;
    double angle = 0;
    if (std::abs(det) < 0.05 * glm::length(x) * glm::length(z) || !(std::abs(det) > 0)) {
      // Seen edge-on: up the screen opens the flap.
      angle = start.peel_angle - 0.01 * travel.y;
    } else {
      const glm::dvec2 d = to - h;
      const double a = (d.x * z.y - d.y * z.x) / det;
      const double b = (x.x * d.y - x.y * d.x) / det;
      angle = std::atan2(b, a);
      if (angle < 0) angle = angle > -0.5 * M_PI ? 0.0 : M_PI;
    }
    p.peel_angle = std::clamp(angle, 0.0, M_PI);
    return p;
  }
  const int axis = KindOfHandle(handle) == HandleKind::kKnifeLine ? 0 : handle;
  const glm::dvec3 centre(0.5);
  glm::dvec3 end = centre;
  end[axis] += 0.5;
  const glm::dvec2 s0 = Xy(ProjectToWindow(camera, World(box, centre)));
  const glm::dvec2 image = Xy(ProjectToWindow(camera, World(box, end))) - s0;
  const double image2 = glm::dot(image, image);
  if (!(image2 >= 1.0)) return p;  // the axis points at the viewer: no defined drag
  const GizmoMode m = KindOfHandle(handle) == HandleKind::kKnifeLine ? GizmoMode::kTranslate : mode;
  switch (m) {
    case GizmoMode::kTranslate: {
      glm::dvec3 unit_box(0.0);
      unit_box[axis] = 0.5;
      const glm::dvec3 half_axis_norm = glm::dmat3(box.norm_from_box) * unit_box;
      p.translation = start.translation + glm::dot(travel, image) / image2 * half_axis_norm;
      break;
    }
    case GizmoMode::kRotate: {
      const glm::dvec2 across = glm::dvec2(-image.y, image.x) / std::sqrt(image2);
      p.rotation_deg[axis] = start.rotation_deg[axis] + kDegreesPerPixel * glm::dot(travel, across);
      break;
    }
    case GizmoMode::kScale:
      p.scale = start.scale * std::exp(glm::dot(travel, image) / std::sqrt(image2) / kScalePixels);
      break;
  }
  return p;
}

}  // namespace viewer
