// A volume displaced and cut by deformations (Correa, Silver, Chen 2006; the
// names of core::kDeformationTable, as a deform object's) as plain CPU data, shared by `ibr
// volume`, the volume bench and volume objects in scene files (ibr/scene_renderer.h): parse -> this
// data -> render::VolumePass.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/transfer_function.h"
#include "core/volume.h"
#include "core/volume_displacement.h"
#include "render/passes/volume_pass.h"
#include "scene/scene.h"

namespace ibr {

// Everything a render::VolumePass needs.
struct VolumeObjectData {
  core::Volume volume;
  core::VolumeStats stats;          // of the volume's stored values (iso range, info)
  core::TransferFunction transfer;  // normalised (core::NormalizedTransfer)
  std::vector<render::VolumeMapInput> maps;
  // Volume texture space -> world: extent-scaled, centred at the origin (the
  // object frame of a scene's volume object, before its transform).
  glm::mat4 world_from_volume{1.0f};
  double radius = 1;  // of the volume's bounding sphere, world units
  // The maps were sampled as a preview (UpdateVolumeObject's `preview`: a
  // rougher peel fill); the next update without it resamples them.
  bool preview_maps = false;
};

// `transfer` may be in stored units (core::TransferUnits::kData): it is
// converted with the volume's normalisation range.
// Each deformation sampled on a map_size grid (core::VolumeMapDims: thin
// along axes it does not vary on), placed by its parent_from_box into the
// volume's texture space (eq. 10's M); several compose by eq. 9.
// InputError naming `where` on a bad size or deformation.
// The volume is taken by value: callers that are done with theirs move it in.
VolumeObjectData MakeVolumeObject(core::Volume volume, const core::TransferFunction& transfer,
                                  const std::vector<core::Deformation>& deformations, int map_size,
                                  const std::string& where = "ibr volume");

// The transfer function `name` (preset or file) or, when empty, the preset
// whose name starts the volume's file name (tooth, neghip, bucky), else a
// grey ramp over the volume's 50th..99th percentile window in stored units
// (core::WindowTransfer; "ramp" when no volume is given).
core::TransferFunction TransferForVolume(const std::string& name,
                                         const std::filesystem::path& volume_path,
                                         const core::Volume* volume = nullptr);

// Radiology's window/level in the volume's stored units (e.g. width 400,
// level 40 for soft tissue in HU): a white ramp transparent at level -
// width/2 and opaque at level + width/2 (core::WindowTransfer; values above
// the window opaque, below it transparent). InputError naming `where` when
// width is not finite and > 0, level is not finite, or the window starts at
// or above the data maximum (every voxel transparent: nothing would draw). A
// window ending at or below the data minimum makes every voxel opaque (the
// volume's box): a warning, not an error.
core::TransferFunction WindowLevelTransfer(double width, double level,
                                           const core::VolumeStats& stats,
                                           const std::string& where);

// "dvr" or "iso:VALUE" into options.mode; returns VALUE (the volume's stored
// units, e.g. HU) for iso, to be set with SetIsoValue once the volume is
// known. InputError naming `where`.
std::optional<double> ApplyVolumeMode(const std::string& mode, render::VolumePassOptions& options,
                                      const std::string& where);
// options.iso_value (the pass's normalised scalar) from `value` in stored
// units; InputError naming `where` and the data range when `value` is
// outside it (an iso surface there would be empty).
void SetIsoValue(const VolumeObjectData& data, double value, render::VolumePassOptions& options,
                 const std::string& where);

// A scene's volume object settings (scene/scene.h: deformation(s), map_size, mode,
// spacing, displacement_bits, lighting, jacobian), errors naming the file and
// JSON pointer of the value.
struct VolumeObjectOptions {
  // None: plain DVR / iso. Each its own map, placed by its parent_from_box.
  std::vector<core::Deformation> deformations;
  int map_size = 64;  // texels per axis of each deformation's map
  render::VolumePassOptions pass;
  std::optional<double> iso_value;  // "iso:VALUE" in stored units; LoadVolumeObject sets pass's
  // An inline "transfer" object (the viewer's edited function, data or
  // normalised units): replaces the one LoadVolumeObject reads by name.
  // UpdateVolumeObject reports a change of it; the pass takes it through
  // render::VolumePass::SetTransferFunction (no volume upload).
  std::optional<core::TransferFunction> transfer;
  // InputError on bad values: the deformations' and the pass's Check(), a map size
  // outside 1..512.
  void Check() const;
  // Field by field (tests/ibr/object_kind_registry_test: the CLI and a scene agree).
  bool operator==(const VolumeObjectOptions&) const = default;
};

// The iso value `options` draws, in the volume's stored units (what a user
// types and the viewer's slider shows): the value given (options.iso_value),
// else the pass's normalised iso value mapped back
// (core::Volume::FromNormalized), within the data range.
double IsoValueInDataUnits(const VolumeObjectData& data, const VolumeObjectOptions& options);

// What changing a volume object's options invalidated (UpdateVolumeObject).
struct VolumeObjectChange {
  bool maps = false;      // the maps were resampled (deformations, map size)
  bool pass = false;      // the pass options differ (render::VolumePass::SetOptions)
  bool transfer = false;  // options.transfer differs (render::VolumePass::SetTransferFunction)
  bool Any() const { return maps || pass || transfer; }
};
// Turns `data`, made with `old_options`, into what MakeVolumeObject makes
// with `options` (same volume and transfer function): only deformation or
// map-size changes resample the maps (milliseconds for 64^3); the
// pass options (mode, iso value, spacing, lighting, Jacobian, bits) touch no
// data here, the caller hands them to the pass. options.Check() first
// (InputError naming `where`); on an error nothing changes. `preview` (the
// viewer while a parameter moves): a peel's map is filled with fewer
// iterations (data.preview_maps); an update without it resamples the map.
VolumeObjectChange UpdateVolumeObject(VolumeObjectData& data,
                                      const VolumeObjectOptions& old_options,
                                      const VolumeObjectOptions& options, const std::string& where,
                                      bool preview = false);
VolumeObjectOptions VolumeObjectOptionsFrom(const scene::Settings& settings);

// A scene's volume object: reads the volume and the transfer function, samples
// the effect; world_from_volume = the object's transform * the centred box.
// Errors name the file and JSON pointer.
struct LoadedVolume {
  VolumeObjectData data;
  VolumeObjectOptions options;
};
LoadedVolume LoadVolumeObject(const scene::Object& object);
// The proxy box (core::ProxyBox, grown by the maps) in the world: what the
// object can cover, for the scene's bounds.
glm::dmat4 WorldFromProxy(const VolumeObjectData& data);

}  // namespace ibr
