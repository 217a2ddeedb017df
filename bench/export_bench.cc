#include "bench/export_bench.h"

#include <fmt/format.h>

#include <chrono>

#include "bench/cgal_surface_mesher.h"
#include "bench/peer.h"
#include "capture/synthetic.h"
#include "core/distance_field.h"
#include "core/error.h"
#include "core/mesh_compare.h"
#include "ibr/dataset_maps.h"
#include "ibr/jobs/demo_job.h"
#include "ibr/mesh_export.h"

namespace bench {
namespace {

namespace fs = std::filesystem;

capture::SceneMesh ObjectScene(const std::string& name) {
  if (name == "sphere" || name == "box" || name == "torus") return capture::MakeShapeScene(name);
  const fs::path file = ibr::SharedDataDir() / "meshes" / (name + ".obj");
  if (!fs::exists(file)) {
    core::ThrowInputError("bench export", "object '{}': '{}' is absent", name, file.string());
  }
  return capture::LoadSceneMesh(file);
}

std::vector<std::string> Row(const std::string& object, const ExportBenchOptions& o, int res,
                             const std::string& method, double voxel, double seconds,
                             const core::TriangleMesh& mesh, const core::MeshComparison& c) {
  return {object,
          std::to_string(o.map_size),
          std::to_string(res),
          method,
          Num(voxel, 5),
          Num(seconds, 3),
          std::to_string(mesh.positions.size()),
          std::to_string(mesh.triangle_count()),
          core::IsClosedOutward(mesh) ? "1" : "0",
          Num(c.a_to_b_mean, 5),
          Num(c.a_to_b_p95, 5),
          Num(c.b_to_a_mean, 5),
          Num(c.b_to_a_p95, 5),
          Num(c.normal_consistency, 4)};
}

}  // namespace

ExportBenchOptions ExportBenchOptions::Quick() {
  ExportBenchOptions o;
  o.objects = {"sphere"};
  o.map_size = 128;
  o.resolutions = {64};
  o.samples = 20000;
  return o;
}

void ExportBenchOptions::Check() const {
  if (objects.empty()) core::ThrowInputError("bench export", "no objects");
  if (map_size < 16 || map_size > 4096) {
    core::ThrowInputError("bench export", "--size {} outside 16..4096", map_size);
  }
  for (int r : resolutions) {
    if (r < 8 || r > 1024)
      core::ThrowInputError("bench export", "resolution {} outside 8..1024", r);
  }
  if (samples < 100) core::ThrowInputError("bench export", "--samples {} below 100", samples);
}

ExportBenchResult RunExportBench(render::ProgramCache& programs, const ExportBenchOptions& options,
                                 const fs::path& work_dir) {
  options.Check();
  ExportBenchResult result{
      Table({"object", "map_size", "resolution", "method", "voxel", "time_s", "vertices",
             "triangles", "closed_outward", "to_truth_mean", "to_truth_p95", "from_truth_mean",
             "from_truth_p95", "normal_consistency"})};
  for (const std::string& object : options.objects) {
    const capture::SceneMesh scene = ObjectScene(object);
    const double diagonal = core::BoundsDiagonal(scene.mesh);
    capture::CaptureOptions co;
    co.size = options.map_size;
    co.rig = "cube";
    const fs::path dataset_dir = work_dir / ("export_" + object);
    fs::remove_all(dataset_dir);
    const capture::Dataset dataset = capture::CaptureDataset(programs, scene, co, dataset_dir);
    const ibr::MapSet maps = ibr::MapsFromDataset(dataset);
    fmt::print("bench export: {} ({} triangles), {} cube maps of {} px\n", object,
               scene.mesh.triangle_count(), maps.maps.size(), options.map_size);
    for (int res : options.resolutions) {
      const double voxel = ibr::DatasetVoxelSize(dataset.bounds->extent(), res);
      for (int refine : {10, 0}) {
        ibr::MeshExportOptions mo;
        mo.resolution = res;
        mo.voxel_size = voxel;
        mo.refine_steps = refine;
        ibr::MeshExportStats stats;
        const ibr::ColouredMesh mesh = ibr::ExtractObjectMesh(maps, mo, &stats);
        const core::MeshComparison c =
            core::CompareMeshes(mesh.mesh, scene.mesh, options.samples, diagonal);
        const std::string method = refine ? "ibr depth-object" : "ibr depth-object unrefined";
        result.table.AddRow(
            Row(object, options, res, method, voxel, stats.total_s(), mesh.mesh, c));
        fmt::print(
            "  {} {}: {:.3f} s (field {:.3f}, extract {:.3f}, refine {:.3f}, colour {:.3f}), "
            "p95 {:.5f} / {:.5f} diag\n",
            method, res, stats.total_s(), stats.field_s, stats.extract_s, stats.refine_s,
            stats.colour_s, c.a_to_b_p95, c.b_to_a_p95);
      }
      if (res == options.resolutions.front() && object == options.objects.front()) {
        // CGAL's surface mesher on the same field, facets about a voxel in
        // size and within a tenth of a voxel of the surface: once (the
        // first object, the coarsest resolution), its time is minutes.
        ibr::MeshExportOptions mo;
        mo.voxel_size = voxel;
        const auto field = ibr::MakeObjectField(maps, mo, ibr::kBandVoxels * voxel);
        const glm::dvec3 centre(maps.world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0));
        const double radius =
            0.5 * glm::length(glm::dvec3(maps.world_from_box * glm::dvec4(1.0)) -
                              glm::dvec3(maps.world_from_box * glm::dvec4(0, 0, 0, 1)));
        if (field(centre) < 0) {
          const auto t0 = std::chrono::steady_clock::now();
          const core::TriangleMesh cgal =
              CgalSurfaceMesh(field, centre, radius, voxel, 0.1 * voxel);
          const double s =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          const core::MeshComparison c =
              core::CompareMeshes(cgal, scene.mesh, options.samples, diagonal);
          result.table.AddRow(Row(object, options, res, "cgal surface-mesher", voxel, s, cgal, c));
          fmt::print("  cgal surface-mesher {}: {:.3f} s, p95 {:.5f} / {:.5f} diag\n", res, s,
                     c.a_to_b_p95, c.b_to_a_p95);
        } else {
          fmt::print("  cgal surface-mesher: skipped (the box centre is outside {})\n", object);
        }
      }
      Open3dPeerOptions po;
      po.methods = {fmt::format("tsdf:{}", res)};
      po.work_dir = work_dir / ("open3d_" + object + "_" + std::to_string(res));
      po.far_pinhole = true;
      const Open3dRun run = RunOpen3dPeer(dataset_dir, po);
      for (const Open3dResult& r : run.results) {
        if (r.mesh.empty()) {
          fmt::print("  open3d {}: no triangles\n", r.name());
          continue;
        }
        const capture::SceneMesh peer =
            capture::LoadSceneMesh(r.mesh, {}, capture::MeshTextures::kSkip);
        const core::MeshComparison c =
            core::CompareMeshes(peer.mesh, scene.mesh, options.samples, diagonal);
        result.table.AddRow(Row(object, options, res, "open3d " + r.name(), r.voxel_size,
                                r.integrate_s + r.extract_s, peer.mesh, c));
        fmt::print("  open3d {}: {:.3f} s, p95 {:.5f} / {:.5f} diag\n", r.name(),
                   r.integrate_s + r.extract_s, c.a_to_b_p95, c.b_to_a_p95);
      }
    }
  }
  return result;
}

}  // namespace bench
