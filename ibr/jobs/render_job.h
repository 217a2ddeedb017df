// `ibr render` as one library call. DATASET: a dataset's depth object or
// visual hull (Kautz-Seidel 2001, sec. 4-5) as a one-object scene, rendered
// by ibr::SceneRenderer from novel cameras (another dataset's, or a turntable
// orbit) and written by the one writer of rendered datasets
// (ibr::RenderViewsToDataset: color/NAME.png, depth/NAME.exr camera z with 0
// where empty, mask/NAME.png, dataset.json, staged so a failure leaves
// nothing behind); optionally compared with a true mesh (core/metrics).
// SCENE.json: every camera of the scene file (ibr::RenderSceneToDataset).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "core/metrics.h"
#include "ibr/depth_object.h"
#include "ibr/scene_renderer.h"
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
  SceneRenderStats render;  // per view: draw + readback (the scene renderer's)
  // With a truth mesh: silhouette IoU per view, and the depth errors of every
  // pixel both cover, as fractions of the mesh's largest extent.
  std::vector<double> iou;
  std::optional<core::ErrorStats> depth_error;
};

// A dataset's depth object as `ibr view` opens it, before any window or
// context: the manifest read (ReadMapDataset: the map limit checked before
// any image is read), its up (capture::DefaultUp), its maps, and `options`
// with, when `outside_auto`, the outside policy ChooseOutsidePolicy picks for
// the maps (its reason said through `say`).
struct DatasetObject {
  MapSet maps;
  DepthObjectOptions options;
  capture::UpChoice up;
  std::string name;  // the dataset folder's name
};
DatasetObject LoadDatasetObject(const std::filesystem::path& dataset,
                                const DepthObjectOptions& options, bool outside_auto,
                                const std::function<void(const std::string&)>& say);

// Needs a current context. `progress` gets one line per view.
DatasetRenderStats RenderDatasetToDataset(
    render::ProgramCache& programs, const DatasetRenderJob& job, const std::filesystem::path& out,
    const std::function<void(const std::string&)>& progress = {});

// `ibr render`'s whole job: job.dataset a scene file (*.json; it names its
// own cameras and options, so cameras, orbit, size, truth mesh, up and arc
// must be unset, else InputError) through RenderSceneToDataset, else
// RenderDatasetToDataset. `progress` gets one line per view ("render: ...");
// returns the summary lines (accuracy, frame time, where the output went).
// A truth mesh with no measurable pixel in any view is an InputError, never
// a NaN. Needs a current context.
std::vector<std::string> RenderToDataset(render::ProgramCache& programs,
                                         const DatasetRenderJob& job,
                                         const std::filesystem::path& out,
                                         const std::function<void(const std::string&)>& progress);

}  // namespace ibr
