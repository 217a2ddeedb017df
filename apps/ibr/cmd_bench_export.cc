// `ibr bench export`: the exported depth-object mesh against the true mesh,
// beside Open3D's TSDF of the same maps (bench/export_bench.h). Printed and
// written, never asserted.
#include <fmt/format.h>

#include <filesystem>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "bench/export_bench.h"

namespace apps {
namespace {

void AddExportBench(CLI::App& app) {
  auto* cmd = BenchGroup(app)->add_subcommand(
      "export", "Exported meshes vs the true mesh (Chamfer, normals, time) beside Open3D's TSDF");
  static std::filesystem::path csv, out;
  static bool quick = false;
  static bench::ExportBenchOptions options;
  AddBenchOutputs(cmd, csv, out, quick);
  cmd->add_option("--objects", options.objects, "sphere, box, torus or shared meshes (spot, ...)")
      ->capture_default_str();
  cmd->add_option("--size", options.map_size, "cube map pixels")->capture_default_str();
  cmd->add_option("--resolutions", options.resolutions, "voxels along the bounds' largest edge")
      ->capture_default_str();
  cmd->add_option("--samples", options.samples, "Chamfer samples per surface")
      ->capture_default_str();
  cmd->callback([] {
    const bench::ExportBenchOptions o = quick ? bench::ExportBenchOptions::Quick() : options;
    const auto gl = StartBenchGl("ibr bench export", 0);
    const std::filesystem::path out_dir = CheckBenchOutputs("ibr bench export", csv, out);
    const bench::ExportBenchResult result =
        bench::RunExportBench(gl->programs, o, out_dir / "export_work");
    fmt::print("{}\n", result.table.Format());
    result.table.WriteCsv(csv);
    fmt::print("bench export: wrote {}\n", csv.string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench export", AddExportBench);

}  // namespace apps
