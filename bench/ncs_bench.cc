#include "bench/ncs_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <set>

#include "bench/sweep.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/image_compose.h"
#include "core/image_io.h"
#include "core/mesh.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/relief_surface_pass.h"

namespace bench {

namespace {
// The scene: the paper's donut case, R = 1, r = 0.4, 48 x 24 quads (1152
// triangles, the paper's base model has 528), bumps at full height,
// max displacement 0.08 (a fifth of the tube radius).
constexpr float kMajor = 1.0f, kMinor = 0.4f, kMaxDisplacement = 0.08f;
constexpr int kRingSegments = 48, kTubeSegments = 24;

glm::vec3 EyeOf(const std::string& view) {
  if (view == "oblique") return {0.3f, -3.0f, 1.75f};
  if (view == "grazing") return {0.0f, -3.4f, 0.55f};
  if (view == "edge") return {0.0f, -3.4f, 0.24f};
  core::ThrowInputError("NcsBench", "unknown view '{}' (oblique, grazing, edge)", view);
}

render::ViewSetup MakeView(const std::string& view, int size) {
  render::ViewSetup setup;
  setup.cam_from_world = core::CamFromWorldLookAt(EyeOf(view), {0, 0, 0}, {0, 0, 1});
  const double f = 1.05 * size;
  setup.clip_from_cam =
      core::ClipFromCamPerspective(f, f, size / 2.0, size / 2.0, size, size, 0.1, 20.0);
  return setup;
}

// Red: only the method covers; green: only the truth covers; grey: both.
core::Image8 SilhouetteDiff(const core::Image8& color, const core::Image8& truth) {
  core::Image8 out(color.width(), color.height(), 4, 0);
  for (int y = 0; y < color.height(); ++y) {
    for (int x = 0; x < color.width(); ++x) {
      const bool a = color.at(x, y, 3) == 255, b = truth.at(x, y, 3) == 255;
      out.at(x, y, 0) = a && !b ? 255 : (a && b ? 90 : 0);
      out.at(x, y, 1) = b && !a ? 255 : (a && b ? 90 : 0);
      out.at(x, y, 2) = a && b ? 90 : 0;
      out.at(x, y, 3) = 255;
    }
  }
  return out;
}

core::Image8 Opaque(const core::Image8& image) {
  core::Image8 out = image;
  for (int y = 0; y < out.height(); ++y) {
    for (int x = 0; x < out.width(); ++x) out.at(x, y, 3) = 255;
  }
  return out;
}
}  // namespace

std::vector<std::string> NcsBenchViewNames() { return {"oblique", "grazing", "edge"}; }

void NcsBenchOptions::Check() const {
  // The frame budget and the GL limits: render::CheckFrameSize (ibr bench ncs).
  if (size < 16 || size > 16384)
    core::ThrowInputError("NcsBenchOptions", "size {} outside 16..16384", size);
  if (height_map_size < 4 || height_map_size > 1024) {
    core::ThrowInputError("NcsBenchOptions", "height_map_size {} outside 4..1024", height_map_size);
  }
  if (steps.empty() || step_enlargements.empty() || tilings.empty() || views.empty()) {
    core::ThrowInputError("NcsBenchOptions", "every sweep list needs at least one value");
  }
  for (int s : steps) {
    if (s < 1 || s > 4096) core::ThrowInputError("NcsBenchOptions", "steps {} outside 1..4096", s);
  }
  for (float c : step_enlargements) {
    if (!(c >= 0.01f && c <= 1000))
      core::ThrowInputError("NcsBenchOptions", "c {} outside [0.01, 1000]", c);
  }
  for (int t : tilings) {
    if (t < 1 || t > 64) core::ThrowInputError("NcsBenchOptions", "tiling {} outside 1..64", t);
  }
  for (const std::string& v : views) EyeOf(v);
  if (max_truth_subdivisions < 1 || max_truth_subdivisions > 256) {
    core::ThrowInputError("NcsBenchOptions", "max_truth_subdivisions {} outside 1..256",
                          max_truth_subdivisions);
  }
  timer.Check();
}

NcsBenchOptions NcsBenchOptions::Quick() {
  NcsBenchOptions o;
  o.size = 96;
  o.height_map_size = 32;
  o.steps = {16};
  o.step_enlargements = {1.0f, 2.5f};  // two points of Fig. 7
  o.tilings = {1, 4};
  o.views = {"grazing"};
  o.max_truth_subdivisions = 4;  // below tiling 4's 6: the cap is exercised
  o.timer = {.warmup_frames = 1, .timed_frames = 1};
  return o;
}

namespace {
// One relief-method setting of the sweep; c applies to NCS only.
struct ReliefConfig {
  render::ReliefMethod method;
  int steps;
  float c;
};

// method x steps x c, in that nesting order.
std::vector<ReliefConfig> ReliefConfigs(const NcsBenchOptions& options) {
  std::vector<ReliefConfig> configs;
  for (render::ReliefMethod method : {render::ReliefMethod::kNcs, render::ReliefMethod::kRelief,
                                      render::ReliefMethod::kPom, render::ReliefMethod::kCrm}) {
    const bool ncs = method == render::ReliefMethod::kNcs;
    const std::vector<float> cs = ncs ? options.step_enlargements : std::vector<float>{1.0f};
    for (const auto& [steps, c] : Product(options.steps, cs)) configs.push_back({method, steps, c});
  }
  return configs;
}

// The tessellated ground truth at one tiling.
struct Truth {
  core::TriangleMesh mesh;
  std::string subdivisions, subdivisions_wanted, triangles;
};

// What the sweep shares: the torus, its relief surface, the targets, the
// tables and the strip being assembled.
struct NcsRun {
  NcsRun(render::ProgramCache& programs, const NcsBenchOptions& o, const core::TriangleMesh& mesh,
         const core::ImageF& height, const render::ReliefGeometryOptions& geometry)
      : options(o),
        torus(mesh),
        height_map(height),
        surface(programs, torus, height_map, geometry),
        relief_target(render::FrameTargetOptions(o.size, o.size)),
        mesh_target(render::FrameTargetOptions(o.size, o.size)) {}
  const NcsBenchOptions& options;
  const core::TriangleMesh torus;
  const core::ImageF height_map;
  render::ReliefSurface surface;
  render::RenderTarget relief_target, mesh_target;
  NcsBenchResult result{
      Table({"method", "view", "tiling", "steps", "c", "ms_per_frame", "min_ms_per_frame",
             "silhouette_iou", "wrong_silhouette_px", "mean_depth_error", "p95_depth_error",
             "early_termination_px", "truth_px", "triangles", "truth_subdivisions",
             "truth_subdivisions_wanted"}),
      Table({"view", "tiling", "steps", "c", "early_termination_px", "wrong_silhouette_px",
             "min_ms_per_frame", "source"}),
      Table({"view", "tiling", "steps", "ncs_ms", "relief_ms", "pom_ms", "tessellated_ms",
             "ncs_over_relief", "ncs_over_tessellated", "crm_ms", "ncs_over_crm"}),
      {}};
  std::vector<core::Image8> strip_top, strip_bottom;
};

// Ground truth: a vertex per texel along the ring (the finer direction per
// base quad is the tube: texels per quad = size * tiling / 24).
Truth MakeTruth(const NcsRun& run, int tiling) {
  core::DisplacedMeshOptions dm;
  dm.max_displacement = kMaxDisplacement;
  dm.tiling = static_cast<float>(tiling);
  const int wanted = (run.options.height_map_size * tiling + kTubeSegments - 1) / kTubeSegments;
  dm.subdivisions = std::clamp(wanted, 1, run.options.max_truth_subdivisions);
  fmt::print(stderr,
             "bench ncs: tiling {}: ground truth {} subdivisions per base triangle (a vertex "
             "per texel wants {}, cap {})\n",
             tiling, dm.subdivisions, wanted, run.options.max_truth_subdivisions);
  Truth truth{core::TessellateDisplaced(run.torus, run.height_map, dm),
              std::to_string(dm.subdivisions), std::to_string(wanted), ""};
  truth.triangles = std::to_string(truth.mesh.triangle_count());
  return truth;
}

// The relief setting `config` at one view and tiling against the truth's
// frame: a table row, a Figure 7 row (NCS), the summary's time and the strip.
void MeasureRelief(NcsRun& run, const ReliefConfig& config, const std::string& view_name,
                   int tiling, const Truth& truth, const render::Frame& truth_frame,
                   bool strip_here, std::map<std::pair<std::string, int>, double>& ms_at) {
  const NcsBenchOptions& options = run.options;
  const render::ViewSetup view = MakeView(view_name, options.size);
  const bool ncs = config.method == render::ReliefMethod::kNcs;
  const float c = config.c;
  const int steps = config.steps;
  render::ReliefSurfaceOptions o;
  o.method = config.method;
  o.steps = steps;
  o.step_enlargement = c;
  o.tiling = static_cast<float>(tiling);
  run.surface.SetOptions(o);
  const core::TimingStats time = render::TimeFrames(
      [&] { render::DrawFrame(run.relief_target, run.surface, view); }, options.timer);
  const double ms = time.min_ms;
  render::DrawFrame(run.relief_target, run.surface, view);
  const render::Frame frame = render::ReadFrame(run.relief_target);
  const core::ViewMetrics e =
      core::CompareFrames(frame.color, frame.depth, truth_frame.color, truth_frame.depth);
  const std::string early =
      std::to_string(frame.CountOutcome(render::OutcomeBit(render::RayOutcome::kEarlyTermination)));
  run.result.table.AddRow(
      {render::ReliefMethodName(config.method), view_name, std::to_string(tiling),
       std::to_string(steps), ncs ? Num(c, 1) : "", Num(time.median_ms, 2), Num(ms, 2),
       Num(e.iou, 4), std::to_string(e.wrong_pixels), Num(e.depth.mean, 5), Num(e.depth.p95, 5),
       early, std::to_string(e.truth_pixels), std::to_string(run.torus.triangle_count()),
       truth.subdivisions, truth.subdivisions_wanted});
  if (ncs) {
    run.result.fig7.AddRow({view_name, std::to_string(tiling), std::to_string(steps), Num(c, 1),
                            early, std::to_string(e.wrong_pixels), Num(ms, 2),
                            "Chen-Chang Fig. 7 (red pixels: early termination)"});
  }
  // (method, steps) -> fastest frame, for the summary (c = 2.5): on a
  // machine shared with other work the minimum is the least disturbed figure.
  const bool summary_c =
      !ncs || std::abs(c - 2.5f) < 1e-6f ||
      (options.step_enlargements.size() == 1 && c == options.step_enlargements[0]);
  if (summary_c) ms_at[{render::ReliefMethodName(config.method), steps}] = ms;
  // The strip: the middle step count, c = 2.5 (or the only c).
  if (strip_here && steps == options.steps[options.steps.size() / 2] && summary_c) {
    run.strip_top.push_back(Opaque(frame.color));
    run.strip_bottom.push_back(SilhouetteDiff(frame.color, truth_frame.color));
  }
}

// The truth row and every relief setting at one view and tiling, then the
// summary rows of that view and tiling.
void MeasureView(NcsRun& run, const std::string& view_name, int tiling, const Truth& truth,
                 render::MeshPass& truth_pass, bool strip_here) {
  const int n = run.options.size;
  const render::ViewSetup view = MakeView(view_name, n);
  render::DrawFrame(run.mesh_target, truth_pass, view);
  const render::Frame truth_frame = render::ReadFrame(run.mesh_target);
  const core::TimingStats truth_time = render::TimeFrames(
      [&] { render::DrawFrame(run.mesh_target, truth_pass, view); }, run.options.timer);
  const double truth_ms = truth_time.min_ms;
  int64_t truth_px = 0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) truth_px += truth_frame.color.at(x, y, 3) == 255;
  }
  run.result.table.AddRow({"tessellated", view_name, std::to_string(tiling), "", "",
                           Num(truth_time.median_ms, 2), Num(truth_time.min_ms, 2), Num(1.0, 4),
                           "0", Num(0.0, 5), Num(0.0, 5), "0", std::to_string(truth_px),
                           truth.triangles, truth.subdivisions, truth.subdivisions_wanted});
  if (strip_here) {
    run.strip_top.push_back(Opaque(truth_frame.color));
    run.strip_bottom.push_back(SilhouetteDiff(truth_frame.color, truth_frame.color));
  }
  std::map<std::pair<std::string, int>, double> ms_at;
  Sweep<ReliefConfig>(ReliefConfigs(run.options), {}, [&](const ReliefConfig& config, int) {
    MeasureRelief(run, config, view_name, tiling, truth, truth_frame, strip_here, ms_at);
  });
  for (int steps : run.options.steps) {
    const double ncs_ms = ms_at[{"ncs", steps}], relief_ms = ms_at[{"relief", steps}],
                 pom_ms = ms_at[{"pom", steps}], crm_ms = ms_at[{"crm", steps}];
    run.result.summary.AddRow({view_name, std::to_string(tiling), std::to_string(steps),
                               Num(ncs_ms, 2), Num(relief_ms, 2), Num(pom_ms, 2), Num(truth_ms, 2),
                               Num(ncs_ms / relief_ms, 2), Num(ncs_ms / truth_ms, 2),
                               Num(crm_ms, 2), Num(ncs_ms / crm_ms, 2)});
  }
}
}  // namespace

NcsBenchResult RunNcsBench(render::ProgramCache& programs, const NcsBenchOptions& options) {
  options.Check();
  const core::TriangleMesh torus = core::MakeTorus(kMajor, kMinor, kRingSegments, kTubeSegments);
  core::HeightMapOptions hm;
  hm.pattern = core::HeightPattern::kBumps;
  hm.size = options.height_map_size;
  hm.level = 1.0f;
  render::ReliefGeometryOptions geometry;
  geometry.max_displacement = kMaxDisplacement;
  geometry.tangent_maps.size = 512;  // the paper's map size
  geometry.tangent_maps.wrap_u = geometry.tangent_maps.wrap_v = true;
  NcsRun run(programs, options, torus, core::MakeHeightMap(hm), geometry);
  const int strip_tiling = options.tilings.front();
  const std::string strip_view =
      std::find(options.views.begin(), options.views.end(), "grazing") != options.views.end()
          ? "grazing"
          : options.views.front();
  for (int tiling : options.tilings) {
    const Truth truth = MakeTruth(run, tiling);
    const render::GpuMesh truth_gpu(truth.mesh);
    render::MeshPass truth_pass(programs, truth_gpu);
    for (const std::string& view_name : options.views) {
      MeasureView(run, view_name, tiling, truth, truth_pass,
                  tiling == strip_tiling && view_name == strip_view);
    }
  }
  NcsBenchResult result = std::move(run.result);
  std::vector<core::Image8> cells = run.strip_top;
  cells.insert(cells.end(), run.strip_bottom.begin(), run.strip_bottom.end());
  result.strip = core::ContactSheet(cells, static_cast<int>(run.strip_top.size()));
  result.strip_view = strip_view;
  result.strip_tiling = strip_tiling;
  return result;
}

void WriteNcsBench(const NcsBenchResult& result, const std::filesystem::path& csv,
                   const std::filesystem::path& out_dir) {
  result.table.WriteCsv(csv);
  std::filesystem::create_directories(out_dir);
  result.summary.WriteCsv(out_dir / "ncs_summary.csv");
  result.fig7.WriteCsv(out_dir / "ncs_fig7.csv");
  core::WriteImage(out_dir / "ncs_silhouettes_grazing.png", result.strip);
  // Error versus time at the strip's view and tiling (the grazing view when
  // swept, the first tiling): one series per method (and c), one point per
  // step count.
  const Table& t = result.table;
  const std::string plot_view = result.strip_view,
                    plot_tiling = std::to_string(result.strip_tiling);
  Table plot({"series", "ms_per_frame", "wrong_silhouette_px", "p95_depth_error"});
  for (const auto& r : t.rows()) {
    if (r[t.Column("view")] != plot_view || r[t.Column("tiling")] != plot_tiling) continue;
    const std::string method = r[t.Column("method")], c = r[t.Column("c")];
    plot.AddRow({c.empty() ? method : method + " c=" + c, r[t.Column("min_ms_per_frame")],
                 r[t.Column("wrong_silhouette_px")], r[t.Column("p95_depth_error")]});
  }
  PlotOptions p;
  p.x_column = "ms_per_frame";
  p.series_column = "series";
  p.x_label = "fastest ms per frame (llvmpipe; points = step counts)";
  p.log_x = true;
  p.title = fmt::format("Silhouette error vs time ({} view, tiling {})", plot_view, plot_tiling);
  p.y_column = "wrong_silhouette_px";
  p.y_label = "wrong silhouette pixels vs tessellated truth";
  PlotPng(plot, p, out_dir / "ncs_silhouette_error_vs_time.png");
  p.title = fmt::format("Depth error vs time ({} view, tiling {})", plot_view, plot_tiling);
  p.y_column = "p95_depth_error";
  p.y_label = "p95 |camera z - truth| (scene units)";
  p.log_y = true;
  PlotPng(plot, p, out_dir / "ncs_depth_error_vs_time.png");
  // Early termination against c (the paper's Figure 7), at the strip's
  // view and tiling: one series per step count.
  Table fig7({"series", "c", "early_termination_px"});
  for (const auto& r : result.fig7.rows()) {
    if (r[0] != plot_view || r[1] != plot_tiling) continue;
    fig7.AddRow({r[2] + " steps", r[3], r[4]});
  }
  PlotPng(
      fig7,
      {.title = fmt::format("NCS early termination vs c (Chen-Chang Fig. 7), {} view, tiling {}",
                            plot_view, plot_tiling),
       .x_column = "c",
       .y_column = "early_termination_px",
       .series_column = "series",
       .x_label = "step enlargement c",
       .y_label = "early-terminated pixels",
       .log_x = true},
      out_dir / "ncs_early_termination_vs_c.png");
  // Cost versus tiling (the paper's Figure 6): one series per method and
  // view, at the middle step count, c = 2.5.
  Table fig6({"series", "tiling", "ms_per_frame"});
  std::set<int> step_counts;
  for (const auto& r : result.summary.rows()) step_counts.insert(std::stoi(r[2]));
  const std::string middle_steps =
      step_counts.empty() ? ""
                          : std::to_string(*std::next(step_counts.begin(),
                                                      static_cast<long>(step_counts.size() / 2)));
  for (const auto& r : result.summary.rows()) {
    if (r[2] != middle_steps) continue;
    fig6.AddRow({"ncs " + r[0], r[1], r[3]});
    fig6.AddRow({"relief " + r[0], r[1], r[4]});
    fig6.AddRow({"crm " + r[0], r[1], r[9]});
    fig6.AddRow({"tessellated " + r[0], r[1], r[6]});
  }
  PlotPng(
      fig6,
      {.title = fmt::format("Cost vs tiling (Chen-Chang Fig. 6), {} steps, c = 2.5", middle_steps),
       .x_column = "tiling",
       .y_column = "ms_per_frame",
       .series_column = "series",
       .x_label = "height map tiling",
       .y_label = "ms per frame",
       .log_x = true,
       .log_y = true},
      out_dir / "ncs_time_vs_tiling.png");
}

}  // namespace bench
