// `ibr bench volume --csv FILE [--out DIR]`: the cost of discontinuous
// displacement of volumes (Correa et al. 2006, Tables 1-2 analogues) with the
// VTK GPU ray caster in the same run. Flags -> bench::RunVolumeBench.
#include <fmt/format.h>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "bench/volume_bench.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

void AddVolumeBench(CLI::App& app) {
  static bench::VolumeBenchOptions options;
  auto* cmd = BenchGroup(app)->add_subcommand(
      "volume",
      "Volume DVR with displacement maps: time per volume, sampling, map size, area, floors, "
      "goals (CSV_goals.csv); VTK peers (plain and prewarped)");
  AddBenchOutputs(cmd, options.csv, options.out, options.quick);
  cmd->add_option("--shared-data", options.shared_data, "the shared data folder (volumes/)")
      ->default_val("../shared/data");
  cmd->add_option("--size", options.size, "image size in pixels")->capture_default_str();
  cmd->add_flag("!--no-peer", options.peer, "skip the VTK peers");
  cmd->callback([] {
    CheckBenchOutputs("ibr bench volume", options.csv, options.out);
    const auto gl = StartBenchGl("ibr bench volume", options.size);
    bench::RunVolumeBench(options);
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench volume", AddVolumeBench);

}  // namespace apps
