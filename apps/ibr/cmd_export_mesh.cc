// `ibr export mesh DIR --out FILE.ply|.obj` and `ibr export points DIR --out
// FILE.ply`: the depth object or visual hull of a dataset as a closed mesh,
// and the fused point cloud of its maps (ibr/mesh_export.h).
#include <fmt/format.h>

#include <filesystem>

#include "apps/ibr/commands.h"
#include "ibr/mesh_export.h"

namespace apps {
namespace {

struct ExportMeshCommandOptions {
  std::filesystem::path dataset;
  std::filesystem::path out;
  std::string method = "depth-object";
  std::string colour = "vdt";
  ibr::MeshExportOptions mesh;
};

void AddExportMeshCommands(CLI::App& app) {
  static ExportMeshCommandOptions o;
  CLI::App* group = app.get_subcommand("export");
  auto* mesh = group->add_subcommand(
      "mesh", "The depth object or visual hull as a closed, outward-oriented mesh (PLY or OBJ)");
  mesh->add_option("DIR", o.dataset, "dataset directory")->required();
  mesh->add_option("--out", o.out, "FILE.ply or FILE.obj (+ FILE.mtl)")->required();
  mesh->add_option("--method", o.method, "depth-object | visual-hull")->capture_default_str();
  mesh->add_option("--resolution", o.mesh.resolution,
                   "voxels along the largest edge of the dataset's bounds")
      ->capture_default_str();
  mesh->add_option("--robust", o.mesh.robust_k, "views that may vote a kept point outside")
      ->capture_default_str();
  mesh->add_option("--colour", o.colour, "vertex colours: vdt | none")->capture_default_str();
  mesh->callback([] {
    o.mesh.method = ibr::MethodFromName(o.method);
    o.mesh.colouring = ibr::MeshColouringFromName(o.colour);
    const ibr::ExportSummary s = ibr::ExportDatasetMesh(o.dataset, o.out, o.mesh);
    fmt::print(
        "export mesh: {} of {} views, grid {}x{}x{} (voxel {:.4g}), {} vertices, {} "
        "triangles, volume {:.6g}, {:.2f} s -> {}\n",
        o.method, s.views, s.stats.grid.x, s.stats.grid.y, s.stats.grid.z, s.stats.voxel_size,
        s.vertices, s.triangles, s.volume, s.stats.total_s(),
        std::filesystem::absolute(o.out).string());
  });

  auto* points = group->add_subcommand(
      "points", "The fused point cloud of the depth maps (positions, normals, colours; PLY)");
  points->add_option("DIR", o.dataset, "dataset directory")->required();
  points->add_option("--out", o.out, "FILE.ply")->required();
  points->callback([] {
    const ibr::ExportSummary s = ibr::ExportDatasetPoints(o.dataset, o.out);
    fmt::print("export points: {} points from {} views -> {}\n", s.vertices, s.views,
               std::filesystem::absolute(o.out).string());
  });
}

}  // namespace

// After "export" (commands are added in name order).
IBR_REGISTER_COMMAND("export mesh", AddExportMeshCommands);

}  // namespace apps
