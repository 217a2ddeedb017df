#include "bench/displacement_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "bench/sweep.h"
#include "core/displacement_error.h"
#include "core/error.h"
#include "core/image_compose.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "render/gl/context.h"
#include "render/gl/fill_rate.h"
#include "render/gl/frame_timer.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/displacement_pass.h"

namespace bench {
namespace fs = std::filesystem;

void DisplacementBenchOptions::Check() const {
  if (csv.empty()) core::ThrowInputError("ibr bench displacement", "--csv FILE is required");
}

namespace {

struct Family {
  std::string label;
  render::SliceFamily family;
  bool full_size;
};

// The scene: the paper's displaced polygon (sec. 3, Figures 4 and 10) as a
// 2 x 2 plane, smooth bumps on a solid floor (so every ground-truth pixel
// has surface and holes are see-through, not masking), 256^2 texels.
constexpr int kTexels = 256;
constexpr float kMaxDisplacement = 0.25f, kTiling = 1.0f;
constexpr double kAzimuth = -60;
constexpr int kSheetCount = 32;

// The configuration lists of the sweep: size x elevation x family x slices.
struct DisplacementSweep {
  explicit DisplacementSweep(bool quick)
      : counts(quick ? std::vector<int>{8, 32, 128} : std::vector<int>{8, 16, 32, 64, 128, 256}),
        elevations(quick ? std::vector<double>{90, 60, 10} : std::vector<double>{90, 60, 30, 10}),
        sizes(quick ? std::vector<int>{128} : std::vector<int>{256, 512}),
        timer(quick ? render::FrameTimerOptions{1, 3} : render::FrameTimerOptions{1, 5}) {}
  std::vector<Family> families = {{"surface", render::SliceFamily::kSurfaceAligned, false},
                                  {"orthogonal", render::SliceFamily::kOrthogonal, false},
                                  {"screen", render::SliceFamily::kScreen, false},
                                  {"screen-full", render::SliceFamily::kScreen, true}};
  std::vector<int> counts;
  std::vector<double> elevations;
  std::vector<int> sizes;
  render::FrameTimerOptions timer;
};

// The displaced plane, its slicing pass and its tessellated ground truth.
struct DisplacementScene {
  explicit DisplacementScene(render::ProgramCache& programs)
      : base(DisplacementBaseMesh("plane")),
        height(DisplacementHeightMap(core::HeightPattern::kBumps, kTexels, 0.15f)),
        texture(render::UploadDisplacementTexture(render::MakeDisplacementTexels(height))),
        truth_mesh(render::MakeDisplacedGroundTruth(base, height, kMaxDisplacement, kTiling)),
        texel(core::HeightTexelWorldSize(base, kTexels, kTiling)),
        pass(programs, base, texture, PassOptions()),
        truth_pass(programs, truth_mesh, TruthOptions(texture)) {}
  static render::DisplacementPassOptions PassOptions() {
    render::DisplacementPassOptions pass_options;
    pass_options.max_displacement = kMaxDisplacement;
    pass_options.tiling = kTiling;
    return pass_options;
  }
  static render::MeshPassOptions TruthOptions(const render::Texture& texture) {
    render::MeshPassOptions truth_options;
    truth_options.texture = &texture;
    truth_options.shade = false;
    return truth_options;
  }
  const core::TriangleMesh base;
  const core::ImageF height;
  const render::Texture texture;
  const render::GpuMesh truth_mesh;
  const float texel;
  render::DisplacementPass pass;
  render::MeshPass truth_pass;
};

// The truth's frame and time at one view.
struct TruthFrame {
  render::Frame frame;
  core::TimingStats time;
};

// One family x slice count at one view: the table row and its frame.
core::Image8 MeasureSlicing(DisplacementScene& scene, const DisplacementSweep& sweep,
                            const Family& family, int count, double elevation, int size,
                            render::RenderTarget& target, const render::ViewSetup& view,
                            const TruthFrame& truth, const render::FillRate& fill, Table& table) {
  render::SlicingOptions slicing;
  slicing.family = family.family;
  slicing.count = count;
  slicing.full_size_screen_slices = family.full_size;
  scene.pass.SetSlicing(slicing);
  const core::TimingStats time =
      render::TimeFrames([&] { render::DrawFrame(target, scene.pass, view); }, sweep.timer);
  scene.pass.CountFragments(true);
  render::DrawFrame(target, scene.pass, view);
  scene.pass.CountFragments(false);
  const double fragments = scene.pass.last_stats().fragments;
  const render::Frame frame = render::ReadFrame(target);
  core::DisplacementErrorOptions error_options;
  error_options.depth_unit = scene.texel;
  const core::DisplacementError error = core::CompareToGroundTruth(
      frame.color, frame.depth, truth.frame.color, truth.frame.depth, error_options);
  const double fill_fraction =
      fragments < 0 ? std::nan("")
                    : fragments / (time.median_ms * 1e-3) / fill.fragments_per_second;
  table.AddRow({family.label, std::to_string(count), Num(elevation, 0), std::to_string(size),
                Num(time.median_ms, 2), Num(fragments * 1e-6, 2), Num(fill_fraction, 3),
                Num(error.coverage_iou, 4), Num(error.mean_depth_error, 3),
                Num(error.p95_depth_error, 3), std::to_string(error.see_through_pixels),
                Num(truth.time.median_ms, 2), Num(time.median_ms / truth.time.median_ms, 2)});
  return frame.color;
}

// For each family at elevation 60 (the "60-degree view") and 30 (60 degrees
// from the normal), largest size: fewest slices with p95 < 1 texel.
Table SlicesSummary(const Table& table, const DisplacementSweep& sweep) {
  Table summary({"elevation_deg", "family", "slices_for_p95_under_1_texel", "ms_per_frame",
                 "truth_ms_per_frame", "time_vs_truth"});
  const int largest = sweep.sizes.back();
  for (double elevation : {60.0, 30.0}) {
    for (const Family& family : sweep.families) {
      std::string slices = "none", ms = "-", truth_ms = "-", ratio = "-";
      for (const auto& row : table.rows()) {
        if (row[0] != family.label || std::stod(row[2]) != elevation ||
            std::stoi(row[3]) != largest)
          continue;
        const double p95 = std::strtod(row[9].c_str(), nullptr);
        if (std::isfinite(p95) && p95 < 1.0) {
          slices = row[1];
          ms = row[4];
          truth_ms = row[11];
          ratio = row[12];
          break;  // rows are in increasing slice count
        }
      }
      const auto& elevations = sweep.elevations;
      if (std::find(elevations.begin(), elevations.end(), elevation) == elevations.end()) continue;
      summary.AddRow({Num(elevation, 0), family.label, slices, ms, truth_ms, ratio});
    }
  }
  return summary;
}

// Error-vs-time plots at elevation 60 and the grazing one, and the grazing
// contact sheet (truth, then each family at kSheetCount slices).
void WriteDisplacementFigures(const fs::path& out, const Table& table,
                              const DisplacementSweep& sweep, const core::Image8& grazing_truth,
                              std::map<std::string, std::vector<core::Image8>>& grazing_images) {
  fs::create_directories(out);
  const int largest = sweep.sizes.back();
  const double grazing = sweep.elevations.back();
  const std::string largest_size = std::to_string(largest);
  for (double elevation : {60.0, grazing}) {
    Table subset(table.columns());
    for (const auto& row : table.rows()) {
      if (std::stod(row[2]) == elevation && row[3] == largest_size) subset.AddRow(row);
    }
    if (subset.rows().empty()) continue;
    const fs::path png = out / fmt::format("error_vs_time_elev{:.0f}.png", elevation);
    PlotPng(subset,
            {.title = fmt::format(
                 "displacement by slicing: p95 depth error vs time, elevation {:.0f} deg, {} px",
                 elevation, largest),
             .x_column = "ms_per_frame",
             .y_column = "p95_depth_error_texels",
             .series_column = "family",
             .x_label = "ms per frame (median)",
             .y_label = "p95 depth error (height texels)",
             .log_x = true,
             .log_y = true},
            png);
    fmt::print("wrote {}\n", png.string());
  }
  std::vector<core::Image8> sheet_images = {grazing_truth};
  for (const Family& family : sweep.families) {
    for (const auto& im : grazing_images[family.label]) sheet_images.push_back(im);
  }
  const fs::path sheet = out / "grazing_contact_sheet.png";
  core::WriteImage(sheet, core::ContactSheet(sheet_images, static_cast<int>(sheet_images.size())));
  fmt::print(
      "wrote {} (elevation {:.0f} deg, {} slices; left to right: tessellated ground truth, "
      "surface, "
      "orthogonal, screen, screen-full)\n",
      sheet.string(), grazing, kSheetCount);
}

}  // namespace

DisplacementBenchResult RunDisplacementBench(const DisplacementBenchOptions& options) {
  options.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  fmt::print("{} | {}\n", context->info().renderer, context->info().version);
  DisplacementScene scene(programs);
  const DisplacementSweep sweep(options.quick);
  Table table({"family", "slices", "elevation_deg", "size_px", "ms_per_frame", "fragments_M",
               "fill_fraction", "coverage_iou", "mean_depth_error_texels", "p95_depth_error_texels",
               "see_through_pixels", "truth_ms_per_frame", "time_vs_truth"});
  std::map<std::string, std::vector<core::Image8>> grazing_images;
  core::Image8 grazing_truth;
  const double grazing = sweep.elevations.back();
  for (int size : sweep.sizes) {
    render::FillRateOptions fill_options;
    fill_options.width = fill_options.height = size;
    fill_options.linear_filter = true;  // the pass samples LINEAR
    fill_options.timer = sweep.timer;
    const render::FillRate fill = render::MeasureFillRate(programs, fill_options);
    fmt::print("size {} px: calibrated fill rate (LINEAR) {:.1f} M fragments/s\n", size,
               fill.fragments_per_second * 1e-6);
    render::RenderTarget target(render::FrameTargetOptions(size, size));
    render::RenderTarget truth_target(render::FrameTargetOptions(size, size));
    for (double elevation : sweep.elevations) {
      const render::ViewSetup view =
          ibr::DisplacementOrbitView(scene.base, kMaxDisplacement,
                                     {.elevation_deg = elevation, .azimuth_deg = kAzimuth}, size);
      TruthFrame truth;
      truth.time = render::TimeFrames(
          [&] { render::DrawFrame(truth_target, scene.truth_pass, view); }, sweep.timer);
      render::DrawFrame(truth_target, scene.truth_pass, view);
      truth.frame = render::ReadFrame(truth_target);
      const bool sheet_view = elevation == grazing && size == sweep.sizes.front();
      if (sheet_view) grazing_truth = truth.frame.color;
      for (const auto& [family, count] : Product(sweep.families, sweep.counts)) {
        core::Image8 color = MeasureSlicing(scene, sweep, family, count, elevation, size, target,
                                            view, truth, fill, table);
        if (sheet_view && count == kSheetCount) {
          grazing_images[family.label].push_back(std::move(color));
        }
      }
    }
  }
  fmt::print("{}", table.Format());
  table.WriteCsv(options.csv);
  Table summary = SlicesSummary(table, sweep);
  fmt::print(
      "\nslices needed for p95 depth error < 1 texel ({} px; texel = {:.5f} scene units):\n{}",
      sweep.sizes.back(), scene.texel, summary.Format());
  if (!options.out.empty()) {
    WriteDisplacementFigures(options.out, table, sweep, grazing_truth, grazing_images);
  }
  return {std::move(table), std::move(summary)};
}

}  // namespace bench
