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
#include "apps/ibr/viewer_flags.h"
#include "apps/viewer/input_events.h"
#include "apps/viewer/scenes.h"
#include "apps/viewer/viewer.h"
#include "capture/builtin_scenes.h"
#include "ibr/jobs/render_job.h"
#include "ibr/views.h"
#include "scene/scene.h"

namespace apps {
namespace {

struct ViewCommandOptions {
  std::filesystem::path dataset;
  ibr::DepthObjectFlags flags;
  std::string up;  // empty: a dataset's own (capture::DefaultUp), a scene's +y
  std::filesystem::path replay;
  viewer::ViewerOptions viewer;
};

void RunView(ViewCommandOptions& o) {
  if (!o.up.empty()) o.viewer.up = glm::vec3(ibr::ParseUp(o.up, "--up"));
  if (!o.replay.empty()) o.viewer.replay = viewer::ReadRecording(o.replay);
  if (!o.viewer.save_scene.empty() && o.dataset.extension() != ".json")
    core::ThrowInputError("ibr view", "--save-scene needs a scene file (SCENE.json)");
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
  AddViewerFlags(cmd, o.viewer);
  cmd->add_option("--up", o.up,
                  "the world's up: x, y, z, -x, -y, -z or 'X,Y,Z' (default: a dataset's "
                  "\"up\", else its cameras' mean up; a scene's +y)");
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
