#include "apps/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <fmt/format.h>
#include <imgui.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "core/timing.h"
#include "render/gl/context.h"
#include "render/gl/gl.h"

namespace viewer {

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
  if (coarse_factor < 1 || coarse_factor > 8) {
    core::ThrowInputError("ViewerOptions", "coarse factor {} outside 1..8", coarse_factor);
  }
  if (!(std::abs(glm::length(up) - 1.0f) < 1e-4f))
    core::ThrowInputError("ViewerOptions", "up ({}, {}, {}) is not a unit vector", up.x, up.y,
                          up.z);
}

FrameCamera OrbitCamera(glm::vec3 centre, float radius, float azimuth_degrees,
                        float elevation_degrees, float distance_scale, float fov_y_degrees,
                        int width, int height, glm::vec3 up) {
  const float az = glm::radians(azimuth_degrees);
  // Clamp short of the poles so the up vector stays defined.
  const float el = glm::radians(std::clamp(elevation_degrees, -89.0f, 89.0f));
  const float fov = glm::radians(fov_y_degrees);
  const float distance = distance_scale * radius / std::sin(0.5f * fov);
  // Orbit frame: e0, e1 span the plane orthogonal to the pole `up`.
  const glm::vec3 helper = std::abs(up.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::vec3 e0 = glm::normalize(glm::cross(helper, up));
  const glm::vec3 e1 = glm::cross(up, e0);
  const glm::vec3 eye = centre + distance * (std::cos(el) * std::cos(az) * e0 +
                                             std::cos(el) * std::sin(az) * e1 + std::sin(el) * up);
  FrameCamera camera;
  camera.cam_from_world = core::CamFromWorldLookAt(eye, centre, up);
  camera.fx = camera.fy = 0.5 * height / std::tan(0.5 * fov);
  camera.cx = 0.5 * width;
  camera.cy = 0.5 * height;
  camera.width = width;
  camera.height = height;
  camera.near =
      std::max(1e-4, std::max(1e-3 * distance, static_cast<double>(distance - 2.0f * radius)));
  camera.far = distance + 4.0 * radius;
  camera.clip_from_cam = core::ClipFromCamPerspective(camera.fx, camera.fy, camera.cx, camera.cy,
                                                      width, height, camera.near, camera.far);
  return camera;
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

}  // namespace

void Run(const SceneFactory& make_scene, const ViewerOptions& options) {
  options.Check();
  GlfwSession glfw;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, options.screenshot.empty() ? GLFW_TRUE : GLFW_FALSE);
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
  glfwSwapInterval(options.screenshot.empty() ? 1 : 0);
  const render::GlInfo info =
      render::InitializeCurrentContext("window", render::HeadlessContextOptions::DefaultDebug());
  spdlog::info("viewer: {} | {}", info.version, info.renderer);
  std::unique_ptr<Scene> scene_owner = make_scene();
  Scene& scene = *scene_owner;
  glfwSetWindowTitle(window, scene.Title().c_str());

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
  std::deque<double> frame_ms;
  int frame = 0;
  std::string error;
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    if (fb_w <= 0 || fb_h <= 0) continue;

    // Orbit with the left mouse button (when ImGui does not want the mouse), zoom with the wheel.
    ImGuiIO& io = ImGui::GetIO();
    if (!io.WantCaptureMouse) {
      double x = 0, y = 0;
      glfwGetCursorPos(window, &x, &y);
      const bool down = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
      if (down && orbit.dragging) {
        orbit.azimuth -= 0.4f * static_cast<float>(x - orbit.last_x);
        orbit.elevation = std::clamp(orbit.elevation + 0.4f * static_cast<float>(y - orbit.last_y),
                                     -89.0f, 89.0f);
      }
      orbit.dragging = down;
      orbit.last_x = x;
      orbit.last_y = y;
      if (io.MouseWheel != 0)
        orbit.distance_scale =
            std::clamp(orbit.distance_scale * std::pow(0.9f, io.MouseWheel), 0.2f, 20.0f);
    }

    // Coarse frames while the mouse drags; the full frame when it stops.
    const int scale = orbit.dragging ? options.coarse_factor : 1;
    const FrameCamera camera = OrbitCamera(
        scene.Centre(), scene.Radius(), orbit.azimuth, orbit.elevation, orbit.distance_scale,
        options.fov_y_degrees, std::max(fb_w / scale, 1), std::max(fb_h / scale, 1), up);
    glFinish();
    core::Stopwatch watch;
    const render::RenderTarget* target = nullptr;
    try {
      target = &scene.Render(camera);
      glFinish();
      error.clear();
    } catch (const core::InputError& e) {
      error = e.what();
    }
    frame_ms.push_back(watch.ElapsedMs());
    if (frame_ms.size() > 30) frame_ms.pop_front();

    render::BindDefaultFramebuffer(fb_w, fb_h);
    glClearColor(0.12f, 0.12f, 0.14f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    if (target) {
      glBlitNamedFramebuffer(target->framebuffer().id(), 0, 0, 0, target->width(), target->height(),
                             0, 0, fb_w, fb_h, GL_COLOR_BUFFER_BIT,
                             scale > 1 ? GL_LINEAR : GL_NEAREST);
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (options.panel) {
      ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
      ImGui::SetNextWindowSize(ImVec2(400, 0), ImGuiCond_FirstUseEver);
      ImGui::Begin(scene.Title().c_str());
      const core::TimingStats stats = core::Summarize({frame_ms.begin(), frame_ms.end()});
      ImGui::Text("frame %.1f ms (median of %d), %dx%d%s", stats.median_ms, stats.samples,
                  camera.width, camera.height, scale > 1 ? " (coarse while dragging)" : "");
      const std::string status = scene.Status();
      if (!status.empty()) ImGui::TextUnformatted(status.c_str());
      if (!error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", error.c_str());
      ImGui::Separator();
      ImGui::SliderFloat("azimuth", &orbit.azimuth, -180, 180);
      ImGui::SliderFloat("elevation", &orbit.elevation, -89, 89);
      ImGui::SliderFloat("distance", &orbit.distance_scale, 0.2f, 5.0f);
      ImGui::Separator();
      scene.DrawControls();
      ImGui::End();
    }
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    ++frame;
    if (!options.screenshot.empty() && frame >= options.frames) {
      core::Image8 shot(fb_w, fb_h, 4);
      glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
      glReadBuffer(GL_BACK);
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, fb_w, fb_h, GL_RGBA, GL_UNSIGNED_BYTE, shot.data());
      for (int y = 0; y < fb_h / 2; ++y) {
        auto top = shot.row(y);
        auto bottom = shot.row(fb_h - 1 - y);
        std::swap_ranges(top.begin(), top.end(), bottom.begin());
      }
      for (int y = 0; y < fb_h; ++y)
        for (int x = 0; x < fb_w; ++x) shot.at(x, y, 3) = 255;
      core::WriteImage(options.screenshot, shot);
      fmt::print("view: wrote {} after {} frames, last frame {:.1f} ms\n",
                 options.screenshot.string(), frame, frame_ms.back());
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    }
    glfwSwapBuffers(window);
  }
  scene_owner.reset();  // GPU resources go while the context still exists
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
}

}  // namespace viewer
