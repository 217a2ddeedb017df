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
  cmd->add_option("--csv", options.csv, "CSV file for the table")->required();
  cmd->add_option("--out", options.out,
                  "directory for the error-vs-time plots and the grazing contact sheet");
  cmd->add_flag("--quick", options.quick, "small sweep (CI smoke run)");
  cmd->callback([] { bench::RunDisplacementBench(options); });
}

}  // namespace

IBR_REGISTER_COMMAND("bench displacement", AddDisplacementBench);

}  // namespace apps
