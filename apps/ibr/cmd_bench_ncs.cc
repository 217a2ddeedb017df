// `ibr bench ncs`: NCS / relief / POM / CRM vs the tessellated ground truth
// (bench/ncs_bench.h). Figures are printed and written, never asserted.
#include <fmt/format.h>

#include <filesystem>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "bench/ncs_bench.h"
#include "core/error.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {

namespace {

void AddNcsBench(CLI::App& app) {
  auto* cmd = BenchGroup(app)->add_subcommand("ncs",
                                              "NCS (Chen-Chang) vs relief mapping, POM and the "
                                              "tessellated ground truth on a displaced torus");
  static std::filesystem::path csv, out;
  static bool quick = false;
  static bench::NcsBenchOptions options;
  AddBenchOutputs(cmd, csv, out, quick);
  cmd->add_option("--size", options.size, "frame width = height in pixels")->capture_default_str();
  cmd->add_option("--steps", options.steps, "linear-search step counts")->capture_default_str();
  cmd->add_option("--c", options.step_enlargements, "NCS step enlargements c")
      ->capture_default_str();
  cmd->add_option("--tilings", options.tilings, "height map tilings")->capture_default_str();
  cmd->add_option("--views", options.views, "oblique, grazing, edge")->capture_default_str();
  cmd->add_option("--height-map-size", options.height_map_size,
                  "height map texels per side (Chen-Chang Fig. 6: 512)")
      ->capture_default_str();
  cmd->add_option("--max-truth-subdivisions", options.max_truth_subdivisions,
                  "cap on the ground truth's subdivisions per base triangle")
      ->capture_default_str();
  cmd->callback([] {
    bench::NcsBenchOptions o = quick ? bench::NcsBenchOptions::Quick() : options;
    const auto gl = StartBenchGl("ibr bench ncs", o.size);
    o.Check();
    const std::filesystem::path& csv_path = csv;
    const std::filesystem::path out_dir = CheckBenchOutputs("ibr bench ncs", csv, out);
    const bench::NcsBenchResult result = bench::RunNcsBench(gl->programs, o);
    fmt::print("{}\n", result.table.Format());
    fmt::print(
        "NCS cost relative to relief mapping and to the tessellated ground truth (c = 2.5, fastest "
        "frame):\n{}\n",
        result.summary.Format());
    fmt::print("NCS early termination against c (Chen-Chang Fig. 7):\n{}\n", result.fig7.Format());
    bench::WriteNcsBench(result, csv_path, out_dir);
    fmt::print("wrote {} and plots, summary, silhouette strip in {}\n", csv_path.string(),
               out_dir.string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench ncs", AddNcsBench);

}  // namespace apps
