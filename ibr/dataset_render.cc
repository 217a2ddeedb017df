#include "ibr/dataset_render.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/builtin_scenes.h"
#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/demo_scene.h"
#include "ibr/views.h"
#include "render/gl/gl.h"
#include "render/passes/pass.h"

namespace ibr {
namespace {

// --cameras PATH: a dataset folder or manifest (images not needed), or a
// scene file whose "cameras" are used (an orbit goes around the dataset's box).
std::vector<NamedView> NovelViews(const std::filesystem::path& path, int size,
                                  const capture::Dataset& dataset) {
  bool scene_file = false;
  if (!std::filesystem::exists(path)) {
    core::ThrowFileError("ibr render", path,
                         "--cameras: does not exist (a dataset folder, a cameras-only "
                         "dataset.json or a scene file)");
  }
  if (!std::filesystem::is_directory(path)) {
    std::ifstream in(path, std::ios::binary);
    if (!in) core::ThrowFileError("ibr render", path, "--cameras: cannot open");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    scene_file = j.is_object() && !j.contains("format") && j.contains("cameras");
  }
  if (!scene_file) return NamedViewsFromDataset(capture::ReadCameras(path), size);
  const scene::Scene file = scene::ReadScene(path, capture::DefaultSharedDataDir());
  std::vector<NamedView> views = SceneCameraViews(file.cameras, DatasetBox(dataset));
  if (size > 0)
    for (NamedView& v : views) v.view.camera = ResizeCamera(v.view.camera, size);
  return views;
}

}  // namespace

void DatasetRenderJob::Check() const {
  constexpr const char* kWhere = "ibr render";
  if (cameras.empty() == (orbit <= 0))
    core::ThrowInputError(kWhere, "give exactly one of --cameras OTHER_DATASET or --orbit N");
  // The upper bound: render::CheckFrameSize (GL limits, frame budget) per view.
  if (size < 0) core::ThrowInputError(kWhere, "--size {} is negative", size);
  if (!(arc_deg > 0 && arc_deg <= 360))
    core::ThrowInputError(kWhere, "--arc {} degrees outside (0, 360]", arc_deg);
  if (arc_deg < 360 && orbit <= 0) core::ThrowInputError(kWhere, "--arc goes with --orbit N");
  if (up && orbit <= 0)
    core::ThrowInputError(kWhere, "--up goes with --orbit N (--cameras name their own poses)");
  options.Check();
}

DatasetRenderStats RenderDatasetToDataset(render::ProgramCache& programs,
                                          const DatasetRenderJob& job,
                                          const std::filesystem::path& out,
                                          const std::function<void(const std::string&)>& progress) {
  job.Check();
  // Parse -> plain CPU data -> GPU -> passes. The manifests first: no image
  // is opened before the map count and every frame size are checked.
  const capture::Dataset dataset = ReadMapDataset(job.dataset);
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  std::vector<NamedView> views;
  OrbitOptions orbit;
  orbit.count = job.orbit;
  orbit.size = job.size > 0 ? job.size : 512;
  orbit.arc_deg = job.arc_deg;
  if (job.orbit > 0) {
    const capture::UpChoice up =
        job.up ? capture::UpChoice{*job.up, "--up"} : capture::DefaultUp(dataset);
    orbit.up = up.up;
    orbit.towards = -MeanViewDirection(ViewsFromDataset(dataset));
    say(fmt::format("orbit up ({:.3f}, {:.3f}, {:.3f}) from {}{}", up.up.x, up.up.y, up.up.z,
                    up.source, job.up ? "" : " (--up to change)"));
    if (job.arc_deg < 360) {
      say(fmt::format("orbit arc {:g} degrees centred on the input views' mean direction",
                      job.arc_deg));
    }
  }
  if (!job.cameras.empty()) {
    views = NovelViews(job.cameras, job.size, dataset);
    const render::GlSizeLimits limits = render::QueryGlSizeLimits();
    for (const NamedView& v : views) {
      render::CheckFrameSize(
          "ibr render",
          job.size > 0 ? std::string("--size")
                       : fmt::format("--cameras '{}': view '{}'", job.cameras.string(), v.name),
          v.view.camera.width, v.view.camera.height, limits);
    }
  } else {
    render::CheckFrameSize("ibr render", "--size", orbit.size, orbit.size);
  }
  MapSet maps = MapsFromDataset(dataset);
  if (job.cameras.empty()) views = OrbitViews(maps, orbit);
  if (views.empty()) core::ThrowInputError("ibr render", "no cameras to render from");
  DepthObjectOptions options = job.options;
  if (job.outside_auto) {
    const OutsideChoice choice = ChooseOutsidePolicy(maps);
    options.outside = choice.policy;
    say(choice.reason);
  }
  DatasetRenderStats stats;
  stats.maps = maps.maps.size();
  spdlog::info("render: {} maps from {}, {} views, {} {} slicing, {} slices{}", stats.maps,
               job.dataset.string(), views.size(), MethodName(options.method),
               SlicingName(options.slicing), SliceCountName(options.slices),
               options.robust_k > 0 ? fmt::format(", robust k={}", options.robust_k) : "");

  DepthObjectRenderer renderer(programs, std::move(maps));
  capture::DatasetWriter writer(out);
  std::optional<capture::SceneMesh> truth;
  double edge = 1;
  if (!job.truth_mesh.empty()) {
    truth = capture::LoadSceneMesh(job.truth_mesh);
    glm::vec3 lo, hi;
    truth->mesh.Bounds(lo, hi);
    edge = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  }
  // Warm-up (shader compilation) so the first view's time is a frame time.
  renderer.RenderImages(views[0].view, options);
  std::vector<double> errors;
  for (size_t i = 0; i < views.size(); ++i) {
    const NamedView& v = views[i];
    render::RenderTarget target(
        DepthObjectRenderer::OutputTargetOptions(v.view.camera.width, v.view.camera.height));
    glFinish();
    core::Stopwatch watch;
    renderer.Render(v.view, options, target);
    glFinish();
    stats.frame_ms.push_back(watch.ElapsedMs());
    const DepthObjectFrame frame = DepthObjectRenderer::ReadFrame(target);
    const int cam = writer.AddCamera(CaptureCamera(v.view.camera));
    writer.AddView(v.name, cam, RigidFromMat4(v.view.cam_from_world), frame.color,
                   DatasetDepth(frame.depth), frame.mask, {});
    int64_t covered = 0;
    for (uint8_t m : frame.mask.values()) covered += m > 0;
    std::string accuracy;
    if (truth) {
      const MeshAccuracy a = CompareToMesh(programs, *truth, v.view, frame.depth, edge);
      errors.insert(errors.end(), a.depth_errors.begin(), a.depth_errors.end());
      stats.iou.push_back(a.iou);
      accuracy = fmt::format(", vs mesh IoU {:.4f}", a.iou);
    }
    if (progress) {
      progress(fmt::format("view {}/{} {} {}x{}: {:.1f} ms, {} object pixels{}", i + 1,
                           views.size(), v.name, v.view.camera.width, v.view.camera.height,
                           stats.frame_ms.back(), covered, accuracy));
    }
  }
  if (truth) stats.depth_error = core::SummarizeErrors(std::move(errors));
  if (dataset.bounds) writer.SetBounds(*dataset.bounds);
  writer.SetDepthUnits(dataset.depth_units);
  writer.Commit();
  return stats;
}

}  // namespace ibr
