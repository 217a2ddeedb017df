// `ibr bench scene`: per effect, the frame time of a scene with the effect on,
// named but disabled, and absent, in one run (bench/scene_bench.h). Figures
// are printed and written, never asserted.
#include <fmt/format.h>

#include <filesystem>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "bench/scene_bench.h"
#include "core/error.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

void AddSceneBench(CLI::App& app) {
  auto* cmd = BenchGroup(app)->add_subcommand(
      "scene",
      "Cost of each effect in a scene: on, named but disabled, and absent (ratios to absent)");
  static std::filesystem::path csv, out;
  static bench::SceneBenchOptions options;
  AddBenchOutputs(cmd, csv, out, options.quick);
  cmd->add_option("--size", options.size, "frame width = height in pixels")->capture_default_str();
  cmd->add_option("--rounds", options.rounds,
                  "interleaved rounds of the effect disabled, absent and absent again")
      ->capture_default_str();
  cmd->add_option("--on-every", options.on_every,
                  "the effect enabled joins every N-th round (from the first)")
      ->capture_default_str();
  cmd->add_option("--frames", options.frames, "timed frames per configuration and round")
      ->capture_default_str();
  cmd->callback([] {
    const auto gl = StartBenchGl("ibr bench scene", options.size);
    options.Check();
    const std::filesystem::path out_dir = CheckBenchOutputs("ibr bench scene", csv, out);
    const bench::SceneBenchResult result = bench::RunSceneBench(options);
    fmt::print("{}\n", result.table.Format());
    bench::WriteSceneBench(result, csv, out_dir);
    fmt::print("wrote {} and scene_bench.png in {}\n", csv.string(), out_dir.string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench scene", AddSceneBench);

}  // namespace apps
