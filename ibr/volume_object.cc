#include "ibr/volume_object.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "core/volume_io.h"
#include "ibr/deform_object.h"

namespace ibr {

core::TransferFunction TransferForVolume(const std::string& name,
                                         const std::filesystem::path& volume_path,
                                         const core::Volume* volume) {
  if (!name.empty()) return core::TransferFromPresetOrFile(name);
  std::string stem = volume_path.filename().string();
  std::transform(stem.begin(), stem.end(), stem.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* preset : {"tooth", "neghip", "bucky"}) {
    if (stem.rfind(preset, 0) == 0) return core::TransferPreset(preset);
  }
  if (volume == nullptr) return core::TransferPreset("ramp");
  const core::VolumeStats st = core::ComputeVolumeStats(*volume);
  // The 50th..99th percentile window: the upper half of the values, so the
  // most common value (air in a CT, the background of a scan) stays
  // transparent instead of fogging long rays, and outliers (metal, padding)
  // do not squeeze the data into a sliver. Narrower distributions fall back
  // to the 1st..99th percentiles, then to the whole range.
  if (st.p99 > st.p50) return core::WindowTransfer(st.p50, st.p99);
  if (st.p99 > st.p1) return core::WindowTransfer(st.p1, st.p99);
  return core::WindowTransfer(st.min, st.max);
}

core::TransferFunction WindowLevelTransfer(double width, double level,
                                           const core::VolumeStats& stats,
                                           const std::string& where) {
  if (!(width > 0) || !std::isfinite(width) || !std::isfinite(level)) {
    core::ThrowInputError(where,
                          "window {} / level {}: the width must be finite and > 0 and the "
                          "level finite",
                          width, level);
  }
  const double lo = level - 0.5 * width, hi = level + 0.5 * width;
  if (lo >= stats.max) {
    core::ThrowInputError(where,
                          "window [{}, {}] starts at or above the data maximum {} (range [{}, "
                          "{}], percentiles 1/50/99: {} / {} / {}): every voxel would be "
                          "transparent",
                          lo, hi, stats.max, stats.min, stats.max, stats.p1, stats.p50, stats.p99);
  }
  if (hi <= stats.min) {
    spdlog::warn(
        "{}: window [{}, {}] ends at or below the data minimum {}: every voxel is opaque, "
        "the image is the volume's box",
        where, lo, hi, stats.min);
  }
  return core::WindowTransfer(lo, hi);
}

namespace {

// The effect sampled on a map_size grid placed by `placement` (see
// MakeVolumeObject).
// The peel fill's iterations for a preview: a tenth of the default's
// smoothing, enough for a map that shows the peel while the angle moves.
constexpr int kPreviewFillIterations = 20;

render::VolumeMapInput SampleMap(const core::Deformation& d, int map_size, bool preview = false) {
  core::Deformation unplaced = d;
  unplaced.parent_from_box = glm::dmat4(1.0);  // the PlacedMap's placement
  const glm::ivec3 dims = core::VolumeMapDims(d, map_size);
  return {preview ? core::SampleDeformationMap(unplaced, dims, 2, kPreviewFillIterations)
                  : core::SampleDeformationMap(unplaced, dims, 2),
          core::VolumeMapPlacement(d)};
}

std::vector<render::VolumeMapInput> SampleMaps(const std::vector<core::Deformation>& deformations,
                                               int map_size, bool preview = false) {
  std::vector<render::VolumeMapInput> maps;
  for (const core::Deformation& d : deformations) maps.push_back(SampleMap(d, map_size, preview));
  return maps;
}

}  // namespace

VolumeObjectData MakeVolumeObject(core::Volume volume, const core::TransferFunction& transfer,
                                  const std::vector<core::Deformation>& deformations, int map_size,
                                  const std::string& where) {
  VolumeObjectData s;
  s.volume = std::move(volume);
  s.stats = core::ComputeVolumeStats(s.volume);
  s.transfer = core::NormalizedTransfer(transfer, s.volume.NormalizationRange());
  const glm::vec3 extent(s.volume.Extent());
  s.world_from_volume = glm::scale(glm::translate(glm::mat4(1.0f), -0.5f * extent), extent);
  s.radius = 0.5 * glm::length(s.volume.Extent());
  if (!deformations.empty()) {
    if (map_size < 1 || map_size > 512)
      core::ThrowInputError(where, "map size {} not in [1, 512]", map_size);
    for (const core::Deformation& d : deformations) {
      try {
        d.Check();
      } catch (const core::InputError& e) {
        throw core::InputError(fmt::format("{}: {}", where, e.what()));
      }
    }
    s.maps = SampleMaps(deformations, map_size);
  }
  return s;
}

void VolumeObjectOptions::Check() const {
  for (const core::Deformation& d : deformations) d.Check();
  if (map_size < 1 || map_size > 512)
    core::ThrowInputError("VolumeObjectOptions", "map size {} not in [1, 512]", map_size);
  pass.Check();
  if (transfer) transfer->Check("VolumeObjectOptions: transfer");
}

VolumeObjectChange UpdateVolumeObject(VolumeObjectData& data,
                                      const VolumeObjectOptions& old_options,
                                      const VolumeObjectOptions& options, const std::string& where,
                                      bool preview) {
  try {
    options.Check();
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", where, e.what()));
  }
  VolumeObjectChange change;
  change.pass = old_options.pass != options.pass;
  change.transfer = old_options.transfer != options.transfer;
  change.maps = old_options.deformations != options.deformations ||
                (!options.deformations.empty() && old_options.map_size != options.map_size) ||
                (data.preview_maps && !preview);
  if (change.maps) {
    data.maps = SampleMaps(options.deformations, options.map_size, preview);
    data.preview_maps =
        preview && std::any_of(options.deformations.begin(), options.deformations.end(),
                               [](const core::Deformation& d) {
                                 return d.kind == core::DeformationKind::kPeel;
                               });
  }
  return change;
}

std::optional<double> ApplyVolumeMode(const std::string& mode, render::VolumePassOptions& options,
                                      const std::string& where) {
  if (mode == "dvr") {
    options.mode = render::VolumeMode::kDvr;
    return std::nullopt;
  }
  if (mode.rfind("iso:", 0) == 0) {
    try {
      size_t used = 0;
      const double v = std::stod(mode.substr(4), &used);
      if (used == mode.size() - 4 && std::isfinite(v)) {
        options.mode = render::VolumeMode::kIso;
        return v;
      }
    } catch (const std::exception&) {
    }
  }
  core::ThrowInputError(where, "'{}': expected dvr or iso:VALUE (VALUE in the volume's units)",
                        mode);
}

void SetIsoValue(const VolumeObjectData& data, double value, render::VolumePassOptions& options,
                 const std::string& where) {
  const core::VolumeStats& st = data.stats;
  if (!(value >= st.min && value <= st.max)) {
    core::ThrowInputError(where,
                          "iso value {} is outside the data range [{}, {}] (percentiles 1/50/99: "
                          "{} / {} / {})",
                          value, st.min, st.max, st.p1, st.p50, st.p99);
  }
  options.iso_value = data.volume.ToNormalized(value);
}

double IsoValueInDataUnits(const VolumeObjectData& data, const VolumeObjectOptions& options) {
  const double value =
      options.iso_value ? *options.iso_value : data.volume.FromNormalized(options.pass.iso_value);
  return std::clamp(value, data.stats.min, data.stats.max);
}

VolumeObjectOptions VolumeObjectOptionsFrom(const scene::Settings& s) {
  VolumeObjectOptions o;
  o.deformations = DeformationsFrom(s, "none", /*placement_key=*/true);
  o.map_size = s.GetInt("map_size", o.map_size);
  if (o.map_size < 1 || o.map_size > 512)
    s.Fail("map_size", fmt::format("{} outside 1..512", o.map_size));
  const auto fail_as = [&](const std::string& key, auto&& apply) {
    try {
      apply();
    } catch (const core::InputError& error) {
      s.Fail(key, error.what());
    }
  };
  const std::string mode = s.GetString("mode", "dvr");
  fail_as("mode", [&] { o.iso_value = ApplyVolumeMode(mode, o.pass, "mode"); });
  o.pass.sampling_distance_voxels = s.GetDouble("spacing", o.pass.sampling_distance_voxels);
  o.pass.displacement_bits = s.GetInt("displacement_bits", o.pass.displacement_bits);
  const std::string lighting =
      s.GetString("lighting", std::string(render::VolumeLightingName(o.pass.lighting)));
  fail_as("lighting", [&] { o.pass.lighting = render::VolumeLightingFromName(lighting); });
  const std::string jacobian =
      s.GetString("jacobian", std::string(render::VolumeJacobianName(o.pass.jacobian)));
  fail_as("jacobian", [&] { o.pass.jacobian = render::VolumeJacobianFromName(jacobian); });
  if (const scene::Setting* t = s.Find("transfer"); t && t->value.is_object()) {
    // Checked by the scene reader; read again here for the options.
    std::istringstream text(t->value.dump());
    fail_as("transfer", [&] { o.transfer = core::ReadTransferFunction(text, "inline object"); });
  }
  // The remaining checks name the first key they could come from.
  fail_as(s.Has("spacing") ? "spacing" : "displacement_bits", [&] { o.pass.Check(); });
  return o;
}

LoadedVolume LoadVolumeObject(const scene::Object& o) {
  LoadedVolume l;
  l.options = VolumeObjectOptionsFrom(o.settings);
  core::Volume volume;
  try {
    volume = core::ReadVolume(o.volume);
    render::CheckVolumeFits(volume.dims, {}, render::Max3dTextureSize());
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}/volume: {}", o.where, e.what()));
  }
  core::TransferFunction transfer;
  const scene::Setting* t = o.settings.Find("transfer");
  try {
    transfer = l.options.transfer
                   ? *l.options.transfer
                   : TransferForVolume(t ? t->value.get<std::string>() : "", o.volume, &volume);
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", t ? t->where : o.where, e.what()));
  }
  l.data = MakeVolumeObject(std::move(volume), transfer, l.options.deformations, l.options.map_size,
                            o.where);
  l.data.world_from_volume = glm::mat4(o.world_from_object) * l.data.world_from_volume;
  if (l.options.iso_value) {
    const scene::Setting* m = o.settings.Find("mode");
    SetIsoValue(l.data, *l.options.iso_value, l.options.pass, m ? m->where : o.where);
  }
  return l;
}

glm::dmat4 WorldFromProxy(const VolumeObjectData& data) {
  // The box and frame render::VolumePass draws (VolumePass::world_from_proxy).
  return glm::dmat4(data.world_from_volume) *
         glm::dmat4(render::TexFromProxy(render::VolumeProxyBox(data.maps)));
}

}  // namespace ibr
