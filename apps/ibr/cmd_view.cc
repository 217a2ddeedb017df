// `ibr view DATASET`: the interactive viewer on a dataset's depth object or
// visual hull. Orbit with the mouse; switch method, slicing, slice count,
// texturing and the robust k in the panel; the frame time is shown.
// `ibr view SCENE.json`: any scene file (scene/scene.h) through
// ibr::SceneRenderer, the panel listing its objects and passes and editing
// deform and volume objects' parameters.
#ifdef IBR_HAVE_VIEWER

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
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
#include "ibr/views.h"
#include "render/gl/shader_program.h"

namespace apps {
namespace {

struct ViewCommandOptions {
  std::filesystem::path dataset;
  ibr::DepthObjectFlags flags;
  std::string window = "960x720";
  std::string up;  // empty: a dataset's own (capture::DefaultUp), a scene's +y
  bool no_panel = false;
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

// A combo box over `values`, labelled by `name`; true when the choice changed.
template <typename T, typename NameOf>
bool ComboOf(const char* label, T& current, std::initializer_list<T> values, NameOf name) {
  bool changed = false;
  if (ImGui::BeginCombo(label, std::string(name(current)).c_str())) {
    for (T v : values) {
      if (ImGui::Selectable(std::string(name(v)).c_str(), v == current) && v != current) {
        current = v;
        changed = true;
      }
    }
    ImGui::EndCombo();
  }
  return changed;
}

// A float slider over a double option (clamped to [lo, hi], typed values too).
bool SliderDouble(const char* label, double& value, float lo, float hi, const char* format) {
  float v = static_cast<float>(value);
  if (!ImGui::SliderFloat(label, &v, lo, hi, format, ImGuiSliderFlags_AlwaysClamp)) return false;
  value = v;
  return true;
}

// Slider range of a deformation's amount and width per kind (the values
// core::Deformation::Check accepts, narrowed to what is worth dragging
// through); width {0, 0}: unused.
struct DeformationRanges {
  float amount_lo, amount_hi, width_lo, width_hi;
};
DeformationRanges RangesOf(core::DeformationKind kind) {
  switch (kind) {
    case core::DeformationKind::kTwist:
      return {-6.3f, 6.3f, 0.0f, 0.5f};
    case core::DeformationKind::kBend:
      return {-3.14f, 3.14f, 0.0f, 0.0f};
    case core::DeformationKind::kPull:
      return {-1.0f, 1.0f, 0.005f, 0.3f};
    case core::DeformationKind::kKnife:
      return {0.01f, 0.5f, 0.05f, 1.0f};
    case core::DeformationKind::kPeel:
      return {0.0f, 3.14f, 0.02f, 0.5f};
    case core::DeformationKind::kClip:
    case core::DeformationKind::kCutaway:
      return {0.0f, 1.0f, 0.0f, 0.0f};
    case core::DeformationKind::kWedge:
      return {0.05f, 3.14f, 0.0f, 1.0f};
  }
  return {0, 1, 0, 1};
}

// A scene file: every enabled object drawn by ibr::SceneRenderer into its
// frame target (the headless path of `ibr render SCENE.json`). The panel
// lists the objects and passes and shows each deform and volume object's
// cheap-to-change options as controls; a change goes to
// SceneRenderer::UpdateDeform / UpdateVolume, which rebuild only what it
// invalidates and reject invalid options (the error shows in the panel).
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
  }

  std::string Title() const override { return title_; }
  glm::vec3 Centre() const override { return centre_; }
  float Radius() const override { return radius_; }

  void DrawControls() override {
    ImGui::TextUnformatted("objects:");
    for (const std::string& o : objects_) ImGui::BulletText("%s", o.c_str());
    ImGui::TextUnformatted("passes:");
    for (const std::string& p : renderer_.PassNames()) ImGui::BulletText("%s", p.c_str());
    if (!error_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", error_.c_str());
    for (size_t i = 0; i < loaded_.objects.size(); ++i) {
      const ibr::LoadedObject& o = loaded_.objects[i];
      if (o.type != scene::ObjectType::kDeform && o.type != scene::ObjectType::kVolume) continue;
      ImGui::PushID(static_cast<int>(i));
      const std::string header = fmt::format("{} ({})", o.name, scene::ObjectTypeName(o.type));
      if (ImGui::CollapsingHeader(header.c_str(), ImGuiTreeNodeFlags_DefaultOpen)) {
        try {
          if (o.type == scene::ObjectType::kDeform) {
            DeformControls(i);
          } else {
            VolumeControls(i);
          }
        } catch (const core::InputError& e) {
          error_ = e.what();  // the object is unchanged
        }
      }
      ImGui::PopID();
    }
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
  // Per deformation: kind, amount, width; cut and thickness; step policy,
  // threshold and base step; skip; the implicit (shown).
  void DeformControls(size_t index) {
    const ibr::LoadedObject& object = loaded_.objects[index];
    ibr::DeformObjectOptions o = object.deform_options;
    bool changed = false;
    for (size_t t = 0; t < o.deformation.terms.size(); ++t) {
      core::Deformation& d = o.deformation.terms[t];
      ImGui::PushID(static_cast<int>(t));
      ImGui::Text("deformation %zu: %s", t + 1, core::DeformationKindName(d.kind).c_str());
      const DeformationRanges r = RangesOf(d.kind);
      changed |= SliderDouble("amount", d.amount, r.amount_lo, r.amount_hi, "%.3f");
      if (r.width_hi > r.width_lo)
        changed |= SliderDouble("width", d.width, r.width_lo, r.width_hi, "%.3f");
      ImGui::PopID();
    }
    render::DeformPassOptions& pass = o.pass;
    changed |= ComboOf("cut", pass.cut,
                       {core::CutMode::kNone, core::CutMode::kHollow, core::CutMode::kSolid,
                        core::CutMode::kThick},
                       core::CutModeName);
    if (pass.cut == core::CutMode::kThick) {
      changed |= ImGui::SliderFloat("thickness", &pass.thickness, 0.005f, 0.3f, "%.3f",
                                    ImGuiSliderFlags_AlwaysClamp);
    }
    if (pass.cut == core::CutMode::kSolid || pass.cut == core::CutMode::kThick)
      changed |= ImGui::Checkbox("solid by search (sec. 5.1.2)", &pass.solid_search);
    changed |= ComboOf("step", pass.step_policy,
                       {render::RayStepPolicy::kFixed, render::RayStepPolicy::kThreshold,
                        render::RayStepPolicy::kJacobian},
                       render::RayStepPolicyName);
    if (pass.step_policy == render::RayStepPolicy::kThreshold) {
      changed |= ImGui::SliderFloat("threshold", &pass.threshold, 0.001f, 0.2f, "%.3f",
                                    ImGuiSliderFlags_AlwaysClamp);
    }
    changed |= ImGui::SliderFloat("step voxels", &pass.step_voxels, 0.25f, 4.0f, "%.2f",
                                  ImGuiSliderFlags_AlwaysClamp);
    changed |= ImGui::Checkbox("skip empty space (cut)", &pass.skip_empty);
    changed |= ImGui::Checkbox("skip by the distance field", &pass.skip_object);
    const ibr::DeformObjectData& data = *object.deform;
    if (pass.implicit == render::DeformImplicit::kDepthCube) {
      ImGui::Text("implicit: depth cube, 6 maps of %d px (built %dx, %.2f s)", o.sdf_resolution,
                  data.implicit_builds, data.sdf_seconds);
    } else {
      ImGui::Text("implicit: sdf %dx%dx%d, reach %.3f (built %dx, %.2f s)", data.sdf.size.x,
                  data.sdf.size.y, data.sdf.size.z, data.sdf_reach, data.implicit_builds,
                  data.sdf_seconds);
    }
    if (changed) {
      renderer_.UpdateDeform(loaded_, index, o);
      error_.clear();
    }
  }

  // The effect's main parameter; lighting; mode and iso value; spacing.
  void VolumeControls(size_t index) {
    ibr::VolumeObjectOptions o = loaded_.objects[index].volume_options;
    bool changed = false;
    if (o.effect) {
      core::EffectOptions& e = *o.effect;
      ImGui::Text("effect: %s", std::string(core::EffectName(e.effect)).c_str());
      switch (e.effect) {
        case core::Effect::kPeel:
          changed |= SliderDouble("peel angle (deg)", e.peel_angle_deg, 0, 180, "%.1f");
          break;
        case core::Effect::kSlices:
          changed |= SliderDouble("slice gap", e.slices_gap, 0,
                                  0.95f * static_cast<float>(e.slices_period), "%.3f");
          break;
        case core::Effect::kSeam:
          changed |= SliderDouble("seam width", e.seam_width, 0, 1, "%.3f");
          break;
        case core::Effect::kPull:
          changed |= SliderDouble("pull sigma", e.pull_sigma, 0.02f, 0.5f, "%.3f");
          break;
        case core::Effect::kWave:
          changed |= SliderDouble("wave amplitude", e.wave_amplitude, -0.2f, 0.2f, "%.3f");
          break;
        case core::Effect::kClip:
          changed |= SliderDouble("clip height", e.clip_height, 0, 1, "%.3f");
          break;
        case core::Effect::kCutaway:
          changed |= SliderDouble("cutaway corner", e.cutaway_corner, 0, 1, "%.3f");
          break;
        case core::Effect::kWedge:
          changed |= SliderDouble("wedge angle (deg)", e.wedge_angle_deg, 1, 180, "%.1f");
          break;
      }
    } else {
      ImGui::TextUnformatted("effect: none");
    }
    render::VolumePassOptions& pass = o.pass;
    changed |= ComboOf("lighting", pass.lighting,
                       {render::VolumeLighting::kNone, render::VolumeLighting::kGradient,
                        render::VolumeLighting::kTransformed, render::VolumeLighting::kBlended},
                       render::VolumeLightingName);
    changed |=
        ComboOf("mode", pass.mode, {render::VolumeMode::kDvr, render::VolumeMode::kIso},
                [](render::VolumeMode m) { return m == render::VolumeMode::kDvr ? "dvr" : "iso"; });
    if (pass.mode == render::VolumeMode::kIso)
      changed |= SliderDouble("iso value", pass.iso_value, 0, 1, "%.3f");
    changed |= SliderDouble("spacing (voxels)", pass.sampling_distance_voxels, 0.25f, 4, "%.2f");
    if (changed) {
      renderer_.UpdateVolume(loaded_, index, o);
      error_.clear();
    }
  }

  std::string title_;
  render::ProgramCache programs_;
  ibr::LoadedScene loaded_;
  ibr::SceneRenderer renderer_;
  std::vector<std::string> objects_;
  std::string error_;  // the last rejected change
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
  o.viewer.panel = !o.no_panel;
  if (!o.up.empty()) o.viewer.up = glm::vec3(ibr::ParseUp(o.up, "--up"));
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
  cmd->add_option("--up", o.up,
                  "the world's up: x, y, z, -x, -y, -z or 'X,Y,Z' (default: a dataset's "
                  "\"up\", else its cameras' mean up; a scene's +y)");
  cmd->add_flag("--no-panel", o.no_panel,
                "hide the control panel (screenshots of the object alone)");
  cmd->add_option("--coarse", o.viewer.coarse_factor,
                  "resolution divisor while the mouse drags (1 = off)")
      ->capture_default_str();
  cmd->callback([] { RunView(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("view", AddViewCommand);

}  // namespace apps

#endif  // IBR_HAVE_VIEWER
