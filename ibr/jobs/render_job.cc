#include "ibr/jobs/render_job.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/builtin_scenes.h"
#include "capture/dataset.h"
#include "capture/input_kind.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "core/metrics.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/jobs/demo_job.h"
#include "ibr/kinds/depth_object_kind.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
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
  // What was given comes first: a volume or a mesh is named with its command.
  capture::CheckDatasetInput(kWhere, dataset, /*scene_ok=*/true);
  if (cameras.empty() == (orbit <= 0))
    core::ThrowInputError(kWhere, "give exactly one of --cameras OTHER_DATASET or --orbit N");
  // The upper bound: render::CheckFrameSize (GL limits, memory budget) per view.
  if (size < 0) core::ThrowInputError(kWhere, "--size {} is negative", size);
  if (!(arc_deg > 0 && arc_deg <= 360))
    core::ThrowInputError(kWhere, "--arc {} degrees outside (0, 360]", arc_deg);
  if (arc_deg < 360 && orbit <= 0) core::ThrowInputError(kWhere, "--arc goes with --orbit N");
  if (up && orbit <= 0)
    core::ThrowInputError(kWhere, "--up goes with --orbit N (--cameras name their own poses)");
  options.Check();
}

namespace {

// Every map becomes textures (at most GL_MAX_TEXTURE_SIZE a side) and is held
// on the CPU and the GPU at once: colour 3 + depth 4 + mask 1 bytes per
// pixel as images, twice while the scene's pass is built (the loaded scene's
// copy and the pass's own), RGBA8 4 + R32F 4 + R8 1 as textures. Both are
// checked from the manifest, before any image is read, each refusal naming
// its reason.
void CheckMapsFit(const capture::Dataset& dataset, const render::GlSizeLimits& limits) {
  constexpr uint64_t kBytesPerPixel = 2 * (3 + 4 + 1) + 4 + 4 + 1;
  const std::string where = fmt::format("ibr render: '{}'", dataset.root.string());
  uint64_t bytes = 0;
  for (const capture::DatasetView& v : dataset.views) {
    const capture::Camera& c = dataset.camera(v);
    if (c.width > limits.max_texture_size || c.height > limits.max_texture_size) {
      core::ThrowInputError(where,
                            "view '{}': a {}x{} map is larger than this GL implementation's "
                            "textures, at most {} a side (GL_MAX_TEXTURE_SIZE)",
                            v.name, c.width, c.height, limits.max_texture_size);
    }
    bytes += uint64_t(c.width) * uint64_t(c.height) * kBytesPerPixel;
  }
  core::CheckMemory(bytes, where,
                    fmt::format("its {} maps ({} bytes per pixel as images and textures)",
                                dataset.views.size(), kBytesPerPixel));
}

// `options` with the outside policy ChooseOutsidePolicy picks for `maps`
// when `outside_auto` (its reason said).
DepthObjectOptions WithOutsidePolicy(const MapSet& maps, DepthObjectOptions options,
                                     bool outside_auto,
                                     const std::function<void(const std::string&)>& say) {
  if (outside_auto) {
    const OutsideChoice choice = ChooseOutsidePolicy(maps);
    options.outside = choice.policy;
    if (say) say(choice.reason);
  }
  return options;
}

}  // namespace

DatasetObject LoadDatasetObject(const std::filesystem::path& path,
                                const DepthObjectOptions& options, bool outside_auto,
                                const std::function<void(const std::string&)>& say) {
  options.Check();
  const capture::Dataset dataset = ReadMapDataset(path);
  DatasetObject object;
  object.up = capture::DefaultUp(dataset);
  object.maps = MapsFromDataset(dataset);
  object.options = WithOutsidePolicy(object.maps, options, outside_auto, say);
  object.name =
      path.filename().empty() ? path.parent_path().filename().string() : path.filename().string();
  return object;
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
  CheckMapsFit(dataset, render::QueryGlSizeLimits());
  MapSet maps = MapsFromDataset(dataset);
  if (job.cameras.empty()) views = OrbitViews(maps, orbit);
  if (views.empty()) core::ThrowInputError("ibr render", "no cameras to render from");
  const DepthObjectOptions options = WithOutsidePolicy(maps, job.options, job.outside_auto, say);
  DatasetRenderStats stats;
  stats.maps = maps.maps.size();
  spdlog::info("render: {} maps from {}, {} views, {} {} slicing, {} slices{}", stats.maps,
               job.dataset.string(), views.size(), MethodName(options.method),
               SlicingName(options.slicing), SliceCountName(options.slices),
               options.robust_k > 0 ? fmt::format(", robust k={}", options.robust_k) : "");

  // A one-object scene: the dataset's maps as a depth object (or visual
  // hull) in the world, drawn by the scene renderer like any scene's.
  LoadedScene scene = DepthObjectScene(job.dataset.filename().string(), std::move(maps), options);
  SceneRenderer renderer(programs, scene);
  scene.objects.clear();  // the pass holds its own copy of the maps (CheckMapsFit counts both)

  std::optional<capture::SceneMesh> truth;
  double edge = 1;
  if (!job.truth_mesh.empty()) {
    truth = capture::LoadSceneMesh(job.truth_mesh, {}, capture::MeshTextures::kSkip);
    glm::vec3 lo, hi;
    truth->mesh.Bounds(lo, hi);
    edge = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  }
  std::vector<double> errors;
  const auto measure = [&](const NamedView& v, const render::Frame& frame) -> std::string {
    if (!truth) return "";
    const MeshAccuracy a = CompareToMesh(programs, *truth, v.view, frame.depth, edge);
    core::CheckMeasurable(
        a.rendered_pixels, a.truth_pixels, static_cast<int64_t>(a.depth_errors.size()),
        fmt::format("ibr render --truth-mesh '{}'", job.truth_mesh.string()), v.name);
    errors.insert(errors.end(), a.depth_errors.begin(), a.depth_errors.end());
    stats.iou.push_back(a.iou);
    return fmt::format(", vs mesh IoU {:.4f}", a.iou);
  };
  stats.render = RenderViewsToDataset(
      renderer, views, out, {.bounds = dataset.bounds, .depth_units = dataset.depth_units},
      progress, measure);
  if (truth) stats.depth_error = core::SummarizeErrors(std::move(errors));
  return stats;
}

std::vector<std::string> RenderToDataset(render::ProgramCache& programs,
                                         const DatasetRenderJob& job,
                                         const std::filesystem::path& out,
                                         const std::function<void(const std::string&)>& progress) {
  const std::string where = std::filesystem::absolute(out).string();
  if (job.dataset.extension() == ".json") {
    capture::CheckDatasetInput("ibr render", job.dataset, /*scene_ok=*/true);
    if (!job.cameras.empty() || job.orbit > 0 || job.size > 0 || !job.truth_mesh.empty() ||
        job.up || job.arc_deg != 360) {
      core::ThrowInputError(
          "ibr render",
          "a scene file names its own cameras and options: give only SCENE.json and --out");
    }
    const scene::Scene file = scene::ReadScene(job.dataset, capture::DefaultSharedDataDir());
    const LoadedScene loaded = LoadScene(programs, file);
    const SceneRenderStats stats = RenderSceneToDataset(programs, loaded, out, progress);
    return {fmt::format(
        "render: scene {}: {} views, passes [{}]{}, {:.1f} ms per frame (median; draw + readback "
        "+ composite) -> {}",
        job.dataset.string(), stats.frame_ms.size(), fmt::join(stats.passes, ", "),
        loaded.disabled.empty() ? "" : fmt::format(" ({} disabled)", loaded.disabled.size()),
        core::Summarize(stats.frame_ms).median_ms, where)};
  }
  const DatasetRenderStats stats = RenderDatasetToDataset(programs, job, out, progress);
  std::vector<std::string> lines;
  if (stats.depth_error) {
    const core::ErrorStats& e = *stats.depth_error;
    // Every view was checked (core::CheckMeasurable); an empty pool is never printed as NaN.
    if (e.count == 0 || stats.iou.empty()) {
      core::ThrowInputError("ibr render", "--truth-mesh '{}': no pixel to measure in any view",
                            job.truth_mesh.string());
    }
    // A mean above the p95: a few large errors dominate; the max says how large.
    lines.push_back(fmt::format(
        "render: vs {}: silhouette IoU mean {:.4f} / worst {:.4f}; depth error mean {:.5f} / p95 "
        "{:.5f}{} of the mesh's largest extent",
        job.truth_mesh.string(), core::SummarizeErrors(stats.iou).mean,
        *std::min_element(stats.iou.begin(), stats.iou.end()), e.mean, e.p95,
        core::HeavyTailNote(e, 5)));
  }
  const core::TimingStats t = core::Summarize(stats.render.frame_ms);
  lines.push_back(fmt::format(
      "render: {} views, passes [{}], {:.1f} ms per frame (median; min {:.1f}; draw + readback) "
      "-> {}",
      stats.render.frame_ms.size(), fmt::join(stats.render.passes, ", "), t.median_ms, t.min_ms,
      where));
  return lines;
}

}  // namespace ibr
