// The viewer's gizmo geometry (apps/viewer/gizmo.h) and its events file
// (apps/viewer/input_events.h), CPU only: a dragged axis moves the box so
// its centre follows the mouse; the peel angle read from the mouse is the
// angle of the flap edge drawn there; a handle is picked where it is drawn;
// recordings round-trip and bad bytes are refused with one InputError.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "apps/viewer/gizmo.h"
#include "apps/viewer/input_events.h"
#include "core/error.h"

namespace viewer {
namespace {

// A box of 1.1 x 0.8 x 0.6 (norm units) about the origin, in a world that
// scales norm units by 2, seen by the viewer's orbit camera.
GizmoBox Box() {
  GizmoBox box;
  box.world_from_norm = glm::dmat4(2.0);
  box.world_from_norm[3] = glm::dvec4(0.3, -0.2, 0.1, 1.0);
  box.norm_from_box = glm::dmat4(1.0);
  box.norm_from_box[0][0] = 1.1, box.norm_from_box[1][1] = 0.8, box.norm_from_box[2][2] = 0.6;
  box.norm_from_box[3] = glm::dvec4(-0.55, -0.4, -0.3, 1.0);
  return box;
}

glm::dvec2 Window(const FrameCamera& camera, const GizmoBox& box, const glm::dvec3& u) {
  const glm::dvec3 p = ProjectToWindow(
      camera, glm::dvec3(box.world_from_norm * box.norm_from_box * glm::dvec4(u, 1.0)));
  return {p.x, p.y};
}

FrameCamera Camera(float azimuth, float elevation) {
  return OrbitCamera(glm::vec3(0.3f, -0.2f, 0.1f), 1.6f, azimuth, elevation, 1.3f, 40.0f, 800, 600);
}

// Each axis handle, dragged by a few pixels along its image: the box's
// centre lands within a pixel of where the mouse went (the drag's model is
// the projection's linearisation; a few pixels keep perspective negligible).
TEST(Gizmo, DraggedAxisCentreFollowsTheMouse) {
  const GizmoBox box = Box();
  const FrameCamera camera = Camera(35, 25);
  for (int axis = 0; axis < 3; ++axis) {
    SCOPED_TRACE(axis);
    glm::dvec3 end(0.5);
    end[axis] = 1.0;
    const glm::dvec2 centre = Window(camera, box, glm::dvec3(0.5));
    const glm::dvec2 direction = glm::normalize(Window(camera, box, end) - centre);
    const glm::dvec2 from = centre + 20.0 * direction;  // on the handle
    ASSERT_EQ(PickHandle(box, camera, from), std::optional<int>(axis));
    const GizmoPlacement moved =
        DragHandle(box, {}, GizmoMode::kTranslate, axis, camera, from, from + 6.0 * direction);
    GizmoBox after = box;
    after.norm_from_box[3] += glm::dvec4(moved.translation, 0.0);
    EXPECT_NEAR(glm::length(Window(camera, after, glm::dvec3(0.5)) - (centre + 6.0 * direction)),
                0.0, 1.0);
    for (int other = 0; other < 3; ++other) {
      if (other != axis) {
        EXPECT_EQ(moved.translation[other], 0.0);
      }
    }
  }
}

// The knife's line drags the box across the cut (its x axis) alone.
TEST(Gizmo, KnifeLineMovesTheBoxAcrossTheCut) {
  GizmoBox box = Box();
  box.knife = true;
  const FrameCamera camera = Camera(20, 50);
  const glm::dvec2 on_line = Window(camera, box, {0.5, 0.5, 1.0});
  ASSERT_EQ(PickHandle(box, camera, on_line), std::optional<int>(3));
  const GizmoPlacement moved =
      DragHandle(box, {}, GizmoMode::kRotate, 3, camera, on_line, on_line + glm::dvec2(15, 0));
  EXPECT_NE(moved.translation.x, 0.0);
  EXPECT_EQ(moved.translation.y, 0.0);
  EXPECT_EQ(moved.translation.z, 0.0);
  EXPECT_EQ(moved.rotation_deg, glm::dvec3(0.0));  // the line always translates
}

// The mouse on the flap edge drawn at angle a gives back a (seen from the
// side, where the flap turns in the image plane up to perspective).
TEST(Gizmo, PeelAngleFollowsTheMouse) {
  GizmoBox box = Box();
  box.peel_angle = 0.4;
  box.peel_hinge = {0.5, 0.85};              // a deform object's peel of thickness 0.15
  const FrameCamera camera = Camera(0, 89);  // looking down the box's y (the orbit's pole)
  const double top = 0.85;
  const glm::dvec2 grab =
      Window(camera, box, {0.5 + 0.5 * std::cos(0.4), 0.5, top + 0.5 * std::sin(0.4)});
  ASSERT_EQ(PickHandle(box, camera, grab), std::optional<int>(4));
  for (double a : {0.0, 0.3, 1.2, 2.0, 2.9, M_PI}) {
    const glm::dvec2 to =
        Window(camera, box, {0.5 + 0.5 * std::cos(a), 0.5, top + 0.5 * std::sin(a)});
    const GizmoPlacement p =
        DragHandle(box, {.peel_angle = 0.4}, GizmoMode::kTranslate, 4, camera, grab, to);
    EXPECT_NEAR(p.peel_angle, a, 0.05) << a;
  }
  // Below the hinge plane: clamped to the nearer end of [0, pi].
  const glm::dvec2 below = Window(camera, box, {0.9, 0.5, top - 0.2});
  EXPECT_EQ(DragHandle(box, {}, GizmoMode::kTranslate, 4, camera, grab, below).peel_angle, 0.0);
}

TEST(Gizmo, ScaleAndRotateFollowTheTravel) {
  const GizmoBox box = Box();
  const FrameCamera camera = Camera(35, 25);
  const glm::dvec2 centre = Window(camera, box, glm::dvec3(0.5));
  const glm::dvec2 x = glm::normalize(Window(camera, box, {1.0, 0.5, 0.5}) - centre);
  const GizmoPlacement out =
      DragHandle(box, {}, GizmoMode::kScale, 0, camera, centre, centre + 150.0 * x);
  EXPECT_NEAR(out.scale, std::exp(1.0), 1e-9);  // one e-fold per 150 px along the axis
  const GizmoPlacement in =
      DragHandle(box, {}, GizmoMode::kScale, 0, camera, centre, centre - 150.0 * x);
  EXPECT_NEAR(in.scale, std::exp(-1.0), 1e-9);
  const glm::dvec2 across(-x.y, x.x);
  const GizmoPlacement turned =
      DragHandle(box, {}, GizmoMode::kRotate, 0, camera, centre, centre + 40.0 * across);
  EXPECT_NEAR(turned.rotation_deg.x, 20.0, 1e-9);  // 0.5 degrees a pixel
  EXPECT_EQ(turned.rotation_deg.y, 0.0);
}

TEST(Gizmo, NothingPickedAwayFromTheHandles) {
  const FrameCamera camera = Camera(35, 25);
  EXPECT_FALSE(PickHandle(Box(), camera, {5, 5}).has_value());
  // Every drawn line is inside the window for a framed box.
  for (const OverlayLine& l : GizmoLines(Box(), camera, GizmoMode::kRotate)) {
    EXPECT_GE(std::min(l.a.x, l.b.x), 0.0f);
    EXPECT_LE(std::max(l.a.y, l.b.y), 600.0f);
  }
}

InputRecording Recording() {
  InputRecording r;
  r.width = 640, r.height = 480, r.azimuth_deg = -12.5f, r.elevation_deg = 33, r.panel = false;
  InputEvent move;
  move.type = InputEvent::Type::kMove, move.frame = 1, move.t = 0.125, move.x = 10.5, move.y = 7;
  InputEvent press;
  press.type = InputEvent::Type::kButton, press.frame = 2, press.code = 0, press.mods = 1;
  InputEvent scroll;
  scroll.type = InputEvent::Type::kScroll, scroll.frame = 2, scroll.x = 0, scroll.y = -1;
  InputEvent key;
  key.type = InputEvent::Type::kKey, key.frame = 5, key.code = 'R';
  key.action = InputEvent::Action::kRepeat;
  r.events = {move, press, scroll, key};
  return r;
}

TEST(InputEvents, RecordingRoundTrips) {
  std::stringstream s;
  WriteRecording(s, Recording());
  EXPECT_EQ(ReadRecording(s, "r.json"), Recording());
}

// Mutated recordings: read or refused with an InputError naming the file,
// never a crash (deterministic seed).
TEST(InputEvents, MutatedRecordingsAreReadOrRefused) {
  std::stringstream s;
  WriteRecording(s, Recording());
  const std::string good = s.str();
  std::mt19937 rng(35);
  int refused = 0;
  for (int i = 0; i < 2000; ++i) {
    std::string bytes = good;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) bytes[rng() % bytes.size()] = static_cast<char>(rng() % 256);
    std::istringstream in(bytes);
    try {
      ReadRecording(in, "fuzz.json");
    } catch (const core::InputError& error) {
      EXPECT_NE(std::string(error.what()).find("fuzz.json"), std::string::npos) << error.what();
      ++refused;
    }
  }
  EXPECT_GT(refused, 1000);
}

}  // namespace
}  // namespace viewer
