#include "bench/map_count_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bench/peer.h"
#include "bench/sweep.h"
#include "core/error.h"
#include "core/metrics.h"
#include "core/timing.h"
#include "ibr/depth_object.h"
#include "ibr/jobs/demo_job.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "render/gl/frame_timer.h"
#include "render/gl/gl_queries.h"

namespace bench {
namespace {

// Two novel views on a 7-view orbit (25 degrees up): azimuths no ring
// camera of these counts shares. View 0 is timed; both are measured.
std::vector<ibr::ViewCamera> SweepViews(const ibr::MapSet& maps, int size) {
  ibr::OrbitOptions orbit;
  orbit.count = 7;
  orbit.size = size;
  orbit.elevation_deg = 25;
  const std::vector<ibr::NamedView> all = ibr::OrbitViews(maps, orbit);
  return {all[1].view, all[4].view};
}

capture::Bounds MeshBounds(const capture::SceneMesh& scene) {
  glm::vec3 lo, hi;
  scene.mesh.Bounds(lo, hi);
  return {glm::dvec3(lo), glm::dvec3(hi)};
}

// Least-squares slope of y over x (ms per additional map).
double Slope(const std::vector<std::pair<double, double>>& xy) {
  if (xy.size() < 2) return std::nan("");
  double sx = 0, sy = 0;
  for (const auto& [x, y] : xy) sx += x, sy += y;
  const double n = static_cast<double>(xy.size()), mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0;
  for (const auto& [x, y] : xy) sxx += (x - mx) * (x - mx), sxy += (x - mx) * (y - my);
  return sxy / sxx;
}

// A path of the cost sweep at its slice count.
struct MapPath {
  std::string name;
  ibr::Slicing slicing = ibr::Slicing::kRay;
  int slices = 0;
};

// What the sweep shares: the mesh, the options and paths, the tables, and
// per path name the (maps, ms per frame) points of its least-squares fit.
struct MapCountRun {
  MapCountRun(render::ProgramCache& p, const std::string& o, const capture::SceneMesh& s,
              const MapCountSweepOptions& opts)
      : programs(p), object(o), scene(s), options(opts), edge(CubeEdge(MeshBounds(s))) {}
  render::ProgramCache& programs;
  const std::string& object;
  const capture::SceneMesh& scene;
  const MapCountSweepOptions& options;
  const double edge;
  const render::FrameTimerOptions timer{1, 3};
  const std::vector<MapPath> paths = {
      {"ray-skip", ibr::Slicing::kRay, ibr::DepthObjectOptions::kAutoSlices},
      {"orthogonal", ibr::Slicing::kOrthogonal, options.ortho_slices}};
  MapCountSweepResult result{
      Table({"object", "maps", "map_size", "size", "path", "slices", "upload_ms", "first_frame_ms",
             "ms_per_frame", "ms_per_map", "iou", "p95_depth_error"}),
      Table({"object", "maps", "max_maps", "size", "ms_per_frame", "iou_vs_all", "p95_vs_all",
             "iou_vs_mesh", "p95_vs_mesh"})};
  std::map<std::string, std::vector<std::pair<double, double>>> fit;
};

// A ring of the sweep; at the largest (the last in the list) the subsets are
// measured too.
struct RingConfig {
  int count = 0;
  bool largest = false;
};

std::vector<RingConfig> RingConfigs(const MapCountSweepOptions& options) {
  std::vector<RingConfig> rings;
  for (size_t i = 0; i < options.counts.size(); ++i)
    rings.push_back({options.counts[i], i + 1 == options.counts.size()});
  return rings;
}

// One ring capture as its measures see it: the renderer with its maps
// uploaded, the two views (view 0 timed) and the frame target.
struct Ring {
  int count;
  double capture_s, upload_ms;
  ibr::DepthObjectRenderer& renderer;
  const std::vector<ibr::ViewCamera>& views;
  const render::RenderTarget& target;
};

// One path at one ring: a cost row (not drawn: the slice paths past 255
// maps), and the frames from both views (empty when not drawn).
std::vector<render::Frame> MeasureCost(MapCountRun& run, const Ring& ring, const MapPath& path) {
  const std::string& object = run.object;
  const int count = ring.count, map_size = run.options.map_size, size = run.options.view_size;
  ibr::DepthObjectOptions o;
  o.slicing = path.slicing;
  o.slices = path.slices;
  o.texturing = ibr::Texturing::kNone;
  const ibr::FrameParams params = ibr::PrepareFrame(ring.renderer.maps(), ring.views[0], o);
  if (path.slicing != ibr::Slicing::kRay && params.active.size() > 255) {
    fmt::print(stderr,
               "{:7} {:4} maps {:10}: not drawn (the slice paths count at most 255 maps in "
               "the stencil)\n",
               object, count, path.name);
    run.result.cost.AddRow({object, std::to_string(count), std::to_string(map_size),
                            std::to_string(size), path.name, std::to_string(params.slice_count),
                            Num(ring.upload_ms, 1), "nan", "nan", "nan", "nan", "nan"});
    return {};
  }
  core::Stopwatch first;
  render::Frame frame0 = ring.renderer.RenderFrame(ring.views[0], o);
  const double first_ms = first.ElapsedMs();
  const core::TimingStats t = render::TimeFrames(
      [&] { ring.renderer.DrawFrame(ring.views[0], o, ring.target); }, run.timer);
  std::vector<render::Frame> frames;
  frames.push_back(std::move(frame0));
  frames.push_back(ring.renderer.RenderFrame(ring.views[1], o));
  double iou = 0;
  std::vector<double> errors;
  for (size_t i = 0; i < ring.views.size(); ++i) {
    ibr::MeshAccuracy a =
        ibr::CompareToMesh(run.programs, run.scene, ring.views[i], frames[i].depth, run.edge);
    iou += a.iou / static_cast<double>(ring.views.size());
    errors.insert(errors.end(), a.depth_errors.begin(), a.depth_errors.end());
  }
  const double p95 = core::Percentile(errors, 0.95);
  run.fit[path.name].emplace_back(count, t.median_ms);
  run.result.cost.AddRow({object, std::to_string(count), std::to_string(map_size),
                          std::to_string(size), path.name, std::to_string(params.slice_count),
                          Num(ring.upload_ms, 1), Num(first_ms, 1), Num(t.median_ms, 2),
                          Num(t.median_ms / count, 3), Num(iou, 4), Num(p95, 5)});
  fmt::print(stderr,
             "{:7} {:4} maps {:10} ({} slices): capture {:.1f} s, upload {:.1f} ms, first "
             "frame {:.0f} ms, {:.1f} ms/frame = {:.3f} ms/map, IoU {:.4f}, p95 {:.5f} edges\n",
             object, count, path.name, params.slice_count, ring.capture_s, ring.upload_ms, first_ms,
             t.median_ms, t.median_ms / count, iou, p95);
  return frames;
}

// The frame's subset of `k` maps (ibr::NearestMaps) at the largest ring,
// against the frames from every map (`all_frames`) and against the mesh.
void MeasureSubset(MapCountRun& run, const Ring& ring, int k,
                   const std::vector<render::Frame>& all_frames) {
  ibr::DepthObjectOptions o;
  o.slicing = ibr::Slicing::kRay;
  o.texturing = ibr::Texturing::kNone;
  o.max_maps = k;
  // The same steps as the frame from every map (auto counts the finest
  // texel of the maps used).
  ibr::DepthObjectOptions every;
  every.slicing = ibr::Slicing::kRay;
  o.slices = ibr::PrepareFrame(ring.renderer.maps(), ring.views[0], every).slice_count;
  ring.renderer.RenderFrame(ring.views[0], o);  // program, skip grid of this subset
  const core::TimingStats t = render::TimeFrames(
      [&] { ring.renderer.DrawFrame(ring.views[0], o, ring.target); }, run.timer);
  std::vector<core::ViewMetrics> vs_all;
  double iou_mesh = 0;
  std::vector<double> mesh_errors;
  for (size_t i = 0; i < ring.views.size(); ++i) {
    const render::Frame f = ring.renderer.RenderFrame(ring.views[i], o);
    vs_all.push_back(core::CompareDepth(f.depth, all_frames[i].depth, run.edge));
    ibr::MeshAccuracy a =
        ibr::CompareToMesh(run.programs, run.scene, ring.views[i], f.depth, run.edge);
    iou_mesh += a.iou / static_cast<double>(ring.views.size());
    mesh_errors.insert(mesh_errors.end(), a.depth_errors.begin(), a.depth_errors.end());
  }
  const core::PooledMetrics p = core::Pool(vs_all);
  const double p95_mesh = core::Percentile(mesh_errors, 0.95);
  run.result.subset.AddRow({run.object, std::to_string(ring.count), std::to_string(k),
                            std::to_string(run.options.view_size), Num(t.median_ms, 2),
                            Num(p.iou_mean, 4), Num(p.depth.p95, 5), Num(iou_mesh, 4),
                            Num(p95_mesh, 5)});
  fmt::print(stderr,
             "{:7} {:4} maps, nearest {:4}: {:.1f} ms/frame, against every map IoU {:.4f} "
             "p95 {:.5f} edges; against the mesh IoU {:.4f} p95 {:.5f}\n",
             run.object, ring.count, k, t.median_ms, p.iou_mean, p.depth.p95, iou_mesh, p95_mesh);
}

// One ring: its capture and upload, every path's cost, and at the largest
// ring the subsets.
void MeasureRing(MapCountRun& run, const RingConfig& config) {
  const int count = config.count;
  core::Stopwatch capture_watch;
  const ibr::MapSet maps = ibr::CaptureMaps(run.programs, run.scene, fmt::format("ring:{}", count),
                                            run.options.map_size);
  const double capture_s = capture_watch.ElapsedMs() / 1000.0;
  // The upload: the renderer (map table buffers) and every map's layers.
  render::WaitForGpu();
  core::Stopwatch upload_watch;
  ibr::DepthObjectRenderer renderer(run.programs, maps);
  renderer.Upload(ibr::Method::kDepthObject);
  render::WaitForGpu();
  const double upload_ms = upload_watch.ElapsedMs();
  const std::vector<ibr::ViewCamera> views = SweepViews(maps, run.options.view_size);
  const render::RenderTarget target(
      render::FrameTargetOptions(views[0].camera.width, views[0].camera.height));
  const Ring ring{count, capture_s, upload_ms, renderer, views, target};
  std::vector<render::Frame> all_frames;  // ray-skip from every map (the subsets' reference)
  Sweep<MapPath>(run.paths, {}, [&](const MapPath& path, int) {
    std::vector<render::Frame> frames = MeasureCost(run, ring, path);
    if (path.slicing == ibr::Slicing::kRay && !frames.empty()) all_frames = std::move(frames);
  });
  if (!config.largest || all_frames.empty()) return;
  for (const int k : run.options.subsets) {
    if (k < count) MeasureSubset(run, ring, k, all_frames);
  }
}

}  // namespace

MapCountSweepOptions MapCountSweepOptions::Quick() {
  MapCountSweepOptions o;
  o.counts = {6, 24};
  o.subsets = {6, 12};
  o.map_size = 64;
  o.view_size = 128;
  o.ortho_slices = 16;
  return o;
}

MapCountSweepResult RunMapCountSweep(render::ProgramCache& programs, const std::string& object,
                                     const capture::SceneMesh& scene,
                                     const MapCountSweepOptions& options) {
  MapCountRun run(programs, object, scene, options);
  Sweep<RingConfig>(RingConfigs(options), {},
                    [&](const RingConfig& ring, int) { MeasureRing(run, ring); });
  for (const MapPath& path : run.paths) {
    fmt::print(stderr, "{:7} {:10}: {:.3f} ms per additional map (least squares over counts)\n",
               object, path.name, Slope(run.fit[path.name]));
  }
  return std::move(run.result);
}

void WriteMapCountSweep(const MapCountSweepResult& result, const std::filesystem::path& stem,
                        const std::filesystem::path& out) {
  result.cost.WriteCsv(stem.string() + "_maps.csv");
  result.subset.WriteCsv(stem.string() + "_maps_subset.csv");
  fmt::print("\n{}\n\n{}\n", result.cost.Format(), result.subset.Format());
  if (out.empty()) return;
  PlotPng(result.cost,
          {.title = "Depth object: ms per frame vs map count (ring captures)",
           .x_column = "maps",
           .y_column = "ms_per_frame",
           .series_column = "path",
           .x_label = "maps",
           .y_label = "ms per frame"},
          out / "maps_cost.png");
  if (!result.subset.rows().empty()) {
    PlotPng(result.subset,
            {.title = "The nearest max_maps maps: p95 depth error against every map",
             .x_column = "max_maps",
             .y_column = "p95_vs_all",
             .series_column = "object",
             .x_label = "maps the frame tests (of the largest ring)",
             .y_label = "p95 depth error (cube edges)"},
            out / "maps_subset_error.png");
  }
}

}  // namespace bench
