// `ibr view DATASET`: the interactive viewer on a dataset's depth object or
// visual hull. Orbit with the mouse; switch method, slicing, slice count,
// texturing and the robust k in the panel; the frame time is shown.
// `ibr view SCENE.json`: any scene file (scene/scene.h) through
// ibr::SceneRenderer, the panel listing its objects and passes.
#ifdef IBR_HAVE_VIEWER

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "apps/ibr/commands.h"
#include "apps/viewer/viewer.h"
#include "capture/builtin_scenes.h"
#include "capture/dataset.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/scene_renderer.h"
#include "render/gl/shader_program.h"

namespace apps {
namespace {

struct ViewCommandOptions {
  ViewCommandOptions() { flags.slicing = "ray"; }  // the fastest path (empty-space skipping)
  std::filesystem::path dataset;
  ibr::DepthObjectFlags flags;
  std::string window = "960x720";
  viewer::ViewerOptions viewer;
};

class DatasetScene : public viewer::Scene {
 public:
  DatasetScene(const ibr::DepthObjectOptions& options, ibr::MapSet maps, std::string name)
      : name_(std::move(name)), renderer_(programs_, std::move(maps)), options_(options) {
    options_.background = {0.12f, 0.12f, 0.14f, 1.0f};
    options_.Check();
    const glm::dmat4& m = renderer_.maps().world_from_box;
    centre_ = glm::vec3(m * glm::dvec4(0.5, 0.5, 0.5, 1.0));
    radius_ = 0.5f * static_cast<float>(glm::length(glm::dvec3(m * glm::dvec4(1, 1, 1, 0))));
  }

  std::string Title() const override { return "ibr view: " + name_; }
  glm::vec3 Centre() const override { return centre_; }
  float Radius() const override { return radius_; }

  void DrawControls() override {
    int method = options_.method == ibr::Method::kDepthObject ? 0 : 1;
    if (ImGui::Combo("method", &method, "depth object\0visual hull\0")) {
      options_.method = method == 0 ? ibr::Method::kDepthObject : ibr::Method::kVisualHull;
    }
    int slicing = static_cast<int>(options_.slicing);
    if (ImGui::Combo("slicing", &slicing, "orthogonal\0screen\0ray\0")) {
      options_.slicing = static_cast<ibr::Slicing>(slicing);
    }
    bool fast = options_.slice_path == ibr::SlicePath::kFast;
    if (ImGui::Checkbox("fast slices (one draw)", &fast)) {
      options_.slice_path = fast ? ibr::SlicePath::kFast : ibr::SlicePath::kExact;
    }
    ImGui::SameLine();
    ImGui::Checkbox("sub-texel depth (ray)", &options_.subtexel_depth);
    ImGui::SliderInt("slices (0 = auto)", &options_.slices, 0, 512);
    int texturing = static_cast<int>(options_.texturing);
    if (ImGui::Combo("texturing", &texturing, "view-dependent\0visibility\0none\0paper blend\0")) {
      options_.texturing = static_cast<ibr::Texturing>(texturing);
    }
    const int maps = static_cast<int>(renderer_.maps().maps.size());
    ImGui::SliderInt("robust k", &options_.robust_k, 0, std::max(0, maps - 1));
  }

  const render::RenderTarget& Render(const viewer::FrameCamera& camera) override {
    if (!output_ || output_->width() != camera.width || output_->height() != camera.height) {
      output_ = std::make_unique<render::RenderTarget>(
          ibr::DepthObjectRenderer::OutputTargetOptions(camera.width, camera.height));
    }
    ibr::ViewCamera view;
    view.camera = ibr::MapCamera::Pinhole(camera.width, camera.height, camera.fx, camera.fy,
                                          camera.cx, camera.cy);
    view.cam_from_world = glm::dmat4(camera.cam_from_world);
    renderer_.Render(view, options_, *output_);
    return *output_;
  }

  std::string Status() const override {
    return fmt::format(
        "{} maps, {} {}{} path, {} slices{}", renderer_.maps().maps.size(),
        ibr::MethodName(options_.method), ibr::SlicingName(options_.slicing),
        options_.slicing != ibr::Slicing::kRay && options_.slice_path == ibr::SlicePath::kFast
            ? " fast"
            : "",
        ibr::SliceCountName(options_.slices),
        options_.slicing == ibr::Slicing::kRay && options_.method == ibr::Method::kDepthObject &&
                options_.subtexel_depth
            ? ", sub-texel"
            : "");
  }

 private:
  std::string name_;
  render::ProgramCache programs_;
  ibr::DepthObjectRenderer renderer_;
  ibr::DepthObjectOptions options_;
  std::unique_ptr<render::RenderTarget> output_;
  glm::vec3 centre_{0};
  float radius_ = 1;
};

// A scene file: every enabled object drawn by ibr::SceneRenderer into its
// frame target (the headless path of `ibr render SCENE.json`), shown as is.
class SceneFileScene : public viewer::Scene {
 public:
  explicit SceneFileScene(const scene::Scene& file)
      : title_("ibr view: " + file.name),
        loaded_(ibr::LoadScene(programs_, file)),
        renderer_(programs_, loaded_) {
    const capture::Bounds& b = loaded_.bounds;
    centre_ = glm::vec3(0.5 * (b.min + b.max));
    radius_ = 0.5f * static_cast<float>(glm::length(b.max - b.min));
    for (const scene::Object& o : file.objects) {
      objects_.push_back(fmt::format("{} ({}){}", o.name, scene::ObjectTypeName(o.type),
                                     o.enabled ? "" : ": disabled"));
    }
    passes_ = renderer_.PassNames();
  }

  std::string Title() const override { return title_; }
  glm::vec3 Centre() const override { return centre_; }
  float Radius() const override { return radius_; }

  void DrawControls() override {
    ImGui::TextUnformatted("objects:");
    for (const std::string& o : objects_) ImGui::BulletText("%s", o.c_str());
    ImGui::TextUnformatted("passes:");
    for (const std::string& p : passes_) ImGui::BulletText("%s", p.c_str());
  }

  const render::RenderTarget& Render(const viewer::FrameCamera& camera) override {
    ibr::ViewCamera view;
    view.camera = ibr::MapCamera::Pinhole(camera.width, camera.height, camera.fx, camera.fy,
                                          camera.cx, camera.cy);
    view.cam_from_world = glm::dmat4(camera.cam_from_world);
    return renderer_.Draw(view);
  }

  std::string Status() const override {
    return fmt::format("{} objects drawn, {} disabled", loaded_.objects.size(),
                       loaded_.disabled.size());
  }

 private:
  std::string title_;
  render::ProgramCache programs_;
  ibr::LoadedScene loaded_;
  ibr::SceneRenderer renderer_;
  std::vector<std::string> objects_, passes_;
  glm::vec3 centre_{0};
  float radius_ = 1;
};

// `ibr view SCENE.json`: the file's schema is checked before a window opens;
// its objects load with the window's context current (captures render).
void RunSceneView(const ViewCommandOptions& o) {
  const scene::Scene file = scene::ReadScene(o.dataset, capture::DefaultSharedDataDir());
  viewer::Run([&] { return std::make_unique<SceneFileScene>(file); }, o.viewer);
}

void RunView(ViewCommandOptions& o) {
  int w = 0, h = 0;
  char x = 0;
  if (std::sscanf(o.window.c_str(), "%d%c%d", &w, &x, &h) != 3 || x != 'x') {
    core::ThrowInputError("ibr view", "--window '{}' is not WIDTHxHEIGHT", o.window);
  }
  o.viewer.width = w;
  o.viewer.height = h;
  o.viewer.Check();
  if (o.dataset.extension() == ".json") return RunSceneView(o);
  // Validate everything before a window opens.
  const ibr::DepthObjectOptions options =
      ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(o.flags));
  // The map limit is checked on the manifest, before any image is read.
  const capture::Dataset dataset = ibr::ReadMapDataset(o.dataset);
  ibr::MapSet maps = ibr::MapsFromDataset(dataset);
  const std::string name = o.dataset.filename().empty()
                               ? o.dataset.parent_path().filename().string()
                               : o.dataset.filename().string();
  viewer::Run([&] { return std::make_unique<DatasetScene>(options, std::move(maps), name); },
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
  cmd->add_option("--up", o.viewer.up, "the world's up axis: x, y, z, -x, -y, -z")
      ->capture_default_str();
  cmd->add_option("--coarse", o.viewer.coarse_factor,
                  "resolution divisor while the mouse drags (1 = off)")
      ->capture_default_str();
  cmd->callback([] { RunView(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("view", AddViewCommand);

}  // namespace apps

#endif  // IBR_HAVE_VIEWER
