#include "apps/viewer/scenes.h"

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>

#include "apps/viewer/scene_edits.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/kinds/depth_object_kind.h"

namespace viewer {

ibr::ViewCamera ViewCameraOf(const FrameCamera& camera) {
  return ibr::NamedViewsFromDataset(CamerasOf(camera)).front().view;
}

namespace {

// The options are `ibr render`'s (its background too: the viewer draws the
// frame over its own).
class DatasetScene : public Scene {
 public:
  DatasetScene(const ibr::DepthObjectOptions& options, ibr::MapSet maps, std::string name)
      : name_(std::move(name)),
        options_(options),
        map_count_(static_cast<int>(maps.maps.size())),
        centre_(maps.world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0)),
        radius_(0.5f * static_cast<float>(
                           glm::length(glm::dvec3(maps.world_from_box * glm::dvec4(1, 1, 1, 0))))),
        scene_(ibr::DepthObjectScene(name_, std::move(maps), options_)),
        renderer_(programs_, scene_) {}

  std::string Title() const override { return "ibr view: " + name_; }
  glm::vec3 Centre() const override { return centre_; }
  float Radius() const override { return radius_; }

  bool DrawControls() override {
    const ibr::DepthObjectOptions before = options_;
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
    ImGui::SliderInt("robust k", &options_.robust_k, 0, std::max(0, map_count_ - 1));
    if (options_ == before) return false;
    // The pass takes the options; the maps stay uploaded.
    renderer_.UpdateDepthObject(scene_, 0, options_);
    return true;
  }

  const render::RenderTarget& Render(const FrameCamera& camera) override {
    return renderer_.Draw(ViewCameraOf(camera));
  }

  std::string Status() const override {
    return fmt::format(
        "{} maps, {} {}{} path, {} slices{}", map_count_, ibr::MethodName(options_.method),
        ibr::SlicingName(options_.slicing),
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
  ibr::DepthObjectOptions options_;
  int map_count_ = 0;
  glm::vec3 centre_{0};
  float radius_ = 1;
  render::ProgramCache programs_;
  // The one-object scene `ibr render DATASET` draws.
  ibr::LoadedScene scene_;
  ibr::SceneRenderer renderer_;
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
    case core::DeformationKind::kSlices:
      return {0.0f, 0.2f, 0.05f, 1.0f};
    case core::DeformationKind::kSeam:
      return {0.01f, 0.5f, 0.05f, 1.0f};
    case core::DeformationKind::kWave:
      return {-0.2f, 0.2f, 0.05f, 2.0f};
  }
  return {0, 1, 0, 1};
}

}  // namespace

std::unique_ptr<Scene> MakeDatasetScene(const ibr::DepthObjectOptions& options, ibr::MapSet maps,
                                        std::string name) {
  return std::make_unique<DatasetScene>(options, std::move(maps), std::move(name));
}

SceneFileScene::SceneFileScene(const scene::Scene& file)
    : file_(file),
      title_("ibr view: " + file.name),
      loaded_(ibr::LoadScene(programs_, file)),
      renderer_(programs_, loaded_) {
  for (size_t i = 0; i < loaded_.objects.size() && !gizmo_object_; ++i)
    if (HasGizmo(i)) gizmo_object_ = i;
  const capture::Bounds& b = loaded_.bounds;
  centre_ = glm::vec3(0.5 * (b.min + b.max));
  radius_ = 0.5f * static_cast<float>(glm::length(b.max - b.min));
  for (const scene::Object& o : file.objects) {
    objects_.push_back(fmt::format("{} ({}){}", o.name, scene::ObjectTypeName(o.type),
                                   o.enabled ? "" : ": disabled"));
  }
}

bool SceneFileScene::DrawControls() {
  bool changed = false;
  if (gizmo_object_) {
    ImGui::Text("gizmo on '%s': %s%s", loaded_.objects[*gizmo_object_].name.c_str(),
                GizmoModeName(gizmo_mode_), gizmo_shown_ ? "" : " (hidden)");
    ImGui::TextUnformatted("keys: T translate, R rotate, S scale, G hide, N next object");
  }
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
          changed |= DeformControls(i);
        } else {
          changed |= VolumeControls(i);
        }
      } catch (const core::InputError& e) {
        error_ = e.what();  // the object is unchanged
      }
    }
    ImGui::PopID();
  }
  return changed;
}

const render::RenderTarget& SceneFileScene::Render(const FrameCamera& camera) {
  return renderer_.Draw(ViewCameraOf(camera));
}

bool SceneFileScene::DragParameter(double t) {
  for (size_t i = 0; i < loaded_.objects.size(); ++i) {
    const ibr::LoadedObject& object = loaded_.objects[i];
    if (object.type == scene::ObjectType::kDeform &&
        !ibr::DeformOf(object).options.deformation.terms.empty()) {
      ibr::DeformObjectOptions o = ibr::DeformOf(object).options;
      core::Deformation& d = o.deformation.terms.front();
      const DeformationRanges r = RangesOf(d.kind);
      // Clamped: lo + t (hi - lo) may round past hi, which Check rejects.
      d.amount = std::clamp(r.amount_lo + t * (r.amount_hi - r.amount_lo),
                            static_cast<double>(r.amount_lo), static_cast<double>(r.amount_hi));
      UpdateDeformWhileMoving(i, o);
      return true;
    }
    if (object.type == scene::ObjectType::kVolume &&
        !ibr::VolumeOf(object).options.deformations.empty()) {
      ibr::VolumeObjectOptions o = ibr::VolumeOf(object).options;
      core::Deformation& d = o.deformations[0];
      const DeformationRanges r = RangesOf(d.kind);
      d.amount = std::clamp(r.amount_lo + t * (r.amount_hi - r.amount_lo),
                            static_cast<double>(r.amount_lo), static_cast<double>(r.amount_hi));
      renderer_.UpdateVolume(loaded_, i, o, /*preview=*/true);
      return true;
    }
  }
  return false;
}

void SceneFileScene::UpdateDeformWhileMoving(size_t index,
                                             const ibr::DeformObjectOptions& options) {
  const auto build = builds_.find(index);
  const ibr::DeformObjectChange change =
      renderer_.UpdateDeform(loaded_, index, options, /*defer_reach=*/true,
                             build == builds_.end() ? nullptr : build->second.get());
  if (change.implicit_deferred &&
      std::find(unsettled_.begin(), unsettled_.end(), index) == unsettled_.end()) {
    unsettled_.push_back(index);
  }
  FollowBuild(index, change.implicit_deferred, change.deformation);
}

double SceneFileScene::ReachForDrags(size_t index) {
  const ibr::LoadedObject& o = loaded_.objects[index];
  ReachHint& hint = reach_hints_[index];
  const core::DeformationSum& now = ibr::DeformOf(o).options.deformation;
  const bool same_kinds = hint.kinds.terms.size() == now.terms.size() &&
                          std::equal(now.terms.begin(), now.terms.end(), hint.kinds.terms.begin(),
                                     [](const core::Deformation& a, const core::Deformation& b) {
                                       return a.kind == b.kind;
                                     });
  if (!same_kinds || hint.placement != ibr::DeformOf(o).data->placement.object_from_box) {
    // Every term at the slider end that displaces most (the larger |amount|,
    // the widest width).
    hint.kinds = now;
    for (core::Deformation& d : hint.kinds.terms) {
      const DeformationRanges r = RangesOf(d.kind);
      d.amount = std::abs(r.amount_lo) > std::abs(r.amount_hi) ? r.amount_lo : r.amount_hi;
      if (r.width_hi > r.width_lo) d.width = r.width_hi;
    }
    hint.placement = ibr::DeformOf(o).data->placement.object_from_box;
    hint.reach = core::MaxObjectDisplacement(hint.kinds, ibr::DeformOf(o).data->placement,
                                             ibr::DeformOf(o).options.deformation_resolution);
  }
  return hint.reach;
}

void SceneFileScene::FollowBuild(size_t index, bool deferred, bool deformation_moved) {
  auto it = builds_.find(index);
  if (it != builds_.end() && it->second->Used()) {
    builds_.erase(it);
    it = builds_.end();
  }
  if (!deferred)
    unsettled_.erase(std::remove(unsettled_.begin(), unsettled_.end(), index), unsettled_.end());
  const ibr::LoadedObject& o = loaded_.objects[index];
  // Only a field over the box as it stands: one over a box still being
  // dragged would be stale when done (a moved box's field is rebuilt at rest).
  if (ibr::DeformOf(o).options.pass.implicit != render::DeformImplicit::kSdf ||
      ibr::DeformOf(o).data->placement.object_from_box !=
          ibr::DeformOf(o).data->field_placement.object_from_box) {
    return;
  }
  // The field a drag of the sliders cannot outgrow: built when a drag
  // starts to need it, so it is ready (or nearly) when the mouse rests.
  const double reach =
      std::max(ReachForDrags(index), 1.5 * ibr::DeformOf(o).data->max_displacement);
  if (!deferred && (!deformation_moved || ibr::DeformOf(o).data->sdf_reach >= ReachForDrags(index)))
    return;
  ibr::DeformObjectOptions wanted = ibr::DeformOf(o).options;
  wanted.sdf_reach = reach;
  if (it != builds_.end()) {
    if (!it->second->Ready() || it->second->Serves(wanted, ibr::DeformOf(o).data->placement,
                                                   ibr::DeformOf(o).data->max_displacement)) {
      return;  // running, or done and still of use
    }
    stale_.push_back(std::move(it->second));
    builds_.erase(it);
  }
  // One thread at a lower priority: the frames still moving keep the CPU
  // they need (docs/decisions/viewer-manipulation.md).
  builds_[index] = std::make_unique<ibr::DeformFieldBuild>(ibr::DeformOf(o).data, wanted,
                                                           fmt::format("object '{}'", o.name),
                                                           /*threads=*/1, /*nice=*/10);
}

bool SceneFileScene::Poll() {
  std::erase_if(stale_, [](const auto& b) { return b->Ready(); });
  bool changed = false;
  for (size_t index : std::vector<size_t>(unsettled_)) {
    const auto it = builds_.find(index);
    if (it == builds_.end() || !it->second->Ready()) continue;
    try {
      const ibr::DeformObjectChange change =
          renderer_.UpdateDeform(loaded_, index, ibr::DeformOf(loaded_.objects[index]).options,
                                 /*defer_reach=*/true, it->second.get());
      changed |= change.Any();
      FollowBuild(index, change.implicit_deferred, /*deformation_moved=*/false);
    } catch (const core::InputError& e) {
      error_ = e.what();
      builds_.erase(index);
    }
  }
  return changed;
}

void SceneFileScene::Settle() {
  // Emptied first: a failed rebuild is not retried every frame (the error
  // shows in the panel).
  const std::vector<size_t> pending = std::move(unsettled_);
  unsettled_.clear();
  for (size_t i : pending) {
    const auto it = builds_.find(i);
    std::unique_ptr<ibr::DeformFieldBuild> build;
    if (it != builds_.end()) {
      build = std::move(it->second);
      builds_.erase(it);
    }
    // The background field where it serves (waited for), else a rebuild.
    renderer_.UpdateDeform(loaded_, i, ibr::DeformOf(loaded_.objects[i]).options,
                           /*defer_reach=*/false, build.get());
    if (build && !build->Used()) stale_.push_back(std::move(build));
  }
  for (size_t i = 0; i < loaded_.objects.size(); ++i) {
    const ibr::LoadedObject& o = loaded_.objects[i];
    if (o.type == scene::ObjectType::kVolume && ibr::VolumeOf(o).data->preview_maps)
      renderer_.UpdateVolume(loaded_, i, ibr::VolumeOf(o).options);
  }
}

// The first peel among a volume's deformations: the one the gizmo sweeps.
static std::optional<size_t> VolumePeel(const ibr::VolumeObjectOptions& o) {
  for (size_t i = 0; i < o.deformations.size(); ++i) {
    if (o.deformations[i].kind == core::DeformationKind::kPeel) return i;
  }
  return std::nullopt;
}

bool SceneFileScene::HasGizmo(size_t index) const {
  const ibr::LoadedObject& o = loaded_.objects[index];
  return o.type == scene::ObjectType::kDeform ||
         (o.type == scene::ObjectType::kVolume && VolumePeel(ibr::VolumeOf(o).options));
}

GizmoBox SceneFileScene::GizmoBoxOf(size_t index) const {
  const ibr::LoadedObject& o = loaded_.objects[index];
  GizmoBox box;
  if (o.type == scene::ObjectType::kVolume) {
    // The peel's map cube (eq. 10's M) in the volume: its placement is not
    // an option, so no axis handles; the flap's edge sweeps the peel.
    const core::Deformation& d =
        ibr::VolumeOf(o).options.deformations[*VolumePeel(ibr::VolumeOf(o).options)];
    box.world_from_norm = glm::dmat4(ibr::VolumeOf(o).data->world_from_volume);
    box.norm_from_box = d.parent_from_box;
    box.axes = false;
    box.peel_angle = d.amount;
    box.peel_hinge = {0.5, 1.0 - d.width};  // core/deformation.cc: hinge x 0.5, top 1 - T
    box.peel_length = 0.5;
    return box;
  }
  box.world_from_norm = o.world_from_object;  // world_from_object * object_from_norm
  box.norm_from_box = ibr::DeformOf(o).data->placement.object_from_box;
  for (const core::Deformation& d : ibr::DeformOf(o).options.deformation.terms) {
    box.knife |= d.kind == core::DeformationKind::kKnife;
    if (d.kind == core::DeformationKind::kPeel && !box.peel_angle) {
      box.peel_angle = d.amount;
      box.peel_hinge = {0.5, 1.0 - d.width};  // core/deformation.cc: hinge x 0.5, top 1 - T
    }
  }
  return box;
}

bool SceneFileScene::DragVolumePeel(size_t index, double angle) {
  ibr::VolumeObjectOptions o = ibr::VolumeOf(loaded_.objects[index]).options;
  core::Deformation& peel = o.deformations[*VolumePeel(o)];
  if (angle == peel.amount) return false;
  peel.amount = angle;
  try {
    renderer_.UpdateVolume(loaded_, index, o, /*preview=*/true);
    error_.clear();
  } catch (const core::InputError& e) {
    error_ = e.what();
    return false;
  }
  return true;
}

// Each window pixel moves the window or level by this fraction of the data
// range: a drag across a typical window spans the whole range.
constexpr double kWindowLevelPerPixel = 1.0 / 500;

SceneFileScene::TransferSlot& SceneFileScene::TransferOf(size_t index) {
  auto it = transfers_.find(index);
  if (it == transfers_.end()) {
    const ibr::VolumeState& v = ibr::VolumeOf(loaded_.objects[index]);
    const ibr::VolumeObjectData& data = *v.data;
    it = transfers_
             .emplace(index, TransferSlot{TransferEditor(v.options.transfer ? *v.options.transfer
                                                                            : data.transfer,
                                                         data.volume.NormalizationRange(),
                                                         {data.stats.min, data.stats.max}),
                                          VolumeHistogram(data.volume),
                                          {}})
             .first;
  }
  return it->second;
}

void SceneFileScene::ApplyTransfer(size_t index) {
  ibr::VolumeObjectOptions o = ibr::VolumeOf(loaded_.objects[index]).options;
  o.transfer = TransferOf(index).editor.transfer();
  renderer_.UpdateVolume(loaded_, index, o, /*preview=*/true);
  error_.clear();
}

bool SceneFileScene::PointerPress(const FrameCamera& camera, const glm::dvec2& pixel, int mods) {
  window_drag_.reset();
  if (mods & kModControl) {
    std::optional<size_t> volume;
    if (gizmo_object_ && loaded_.objects[*gizmo_object_].type == scene::ObjectType::kVolume)
      volume = gizmo_object_;
    for (size_t i = 0; i < loaded_.objects.size() && !volume; ++i)
      if (loaded_.objects[i].type == scene::ObjectType::kVolume) volume = i;
    if (!volume) return false;
    window_drag_ = volume;
    window_start_ = TransferOf(*volume).editor.window();
    drag_from_ = pixel;
    return true;
  }
  if (!gizmo_shown_ || !gizmo_object_) return false;
  const GizmoBox box = GizmoBoxOf(*gizmo_object_);
  drag_handle_ = PickHandle(box, camera, pixel);
  if (!drag_handle_) return false;
  drag_from_ = pixel;
  drag_box_ = box;
  // A volume's peel has no placement option (GizmoBoxOf): only its angle moves.
  drag_start_ = {{}, {}, 1.0, box.peel_angle.value_or(0.0)};
  if (loaded_.objects[*gizmo_object_].type == scene::ObjectType::kDeform) {
    const ibr::DeformObjectOptions& o = ibr::DeformOf(loaded_.objects[*gizmo_object_]).options;
    drag_start_ = {o.translation, o.rotation_deg, o.scale, box.peel_angle.value_or(0.0)};
  }
  return true;
}

bool SceneFileScene::PointerDrag(const FrameCamera& camera, const glm::dvec2& pixel) {
  if (window_drag_) {
    TransferSlot& slot = TransferOf(*window_drag_);
    const glm::dvec2& data = slot.editor.data_range();
    const WindowLevel wl = DragWindowLevel(window_start_, pixel - drag_from_,
                                           kWindowLevelPerPixel * std::max(data.y - data.x, 1e-9));
    const core::TransferFunction before = slot.editor.transfer();
    slot.editor.SetWindow(wl);
    if (slot.editor.transfer() == before) return false;
    try {
      ApplyTransfer(*window_drag_);
    } catch (const core::InputError& e) {
      error_ = e.what();
      return false;
    }
    return true;
  }
  if (!drag_handle_ || !gizmo_object_) return false;
  const GizmoPlacement p =
      DragHandle(drag_box_, drag_start_, gizmo_mode_, *drag_handle_, camera, drag_from_, pixel);
  const size_t index = *gizmo_object_;
  if (loaded_.objects[index].type == scene::ObjectType::kVolume)
    return DragVolumePeel(index, p.peel_angle);
  ibr::DeformObjectOptions o = ibr::DeformOf(loaded_.objects[index]).options;
  o.translation = p.translation;
  o.rotation_deg = p.rotation_deg;
  o.scale = p.scale;
  if (KindOfHandle(*drag_handle_) == HandleKind::kPeelEdge) {
    for (core::Deformation& d : o.deformation.terms) {
      if (d.kind != core::DeformationKind::kPeel) continue;
      d.amount = p.peel_angle;
      break;
    }
  }
  const ibr::DeformObjectOptions& before = ibr::DeformOf(loaded_.objects[index]).options;
  if (o.translation == before.translation && o.rotation_deg == before.rotation_deg &&
      o.scale == before.scale && o.deformation == before.deformation) {
    return false;
  }
  try {
    UpdateDeformWhileMoving(index, o);
    error_.clear();
  } catch (const core::InputError& e) {
    error_ = e.what();  // e.g. a scale Check refuses; the object is unchanged
    return false;
  }
  return true;
}

void SceneFileScene::PointerRelease() {
  drag_handle_.reset();
  window_drag_.reset();
}

bool SceneFileScene::Key(int key) {
  switch (key) {
    case 'T':
      gizmo_mode_ = GizmoMode::kTranslate;
      break;
    case 'R':
      gizmo_mode_ = GizmoMode::kRotate;
      break;
    case 'S':
      gizmo_mode_ = GizmoMode::kScale;
      break;
    case 'G':
      gizmo_shown_ = !gizmo_shown_;
      break;
    case 'N':
      for (size_t k = 1; gizmo_object_ && k <= loaded_.objects.size(); ++k) {
        const size_t i = (*gizmo_object_ + k) % loaded_.objects.size();
        if (!HasGizmo(i)) continue;
        gizmo_object_ = i;
        break;
      }
      break;
    default:
      break;
  }
  return false;  // the overlay changes, the frame does not
}

std::vector<OverlayLine> SceneFileScene::Overlay(const FrameCamera& camera) const {
  if (!gizmo_shown_ || !gizmo_object_) return {};
  return GizmoLines(GizmoBoxOf(*gizmo_object_), camera, gizmo_mode_, drag_handle_);
}

scene::Scene SceneFileScene::EditedScene(const FrameCamera& camera) const {
  return SceneWithEdits(file_, loaded_, ViewCameraOf(camera));
}

std::string SceneFileScene::Status() const {
  return fmt::format("{} objects drawn, {} disabled", loaded_.objects.size(),
                     loaded_.disabled.size());
}

// Per deformation: kind, amount, width; cut and thickness; step policy,
// threshold and base step; skip; the implicit (shown).
bool SceneFileScene::DeformControls(size_t index) {
  const ibr::LoadedObject& object = loaded_.objects[index];
  ibr::DeformObjectOptions o = ibr::DeformOf(object).options;
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
  changed |= ComboOf(
      "cut", pass.cut,
      {core::CutMode::kNone, core::CutMode::kHollow, core::CutMode::kSolid, core::CutMode::kThick},
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
  const ibr::DeformObjectData& data = *ibr::DeformOf(object).data;
  if (pass.implicit == render::DeformImplicit::kDepthCube) {
    ImGui::Text("implicit: depth cube, 6 maps of %d px (built %dx, %.2f s)", o.sdf_resolution,
                data.implicit_builds, data.sdf_seconds);
  } else {
    ImGui::Text("implicit: sdf %dx%dx%d, reach %.3f (built %dx, %.2f s)", data.sdf.size.x,
                data.sdf.size.y, data.sdf.size.z, data.sdf_reach, data.implicit_builds,
                data.sdf_seconds);
  }
  if (changed) {
    UpdateDeformWhileMoving(index, o);
    error_.clear();
  }
  return changed;
}

// The effect's main parameter; lighting; mode and iso value; spacing.
bool SceneFileScene::VolumeControls(size_t index) {
  ibr::VolumeObjectOptions o = ibr::VolumeOf(loaded_.objects[index]).options;
  bool changed = false;
  for (core::Deformation& d : o.deformations) {
    const DeformationRanges r = RangesOf(d.kind);
    ImGui::PushID(&d);
    ImGui::Text("deformation: %s", core::DeformationKindName(d.kind).c_str());
    changed |= SliderDouble("amount", d.amount, r.amount_lo, r.amount_hi, "%.3f");
    if (r.width_hi > r.width_lo)
      changed |= SliderDouble("width", d.width, r.width_lo, r.width_hi, "%.3f");
    ImGui::PopID();
  }
  if (o.deformations.empty()) ImGui::TextUnformatted("deformation: none");
  render::VolumePassOptions& pass = o.pass;
  changed |= ComboOf("lighting", pass.lighting,
                     {render::VolumeLighting::kNone, render::VolumeLighting::kGradient,
                      render::VolumeLighting::kTransformed, render::VolumeLighting::kBlended},
                     render::VolumeLightingName);
  changed |=
      ComboOf("mode", pass.mode, {render::VolumeMode::kDvr, render::VolumeMode::kIso},
              [](render::VolumeMode m) { return m == render::VolumeMode::kDvr ? "dvr" : "iso"; });
  if (pass.mode == render::VolumeMode::kIso) {
    // In the volume's own units (e.g. HU), over its data range, as
    // `iso:VALUE` is typed; the pass gets the normalised value.
    const ibr::VolumeObjectData& data = *ibr::VolumeOf(loaded_.objects[index]).data;
    double iso = ibr::IsoValueInDataUnits(data, o);
    if (SliderDouble("iso value (data units)", iso, static_cast<float>(data.stats.min),
                     static_cast<float>(data.stats.max), "%.5g")) {
      iso = std::clamp(iso, data.stats.min, data.stats.max);  // float rounding at the ends
      ibr::SetIsoValue(data, iso, pass, "iso value");
      o.iso_value = iso;
      changed = true;
    }
  }
  changed |= SliderDouble("spacing (voxels)", pass.sampling_distance_voxels, 0.25f, 4, "%.2f");
  if (changed) {
    renderer_.UpdateVolume(loaded_, index, o, /*preview=*/true);
    error_.clear();
  }
  if (ImGui::TreeNodeEx("transfer function", ImGuiTreeNodeFlags_DefaultOpen)) {
    TransferSlot& slot = TransferOf(index);
    if (DrawTransferFunctionPanel(slot.editor, slot.histogram, slot.panel)) {
      ApplyTransfer(index);
      changed = true;
    }
    ImGui::TextUnformatted("Ctrl + left drag: window (x) and level (y)");
    ImGui::TreePop();
  }
  return changed;
}

}  // namespace viewer
