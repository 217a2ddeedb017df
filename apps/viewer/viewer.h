// The interactive viewer behind `ibr view`: a GLFW window (X11) whose GL
// context goes through the same GL layer as the headless one
// (render::InitializeCurrentContext), Dear ImGui controls, an orbit camera.
// A scene renders each frame into its own offscreen render target (the same
// code path as headless rendering); the viewer draws it over its background.
//
// Progressive viewing (docs/decisions/progressive-viewer.md): while the
// camera or a parameter moves, frames render at a reduced resolution chosen
// so a frame fits a time budget and are scaled up; when nothing moves, the
// next frame is the exact one (full resolution, the camera `ibr render`
// gets from the cameras file `--camera-out` writes) and is then shown
// without being drawn again until something moves.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/viewer/input_events.h"
#include "capture/dataset.h"
#include "render/gl/render_target.h"
#include "scene/scene.h"

namespace viewer {

// The camera of one frame: pose, pinhole intrinsics (pixels, sparse
// convention) and the matching GL projection.
// A line drawn over the frame (the gizmo; apps/viewer/gizmo.h).
struct OverlayLine {
  glm::vec2 a, b;   // window pixels
  uint32_t colour;  // ImGui's packed ABGR (IM_COL32)
  float thickness;  // pixels
};

struct FrameCamera {
  glm::mat4 cam_from_world{1.0f};
  glm::mat4 clip_from_cam{1.0f};
  double fx = 1, fy = 1, cx = 0, cy = 0;
  int width = 0, height = 0;
  double near = 0.01, far = 100;  // scene units
};

// What the viewer shows. Implementations own their GPU resources; every call
// happens with the window's context current.
class Scene {
 public:
  virtual ~Scene() = default;
  virtual std::string Title() const = 0;
  // Orbit centre and a radius that frames the object (scene units).
  virtual glm::vec3 Centre() const = 0;
  virtual float Radius() const = 0;
  // ImGui widgets for the scene's options (inside the viewer's panel); true
  // when an option changed (the next frame is then a moving one).
  virtual bool DrawControls() = 0;
  // Renders the frame; colour attachment 0 of the returned target is shown.
  virtual const render::RenderTarget& Render(const FrameCamera& camera) = 0;
  // One line of status (e.g. "128 slices, 6 maps"), shown under the timing.
  virtual std::string Status() const { return {}; }
  // A scripted parameter drag (benchmarks): sets the scene's first draggable
  // parameter to fraction `t` in [0, 1] of its slider's range. False when the
  // scene has none (nothing changed).
  virtual bool DragParameter(double /*t*/) { return false; }
  // Before an exact frame: finishes what changes while moving left
  // approximate (e.g. a distance field whose reach a drag outgrew).
  virtual void Settle() {}
  // Called once per frame before Render: true when work finished in the
  // background changed the scene (the frame then counts as moving).
  virtual bool Poll() { return false; }

  // Direct manipulation (apps/viewer/gizmo.h), `camera` the window's full
  // camera, pixels in window coordinates (y down). A left press the scene
  // takes (a handle under the mouse; with Control, window/level) starts a
  // drag instead of an orbit; `mods` GLFW's modifier bits (InputEvent::mods).
  virtual bool PointerPress(const FrameCamera& /*camera*/, const glm::dvec2& /*pixel*/,
                            int /*mods*/) {
    return false;
  }
  // The mouse moved during a drag the scene took: true when the scene changed.
  virtual bool PointerDrag(const FrameCamera& /*camera*/, const glm::dvec2& /*pixel*/) {
    return false;
  }
  virtual void PointerRelease() {}
  // A key press (GLFW key code) the panel did not take: true when the
  // scene changed.
  virtual bool Key(int /*key*/) { return false; }
  // Lines drawn over the frame (the gizmo), not part of the frame itself.
  virtual std::vector<OverlayLine> Overlay(const FrameCamera& camera) const;
  // The scene as edited, its cameras the one `camera` (`--save-scene`).
  // InputError when the scene has no file form (a dataset) or an edit has
  // no scene key.
  virtual scene::Scene EditedScene(const FrameCamera& camera) const;
};

struct ViewerOptions {
  int width = 1024;  // window size in pixels
  int height = 768;
  float fov_y_degrees = 40.0f;
  // Non-empty: render `frames` frames, save the last one (window contents,
  // GUI included) to this PNG and exit. For tests under xvfb-run.
  std::filesystem::path screenshot;
  int frames = 3;
  float azimuth_degrees = 30.0f;  // initial orbit
  float elevation_degrees = 20.0f;
  // The world's up direction, the orbit's pole (unit). +y: the synthetic
  // rigs and most meshes; `ibr view` takes a dataset's own (capture::DefaultUp).
  glm::vec3 up{0, 1, 0};
  // Draw the control panel. Off: the window shows the object alone (for
  // screenshots; the mouse still orbits).
  bool panel = true;
  // While the camera or a parameter moves, frames render at 1 / divisor of
  // the window's width and height and are scaled up (bilinear); the exact
  // full-resolution frame follows when nothing moves. 0: the divisor adapts
  // so a moving frame takes motion_frame_ms (the default); N: fixed at N;
  // 1: every frame at full resolution.
  int coarse_factor = 0;
  // The wall time a moving frame aims at (render, panel and buffer swap),
  // milliseconds: below the period of 15 frames a second, with a margin for
  // the frame-to-frame spread of a shared CPU.
  double motion_frame_ms = 55;
  // With `screenshot`: also write the last exact frame (RGBA, as the frame
  // target holds it) and its camera as a cameras-only dataset.json (what
  // `ibr render --cameras` and a scene's {"dataset": FILE} cameras read).
  std::filesystem::path frame_out;
  std::filesystem::path camera_out;
  // Non-empty: the session's input is written here when the window closes
  // (apps/viewer/input_events.h).
  std::filesystem::path record;
  // Set: the recorded input is fed frame by frame through the live input's
  // handlers (window size, initial orbit and panel taken from it); after
  // its last event the frames run until the exact one, which is the frame
  // `frame_out` and `camera_out` save, then the viewer exits.
  std::optional<InputRecording> replay;
  // Non-empty: on exit, the scene as edited with the window's last camera
  // (Scene::EditedScene; scene/scene_write.h).
  std::filesystem::path save_scene;

  void Check() const;
};

// Opens the window, makes the scene with the window's context current (GPU
// resources need it), runs until the window is closed (or the screenshot is
// saved) and destroys the scene before the context. Throws core::InputError
// when no window can be opened (e.g. no DISPLAY).
using SceneFactory = std::function<std::unique_ptr<Scene>()>;

// A scripted session (benchmarks): input per frame instead of the mouse.
struct ScriptedInput {
  float azimuth_degrees = 30, elevation_degrees = 20;
  std::optional<double> drag;  // Scene::DragParameter(t) when it differs from the last
};
// One shown frame, reported after its buffer swap.
struct FrameReport {
  int frame = 0;
  bool moving = false;      // drawn at a reduced resolution (or at full while moving)
  bool exact = false;       // the full-resolution frame of a camera at rest
  bool drawn = false;       // false: the last frame shown again (nothing moved)
  double divisor = 1;       // window size / frame size
  double render_ms = 0;     // Scene::Render + glFinish
  double frame_ms = 0;      // the whole frame: input, render, panel, swap
  FrameCamera camera;       // the camera drawn (reduced while moving)
  FrameCamera full_camera;  // the same pose at the window's size
  const render::RenderTarget* target = nullptr;  // what is shown
  Scene* scene = nullptr;
};
struct ViewerScript {
  // The input of frame `frame` (0, 1, ...); nullopt ends the run.
  std::function<std::optional<ScriptedInput>(int frame)> input;
  std::function<void(const FrameReport&)> on_frame;  // not counted in frame_ms
};

void Run(const SceneFactory& make_scene, const ViewerOptions& options,
         const ViewerScript* script = nullptr);

// The orbit camera (ibr::OrbitCameraView, the product's one orbit) for a
// window of width x height; `up` is the pole (unit).
FrameCamera OrbitCamera(glm::vec3 centre, float radius, float azimuth_degrees,
                        float elevation_degrees, float distance_scale, float fov_y_degrees,
                        int width, int height, glm::vec3 up = {0, 1, 0});

// The camera as a cameras-only dataset (one PINHOLE camera, one view named
// "view", no images): the file `--camera-out` writes and `ibr render
// --cameras` reads. The viewer's exact frame is rendered from this camera.
capture::Dataset CamerasOf(const FrameCamera& camera);

}  // namespace viewer
