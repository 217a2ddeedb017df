// `ibr view DATASET`: the interactive viewer on a dataset's depth object or
// visual hull. Orbit with the mouse; switch method, slicing, slice count,
// texturing and the robust k in the panel; the frame time is shown.
// `ibr view SCENE.json`: any scene file (scene/scene.h) through
// ibr::SceneRenderer, the panel listing its objects and passes and editing
// deform and volume objects' parameters. Progressive: reduced frames while
// anything moves, the exact frame (`ibr render`'s from the same camera) at rest.
#ifdef IBR_HAVE_VIEWER

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>

#include "apps/ibr/commands.h"
#include "apps/viewer/input_events.h"
#include "apps/viewer/scenes.h"
#include "apps/viewer/viewer.h"
#include "capture/builtin_scenes.h"
#include "capture/dataset.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/views.h"
#include "scene/scene.h"

namespace apps {
namespace {

struct ViewCommandOptions {
  std::filesystem::path dataset;
  ibr::DepthObjectFlags flags;
  std::string window = "960x720";
  std::string up;  // empty: a dataset's own (capture::DefaultUp), a scene's +y
  bool no_panel = false;
  std::filesystem::path replay;
  viewer::ViewerOptions viewer;
};

// `ibr view SCENE.json`: the file's schema is checked before a window opens;
// its objects load with the window's context current (captures render).
void RunSceneView(const ViewCommandOptions& o) {
  const scene::Scene file = scene::ReadScene(o.dataset, capture::DefaultSharedDataDir());
  viewer::Run([&] { return std::make_unique<viewer::SceneFileScene>(file); }, o.viewer);
}

void RunView(ViewCommandOptions& o) {
  int w = 0, h = 0;
  char x = 0;
  if (std::sscanf(o.window.c_str(), "%d%c%d", &w, &x, &h) != 3 || x != 'x') {
    core::ThrowInputError("ibr view", "--window '{}' is not WIDTHxHEIGHT", o.window);
  }
  o.viewer.width = w;
  o.viewer.height = h;
  o.viewer.panel = !o.no_panel;
  if (!o.up.empty()) o.viewer.up = glm::vec3(ibr::ParseUp(o.up, "--up"));
  if (!o.replay.empty()) o.viewer.replay = viewer::ReadRecording(o.replay);
  if (!o.viewer.save_scene.empty() && o.dataset.extension() != ".json")
    core::ThrowInputError("ibr view", "--save-scene needs a scene file (SCENE.json)");
  o.viewer.Check();
  if (o.dataset.extension() == ".json") return RunSceneView(o);
  // Validate everything before a window opens.
  ibr::DepthObjectOptions options = ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(o.flags));
  // The map limit is checked on the manifest, before any image is read.
  const capture::Dataset dataset = ibr::ReadMapDataset(o.dataset);
  if (o.up.empty()) {
    const capture::UpChoice up = capture::DefaultUp(dataset);
    o.viewer.up = glm::vec3(up.up);
    fmt::print("view: up ({:.3f}, {:.3f}, {:.3f}) from {} (--up to change)\n", up.up.x, up.up.y,
               up.up.z, up.source);
  }
  ibr::MapSet maps = ibr::MapsFromDataset(dataset);
  if (o.flags.outside.empty()) {
    const ibr::OutsideChoice choice = ibr::ChooseOutsidePolicy(maps);
    options.outside = choice.policy;
    fmt::print("view: {}\n", choice.reason);
  }
  const std::string name = o.dataset.filename().empty()
                               ? o.dataset.parent_path().filename().string()
                               : o.dataset.filename().string();
  viewer::Run([&] { return viewer::MakeDatasetScene(options, std::move(maps), name); }, o.viewer);
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
  cmd->add_option("--window", o.window, "window size WIDTHxHEIGHT in pixels")
      ->capture_default_str();
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
  cmd->add_flag("--no-panel", o.no_panel,
                "hide the control panel (screenshots of the object alone)");
  cmd->add_option("--coarse", o.viewer.coarse_factor,
                  "resolution divisor while the view or a parameter moves: 0 = adaptive (frames "
                  "of about --motion-ms), N = fixed, 1 = always full resolution")
      ->capture_default_str();
  cmd->add_option("--motion-ms", o.viewer.motion_frame_ms,
                  "adaptive divisor: the frame time, in milliseconds, a moving frame aims at")
      ->capture_default_str();
  cmd->add_option("--frame-out", o.viewer.frame_out,
                  "with --screenshot or --replay: also save the last exact frame (RGBA PNG, no "
                  "panel)");
  cmd->add_option("--camera-out", o.viewer.camera_out,
                  "with --screenshot or --replay: also save its camera (a cameras-only "
                  "dataset.json for "
                  "`ibr render --cameras`)");
  cmd->add_option("--record", o.viewer.record,
                  "write the session's mouse and key events to this JSON file when the window "
                  "closes (docs/guide/viewer.md)");
  cmd->add_option("--replay", o.replay,
                  "replay recorded events (--record) through the same handlers in a hidden "
                  "window, then exit at the exact frame (with --frame-out, --camera-out, "
                  "--save-scene)");
  cmd->add_option("--save-scene", o.viewer.save_scene,
                  "on exit, save the scene as edited, its camera the window's, to this JSON file "
                  "(`ibr render` of it draws the viewer's exact frame)");
  cmd->callback([] { RunView(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("view", AddViewCommand);

}  // namespace apps

#endif  // IBR_HAVE_VIEWER
