// `ibr bench depth-object`: what accuracy costs in time for depth objects
// (Kautz-Seidel 2001, sec. 4), with the Open3D peer in the same run; printed,
// never asserted.
#include <fmt/format.h>

#include "apps/ibr/commands.h"
#include "bench/depth_object_bench.h"

namespace apps {
namespace {

void AddDepthObjectBench(CLI::App& app) {
  static bench::DepthObjectBenchOptions options;
  auto* cmd =
      BenchGroup(app)->add_subcommand("depth-object",
                                      "Slicing family x slices x size x object vs the true mesh, "
                                      "the Open3D peer (TSDF, carving), Fig. 12 analogues");
  AddBenchOutputs(cmd, options.csv, options.out, options.quick);
  cmd->add_option("--objects", options.objects,
                  "only these objects (cup, mug, bunny, cow, spot, teapot)");
  cmd->add_option("--sizes", options.sizes, "only these output sizes (pixels)");
  cmd->add_flag("!--no-figures", options.figures, "skip the Fig. 12 analogues");
  cmd->add_option("--slices", options.slices, "only these slice counts");
  cmd->add_flag("!--no-maps", options.maps_sweep, "skip the cost-per-map sweep (ring captures)");
  cmd->add_option("--map-counts", options.map_counts,
                  "the cost-per-map sweep's ring sizes (default 6 24 64 128 256)");
  cmd->callback([] { bench::RunDepthObjectBench(options); });
}

// Run by `ibr bench depth-object` in a child process per measurement (the
// first image of a fresh process, cold or warm caches); prints one line.
void AddFirstImageBench(CLI::App& app) {
  static bench::FirstImageOptions options;
  auto* cmd = BenchGroup(app)->add_subcommand(
      "first-image",
      "Time to first image of a cube-rig dataset in this process: map upload + program builds + "
      "first frame (what bench depth-object runs cold and warm)");
  cmd->add_option("--dataset", options.dataset, "cube-rig dataset folder")->required();
  cmd->add_option("--slicing", options.slicing, "orthogonal | screen | ray")->capture_default_str();
  cmd->add_option("--skip-grid", options.skip_grid, "empty-space skip grid (0: none)")
      ->capture_default_str();
  cmd->add_flag("--subtexel", options.subtexel, "sub-texel depth lookups");
  cmd->add_option("--size", options.size, "output pixels a side")->capture_default_str();
  cmd->callback(
      [] { fmt::print("{}\n", bench::FormatFirstImageLine(bench::MeasureFirstImage(options))); });
}

}  // namespace

IBR_REGISTER_COMMAND("bench depth-object", AddDepthObjectBench);
IBR_REGISTER_COMMAND("bench first-image", AddFirstImageBench);

}  // namespace apps
