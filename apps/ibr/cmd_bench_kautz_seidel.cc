// `ibr bench kautz-seidel`: the Kautz-Seidel 2001 experiments of sec. 5-6
// (bench/kautz_seidel_experiments.h) with the paper's figures beside ours.
// Figures are printed and written, never asserted.
#include <fmt/format.h>

#include <filesystem>
#include <utility>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "bench/kautz_seidel_experiments.h"
#include "render/gl/context.h"

namespace apps {

namespace {

void AddKautzSeidelBench(CLI::App& app) {
  auto* cmd = BenchGroup(app)->add_subcommand(
      "kautz-seidel",
      "Kautz-Seidel 2001 Fig. 12 and sec. 6: visual hulls beside depth objects, time vs viewing "
      "angle, the 150/70 and 400/150 points, the donut at 15-25 slices");
  static std::filesystem::path csv, out;
  static bool quick = false;
  static bench::KautzSeidelOptions options;
  AddBenchOutputs(cmd, csv, out, quick);
  cmd->add_option("--object", options.object, "bunny, cow, spot, teapot or an analytic shape")
      ->capture_default_str();
  cmd->callback([] {
    bench::KautzSeidelOptions o = options;
    o.quick = quick;
    o.Check();
    const std::filesystem::path out_dir = CheckBenchOutputs("ibr bench kautz-seidel", csv, out);
    const auto gl = StartBenchGl("ibr bench kautz-seidel", 0);
    const bench::KautzSeidelResult r = bench::RunKautzSeidelExperiments(gl->programs, o);
    fmt::print("object: {}\n", r.object);
    for (const auto& [title, table] :
         {std::pair{"Fig. 12 analogues", &r.fig12}, std::pair{"Time vs viewing angle", &r.angle},
          std::pair{"The 150 x 150 / 70 slices and 400 x 400 / 150 slices points", &r.points},
          std::pair{"The donut at 15-25 orthogonal slices", &r.donut}}) {
      fmt::print("{}:\n{}\n", title, table->Format());
    }
    bench::WriteKautzSeidelExperiments(r, csv, out_dir);
    fmt::print("wrote {} (+ _fig12.csv, _angle.csv, _donut.csv) and plots in {}\n", csv.string(),
               out_dir.string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench kautz-seidel", AddKautzSeidelBench);

}  // namespace apps
