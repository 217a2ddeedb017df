// `ibr bench displacement`: what accuracy costs in time for displacement
// mapping by slicing (Kautz-Seidel 2001, sec. 3.4), printed, never asserted.
#include "apps/ibr/commands.h"
#include "bench/displacement_bench.h"

namespace apps {
namespace {

void AddDisplacementBench(CLI::App& app) {
  static bench::DisplacementBenchOptions options;
  auto* cmd = BenchGroup(app)->add_subcommand(
      "displacement",
      "Slicing family x slice count x elevation x resolution vs the tessellated ground truth");
  AddBenchOutputs(cmd, options.csv, options.out, options.quick);
  cmd->callback([] { bench::RunDisplacementBench(options); });
}

}  // namespace

IBR_REGISTER_COMMAND("bench displacement", AddDisplacementBench);

}  // namespace apps
