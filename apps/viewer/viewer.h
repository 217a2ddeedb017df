// The interactive viewer behind `ibr view`: a GLFW window (X11) whose GL
// context goes through the same GL layer as the headless one
// (render::InitializeCurrentContext), Dear ImGui controls, an orbit camera.
// A scene renders each frame into its own offscreen render target (the same
// code path as headless rendering); the viewer blits it to the window.
#pragma once

#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "render/gl/render_target.h"

namespace viewer {

// The camera of one frame: pose, pinhole intrinsics (pixels, sparse
// convention) and the matching GL projection.
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
  // ImGui widgets for the scene's options (inside the viewer's panel).
  virtual void DrawControls() = 0;
  // Renders the frame; colour attachment 0 of the returned target is shown.
  virtual const render::RenderTarget& Render(const FrameCamera& camera) = 0;
  // One line of status (e.g. "128 slices, 6 maps"), shown under the timing.
  virtual std::string Status() const { return {}; }
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
  // While the mouse drags (and for the first frames), frames render at
  // 1 / coarse_factor of the window's resolution and are scaled up; the full
  // frame follows when the mouse stops. 1 = always full resolution.
  int coarse_factor = 2;

  void Check() const;
};

// Opens the window, makes the scene with the window's context current (GPU
// resources need it), runs until the window is closed (or the screenshot is
// saved) and destroys the scene before the context. Throws core::InputError
// when no window can be opened (e.g. no DISPLAY).
using SceneFactory = std::function<std::unique_ptr<Scene>()>;
void Run(const SceneFactory& make_scene, const ViewerOptions& options);

// The orbit camera for a window of width x height; `up` is the pole (unit).
FrameCamera OrbitCamera(glm::vec3 centre, float radius, float azimuth_degrees,
                        float elevation_degrees, float distance_scale, float fov_y_degrees,
                        int width, int height, glm::vec3 up = {0, 1, 0});

}  // namespace viewer
