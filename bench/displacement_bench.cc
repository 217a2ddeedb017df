#include "bench/displacement_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

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

}  // namespace

DisplacementBenchResult RunDisplacementBench(const DisplacementBenchOptions& options) {
  options.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  fmt::print("{} | {}\n", context->info().renderer, context->info().version);

  // The scene: the paper's displaced polygon (sec. 3, Figures 4 and 10) as a
  // 2 x 2 plane, smooth bumps on a solid floor (so every ground-truth pixel
  // has surface and holes are see-through, not masking), 256^2 texels.
  constexpr int kTexels = 256;
  constexpr float kMaxDisplacement = 0.25f, kTiling = 1.0f;
  const core::TriangleMesh base = DisplacementBaseMesh("plane");
  const core::ImageF height = DisplacementHeightMap(core::HeightPattern::kBumps, kTexels, 0.15f);
  const render::Texture texture =
      render::UploadDisplacementTexture(render::MakeDisplacementTexels(height));
  const render::GpuMesh truth_mesh(
      render::MakeDisplacedGroundTruth(base, height, kMaxDisplacement, kTiling));
  const float texel = core::HeightTexelWorldSize(base, kTexels, kTiling);
  render::DisplacementPassOptions pass_options;
  pass_options.max_displacement = kMaxDisplacement;
  pass_options.tiling = kTiling;
  render::DisplacementPass pass(programs, base, texture, pass_options);

  const std::vector<Family> families = {{"surface", render::SliceFamily::kSurfaceAligned, false},
                                        {"orthogonal", render::SliceFamily::kOrthogonal, false},
                                        {"screen", render::SliceFamily::kScreen, false},
                                        {"screen-full", render::SliceFamily::kScreen, true}};
  const std::vector<int> counts =
      options.quick ? std::vector<int>{8, 32, 128} : std::vector<int>{8, 16, 32, 64, 128, 256};
  const std::vector<double> elevations =
      options.quick ? std::vector<double>{90, 60, 10} : std::vector<double>{90, 60, 30, 10};
  const std::vector<int> sizes = options.quick ? std::vector<int>{128} : std::vector<int>{256, 512};
  constexpr double kAzimuth = -60;
  const render::FrameTimerOptions timer =
      options.quick ? render::FrameTimerOptions{1, 3} : render::FrameTimerOptions{1, 5};
  render::MeshPassOptions truth_options;
  truth_options.texture = &texture;
  truth_options.shade = false;
  render::MeshPass truth_pass(programs, truth_mesh, truth_options);

  Table table({"family", "slices", "elevation_deg", "size_px", "ms_per_frame", "fragments_M",
               "fill_fraction", "coverage_iou", "mean_depth_error_texels", "p95_depth_error_texels",
               "see_through_pixels", "truth_ms_per_frame", "time_vs_truth"});
  std::map<std::string, std::vector<core::Image8>> grazing_images;
  core::Image8 grazing_truth;
  const double grazing = elevations.back();
  const int sheet_count = 32;

  for (int size : sizes) {
    render::FillRateOptions fill_options;
    fill_options.width = fill_options.height = size;
    fill_options.linear_filter = true;  // the pass samples LINEAR
    fill_options.timer = timer;
    const render::FillRate fill = render::MeasureFillRate(programs, fill_options);
    fmt::print("size {} px: calibrated fill rate (LINEAR) {:.1f} M fragments/s\n", size,
               fill.fragments_per_second * 1e-6);
    render::RenderTarget target(render::FrameTargetOptions(size, size));
    render::RenderTarget truth_target(render::FrameTargetOptions(size, size));
    for (double elevation : elevations) {
      const render::ViewSetup view = ibr::DisplacementOrbitView(
          base, kMaxDisplacement, {.elevation_deg = elevation, .azimuth_deg = kAzimuth}, size);
      const core::TimingStats truth_time =
          render::TimeFrames([&] { render::DrawFrame(truth_target, truth_pass, view); }, timer);
      render::DrawFrame(truth_target, truth_pass, view);
      const render::Frame truth = render::ReadFrame(truth_target);
      if (elevation == grazing && size == sizes.front()) grazing_truth = truth.color;
      for (const Family& family : families) {
        for (int count : counts) {
          render::SlicingOptions slicing;
          slicing.family = family.family;
          slicing.count = count;
          slicing.full_size_screen_slices = family.full_size;
          pass.SetSlicing(slicing);
          const core::TimingStats time =
              render::TimeFrames([&] { render::DrawFrame(target, pass, view); }, timer);
          pass.CountFragments(true);
          render::DrawFrame(target, pass, view);
          pass.CountFragments(false);
          const double fragments = pass.last_stats().fragments;
          const render::Frame frame = render::ReadFrame(target);
          core::DisplacementErrorOptions error_options;
          error_options.depth_unit = texel;
          const core::DisplacementError error = core::CompareToGroundTruth(
              frame.color, frame.depth, truth.color, truth.depth, error_options);
          const double fill_fraction =
              fragments < 0 ? std::nan("")
                            : fragments / (time.median_ms * 1e-3) / fill.fragments_per_second;
          table.AddRow({family.label, std::to_string(count), Num(elevation, 0),
                        std::to_string(size), Num(time.median_ms, 2), Num(fragments * 1e-6, 2),
                        Num(fill_fraction, 3), Num(error.coverage_iou, 4),
                        Num(error.mean_depth_error, 3), Num(error.p95_depth_error, 3),
                        std::to_string(error.see_through_pixels), Num(truth_time.median_ms, 2),
                        Num(time.median_ms / truth_time.median_ms, 2)});
          if (elevation == grazing && size == sizes.front() && count == sheet_count) {
            grazing_images[family.label].push_back(frame.color);
          }
        }
      }
    }
  }
  fmt::print("{}", table.Format());
  table.WriteCsv(options.csv);

  // For each family at elevation 60 (the "60-degree view") and 30 (60 degrees
  // from the normal), largest size: fewest slices with p95 < 1 texel.
  Table summary({"elevation_deg", "family", "slices_for_p95_under_1_texel", "ms_per_frame",
                 "truth_ms_per_frame", "time_vs_truth"});
  const int largest = sizes.back();
  for (double elevation : {60.0, 30.0}) {
    for (const Family& family : families) {
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
      if (std::find(elevations.begin(), elevations.end(), elevation) == elevations.end()) continue;
      summary.AddRow({Num(elevation, 0), family.label, slices, ms, truth_ms, ratio});
    }
  }
  fmt::print(
      "\nslices needed for p95 depth error < 1 texel ({} px; texel = {:.5f} scene units):\n{}",
      largest, texel, summary.Format());

  if (!options.out.empty()) {
    fs::create_directories(options.out);
    const std::string largest_size = std::to_string(largest);
    for (double elevation : {60.0, grazing}) {
      Table subset(table.columns());
      for (const auto& row : table.rows()) {
        if (std::stod(row[2]) == elevation && row[3] == largest_size) subset.AddRow(row);
      }
      if (subset.rows().empty()) continue;
      const fs::path png = options.out / fmt::format("error_vs_time_elev{:.0f}.png", elevation);
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
    for (const Family& family : families) {
      for (const auto& im : grazing_images[family.label]) sheet_images.push_back(im);
    }
    const fs::path sheet = options.out / "grazing_contact_sheet.png";
    core::WriteImage(sheet,
                     core::ContactSheet(sheet_images, static_cast<int>(sheet_images.size())));
    fmt::print(
        "wrote {} (elevation {:.0f} deg, {} slices; left to right: tessellated ground truth, "
        "surface, "
        "orthogonal, screen, screen-full)\n",
        sheet.string(), grazing, sheet_count);
  }
  return {std::move(table), std::move(summary)};
}

}  // namespace bench
