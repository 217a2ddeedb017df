// `ibr render DATASET` as one library call: a dataset's depth object or
// visual hull (Kautz-Seidel 2001, sec. 4-5) rendered from novel cameras
// (another dataset's, or a turntable orbit) into a new dataset folder
// (color/NAME.png, depth/NAME.exr camera z with 0 where empty, mask/NAME.png,
// dataset.json), staged by capture::DatasetWriter so a failure leaves nothing
// behind; optionally compared with a true mesh (core/metrics).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/metrics.h"
#include "ibr/depth_object.h"
#include "render/gl/shader_program.h"

namespace ibr {

struct DatasetRenderJob {
  std::filesystem::path dataset;  // the maps
  // Render from these cameras: a dataset folder or manifest (images not
  // needed: capture::ReadCameras), or a scene file's "cameras"; or
  std::filesystem::path cameras;
  int orbit = 0;  // N views on a turntable orbit (exactly one of the two)
  int size = 0;   // output width; 0: the cameras' own, orbit 512
  // Orbit axis; nullopt: capture::DefaultUp of the dataset (its "up", else
  // the input cameras' mean up), printed.
  std::optional<glm::dvec3> up;
  // Orbit: the azimuth span (degrees), centred on the input views' mean
  // direction; 360 = the full turntable.
  double arc_deg = 360;
  std::filesystem::path truth_mesh;  // optional: accuracy against this mesh
  DepthObjectOptions options;
  // options.outside was not given: ChooseOutsidePolicy decides (printed).
  bool outside_auto = false;
  void Check() const;  // core::InputError naming the flag
};

struct DatasetRenderStats {
  size_t maps = 0;
  std::vector<double> frame_ms;  // per view: GPU passes + glFinish, no readback
  // With a truth mesh: silhouette IoU per view, and the depth errors of every
  // pixel both cover, as fractions of the mesh's largest extent.
  std::vector<double> iou;
  std::optional<core::ErrorStats> depth_error;
};

// Needs a current context. `progress` gets one line per view.
DatasetRenderStats RenderDatasetToDataset(
    render::ProgramCache& programs, const DatasetRenderJob& job, const std::filesystem::path& out,
    const std::function<void(const std::string&)>& progress = {});

}  // namespace ibr
