// `ibr import colmap|redwood|tum|nerf|middlebury SRC --out DIR`: real data to datasets.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "apps/ibr/commands.h"
#include "capture/colmap_dataset.h"
#include "capture/importers.h"
#include "capture/nerf_import.h"
#include "capture/tum_import.h"
#include "core/error.h"

namespace apps {
namespace {

struct ImportCommandOptions {
  std::filesystem::path source;
  std::filesystem::path out;
  capture::ColmapImportOptions colmap;
  capture::RedwoodImportOptions redwood;
  capture::TumImportOptions tum;
  capture::NerfImportOptions nerf;
  std::string bounds;  // --bounds X0,Y0,Z0,X1,Y1,Z1 of the RGB-D importers
  capture::MiddleburyImportOptions middlebury;
};

void Progress(int i, int n) { spdlog::info("import: view {}/{}", i, n); }
// What the importer says about its result (box, up, depth scale, what renders).
void Note(const std::string& line) { fmt::print("import: {}\n", line); }

void Report(const char* kind, const capture::Dataset& d, const std::filesystem::path& out) {
  fmt::print("import {}: {} views -> {}\n", kind, d.views.size(),
             std::filesystem::absolute(out).string());
}

void AddImportCommand(CLI::App& app) {
  static ImportCommandOptions o;
  auto* cmd = app.add_subcommand(
      "import", "Turn a COLMAP workspace or real RGB-D / multi-view data into a dataset");
  cmd->require_subcommand(1);
  auto common = [](CLI::App* sub) {
    sub->add_option("SRC", o.source, "source folder")->required();
    sub->add_option("--out", o.out, "output dataset directory")->required();
  };
  // --views / --hold-out of the importers that read photos by name.
  auto choose = [](CLI::App* sub, capture::ViewChoice& choice) {
    sub->add_option("--views", choice.views, "import only these photos (NAME,NAME,...)")
        ->delimiter(',');
    sub->add_option("--hold-out", choice.hold_out,
                    "leave these photos out (NAME,...), e.g. to render them as held-out views")
        ->delimiter(',');
  };
  auto* colmap =
      cmd->add_subcommand("colmap", "dense workspace (depth + normals) or sparse model + images");
  common(colmap);
  colmap
      ->add_option("--input-type", o.colmap.input_type,
                   "dense maps: geometric, photometric, or auto (geometric where any exist)")
      ->capture_default_str();
  choose(colmap, o.colmap.choice);
  colmap->add_option("--images", o.colmap.images,
                     "sparse import: image folder (default SRC/images)");
  colmap->add_option("--masks", o.colmap.masks,
                     "sparse import: silhouettes, NAME.png per photo NAME (> 127 = object)");
  colmap
      ->add_option("--bounds-percentile", o.colmap.bounds_percentile,
                   "the box spans this percentile and 100 minus it of the points per axis")
      ->capture_default_str();
  colmap->callback([] {
    Report("colmap", capture::ImportColmap(o.source, o.out, o.colmap, Progress, Note), o.out);
  });
  auto* redwood = cmd->add_subcommand(
      "redwood", "Redwood RGB-D frames (trajectory.log, camera_primesense.json)");
  common(redwood);
  redwood
      ->add_option("--depth-scale", o.redwood.depth_scale,
                   "depth units per metre (Redwood 1000, TUM RGB-D 5000)")
      ->capture_default_str();
  auto bounds = [](CLI::App* sub) {
    sub->add_option("--bounds", o.bounds,
                    "the object's box X0,Y0,Z0,X1,Y1,Z1 in metres (default: what most frames "
                    "agree on, printed)");
  };
  bounds(redwood);
  redwood->callback([] {
    if (!o.bounds.empty()) o.redwood.bounds = capture::ParseBounds(o.bounds, "--bounds");
    Report("redwood", capture::ImportRedwood(o.source, o.out, o.redwood, Progress, Note), o.out);
  });
  auto* tum = cmd->add_subcommand(
      "tum", "TUM RGB-D sequence (rgb.txt, depth.txt, groundtruth.txt), frames by timestamp");
  common(tum);
  tum->add_option("--camera", o.tum.camera,
                  "fr1 | fr2 | fr3 (TUM's calibrations) or FX,FY,CX,CY (default: from the "
                  "sequence's name)");
  tum->add_option("--depth-scale", o.tum.depth_scale, "depth units per metre")
      ->capture_default_str();
  tum->add_option("--max-difference", o.tum.max_difference,
                  "seconds between a colour image and its depth image")
      ->capture_default_str();
  tum->add_option("--max-pose-gap", o.tum.max_pose_gap,
                  "seconds between the ground-truth poses a frame's pose is interpolated from")
      ->capture_default_str();
  tum->add_option("--every", o.tum.every, "take every N-th frame")->capture_default_str();
  bounds(tum);
  tum->callback([] {
    if (!o.bounds.empty()) o.tum.bounds = capture::ParseBounds(o.bounds, "--bounds");
    Report("tum", capture::ImportTum(o.source, o.out, o.tum, Progress, Note), o.out);
  });
  auto* nerf = cmd->add_subcommand(
      "nerf", "NeRF transforms.json (Blender synthetic, instant-ngp, nerfstudio)");
  common(nerf);
  choose(nerf, o.nerf.choice);
  nerf->callback(
      [] { Report("nerf", capture::ImportNerf(o.source, o.out, o.nerf, Progress, Note), o.out); });
  auto* middlebury = cmd->add_subcommand(
      "middlebury", "Middlebury multi-view ring (*_par.txt), masks by threshold");
  common(middlebury);
  middlebury
      ->add_option("--threshold", o.middlebury.threshold,
                   "silhouette threshold, fraction of full scale")
      ->capture_default_str();
  middlebury->add_option("--dilate", o.middlebury.dilate_iterations, "3x3 dilations")
      ->capture_default_str();
  middlebury->add_option("--erode", o.middlebury.erode_iterations, "3x3 erosions")
      ->capture_default_str();
  middlebury->callback([] {
    Report("middlebury", capture::ImportMiddlebury(o.source, o.out, o.middlebury, Progress), o.out);
  });
}

}  // namespace

IBR_REGISTER_COMMAND("import", AddImportCommand);

}  // namespace apps
