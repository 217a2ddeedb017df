// `ibr bench export` (issue 37, part 2): the exported mesh of the depth
// object (ibr/mesh_export.h) against the true mesh, beside Open3D's TSDF of
// the same maps at the same voxel size in the same run. Per object, a cube
// capture (the renderer's 6 orthographic maps; Open3D reads them as far
// pinhole cameras, bench/open3d_peer.py --orthographic far-pinhole), then per
// resolution: ours (refined vertices, and volumeToMesh's own vertices) and
// TSDF (voxel = bounds edge / resolution, truncation 4 voxels), each timed
// from maps in memory to the mesh (TSDF: integration + extraction as Open3D
// reports them) and compared with the truth by core::CompareMeshes: Chamfer
// both ways (mean, p95 in units of the true mesh's bounding-box diagonal)
// and normal consistency; plus whether the mesh is closed and outward.
// Printed and written, never asserted.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"
#include "render/gl/shader_program.h"

namespace bench {

struct ExportBenchOptions {
  // sphere (analytic), and the closed meshes of the shared data.
  std::vector<std::string> objects = {"sphere", "spot", "fandisk"};
  int map_size = 256;  // capture pixels (cube rig)
  std::vector<int> resolutions = {128, 256};
  int samples = 100000;               // Chamfer samples per surface and direction
  static ExportBenchOptions Quick();  // the sphere, 128 px maps, resolution 64, 20000 samples
  void Check() const;
};

struct ExportBenchResult {
  // object, map_size, resolution, method, voxel, time_s, vertices, triangles,
  // closed_outward, to_truth_mean, to_truth_p95, from_truth_mean,
  // from_truth_p95, normal_consistency (distances in true diagonals)
  Table table;
};

// Needs a current context (the captures). `work_dir` receives the datasets and the peer's meshes.
ExportBenchResult RunExportBench(render::ProgramCache& programs, const ExportBenchOptions& options,
                                 const std::filesystem::path& work_dir);

}  // namespace bench
