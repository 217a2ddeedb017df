// `ibr bench depth-object`: what accuracy costs in time for depth objects
// (Kautz-Seidel 2001, sec. 4), with the Open3D peer in the same run; printed,
// never asserted.
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
                  "only these objects (cup, bunny, cow, spot, teapot)");
  cmd->add_option("--sizes", options.sizes, "only these output sizes (pixels)");
  cmd->add_flag("!--no-figures", options.figures, "skip the Fig. 12 analogues");
  cmd->add_option("--slices", options.slices, "only these slice counts");
  cmd->add_flag("!--no-maps", options.maps_sweep, "skip the cost-per-map sweep (ring captures)");
  cmd->add_option("--map-counts", options.map_counts,
                  "the cost-per-map sweep's ring sizes (default 6 24 64 128 256)");
  cmd->callback([] { bench::RunDepthObjectBench(options); });
}

}  // namespace

IBR_REGISTER_COMMAND("bench depth-object", AddDepthObjectBench);

}  // namespace apps
