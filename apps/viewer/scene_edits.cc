#include "apps/viewer/scene_edits.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "core/error.h"
#include "core/transfer_function.h"

namespace viewer {
namespace {

// Comma-joined numbers, each with the digits that parse back to its bits.
std::string Join(const std::vector<double>& values) {
  std::string s;
  for (double v : values) {
    if (!s.empty()) s += ',';
    s += fmt::format("{}", v);
  }
  return s;
}

// The options a load makes of `settings` equal the viewer's, where they
// mean anything (a thickness only with a thick cut, a threshold only with
// the threshold policy).
bool SameDeform(ibr::DeformObjectOptions parsed, const ibr::DeformObjectOptions& viewer) {
  if (viewer.pass.cut != core::CutMode::kThick) parsed.pass.thickness = viewer.pass.thickness;
  if (viewer.pass.step_policy != render::RayStepPolicy::kThreshold)
    parsed.pass.threshold = viewer.pass.threshold;
  const auto same_box = [](const std::optional<core::Box3d>& a,
                           const std::optional<core::Box3d>& b) {
    return a.has_value() == b.has_value() && (!a || (a->lo == b->lo && a->hi == b->hi));
  };
  return parsed.deformation == viewer.deformation && same_box(parsed.region, viewer.region) &&
         parsed.rotation_deg == viewer.rotation_deg && parsed.scale == viewer.scale &&
         parsed.translation == viewer.translation && parsed.pass == viewer.pass &&
         parsed.sdf_resolution == viewer.sdf_resolution &&
         parsed.deformation_resolution == viewer.deformation_resolution &&
         parsed.cap_holes == viewer.cap_holes && parsed.sdf_reach == viewer.sdf_reach;
}

bool SameVolume(ibr::VolumeObjectOptions parsed, const ibr::VolumeObjectOptions& viewer) {
  // The normalised iso value is set from iso_value at load (SetIsoValue).
  parsed.pass.iso_value = viewer.pass.iso_value;
  return parsed.deformations == viewer.deformations && parsed.map_size == viewer.map_size &&
         parsed.pass == viewer.pass && parsed.iso_value == viewer.iso_value &&
         parsed.transfer == viewer.transfer;
}

}  // namespace

scene::Settings DeformSettings(const ibr::DeformObjectOptions& o, scene::Settings s,
                               const std::string& where) {
  std::string kinds;
  std::vector<double> amounts, widths;
  for (const core::Deformation& d : o.deformation.terms) {
    if (!kinds.empty()) kinds += ',';
    kinds += core::DeformationKindName(d.kind);
    amounts.push_back(d.amount);
    widths.push_back(d.width);
  }
  const render::DeformPassOptions& p = o.pass;
  s.Set("deformation", kinds, where);
  s.Set("amount", Join(amounts), where);
  s.Set("width", Join(widths), where);
  s.Set("cut",
        p.cut == core::CutMode::kThick ? fmt::format("thick:{}", static_cast<double>(p.thickness))
                                       : core::CutModeName(p.cut),
        where);
  if (o.region) {
    const core::Box3d& r = *o.region;
    s.Set("region", Join({r.lo.x, r.lo.y, r.lo.z, r.hi.x, r.hi.y, r.hi.z}), where);
  }
  const glm::dvec3 &t = o.translation, &r = o.rotation_deg;
  s.Set("placement", Join({t.x, t.y, t.z, r.x, r.y, r.z, o.scale}), where);
  s.Set("step",
        p.step_policy == render::RayStepPolicy::kThreshold
            ? fmt::format("threshold:{}", static_cast<double>(p.threshold))
            : render::RayStepPolicyName(p.step_policy),
        where);
  s.Set("step_voxels", static_cast<double>(p.step_voxels), where);
  s.Set("skip", p.skip_empty, where);
  s.Set("skip_object", p.skip_object, where);
  s.Set("solid", p.solid_search ? "search" : "csg", where);
  s.Set("implicit", render::DeformImplicitName(p.implicit), where);
  s.Set("resolution", o.sdf_resolution, where);
  s.Set("cap_holes", o.cap_holes, where);
  if (o.sdf_reach) s.Set("reach", *o.sdf_reach, where);
  return s;
}

scene::Settings VolumeSettings(const ibr::VolumeObjectOptions& o, scene::Settings s,
                               const std::string& where) {
  if (!o.deformations.empty()) {
    // The "deformations" list, each with the placement the file gave it (a
    // volume's placements are not edited in the viewer, and a matrix has no
    // exact key form: SameVolume refuses one that differs).
    const scene::Setting* file_list = s.Find("deformations");
    const scene::Setting* placement = s.Find("placement");
    nlohmann::json list = nlohmann::json::array();
    for (size_t i = 0; i < o.deformations.size(); ++i) {
      const core::Deformation& d = o.deformations[i];
      nlohmann::json item = {
          {"name", core::DeformationKindName(d.kind)}, {"amount", d.amount}, {"width", d.width}};
      if (file_list && file_list->value.is_array() && i < file_list->value.size() &&
          file_list->value[i].contains("placement")) {
        item["placement"] = file_list->value[i]["placement"];
      } else if (placement) {
        item["placement"] = placement->value;
      }
      list.push_back(item);
    }
    for (const char* key : {"deformation", "effect", "amount", "width", "placement"}) s.Erase(key);
    s.Set("deformations", list, where);
  }
  s.Set("map_size", o.map_size, where);
  s.Set("mode",
        o.pass.mode == render::VolumeMode::kIso && o.iso_value ? fmt::format("iso:{}", *o.iso_value)
                                                               : "dvr",
        where);
  s.Set("spacing", o.pass.sampling_distance_voxels, where);
  s.Set("displacement_bits", o.pass.displacement_bits, where);
  s.Set("lighting", std::string(render::VolumeLightingName(o.pass.lighting)), where);
  s.Set("jacobian", std::string(render::VolumeJacobianName(o.pass.jacobian)), where);
  // An edited transfer function inline (the file's name otherwise stays).
  if (o.transfer)
    s.Set("transfer", nlohmann::json::parse(core::TransferFunctionJson(*o.transfer)), where);
  return s;
}

scene::Scene SceneWithEdits(const scene::Scene& file, const ibr::LoadedScene& loaded,
                            const ibr::ViewCamera& camera, const std::string& camera_name) {
  scene::Scene out = file;
  for (const ibr::LoadedObject& l : loaded.objects) {
    const auto it = std::find_if(out.objects.begin(), out.objects.end(),
                                 [&](const scene::Object& o) { return o.name == l.name; });
    if (it == out.objects.end()) continue;
    const std::string where = fmt::format("ibr view: object '{}'", l.name);
    if (l.type == scene::ObjectType::kDeform) {
      it->settings = DeformSettings(ibr::DeformOf(l).options, it->settings, where);
      if (!SameDeform(ibr::DeformObjectOptionsFrom(it->settings), ibr::DeformOf(l).options)) {
        core::ThrowInputError("ibr view --save-scene",
                              "object '{}': an edit has no scene key (the saved file would draw "
                              "another deformation)",
                              l.name);
      }
    } else if (l.type == scene::ObjectType::kVolume) {
      it->settings = VolumeSettings(ibr::VolumeOf(l).options, it->settings, where);
      if (!SameVolume(ibr::VolumeObjectOptionsFrom(it->settings), ibr::VolumeOf(l).options)) {
        core::ThrowInputError("ibr view --save-scene",
                              "object '{}': an edit has no scene key (the saved file would "
                              "draw another volume)",
                              l.name);
      }
    }
  }
  scene::ExplicitCamera c;
  c.name = camera_name;
  c.width = camera.camera.width;
  c.height = camera.camera.height;
  c.fx = camera.camera.fx;
  c.fy = camera.camera.fy;
  c.cx = camera.camera.cx;
  c.cy = camera.camera.cy;
  c.orthographic = camera.camera.orthographic;
  c.cam_from_world = camera.cam_from_world;
  out.cameras = scene::Cameras{};
  out.cameras.kind = scene::Cameras::Kind::kList;
  out.cameras.list = {c};
  return out;
}

}  // namespace viewer
