#include "apps/viewer/viewer.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <fmt/format.h>
#include <imgui.h>
#include <spdlog/spdlog.h>

#include "capture/dataset.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "core/timing.h"
#include "ibr/views.h"
#include "render/gl/context.h"
#include "render/gl/gl.h"
#include "render/gl/gl_queries.h"
#include "render/gl/texture_upload.h"
#include "render/gl/window_frame.h"
#include "scene/scene_write.h"

namespace viewer {
namespace {
// The largest divisor while moving: beyond it an object a few hundred pixels
// wide is a few dozen samples across.
constexpr int kMaxDivisor = 8;
}  // namespace

void ViewerOptions::Check() const {
  if (width < 64 || height < 64 || width > 8192 || height > 8192) {
    core::ThrowInputError("ViewerOptions", "window size {}x{} outside 64..8192", width, height);
  }
  if (!(fov_y_degrees > 1 && fov_y_degrees < 170)) {
    core::ThrowInputError("ViewerOptions", "field of view {} outside (1, 170) degrees",
                          fov_y_degrees);
  }
  if (frames < 1 || frames > 100000)
    core::ThrowInputError("ViewerOptions", "frames {} outside 1..100000", frames);
  if (coarse_factor < 0 || coarse_factor > kMaxDivisor) {
    core::ThrowInputError("ViewerOptions", "coarse factor {} outside 0..{} (0 = adaptive)",
                          coarse_factor, kMaxDivisor);
  }
  if (!(motion_frame_ms >= 5 && motion_frame_ms <= 1000)) {
    core::ThrowInputError("ViewerOptions", "motion frame time {} ms outside 5..1000",
                          motion_frame_ms);
  }
  if ((!frame_out.empty() || !camera_out.empty()) && screenshot.empty() && !replay) {
    core::ThrowInputError("ViewerOptions",
                          "the frame and camera outputs go with a screenshot or a replay");
  }
  if (replay && !screenshot.empty())
    core::ThrowInputError("ViewerOptions", "a replay ends by itself: no screenshot with it");
  if (!(std::abs(glm::length(up) - 1.0f) < 1e-4f))
    core::ThrowInputError("ViewerOptions", "up ({}, {}, {}) is not a unit vector", up.x, up.y,
                          up.z);
}

FrameCamera OrbitCamera(glm::vec3 centre, float radius, float azimuth_degrees,
                        float elevation_degrees, float distance_scale, float fov_y_degrees,
                        int width, int height, glm::vec3 up) {
  // The product's one orbit (ibr::OrbitCameraView), clamped short of the
  // poles so dragging over the top does not flip the view.
  ibr::OrbitCamera orbit;
  orbit.azimuth_deg = azimuth_degrees;
  orbit.elevation_deg = std::clamp(elevation_degrees, -89.0f, 89.0f);
  orbit.fov_deg = fov_y_degrees;
  orbit.distance = distance_scale * radius / std::sin(0.5 * glm::radians(orbit.fov_deg));
  orbit.up = up;
  const ibr::ViewCamera view = ibr::OrbitCameraView(centre, radius, orbit, width, height);
  FrameCamera camera;
  camera.cam_from_world = glm::mat4(view.cam_from_world);
  camera.fx = view.camera.fx;
  camera.fy = view.camera.fy;
  camera.cx = view.camera.cx;
  camera.cy = view.camera.cy;
  camera.width = width;
  camera.height = height;
  camera.near = std::max(1e-4, std::max(1e-3 * orbit.distance, orbit.distance - 2.0 * radius));
  camera.far = orbit.distance + 4.0 * radius;
  camera.clip_from_cam = core::ClipFromCamPerspective(camera.fx, camera.fy, camera.cx, camera.cy,
                                                      width, height, camera.near, camera.far);
  return camera;
}

std::vector<OverlayLine> Scene::Overlay(const FrameCamera& /*camera*/) const { return {}; }

scene::Scene Scene::EditedScene(const FrameCamera& /*camera*/) const {
  core::ThrowInputError("ibr view", "--save-scene: '{}' is not a scene file (SCENE.json)", Title());
}

capture::Dataset CamerasOf(const FrameCamera& camera) {
  capture::Dataset cameras;
  cameras.cameras[1] = capture::Camera::Pinhole(camera.width, camera.height, camera.fx, camera.fy,
                                                camera.cx, camera.cy);
  capture::DatasetView view;
  view.name = "view";
  view.camera_id = 1;
  const glm::dmat4 m(camera.cam_from_world);
  view.cam_from_world.rotation = glm::dmat3(m);
  view.cam_from_world.translation = glm::dvec3(m[3]);
  cameras.views.push_back(view);
  return cameras;
}

namespace {

struct GlfwSession {
  GlfwSession() {
    glfwSetErrorCallback(
        [](int code, const char* message) { spdlog::debug("GLFW {}: {}", code, message); });
    if (!glfwInit()) {
      core::ThrowInputError(
          "viewer::Run", "cannot initialise GLFW (is DISPLAY set? use xvfb-run -a for no screen)");
    }
  }
  ~GlfwSession() { glfwTerminate(); }
};

struct OrbitState {
  float azimuth = 30, elevation = 20, distance_scale = 1.3f;
  bool dragging = false;
  double last_x = 0, last_y = 0;
};

// What a frame shows: the orbit pose and the window size.
struct ViewKey {
  float azimuth = 0, elevation = 0, distance_scale = 0;
  int width = 0, height = 0;
  bool operator==(const ViewKey&) const = default;
};

// The divisor of moving frames. Render time is modelled as proportional to
// the pixel count (a ray or slice per pixel dominates), so the divisor that
// fits a budget scales with the square root of the time ratio; the budget of
// the render is the frame budget less what the rest of a frame (panel, swap)
// took. Quarter steps keep the target size from changing every frame.
struct ProgressiveState {
  double divisor = 2;
  double overhead_ms = 5;  // frame time outside Scene::Render, smoothed
  ViewKey key;
  bool has_key = false;
  bool exact_shown = false;

  double RenderBudget(double frame_budget_ms) const {
    return std::max(frame_budget_ms - overhead_ms, 0.25 * frame_budget_ms);
  }
  static double Quantised(double divisor) {
    return std::clamp(std::ceil(divisor * 4.0) / 4.0, 1.0, static_cast<double>(kMaxDivisor));
  }
  // After a full-resolution frame: the divisor its time predicts.
  void StartFrom(double render_ms, double frame_budget_ms) {
    divisor = Quantised(std::sqrt(std::max(render_ms, 1e-3) / RenderBudget(frame_budget_ms)));
  }
  // After a moving frame drawn at `used`: move towards the divisor its time
  // predicts, halfway (one slow frame on a shared CPU does not halve the
  // resolution).
  void Adapt(double used, double render_ms, double frame_ms, double frame_budget_ms) {
    overhead_ms = 0.7 * overhead_ms + 0.3 * std::max(frame_ms - render_ms, 0.0);
    const double wanted =
        used * std::sqrt(std::max(render_ms, 1e-3) / RenderBudget(frame_budget_ms));
    divisor = Quantised(0.5 * (divisor + wanted));
  }
};

// The frame target's colour behind the panel, stretched over the window
// (bilinear: reduced frames are scaled up; a full-size frame samples texel
// centres, so it shows unchanged), composited over the cleared background as
// premultiplied colour (alpha 0 where nothing was drawn; DVR accumulates
// premultiplied colour).
void DrawFrameBehindPanel(const render::RenderTarget& target, int width, int height) {
  render::SampleLinearClamped(target.color(0));
  const GLuint texture = target.color(0).id();
  ImDrawList* list = ImGui::GetBackgroundDrawList();
  list->AddCallback([](const ImDrawList*, const ImDrawCmd*) { render::UsePremultipliedBlend(); },
                    nullptr);
  // GL rows start at the bottom: v runs from 1 at the window's top to 0.
  list->AddImage(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture)), ImVec2(0, 0),
                 ImVec2(static_cast<float>(width), static_cast<float>(height)), ImVec2(0, 1),
                 ImVec2(1, 0));
  list->AddCallback(ImDrawCallback_ResetRenderState, nullptr);
}

// With frame_out and camera_out: the last exact frame and its camera.
void SaveExactFrame(const ViewerOptions& options, const core::Image8& exact_frame,
                    const FrameCamera& exact_camera) {
  if (!options.frame_out.empty()) {
    if (exact_frame.width() == 0)
      core::ThrowInputError("ibr view", "--frame-out: no exact frame was drawn");
    core::WriteImage(options.frame_out, exact_frame);
  }
  if (!options.camera_out.empty()) {
    core::AtomicWriteStream(options.camera_out, [&](std::ostream& out) {
      capture::WriteManifest(out, CamerasOf(exact_camera));
    });
  }
}

// The window's back buffer (GUI included) as an opaque PNG, and the exact
// frame's outputs.
void SaveScreenshot(const ViewerOptions& options, int width, int height,
                    const core::Image8& exact_frame, const FrameCamera& exact_camera) {
  core::Image8 shot = render::ReadBackBuffer(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) shot.at(x, y, 3) = 255;
  core::WriteImage(options.screenshot, shot);
  SaveExactFrame(options, exact_frame, exact_camera);
}

// Input as events: GLFW's callbacks (live; ImGui's callbacks chain to these)
// and a replay (which calls the same callbacks) both end here, where each
// event is stamped with its frame, recorded and queued for the frame's
// handler. The cursor and buttons are tracked from the events, so ImGui sees
// the same mouse live and in a replay (a hidden replay window has no focus
// for ImGui's own polling).
struct InputQueue {
  std::vector<InputEvent> pending;  // this frame's, in order
  bool keep = false;                // record every event
  InputRecording recording;
  int frame = 0;
  core::Stopwatch clock;
  glm::dvec2 cursor{0.0};
  bool has_cursor = false;
  bool down[3] = {false, false, false};
  bool pressed[3] = {false, false, false};  // since ImGui's last frame

  void Add(InputEvent e) {
    e.frame = frame;
    e.t = std::round(clock.ElapsedMs()) / 1000.0;
    if (e.type == InputEvent::Type::kMove) {
      cursor = {e.x, e.y};
      has_cursor = true;
    } else if (e.type == InputEvent::Type::kButton && e.code < 3) {
      down[e.code] = e.action == InputEvent::Action::kPress;
      pressed[e.code] |= down[e.code];
    }
    pending.push_back(e);
    if (keep) recording.events.push_back(e);
  }
};

InputQueue& QueueOf(GLFWwindow* window) {
  return *static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
}
void OnCursor(GLFWwindow* window, double x, double y) {
  InputEvent e;
  e.type = InputEvent::Type::kMove;
  e.x = x, e.y = y;
  QueueOf(window).Add(e);
}
void OnButton(GLFWwindow* window, int button, int action, int mods) {
  if (button < 0 || button > 7 || action == GLFW_REPEAT) return;
  InputEvent e;
  e.type = InputEvent::Type::kButton;
  e.code = button, e.action = static_cast<InputEvent::Action>(action), e.mods = mods;
  QueueOf(window).Add(e);
}
void OnScroll(GLFWwindow* window, double dx, double dy) {
  InputEvent e;
  e.type = InputEvent::Type::kScroll;
  e.x = dx, e.y = dy;
  QueueOf(window).Add(e);
}
void OnKey(GLFWwindow* window, int key, int /*scancode*/, int action, int mods) {
  if (key < 32 || key > GLFW_KEY_LAST) return;  // GLFW_KEY_UNKNOWN
  InputEvent e;
  e.type = InputEvent::Type::kKey;
  e.code = key, e.action = static_cast<InputEvent::Action>(action), e.mods = mods;
  QueueOf(window).Add(e);
}

// Feeds the recorded events of frames up to `frame` through the callbacks
// GLFW would call: ImGui's (which chain to the viewer's), the cursor's
// directly (ImGui 1.86 installs none).
void FeedReplay(GLFWwindow* window, const InputRecording& replay, size_t& next, int frame) {
  for (; next < replay.events.size() && replay.events[next].frame <= frame; ++next) {
    const InputEvent& e = replay.events[next];
    const int action = static_cast<int>(e.action);
    switch (e.type) {
      case InputEvent::Type::kMove:
        OnCursor(window, e.x, e.y);
        break;
      case InputEvent::Type::kButton:
        ImGui_ImplGlfw_MouseButtonCallback(window, e.code, action, e.mods);
        break;
      case InputEvent::Type::kScroll:
        ImGui_ImplGlfw_ScrollCallback(window, e.x, e.y);
        break;
      case InputEvent::Type::kKey:
        ImGui_ImplGlfw_KeyCallback(window, e.code, 0, action, e.mods);
        break;
    }
  }
}

}  // namespace

void Run(const SceneFactory& make_scene, const ViewerOptions& given, const ViewerScript* script) {
  given.Check();
  ViewerOptions options = given;
  const InputRecording* replay = given.replay ? &*given.replay : nullptr;
  if (replay) {
    // The recording's session, as it started.
    options.width = replay->width;
    options.height = replay->height;
    options.azimuth_degrees = replay->azimuth_deg;
    options.elevation_degrees = replay->elevation_deg;
    options.panel = replay->panel;
    options.Check();
  }
  const bool hidden = !options.screenshot.empty() || replay != nullptr;
  GlfwSession glfw;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, hidden ? GLFW_FALSE : GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, script || replay ? GLFW_FALSE : GLFW_TRUE);
  GLFWwindow* window =
      glfwCreateWindow(options.width, options.height, "ibr view", nullptr, nullptr);
  if (!window) {
    // Fall back to 4.3 / 3.3 like the headless context.
    for (int minor_major : {43, 33}) {
      glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, minor_major / 10);
      glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, minor_major % 10);
      window = glfwCreateWindow(options.width, options.height, "ibr view", nullptr, nullptr);
      if (window) break;
    }
  }
  if (!window)
    core::ThrowInputError("viewer::Run", "cannot open a {}x{} OpenGL 3.3+ core window",
                          options.width, options.height);
  glfwMakeContextCurrent(window);
  // No vertical sync for screenshots, scripts and replays: frame times are the work's.
  glfwSwapInterval(!hidden && !script ? 1 : 0);
  const render::GlInfo info =
      render::InitializeCurrentContext("window", render::HeadlessContextOptions::DefaultDebug());
  spdlog::info("viewer: {} | {}", info.version, info.renderer);
  std::unique_ptr<Scene> scene_owner = make_scene();
  Scene& scene = *scene_owner;
  glfwSetWindowTitle(window, scene.Title().c_str());

  // The viewer's callbacks first: ImGui's, installed next, chain to them.
  InputQueue input_queue;
  input_queue.keep = !options.record.empty();
  input_queue.recording.width = options.width;
  input_queue.recording.height = options.height;
  input_queue.recording.azimuth_deg = options.azimuth_degrees;
  input_queue.recording.elevation_deg = options.elevation_degrees;
  input_queue.recording.panel = options.panel;
  glfwSetWindowUserPointer(window, &input_queue);
  glfwSetCursorPosCallback(window, OnCursor);
  glfwSetMouseButtonCallback(window, OnButton);
  glfwSetScrollCallback(window, OnScroll);
  glfwSetKeyCallback(window, OnKey);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini written next to the user's files
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  const glm::vec3 up = options.up;
  OrbitState orbit;
  orbit.azimuth = options.azimuth_degrees;
  orbit.elevation = options.elevation_degrees;
  bool scene_drag = false;  // a left drag the scene took (a gizmo handle)
  size_t replay_next = 0;
  std::deque<double> frame_ms;
  ProgressiveState progressive;
  progressive.divisor = options.coarse_factor > 0 ? options.coarse_factor : 2.0;
  bool controls_changed = false;  // by the panel, during the previous frame
  std::optional<double> last_drag;
  core::Image8 exact_frame;  // with frame_out: the last exact frame
  FrameCamera exact_camera;
  FrameCamera last_full_camera;
  std::optional<scene::Scene> edited;  // --save-scene's, once the session ends
  int frame = 0;
  std::string error;
  const render::RenderTarget* shown = nullptr;
  while (!glfwWindowShouldClose(window)) {
    core::Stopwatch frame_watch;
    std::optional<ScriptedInput> input;
    input_queue.frame = frame;
    if (script) {
      input = script->input(frame);
      if (!input) break;
      glfwPollEvents();
    } else if (replay) {
      glfwPollEvents();
      FeedReplay(window, *replay, replay_next, frame);
    } else if (progressive.exact_shown && options.screenshot.empty()) {
      // At rest with the exact frame shown: sleep until the user acts (or
      // work in the background finishes, Scene::Poll).
      glfwWaitEventsTimeout(0.1);
    } else {
      glfwPollEvents();
    }
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    if (fb_w <= 0 || fb_h <= 0) continue;
    const auto full_camera_now = [&] {
      return OrbitCamera(scene.Centre(), scene.Radius(), orbit.azimuth, orbit.elevation,
                         orbit.distance_scale, options.fov_y_degrees, fb_w, fb_h, up);
    };

    ImGuiIO& io = ImGui::GetIO();
    if (input) {
      orbit.azimuth = input->azimuth_degrees;
      orbit.elevation = input->elevation_degrees;
      if (input->drag && input->drag != last_drag) {
        controls_changed |= scene.DragParameter(*input->drag);
        last_drag = input->drag;
      }
    }
    // This frame's events (live or replayed), in order. A left press the
    // panel does not want goes to the scene (a gizmo handle) or starts an
    // orbit; the wheel zooms; keys the panel does not want go to the scene.
    for (const InputEvent& e : input_queue.pending) {
      switch (e.type) {
        case InputEvent::Type::kMove:
          if (scene_drag) {
            controls_changed |= scene.PointerDrag(full_camera_now(), {e.x, e.y});
          } else if (orbit.dragging) {
            orbit.azimuth -= 0.4f * static_cast<float>(e.x - orbit.last_x);
            orbit.elevation = std::clamp(
                orbit.elevation + 0.4f * static_cast<float>(e.y - orbit.last_y), -89.0f, 89.0f);
          }
          orbit.last_x = e.x;
          orbit.last_y = e.y;
          break;
        case InputEvent::Type::kButton:
          if (e.code != GLFW_MOUSE_BUTTON_LEFT) break;
          if (e.action == InputEvent::Action::kPress && !io.WantCaptureMouse) {
            scene_drag =
                scene.PointerPress(full_camera_now(), {orbit.last_x, orbit.last_y}, e.mods);
            orbit.dragging = !scene_drag;
          } else if (e.action == InputEvent::Action::kRelease) {
            if (scene_drag) scene.PointerRelease();
            scene_drag = false;
            orbit.dragging = false;
          }
          break;
        case InputEvent::Type::kScroll:
          if (!io.WantCaptureMouse && e.y != 0) {
            orbit.distance_scale = std::clamp(
                orbit.distance_scale * std::pow(0.9f, static_cast<float>(e.y)), 0.2f, 20.0f);
          }
          break;
        case InputEvent::Type::kKey:
          if (e.action == InputEvent::Action::kPress && !io.WantCaptureKeyboard)
            controls_changed |= scene.Key(e.code);
          break;
      }
    }
    input_queue.pending.clear();
    controls_changed |= scene.Poll();

    // Moving: the pose, the window or an option changed since the last frame.
    const ViewKey key{orbit.azimuth, orbit.elevation, orbit.distance_scale, fb_w, fb_h};
    const bool moving = progressive.has_key && (key != progressive.key || controls_changed);
    controls_changed = false;
    const bool draw = moving || !progressive.exact_shown;
    // The first frame (no timing yet) and frames at rest are exact.
    const double divisor =
        moving ? (options.coarse_factor > 0 ? static_cast<double>(options.coarse_factor)
                                            : progressive.divisor)
               : 1.0;
    const FrameCamera full_camera = full_camera_now();
    last_full_camera = full_camera;
    const FrameCamera camera =
        divisor > 1 ? OrbitCamera(scene.Centre(), scene.Radius(), orbit.azimuth, orbit.elevation,
                                  orbit.distance_scale, options.fov_y_degrees,
                                  std::max(static_cast<int>(std::lround(fb_w / divisor)), 1),
                                  std::max(static_cast<int>(std::lround(fb_h / divisor)), 1), up)
                    : full_camera;
    double render_ms = 0;
    if (draw) {
      render::WaitForGpu();
      core::Stopwatch watch;
      try {
        if (!moving) scene.Settle();
        shown = &scene.Render(camera);
        render::WaitForGpu();
        error.clear();
      } catch (const core::InputError& e) {
        shown = nullptr;
        error = e.what();
      }
      render_ms = watch.ElapsedMs();
      frame_ms.push_back(render_ms);
      if (frame_ms.size() > 30) frame_ms.pop_front();
      progressive.key = key;
      progressive.has_key = true;
      progressive.exact_shown = !moving;
    }

    render::BindDefaultFramebuffer(fb_w, fb_h);
    render::ClearBoundFramebuffer({0.12f, 0.12f, 0.14f, 1.0f});

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    // The mouse as the events left it (see InputQueue).
    io.MousePos = input_queue.has_cursor ? ImVec2(static_cast<float>(input_queue.cursor.x),
                                                  static_cast<float>(input_queue.cursor.y))
                                         : ImVec2(-FLT_MAX, -FLT_MAX);
    for (int b = 0; b < 3; ++b) {
      io.MouseDown[b] = input_queue.down[b] || input_queue.pressed[b];
      input_queue.pressed[b] = false;
    }
    ImGui::NewFrame();
    if (shown) DrawFrameBehindPanel(*shown, fb_w, fb_h);
    if (options.panel) {
      ImDrawList* overlay = ImGui::GetBackgroundDrawList();
      for (const OverlayLine& l : scene.Overlay(full_camera))
        overlay->AddLine(ImVec2(l.a.x, l.a.y), ImVec2(l.b.x, l.b.y), l.colour, l.thickness);
      ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
      ImGui::SetNextWindowSize(ImVec2(400, 0), ImGuiCond_FirstUseEver);
      ImGui::Begin(scene.Title().c_str());
      const core::TimingStats stats = core::Summarize({frame_ms.begin(), frame_ms.end()});
      ImGui::Text("render %.1f ms (median of %d), %dx%d%s", stats.median_ms, stats.samples,
                  shown ? shown->width() : 0, shown ? shown->height() : 0,
                  progressive.exact_shown ? " (exact)" : " (reduced while moving)");
      const std::string status = scene.Status();
      if (!status.empty()) ImGui::TextUnformatted(status.c_str());
      if (!error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", error.c_str());
      ImGui::Separator();
      ImGui::SliderFloat("azimuth", &orbit.azimuth, -180, 180);
      ImGui::SliderFloat("elevation", &orbit.elevation, -89, 89);
      ImGui::SliderFloat("distance", &orbit.distance_scale, 0.2f, 5.0f);
      ImGui::Separator();
      controls_changed = scene.DrawControls();
      ImGui::End();
    }
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    ++frame;
    if (draw && !moving && shown) {
      if (!options.frame_out.empty()) exact_frame = shown->ReadColor8();
      exact_camera = camera;
    }
    // A replay ends at the first exact frame after its last event.
    const bool replay_done =
        replay && replay_next == replay->events.size() && draw && !moving && !scene_drag;
    // The edited scene is made before any output is written: an edit it
    // cannot hold stops the run with no file written.
    const auto edited_scene = [&] {
      if (!options.save_scene.empty() && !edited) edited = scene.EditedScene(full_camera);
    };
    if (!options.screenshot.empty() && frame >= options.frames) {
      edited_scene();
      SaveScreenshot(options, fb_w, fb_h, exact_frame, exact_camera);
      fmt::print("view: wrote {} after {} frames, last frame {:.1f} ms\n",
                 options.screenshot.string(), frame, frame_ms.empty() ? 0.0 : frame_ms.back());
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    }
    if (replay_done) {
      edited_scene();
      SaveExactFrame(options, exact_frame, exact_camera);
      fmt::print("view: replayed {} events in {} frames\n", replay->events.size(), frame);
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    }
    glfwSwapBuffers(window);
    render::WaitForGpu();
    const double whole_ms = frame_watch.ElapsedMs();
    if (draw && moving && options.coarse_factor == 0)
      progressive.Adapt(divisor, render_ms, whole_ms, options.motion_frame_ms);
    else if (draw && !moving && options.coarse_factor == 0)
      progressive.StartFrom(render_ms, options.motion_frame_ms);
    if (script && script->on_frame) {
      FrameReport report;
      report.frame = frame - 1;
      report.moving = draw && moving;
      report.exact = draw && !moving;
      report.drawn = draw;
      report.divisor = divisor;
      report.render_ms = render_ms;
      report.frame_ms = whole_ms;
      report.camera = camera;
      report.full_camera = full_camera;
      report.target = shown;
      report.scene = &scene;
      script->on_frame(report);
    }
  }
  if (!options.record.empty()) {
    WriteRecording(options.record, input_queue.recording);
    fmt::print("view: recorded {} events to {}\n", input_queue.recording.events.size(),
               options.record.string());
  }
  if (!options.save_scene.empty()) {
    scene::WriteScene(options.save_scene, edited ? *edited : scene.EditedScene(last_full_camera));
    fmt::print("view: saved the scene to {}\n", options.save_scene.string());
  }
  scene_owner.reset();  // GPU resources go while the context still exists
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
}

}  // namespace viewer
