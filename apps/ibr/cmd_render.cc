// `ibr render SCENE.json`: every camera of a scene file (scene/scene.h)
// through ibr::RenderSceneToDataset.
// `ibr render DATASET`: renders the dataset's depth object or visual hull
// (Kautz-Seidel 2001, sec. 4-5) from novel cameras (another dataset's, or a
// turntable orbit). Output DIR is itself a dataset: color/NAME.png,
// depth/NAME.exr (camera z of the first surface, 0 where empty),
// mask/NAME.png and dataset.json with the cameras; staged, so a failure
// leaves nothing behind.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "apps/ibr/commands.h"
#include "capture/builtin_scenes.h"
#include "capture/dataset.h"
#include "core/error.h"
#include "core/metrics.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/demo_scene.h"
#include "ibr/depth_object.h"
#include "ibr/scene_options.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "render/gl/context.h"
#include "render/gl/gl.h"
#include "render/passes/pass.h"
#include "scene/scene.h"

namespace apps {
namespace {

struct RenderCommandOptions {
  std::filesystem::path dataset;  // or a scene file (*.json)
  ibr::DepthObjectFlags flags;
  std::filesystem::path cameras;
  int orbit = 0;
  int size = 0;                      // 0: the cameras' own width (--cameras) or 512 (--orbit)
  std::filesystem::path truth_mesh;  // optional: report accuracy against this mesh
  std::filesystem::path out;
};

void RunRenderScene(const RenderCommandOptions& o) {
  if (!o.cameras.empty() || o.orbit > 0 || o.size > 0 || !o.truth_mesh.empty()) {
    core::ThrowInputError(
        "ibr render",
        "a scene file names its own cameras and options: give only SCENE.json and --out");
  }
  const scene::Scene file = scene::ReadScene(o.dataset, capture::DefaultSharedDataDir());
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  const ibr::LoadedScene loaded = ibr::LoadScene(programs, file);
  const ibr::SceneRenderStats stats = ibr::RenderSceneToDataset(
      programs, loaded, o.out, [](const std::string& line) { fmt::print("render: {}\n", line); });
  std::string passes;
  for (const std::string& p : stats.passes) passes += (passes.empty() ? "" : ", ") + p;
  const core::TimingStats t = core::Summarize(stats.frame_ms);
  fmt::print(
      "render: scene {}: {} views, passes [{}]{}, {:.1f} ms per frame (median; draw + readback + "
      "composite) -> {}\n",
      o.dataset.string(), stats.frame_ms.size(), passes,
      loaded.disabled.empty() ? "" : fmt::format(" ({} disabled)", loaded.disabled.size()),
      t.median_ms, std::filesystem::absolute(o.out).string());
}

void RunRender(const RenderCommandOptions& o) {
  constexpr const char* kWhere = "ibr render";
  if (o.out.empty()) core::ThrowInputError(kWhere, "--out DIR is required");
  if (o.cameras.empty() == (o.orbit <= 0)) {
    core::ThrowInputError(kWhere, "give exactly one of --cameras OTHER_DATASET or --orbit N");
  }
  if (o.size < 0) core::ThrowInputError(kWhere, "--size {} is negative", o.size);
  const ibr::DepthObjectOptions options =
      ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(o.flags));

  // Parse -> plain CPU data -> GPU -> passes. The manifests first (no image
  // is opened before the map count and every frame size are checked).
  const capture::Dataset dataset = ibr::ReadMapDataset(o.dataset);
  std::vector<ibr::NamedView> views;
  if (!o.cameras.empty()) {
    const capture::Dataset other = capture::ReadDataset(o.cameras);
    const std::vector<ibr::ViewCamera> cams = ibr::ViewsFromDataset(other);
    for (size_t i = 0; i < cams.size(); ++i) {
      ibr::NamedView v{other.views[i].name, cams[i]};
      if (o.size > 0) v.view.camera = ibr::ResizeCamera(v.view.camera, o.size);
      views.push_back(v);
    }
  }
  ibr::OrbitOptions orbit;
  orbit.count = o.orbit;
  orbit.size = o.size > 0 ? o.size : 512;
  auto context = render::HeadlessContext::Create();
  if (o.cameras.empty()) render::CheckFrameSize(kWhere, "--size", orbit.size, orbit.size);
  for (const ibr::NamedView& v : views) {
    render::CheckFrameSize(
        kWhere,
        o.size > 0 ? std::string("--size")
                   : fmt::format("--cameras '{}': view '{}'", o.cameras.string(), v.name),
        v.view.camera.width, v.view.camera.height);
  }
  ibr::MapSet maps = ibr::MapsFromDataset(dataset);
  if (o.cameras.empty()) views = ibr::OrbitViews(maps, orbit);
  spdlog::info("render: {} maps from {}, {} views, {} {} slicing, {} slices{}", maps.maps.size(),
               o.dataset.string(), views.size(), o.flags.method, o.flags.slicing, o.flags.slices,
               o.flags.robust > 0 ? fmt::format(", robust k={}", o.flags.robust) : "");

  render::ProgramCache programs;
  ibr::DepthObjectRenderer renderer(programs, std::move(maps));
  capture::DatasetWriter writer(o.out);
  std::optional<capture::SceneMesh> truth;
  double edge = 1;
  if (!o.truth_mesh.empty()) {
    truth = capture::LoadSceneMesh(o.truth_mesh);
    glm::vec3 lo, hi;
    truth->mesh.Bounds(lo, hi);
    edge = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  }
  // Warm-up (shader compilation) so the first view's time is a frame time.
  renderer.RenderImages(views[0].view, options);
  std::vector<double> times, errors;
  double iou_sum = 0, iou_min = 1;
  for (size_t i = 0; i < views.size(); ++i) {
    const ibr::NamedView& v = views[i];
    render::RenderTarget target(
        ibr::DepthObjectRenderer::OutputTargetOptions(v.view.camera.width, v.view.camera.height));
    glFinish();
    core::Stopwatch watch;
    renderer.Render(v.view, options, target);
    glFinish();
    times.push_back(watch.ElapsedMs());
    const ibr::DepthObjectFrame frame = ibr::DepthObjectRenderer::ReadFrame(target);
    const int cam = writer.AddCamera(ibr::CaptureCamera(v.view.camera));
    writer.AddView(v.name, cam, ibr::RigidFromMat4(v.view.cam_from_world), frame.color,
                   ibr::DatasetDepth(frame.depth), frame.mask, {});
    int64_t covered = 0;
    for (uint8_t m : frame.mask.values()) covered += m > 0;
    std::string accuracy;
    if (truth) {
      const ibr::MeshAccuracy a = ibr::CompareToMesh(programs, *truth, v.view, frame.depth, edge);
      errors.insert(errors.end(), a.depth_errors.begin(), a.depth_errors.end());
      iou_sum += a.iou;
      iou_min = std::min(iou_min, a.iou);
      accuracy = fmt::format(", vs mesh IoU {:.4f}", a.iou);
    }
    fmt::print("render: view {}/{} {} {}x{}: {:.1f} ms, {} object pixels{}\n", i + 1, views.size(),
               v.name, v.view.camera.width, v.view.camera.height, times.back(), covered, accuracy);
  }
  if (truth) {
    const core::ErrorStats e = core::SummarizeErrors(std::move(errors));
    fmt::print(
        "render: vs {}: silhouette IoU mean {:.4f} / worst {:.4f}; depth error mean {:.5f} / p95 "
        "{:.5f} "
        "of the mesh's largest extent\n",
        o.truth_mesh.string(), iou_sum / views.size(), iou_min, e.mean, e.p95);
  }
  if (dataset.bounds) writer.SetBounds(*dataset.bounds);
  writer.SetDepthUnits(dataset.depth_units);
  writer.Commit();
  const core::TimingStats t = core::Summarize(times);
  fmt::print(
      "render: {} views, {:.1f} ms per frame (median; min {:.1f}; GPU passes + glFinish, no "
      "readback) -> {}\n",
      views.size(), t.median_ms, t.min_ms, std::filesystem::absolute(o.out).string());
}

void AddRenderCommand(CLI::App& app) {
  static RenderCommandOptions o;
  auto* cmd = app.add_subcommand("render",
                                 "Render a scene file, or a dataset's depth object or visual hull "
                                 "from novel cameras (Kautz-Seidel 2001, sec. 4-5)");
  cmd->add_option("DATASET", o.dataset, "input dataset directory, or a scene file SCENE.json")
      ->required();
  cmd->add_option("--method", o.flags.method, "depth-object | visual-hull")->capture_default_str();
  cmd->add_option("--slicing", o.flags.slicing, "orthogonal | screen | ray")->capture_default_str();
  cmd->add_option("--slices", o.flags.slices,
                  "slices through the box per frame (ray: steps), or auto (one per depth texel)")
      ->capture_default_str();
  cmd->add_option("--robust", o.flags.robust, "keep pixels where at least N-K maps agree")
      ->capture_default_str();
  cmd->add_option("--texturing", o.flags.texturing, "vdt | visibility | none")
      ->capture_default_str();
  cmd->add_option("--outside", o.flags.outside, "points outside a map's image: pass | fail")
      ->capture_default_str();
  cmd->add_option("--invalid-depth", o.flags.invalid_depth,
                  "depth 0 inside the mask: empty | no-constraint")
      ->capture_default_str();
  cmd->add_option("--cameras", o.cameras, "render from this other dataset's cameras");
  cmd->add_option("--orbit", o.orbit, "render N views on a turntable orbit");
  cmd->add_option("--size", o.size,
                  "output width in pixels (default: the cameras' own, orbit 512)");
  cmd->add_option("--truth-mesh", o.truth_mesh,
                  "also print silhouette IoU and depth error against this mesh");
  cmd->add_option("--out", o.out, "output directory (a dataset of the rendered views)")->required();
  cmd->callback([] {
    if (o.dataset.extension() == ".json") {
      RunRenderScene(o);
    } else {
      RunRender(o);
    }
  });
}

}  // namespace

IBR_REGISTER_COMMAND("render", AddRenderCommand);

}  // namespace apps
