// `ibr bench deform --csv FILE --out DIR`: the cost of deformation and cut
// shaders (Correa, Silver, Chen 2007, Table 1 and Fig. 7 analogues) with
// OpenVDB's level-set builder timed beside our distance field, and what
// accuracy costs (a knife cut against the double sphere tracer). Flags ->
// bench::RunDeformBench -> print.
#include <fmt/format.h>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "bench/deform_bench.h"
#include "bench/paper_tables.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

void AddDeformBench(CLI::App& app) {
  static bench::DeformBenchOptions options;
  auto* cmd = BenchGroup(app)->add_subcommand(
      "deform",
      "Deformation/cut shaders: ms vs deformed screen area, Table 1 ratios; SDF build vs OpenVDB; "
      "error vs time against the sphere tracer");
  AddBenchOutputs(cmd, options.csv, options.out, options.quick);
  cmd->get_option("--out")->required();  // the peer's meshes and the summary tables go there
  cmd->add_option("--shared-data", options.shared_data, "the shared data folder (meshes/)")
      ->default_val("../shared/data");
  cmd->add_option("--size", options.size, "image size in pixels")->capture_default_str();
  cmd->add_flag("!--no-peer", options.peer, "skip the OpenVDB Python peer");
  cmd->add_flag("--sdf-only", options.sdf_only,
                "only the distance-field table (ours vs OpenVDB: build time, accuracy) to --csv");
  cmd->add_flag("--workloads-only", options.workloads_only,
                "only the wedge cut, forward-mesh peer and spread workloads")
      ->excludes("--sdf-only");
  cmd->callback([] {
    options.Check();
    CheckBenchOutputs("ibr bench deform", options.csv, options.out);
    if (options.sdf_only) {
      const bench::Table sdf = bench::RunDeformSdfBench(options);
      fmt::print("{}", sdf.Format());
      sdf.WriteCsv(options.csv);
      fmt::print("wrote {}\n", options.csv.string());
      return;
    }
    const auto gl = StartBenchGl("ibr bench deform", options.size);
    const bench::DeformBenchResult result = bench::RunDeformBench(gl->programs, options);
    fmt::print("{}\n{}\n{}\n{}\n{}\n{}\n{}", result.frames.Format(), result.summary.Format(),
               result.sdf.Format(), result.accuracy.Format(), result.implicits.Format(),
               result.spread.Format(), result.pull.Format());
    fmt::print(
        "{}\n",
        bench::Correa2007GoalsTable(result.wedge, result.forward, result.spread_figures).Format());
    fmt::print("{}\n{}\n{}\n{}\n", result.wedge.Line(), result.forward.Line(),
               result.spread_figures.Line(), result.pull_figures.Line());
    bench::WriteDeformBench(result, options);
    fmt::print("wrote {} and plots in {}\n", options.csv.string(), options.out.string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench deform", AddDeformBench);

}  // namespace apps
