#include "bench/kautz_seidel_experiments.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

#include "bench/displacement_bench.h"
#include "bench/peer.h"
#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/displacement_error.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "ibr/jobs/demo_job.h"
#include "ibr/views.h"
#include "render/passes/pass.h"

namespace bench {
namespace {

namespace fs = std::filesystem;

// The paper's figures (Kautz-Seidel 2001, PIII/800 + GeForce 2 GTS).
constexpr const char* kSourcePoints = "Kautz-Seidel 2001 sec. 6 (Fig. 14)";
constexpr double kPaperFps150 = 24.0;  // object ~150 x 150 px, 70 slices
constexpr double kPaperFps400 = 2.7;   // object ~400 x 400 px, 150 slices
constexpr const char* kSourceAngle = "Kautz-Seidel 2001 sec. 6";
constexpr double kPaperBestAngleSpeedup = 1.2;  // "up to 20 % faster" at oblique views
constexpr const char* kSourceFig12 = "Kautz-Seidel 2001 Fig. 12";
constexpr const char* kSourceDonut = "Kautz-Seidel 2001 sec. 6, Figs. 1, 17, 18";

const std::map<std::string, std::string>& MeshFiles() {
  static const std::map<std::string, std::string> files = {{"bunny", "stanford-bunny.obj"},
                                                           {"cow", "cow.obj"},
                                                           {"spot", "spot.obj"},
                                                           {"teapot", "teapot.obj"}};
  return files;
}

bool IsShape(const std::string& name) {
  const std::vector<std::string> shapes = capture::ShapeNames();
  return std::find(shapes.begin(), shapes.end(), name) != shapes.end();
}

capture::SceneMesh LoadObject(const std::string& name, bool quick, std::string& used) {
  if (quick || IsShape(name)) {
    used = quick ? "cup" : name;
    return capture::MakeShapeScene(used);
  }
  const fs::path path = ibr::SharedDataDir() / "meshes" / MeshFiles().at(name);
  if (!fs::exists(path)) {
    fmt::print("bench kautz-seidel: {} is absent, the cup instead\n", path.string());
    used = "cup";
    return capture::MakeShapeScene(used);
  }
  used = name;
  return capture::LoadSceneMesh(path);
}

// The orbit camera at `elevation_deg` and azimuth `azimuth_deg` (a multiple
// of 15 degrees; 0 looks along a cube axis, face-on to one slicing family).
ibr::ViewCamera ViewAt(const ibr::MapSet& maps, int size, double elevation_deg,
                       double azimuth_deg) {
  constexpr int kCount = 24;
  const int index = static_cast<int>(std::lround(azimuth_deg / (360.0 / kCount)));
  IBR_CHECK_EQ(index * (360.0 / kCount), azimuth_deg);
  ibr::OrbitOptions orbit;
  orbit.count = kCount;
  orbit.size = size;
  orbit.elevation_deg = elevation_deg;
  return ibr::OrbitViews(maps, orbit)[static_cast<size_t>(index % kCount)].view;
}

struct Measured {
  double ms = 0;
  int64_t covered = 0;
  int bbox_px = 0;  // the object's screen bounding box, longer side
  render::Frame frame;
};

Measured Measure(ibr::DepthObjectRenderer& renderer, const ibr::ViewCamera& view,
                 const ibr::DepthObjectOptions& o, const render::FrameTimerOptions& timer) {
  Measured m;
  m.frame = renderer.RenderFrame(view, o);
  int x0 = view.camera.width, y0 = view.camera.height, x1 = -1, y1 = -1;
  for (int y = 0; y < m.frame.color.height(); ++y) {
    for (int x = 0; x < m.frame.color.width(); ++x) {
      if (!m.frame.Covered(x, y)) continue;
      ++m.covered;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  m.bbox_px = x1 < 0 ? 0 : std::max(x1 - x0, y1 - y0) + 1;
  const render::RenderTarget target(
      render::FrameTargetOptions(view.camera.width, view.camera.height));
  m.ms = render::TimeFrames([&] { renderer.DrawFrame(view, o, target); }, timer).median_ms;
  return m;
}

// Fragments the slice passes shade: every slice's coverage x the maps it is
// tested against (the paper's "less pixels have to be drawn"); and that
// number of maps.
std::pair<double, size_t> SliceFragments(ibr::DepthObjectRenderer& renderer,
                                         const ibr::ViewCamera& view,
                                         const ibr::DepthObjectOptions& o) {
  const ibr::FrameParams params = ibr::PrepareFrame(renderer.maps(), view, o);
  double fragments = 0;
  for (const core::Image8& c : renderer.SliceCoverage(params)) {
    for (uint8_t v : c.values()) fragments += v > 0;
  }
  return {fragments * static_cast<double>(params.active.size()), params.active.size()};
}

ibr::DepthObjectOptions Orthogonal(ibr::Method method, int slices) {
  ibr::DepthObjectOptions o;
  o.method = method;
  o.slicing = ibr::Slicing::kOrthogonal;  // the paper's slicing for depth objects
  o.slices = slices;
  o.texturing = ibr::Texturing::kNone;
  return o;
}

const ibr::Method kMethods[] = {ibr::Method::kDepthObject, ibr::Method::kVisualHull};

void Fig12(ibr::DepthObjectRenderer& renderer, const KautzSeidelOptions& options, Table& table) {
  const std::vector<int> sizes =
      options.quick ? std::vector<int>{64, 128} : std::vector<int>{128, 192, 256, 384, 512};
  const std::vector<int> slices =
      options.quick ? std::vector<int>{16, 32} : std::vector<int>{16, 32, 64, 128, 256};
  const int fixed_size = options.quick ? 100 : 300;  // the paper's 300 x 300
  constexpr int kFixedSlices = 128;                  // the paper's 128 slices
  auto add = [&](const std::string& sweep, int size, int n) {
    const ibr::ViewCamera view = ViewAt(renderer.maps(), size, 25, 30);
    double depth_object_ms = 0;
    for (ibr::Method method : kMethods) {
      const Measured m = Measure(renderer, view, Orthogonal(method, n), options.timer);
      if (method == ibr::Method::kDepthObject) depth_object_ms = m.ms;
      table.AddRow({sweep, ibr::MethodName(method), std::to_string(size), std::to_string(n),
                    std::to_string(m.covered), Num(m.ms, 2), Num(m.ms / depth_object_ms, 3),
                    kSourceFig12});
      fmt::print(stderr, "fig12 {:8} {:12} {:4} px {:4} slices: {:8.2f} ms ({} px covered)\n",
                 sweep, ibr::MethodName(method), size, n, m.ms, m.covered);
    }
  };
  for (int size : sizes) add("coverage", size, kFixedSlices);
  for (int n : slices) add("slices", fixed_size, n);
}

void Angle(ibr::DepthObjectRenderer& renderer, const KautzSeidelOptions& options, Table& table) {
  const std::vector<double> elevations =
      options.quick ? std::vector<double>{0, 45} : std::vector<double>{0, 15, 30, 45, 60};
  const std::vector<double> azimuths =
      options.quick ? std::vector<double>{0, 45} : std::vector<double>{0, 15, 30, 45};
  const int size = options.quick ? 96 : 300;
  const int slices = options.quick ? 32 : 128;
  for (ibr::Method method : kMethods) {
    const ibr::DepthObjectOptions o = Orthogonal(method, slices);
    double face_ms = 0, face_fragments = 0;
    for (double el : elevations) {
      for (double az : azimuths) {
        const ibr::ViewCamera view = ViewAt(renderer.maps(), size, el, az);
        const Measured m = Measure(renderer, view, o, options.timer);
        const auto [fragments, active_maps] = SliceFragments(renderer, view, o);
        if (el == elevations.front() && az == azimuths.front()) {
          face_ms = m.ms;
          face_fragments = fragments;
        }
        table.AddRow({ibr::MethodName(method), Num(el, 0), Num(az, 0), std::to_string(size),
                      std::to_string(slices), std::to_string(m.covered),
                      std::to_string(active_maps), Num(fragments, 0), Num(m.ms, 2),
                      Num(m.ms / face_ms, 3), Num(fragments / face_fragments, 3),
                      Num(kPaperBestAngleSpeedup, 2), kSourceAngle});
        fmt::print(stderr, "angle {:12} el {:2.0f} az {:2.0f}: {:8.2f} ms, {:.3g} fragments\n",
                   ibr::MethodName(method), el, az, m.ms, fragments);
      }
    }
  }
}

void Points(render::ProgramCache& programs, ibr::DepthObjectRenderer& renderer,
            const KautzSeidelOptions& options, const capture::SceneMesh& scene,
            const capture::Bounds& bounds, Table& table) {
  // The paper sizes the object on screen, not the frame: a probe frame gives
  // the object's bounding box as a fraction of the frame at this view.
  constexpr int kProbeSize = 400;
  const Measured probe =
      Measure(renderer, ViewAt(renderer.maps(), kProbeSize, 25, 30),
              Orthogonal(ibr::Method::kDepthObject, 32), {.warmup_frames = 0, .timed_frames = 1});
  IBR_CHECK_GT(probe.bbox_px, 0);
  const double fraction = static_cast<double>(probe.bbox_px) / kProbeSize;
  struct Point {
    int object_px, slices;
    double paper_fps;
  };
  const double scale = options.quick ? 1.0 / 3.0 : 1.0;  // quick: the same points, smaller
  const Point points[] = {{static_cast<int>(std::lround(150 * scale)), 70, kPaperFps150},
                          {static_cast<int>(std::lround(400 * scale)), 150, kPaperFps400}};
  const double edge = CubeEdge(bounds);
  double first_ms = 0;
  for (const Point& point : points) {
    const int size = std::max(16, static_cast<int>(std::lround(point.object_px / fraction)));
    const ibr::ViewCamera view = ViewAt(renderer.maps(), size, 25, 30);
    const Measured m =
        Measure(renderer, view, Orthogonal(ibr::Method::kDepthObject, point.slices), options.timer);
    const core::ImageF truth = RenderTruthDepth(programs, scene.mesh, {view}, bounds)[0];
    const ViewMetrics e = CompareDepth(m.frame.depth, truth, edge);
    if (first_ms == 0) first_ms = m.ms;
    table.AddRow({ibr::MethodName(ibr::Method::kDepthObject), std::to_string(point.object_px),
                  std::to_string(size), std::to_string(point.slices), std::to_string(m.bbox_px),
                  std::to_string(m.covered), Num(m.ms, 2), Num(1000.0 / m.ms, 2),
                  Num(point.paper_fps, 1), Num(m.ms / first_ms, 3),
                  Num(kPaperFps150 / point.paper_fps, 3), Num(e.iou, 4), Num(e.depth.p95, 5),
                  kSourcePoints});
    fmt::print(stderr,
               "point {} px object ({} px frame), {} slices: {:.2f} ms ({:.2f} fps; paper {} fps), "
               "IoU {:.4f}, p95 depth {:.5f} edges\n",
               m.bbox_px, size, point.slices, m.ms, 1000.0 / m.ms, point.paper_fps, e.iou,
               e.depth.p95);
  }
}

// The paper's donut (Figs. 1, 17, 18): the 625-polygon torus by orthogonal
// slicing at 15-25 slices, against its tessellated truth.
void Donut(render::ProgramCache& programs, const KautzSeidelOptions& options, Table& table) {
  ibr::DisplacedMeshData data;
  data.base = ibr::DisplacementBaseMesh("torus");
  constexpr int kTexels = 256;
  // A floor of 0.15 (as `ibr demo`): height 0 is never drawn (sec. 3.2), so
  // without it the donut would show holes where the truth has its base.
  data.height = ibr::DisplacementHeightMap(core::HeightPattern::kBumps, kTexels, 0.15f);
  ibr::DisplacedMeshOptions o;  // max displacement 0.15, as `ibr displace`
  o.tiling = 2;
  const int size = options.quick ? 128 : 512;
  const render::ViewSetup view = ibr::DisplacementOrbitView(
      data.base, o.max_displacement, {.elevation_deg = 35, .azimuth_deg = -60}, size);
  o.method = ibr::DisplacementMethod::kTessellated;
  ibr::DisplacedMeshRenderer truth_renderer(programs, data, o);
  const double truth_ms =
      render::TimeFrames([&] { truth_renderer.Draw(view, size, size); }, options.timer).median_ms;
  truth_renderer.Draw(view, size, size);
  const render::Frame truth = truth_renderer.Read();
  core::DisplacementErrorOptions eo;
  eo.depth_unit = core::HeightTexelWorldSize(data.base, kTexels, o.tiling);
  // The paper: 15 slices 41 Hz (Fig. 18), 20 slices 38 Hz (Fig. 17), and
  // "between 15 and 25 slices ... between 35 and 40 Hz" (sec. 6).
  struct Point {
    int slices;
    double paper_fps_min, paper_fps_max;
  };
  const Point points[] = {{15, 41, 41}, {20, 38, 38}, {25, 35, 40}};
  double first_ms = 0;
  for (const Point& point : points) {
    o.method = ibr::DisplacementMethod::kSlicesOrthogonal;
    o.slices = point.slices;
    ibr::DisplacedMeshRenderer renderer(programs, data, o);
    const double ms =
        render::TimeFrames([&] { renderer.Draw(view, size, size); }, options.timer).median_ms;
    renderer.Draw(view, size, size);
    const render::Frame frame = renderer.Read();
    const core::DisplacementError e =
        core::CompareToGroundTruth(frame.color, frame.depth, truth.color, truth.depth, eo);
    if (first_ms == 0) first_ms = ms;
    table.AddRow({std::to_string(point.slices), std::to_string(size),
                  std::to_string(data.base.triangle_count()), Num(ms, 2), Num(1000.0 / ms, 2),
                  Num(point.paper_fps_min, 0), Num(point.paper_fps_max, 0), Num(ms / first_ms, 3),
                  Num(points[0].paper_fps_min / point.paper_fps_max, 3),
                  Num(points[0].paper_fps_min / point.paper_fps_min, 3), Num(e.coverage_iou, 4),
                  Num(e.mean_depth_error, 3), Num(e.p95_depth_error, 3),
                  std::to_string(e.see_through_pixels), Num(truth_ms, 2), kSourceDonut});
    fmt::print(stderr,
               "donut {} slices, {} px: {:.2f} ms ({:.1f} fps; paper {}-{} Hz), IoU {:.4f}, p95 "
               "depth {:.3f} texels, see-through {}\n",
               point.slices, size, ms, 1000.0 / ms, point.paper_fps_min, point.paper_fps_max,
               e.coverage_iou, e.p95_depth_error, e.see_through_pixels);
  }
}

// Rows of `table` whose `column` equals `value`.
Table Filter(const Table& table, const std::string& column, const std::string& value) {
  Table out(table.columns());
  for (const auto& row : table.rows()) {
    if (row[table.Column(column)] == value) out.AddRow(row);
  }
  return out;
}

}  // namespace

void KautzSeidelOptions::Check() const {
  if (!IsShape(object) && !MeshFiles().contains(object)) {
    core::ThrowInputError("bench kautz-seidel", "--object '{}': not bunny, cow, spot, teapot, {}",
                          object, fmt::join(capture::ShapeNames(), ", "));
  }
  if (map_size < 16 || map_size > 4096)
    core::ThrowInputError("bench kautz-seidel", "map size {} outside 16..4096", map_size);
  timer.Check();
}

KautzSeidelResult RunKautzSeidelExperiments(render::ProgramCache& programs,
                                            const KautzSeidelOptions& options) {
  options.Check();
  KautzSeidelResult result{
      "",
      Table({"sweep", "method", "size", "slices", "covered_pixels", "ms_per_frame",
             "ms_over_depth_object", "source"}),
      Table({"method", "elevation_deg", "azimuth_deg", "size", "slices", "covered_pixels",
             "active_maps", "slice_fragments", "ms_per_frame", "ms_over_face_on",
             "fragments_over_face_on", "paper_best_speedup", "source"}),
      Table({"method", "target_object_px", "size", "slices", "object_px", "covered_pixels",
             "ms_per_frame", "fps", "paper_fps", "ms_over_first", "paper_ms_over_first", "iou",
             "p95_depth_error", "source"}),
      Table({"slices", "size", "base_triangles", "ms_per_frame", "fps", "paper_fps_min",
             "paper_fps_max", "ms_over_first", "paper_ms_over_first_min", "paper_ms_over_first_max",
             "coverage_iou", "mean_depth_error_texels", "p95_depth_error_texels", "see_through_px",
             "truth_ms", "source"})};
  const capture::SceneMesh scene = LoadObject(options.object, options.quick, result.object);
  const fs::path work = fs::temp_directory_path() / fmt::format("ibr_bench_ks_{}", ::getpid());
  fs::remove_all(work);
  struct RemoveOnExit {  // also when a capture or read throws
    fs::path dir;
    ~RemoveOnExit() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  } remove_work{work};
  capture::CaptureOptions co;
  co.rig = "cube";  // the paper's six orthographic maps
  co.size = options.quick ? 96 : options.map_size;
  co.shade = false;
  capture::CaptureDataset(programs, scene, co, work / "cube");
  const capture::Dataset cube = capture::ReadDataset(work / "cube");
  const capture::Bounds bounds = *cube.bounds;
  ibr::DepthObjectRenderer renderer(programs, ibr::MapsFromDataset(cube));  // reads the images
  fmt::print(stderr, "kautz-seidel: {} from {} cube maps of {} px\n", result.object,
             cube.views.size(), co.size);
  Fig12(renderer, options, result.fig12);
  Angle(renderer, options, result.angle);
  Points(programs, renderer, options, scene, bounds, result.points);
  Donut(programs, options, result.donut);
  return result;
}

void WriteKautzSeidelExperiments(const KautzSeidelResult& result, const fs::path& csv,
                                 const fs::path& out_dir) {
  const std::string stem = (csv.parent_path() / csv.stem()).string();
  result.points.WriteCsv(csv);
  result.fig12.WriteCsv(stem + "_fig12.csv");
  result.angle.WriteCsv(stem + "_angle.csv");
  result.donut.WriteCsv(stem + "_donut.csv");
  fs::create_directories(out_dir);
  for (const auto& [sweep, x, x_label, png] :
       {std::tuple{"coverage", "covered_pixels", "object pixels (128 slices)",
                   "ks_fig12_time_vs_coverage.png"},
        std::tuple{"slices", "slices", "slices (300 x 300)", "ks_fig12_time_vs_slices.png"}}) {
    PlotPng(Filter(result.fig12, "sweep", sweep),
            {.title = fmt::format("Kautz-Seidel Fig. 12 analogue ({}): depth object vs visual hull",
                                  result.object),
             .x_column = x,
             .y_column = "ms_per_frame",
             .series_column = "method",
             .x_label = x_label,
             .y_label = "ms per frame (median)"},
            out_dir / png);
  }
  // Time against elevation, one line per method and azimuth.
  Table angle({"series", "elevation_deg", "ms_over_face_on"});
  for (const auto& r : result.angle.rows()) {
    angle.AddRow({fmt::format("{} az {}", r[result.angle.Column("method")],
                              r[result.angle.Column("azimuth_deg")]),
                  r[result.angle.Column("elevation_deg")],
                  r[result.angle.Column("ms_over_face_on")]});
  }
  PlotPng(angle,
          {.title = fmt::format("Time vs viewing angle ({}); paper: oblique up to 1.2x faster",
                                result.object),
           .x_column = "elevation_deg",
           .y_column = "ms_over_face_on",
           .series_column = "series",
           .x_label = "elevation (degrees; azimuth 0 = face-on to a cube face)",
           .y_label = "ms per frame / face-on"},
          out_dir / "ks_time_vs_angle.png");
}

}  // namespace bench
