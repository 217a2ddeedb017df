// The viewer's gizmo on a deformation box, as CPU geometry: the box's edges
// and handles projected into the window, picking a handle under the mouse,
// and turning a drag of it into the new placement or parameter. The
// handles (docs/guide/viewer.md):
//   - axis handles, one per box axis from the centre to a face: drag one to
//     translate the box along it; in rotate mode to turn the box about it,
//     in scale mode to scale it (Correa 2007 sec. 3.2: the box's affine map);
//   - a knife's line (where its cut meets the top face): drag it across the
//     object, the box following perpendicular to the cut (Correa 2007 Fig. 4);
//   - a peel's flap edge: the peel angle follows the mouse about the hinge
//     (Correa 2006 Fig. 1's progressive peel).
// Drawing is the viewer's overlay (2D lines over the frame), so the frame
// itself, and its exactness, are untouched. No GL here: testable without a
// context.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "apps/viewer/viewer.h"

namespace viewer {

// u = fx x / z + cx, v = fy y / z + cy of a world point (window pixels, y
// down) and its camera z (<= 0: behind the camera).
glm::dvec3 ProjectToWindow(const FrameCamera& camera, const glm::dvec3& p_world);

enum class GizmoMode { kTranslate, kRotate, kScale };
const char* GizmoModeName(GizmoMode mode);

enum class HandleKind { kAxis, kKnifeLine, kPeelEdge };

// What the gizmo manipulates: a box (u in [0, 1]^3) placed in a frame whose
// units its placement is given in ("norm": a deform object's normalised
// units), and the deformation's line or flap when it has one.
struct GizmoBox {
  glm::dmat4 world_from_norm{1.0};
  glm::dmat4 norm_from_box{1.0};  // core::Placement::object_from_box
  bool axes = true;               // the axis handles (a placement to drag)
  bool knife = false;             // a knife: its cut line x = 0.5 on the top face z = 1
  // A peel: its angle (radians; the flap turns up and over about the hinge,
  // +x towards +z), the hinge line (x, z) along y and the flap's length
  // along x (box units). A deform object's: hinge (0.5, 1 - T), length 0.5
  // (core/deformation.cc); a volume's: (peel_hinge_x, peel_top), 1 - x.
  std::optional<double> peel_angle;
  glm::dvec2 peel_hinge{0.5, 1.0};
  double peel_length = 0.5;
};

// The placement a drag starts from and changes (a deform object's options).
struct GizmoPlacement {
  glm::dvec3 translation{0.0};   // norm units
  glm::dvec3 rotation_deg{0.0};  // Euler angles about the box centre
  double scale = 1.0;
  double peel_angle = 0;  // radians
};

// The box's edges and handles as window lines (segments behind the camera
// left out); `active`: the handle being dragged, drawn thicker.
std::vector<OverlayLine> GizmoLines(const GizmoBox& box, const FrameCamera& camera, GizmoMode mode,
                                    std::optional<int> active = std::nullopt);

// The handle whose projected segment is within `radius_px` of `pixel`, the
// nearest; handle ids: 0..2 the axes, 3 the knife's line, 4 the peel's edge.
std::optional<int> PickHandle(const GizmoBox& box, const FrameCamera& camera,
                              const glm::dvec2& pixel, double radius_px = 8);
HandleKind KindOfHandle(int handle);

// The placement after dragging `handle` from `from` to `to` (window pixels),
// the box as it was at the press (`box`, `start`). Translate: the box moves
// along its axis by the mouse's travel projected on the axis's image; the
// knife's line moves the box along its x (across the cut). Rotate: the Euler
// angle of the axis changes by 0.5 degrees a pixel across the axis's image.
// Scale: exp(travel along the image / 150 px). Peel: the angle of the mouse
// about the hinge in the flap's plane, clamped to [0, pi].
GizmoPlacement DragHandle(const GizmoBox& box, const GizmoPlacement& start, GizmoMode mode,
                          int handle, const FrameCamera& camera, const glm::dvec2& from,
                          const glm::dvec2& to);

}  // namespace viewer
