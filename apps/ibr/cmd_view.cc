// `ibr view DATASET`: the interactive viewer on a dataset's depth object or
// visual hull (ibr::LoadDatasetObject), switching its options in the panel.
// `ibr view SCENE.json`: any scene file through ibr::SceneRenderer, the panel
// editing deform and volume objects. Progressive: reduced frames while
// anything moves, the exact frame (`ibr render`'s) at rest. Window: viewer::Run.
#ifdef IBR_HAVE_VIEWER

#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "apps/ibr/commands.h"
#include "apps/viewer/scenes.h"
#include "apps/viewer/viewer.h"
#include "capture/builtin_scenes.h"
#include "ibr/dataset_render.h"
#include "ibr/views.h"
#include "scene/scene.h"

namespace apps {
namespace {

struct ViewCommandOptions {
  std::filesystem::path dataset;
  ibr::DepthObjectFlags flags;
  std::string up;  // empty: a dataset's own (capture::DefaultUp), a scene's +y
  viewer::ViewerOptions viewer;
};

void RunView(ViewCommandOptions& o) {
  if (!o.up.empty()) o.viewer.up = glm::vec3(ibr::ParseUp(o.up, "--up"));
  o.viewer.Check();
  if (o.dataset.extension() == ".json") {
    // The file's schema is checked before a window opens; its objects load
    // with the window's context current (captures render).
    const scene::Scene file = scene::ReadScene(o.dataset, capture::DefaultSharedDataDir());
    return viewer::Run([&] { return std::make_unique<viewer::SceneFileScene>(file); }, o.viewer);
  }
  // Everything is validated before a window opens.
  ibr::DatasetObject object = ibr::LoadDatasetObject(
      o.dataset, ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(o.flags)),
      o.flags.outside.empty(), [](const std::string& line) { fmt::print("view: {}\n", line); });
  if (o.up.empty()) {
    o.viewer.up = glm::vec3(object.up.up);
    fmt::print("view: up ({:.3f}, {:.3f}, {:.3f}) from {} (--up to change)\n", object.up.up.x,
               object.up.up.y, object.up.up.z, object.up.source);
  }
  viewer::Run(
      [&] { return viewer::MakeDatasetScene(object.options, std::move(object.maps), object.name); },
      o.viewer);
}

void AddViewCommand(CLI::App& app) {
  static ViewCommandOptions o;
  auto* cmd = app.add_subcommand(
      "view",
      "Interactive viewer (GLFW + Dear ImGui) of a dataset's depth object or visual hull, or of "
      "a scene file");
  cmd->add_option("DATASET", o.dataset,
                  "dataset directory (dataset.json), or a scene file SCENE.json (every object "
                  "type; the depth-object flags then do not apply)")
      ->required();
  AddDepthObjectFlags(cmd, o.flags);
  AddWindowFlag(cmd, "ibr view", o.viewer.width, o.viewer.height);
  cmd->add_option("--azimuth", o.viewer.azimuth_degrees, "initial orbit azimuth, degrees")
      ->capture_default_str();
  cmd->add_option("--elevation", o.viewer.elevation_degrees, "initial orbit elevation, degrees")
      ->capture_default_str();
  cmd->add_option("--screenshot", o.viewer.screenshot,
                  "render --frames frames, save the window to this PNG and exit (no interaction)");
  cmd->add_option("--frames", o.viewer.frames, "frames before the screenshot")
      ->capture_default_str();
  cmd->add_option("--up", o.up,
                  "the world's up: x, y, z, -x, -y, -z or 'X,Y,Z' (default: a dataset's "
                  "\"up\", else its cameras' mean up; a scene's +y)");
  cmd->add_flag("--no-panel{false}", o.viewer.panel,
                "hide the control panel (screenshots of the object alone)");
  cmd->add_option("--coarse", o.viewer.coarse_factor,
                  "resolution divisor while the view or a parameter moves: 0 = adaptive (frames "
                  "of about --motion-ms), N = fixed, 1 = always full resolution")
      ->capture_default_str();
  cmd->add_option("--motion-ms", o.viewer.motion_frame_ms,
                  "adaptive divisor: the frame time, in milliseconds, a moving frame aims at")
      ->capture_default_str();
  cmd->add_option("--frame-out", o.viewer.frame_out,
                  "with --screenshot: also save the last exact frame (RGBA PNG, no panel)");
  cmd->add_option("--camera-out", o.viewer.camera_out,
                  "with --screenshot: also save its camera (a cameras-only dataset.json for "
                  "`ibr render --cameras`)");
  cmd->callback([] { RunView(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("view", AddViewCommand);

}  // namespace apps

#endif  // IBR_HAVE_VIEWER
