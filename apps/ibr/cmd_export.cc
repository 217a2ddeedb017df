// `ibr export colmap DIR --out WS`: a dataset as a COLMAP dense workspace.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "apps/ibr/commands.h"
#include "capture/colmap_dataset.h"

namespace apps {
namespace {

struct ExportCommandOptions {
  std::filesystem::path dataset;
  std::filesystem::path out;
  bool text = false;  // sparse model as .txt instead of .bin
  capture::ColmapExportOptions colmap;
};

void AddExportCommand(CLI::App& app) {
  static ExportCommandOptions o;
  auto* cmd = app.add_subcommand("export", "Write a dataset in another tool's format");
  cmd->require_subcommand(1);
  auto* colmap = cmd->add_subcommand(
      "colmap", "COLMAP dense workspace (images, sparse, stereo) for stereo_fusion");
  colmap->add_option("DIR", o.dataset, "dataset directory")->required();
  colmap->add_option("--out", o.out, "workspace directory")->required();
  colmap->add_flag("--text", o.text, "write the sparse model as text (default binary)");
  colmap->add_option("--point-step", o.colmap.point_step_px, "sparse point spacing in pixels")
      ->capture_default_str();
  colmap->callback([] {
    o.colmap.format =
        o.text ? capture::colmap::ModelFormat::kText : capture::colmap::ModelFormat::kBinary;
    const capture::Dataset dataset = capture::ReadDataset(o.dataset);
    capture::ExportColmapWorkspace(dataset, o.out, o.colmap,
                                   [](int i, int n) { spdlog::info("export: view {}/{}", i, n); });
    fmt::print("export colmap: {} views -> {}\n", dataset.views.size(),
               std::filesystem::absolute(o.out).string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("export", AddExportCommand);

}  // namespace apps
