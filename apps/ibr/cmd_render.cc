// `ibr render SCENE.json`: every camera of a scene file (scene/scene.h)
// through ibr::RenderSceneToDataset.
// `ibr render DATASET`: renders the dataset's depth object or visual hull
// (Kautz-Seidel 2001, sec. 4-5) from novel cameras (another dataset's, or a
// turntable orbit, or an arc of it around the input views; its up the
// dataset's, printed). Output DIR is itself a dataset: color/NAME.png,
// depth/NAME.exr (camera z of the first surface, 0 where empty),
// mask/NAME.png and dataset.json with the cameras; staged, so a failure
// leaves nothing behind.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "apps/ibr/commands.h"
#include "capture/builtin_scenes.h"
#include "core/error.h"
#include "core/metrics.h"
#include "core/timing.h"
#include "ibr/dataset_render.h"
#include "ibr/scene_options.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "render/gl/context.h"
#include "scene/scene.h"

namespace apps {
namespace {

struct RenderCommandOptions {
  std::filesystem::path dataset;  // or a scene file (*.json)
  ibr::DepthObjectFlags flags;
  std::filesystem::path cameras;
  int orbit = 0;
  std::string up;                    // empty: the dataset's (capture::DefaultUp)
  double arc_deg = 360;              // orbit azimuth span around the input views
  int size = 0;                      // 0: the cameras' own width (--cameras) or 512 (--orbit)
  std::filesystem::path truth_mesh;  // optional: report accuracy against this mesh
  std::filesystem::path out;
};

void RunRenderScene(const RenderCommandOptions& o) {
  if (!o.cameras.empty() || o.orbit > 0 || o.size > 0 || !o.truth_mesh.empty() || !o.up.empty() ||
      o.arc_deg != 360) {
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
  if (o.out.empty()) core::ThrowInputError("ibr render", "--out DIR is required");
  ibr::DatasetRenderJob job{
      .dataset = o.dataset,
      .cameras = o.cameras,
      .orbit = o.orbit,
      .size = o.size,
      .up = o.up.empty() ? std::nullopt : std::optional(ibr::ParseUp(o.up, "--up")),
      .arc_deg = o.arc_deg,
      .truth_mesh = o.truth_mesh,
      .options = ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(o.flags)),
      .outside_auto = o.flags.outside.empty()};
  job.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  const ibr::DatasetRenderStats stats = ibr::RenderDatasetToDataset(
      programs, job, o.out, [](const std::string& line) { fmt::print("render: {}\n", line); });
  if (stats.depth_error) {
    const core::ErrorStats& e = *stats.depth_error;
    // Every view was checked (core::CheckMeasurable); an empty pool is never printed as NaN.
    if (e.count == 0 || stats.iou.empty()) {
      core::ThrowInputError("ibr render", "--truth-mesh '{}': no pixel to measure in any view",
                            o.truth_mesh.string());
    }
    // A mean above the p95: a few large errors dominate; the max says how large.
    const std::string tail = core::HeavyTailNote(e, 5);
    fmt::print(
        "render: vs {}: silhouette IoU mean {:.4f} / worst {:.4f}; depth error mean {:.5f} / p95 "
        "{:.5f}{} of the mesh's largest extent\n",
        o.truth_mesh.string(), core::SummarizeErrors(stats.iou).mean,
        *std::min_element(stats.iou.begin(), stats.iou.end()), e.mean, e.p95, tail);
  }
  const core::TimingStats t = core::Summarize(stats.frame_ms);
  fmt::print(
      "render: {} views, {:.1f} ms per frame (median; min {:.1f}; GPU passes + glFinish, no "
      "readback) -> {}\n",
      stats.frame_ms.size(), t.median_ms, t.min_ms, std::filesystem::absolute(o.out).string());
}

void AddRenderCommand(CLI::App& app) {
  static RenderCommandOptions o;
  auto* cmd = app.add_subcommand("render",
                                 "Render a scene file, or a dataset's depth object or visual hull "
                                 "from novel cameras (Kautz-Seidel 2001, sec. 4-5)");
  cmd->add_option("DATASET", o.dataset, "input dataset directory, or a scene file SCENE.json")
      ->required();
  AddDepthObjectFlags(cmd, o.flags);
  cmd->add_option("--cameras", o.cameras,
                  "render from these cameras: a dataset (its images not needed), a cameras-only "
                  "dataset.json, or a scene file's \"cameras\"");
  cmd->add_option("--orbit", o.orbit, "render N views on a turntable orbit");
  cmd->add_option("--up", o.up,
                  "orbit axis: x, y, z, -x, -y, -z or three numbers 'X,Y,Z' (default: the "
                  "dataset's \"up\", else its cameras' mean up)");
  cmd->add_option("--arc", o.arc_deg,
                  "orbit: span this many degrees centred on the input views' mean direction")
      ->capture_default_str();
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
