// The Open3D peer of depth objects and visual hulls (issue 5, "Accuracy and
// its cost"), and the accuracy metrics every method is judged by.
//
// RunOpen3dPeer() runs bench/open3d_peer.py with Debian's /usr/bin/python3
// (python3-open3d 0.16): TSDF integration (ScalableTSDFVolume) and voxel
// carving (VoxelGrid.create_dense + carve_depth_map / carve_silhouette) on
// one of our datasets, each result a triangle mesh PLY plus wall times.
// EvaluatePeer() loads those meshes (assimp, capture::LoadSceneMesh), draws
// them with our own reference rasteriser (render::RenderMesh) from the novel
// views and measures them against the true mesh exactly like our renderer's
// output (EvaluateDepthObject()): silhouette IoU and depth error in
// cube-edge units.
//
// Time to first image:
//  - ours:   DepthObjectRenderer construction (map upload) + the first frame;
//  - Open3D: integration or carving + mesh extraction (in Python, as Open3D
//            reports them) + our mesh upload + the first frame.
// Neither counts reading the dataset from disk, Python's start-up, or the
// PLY round trip between the processes (printed separately).
//
// Limits: Open3D has no orthographic camera, so cube-rig (orthographic)
// datasets cannot be fed to it; give it a perspective capture of the same
// object (ibr capture --rig sphere:N). The script then fails with one line
// saying so (InputError here).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "core/image.h"
#include "core/mesh.h"
#include "core/metrics.h"
#include "ibr/depth_object.h"
#include "ibr/image_maps.h"
#include "ibr/views.h"
#include "render/gl/shader_program.h"
#include "render/passes/mesh_pass.h"

namespace bench {

// `s` in single quotes for /bin/sh (a ' inside becomes '\''): one word,
// nothing expanded. Every peer's command line quotes its paths with it.
std::string ShellQuote(const std::string& s);

// ------------------------------------------------------------ metrics ----

// Depth/silhouette metrics shared with ibr/ (core/metrics.h).
using core::CompareDepth;
using core::Pool;
using core::PooledMetrics;
using core::ViewMetrics;

// The largest edge of the bounds: the unit of every depth error.
double CubeEdge(const capture::Bounds& bounds);

// The render setup for a novel view: ibr/views.h.
using ibr::ViewSetupFor;

// The true mesh (world coordinates) from every view: camera z, 0 = empty.
std::vector<core::ImageF> RenderTruthDepth(render::ProgramCache& programs,
                                           const core::TriangleMesh& mesh,
                                           const std::vector<ibr::ViewCamera>& views,
                                           const capture::Bounds& bounds);

// --------------------------------------------------------------- rows ----

// One method's line of the comparison.
struct MethodRow {
  std::string method;         // "depth-object screen 256", "open3d tsdf:128", ...
  double build_s = 0;         // Open3D: integration/carving + extraction; ours: 0
  double upload_ms = 0;       // maps (ours) or mesh (peer) to the GPU
  double first_frame_ms = 0;  // first frame incl. readback
  double time_to_first_image_s = 0;
  double median_frame_ms = 0;  // the other views' frames
  int64_t triangles = 0;       // peer meshes; 0 for ours
  PooledMetrics accuracy;
  std::vector<ViewMetrics> per_view;
};

// Our renderer from every view (first view: time to first image).
MethodRow EvaluateDepthObject(render::ProgramCache& programs, const ibr::MapSet& maps,
                              const ibr::DepthObjectOptions& options,
                              const std::vector<ibr::ViewCamera>& views,
                              const std::vector<core::ImageF>& truth, double cube_edge,
                              const std::string& label);

// ------------------------------------------------------------ Open3D ----

struct Open3dPeerOptions {
  std::filesystem::path python = "/usr/bin/python3";  // Debian's, where python3-open3d lives
  // Empty: bench/open3d_peer.py of the source tree this file was built from.
  std::filesystem::path script;
  // "tsdf:N" (voxel = cube edge / N), "carve-depth:N", "carve-silhouette:N"
  // (N^3 voxels); N in 8..1024. Defaults: PEERS.md's settings minus the
  // 256^3 carving (~13 s a run on a quiet machine; ask for it by name).
  std::vector<std::string> methods = {"tsdf:128", "tsdf:256", "carve-depth:128",
                                      "carve-silhouette:128"};
  std::filesystem::path work_dir;  // required: PLYs and peer.json are written here
  // Orthographic maps (cube rig) as far pinhole cameras (open3d_peer.py
  // --orthographic far-pinhole); false: skipped, as Open3D has no
  // orthographic camera.
  bool far_pinhole = false;
  void Check() const;
};

struct Open3dResult {
  std::string method;  // "tsdf", "carve-depth", "carve-silhouette"
  int resolution = 0;
  double voxel_size = 0;  // scene units
  int views_used = 0;
  double integrate_s = 0;  // integration (TSDF) or carving, wall time
  double extract_s = 0;    // mesh extraction (TSDF) or occupancy -> box faces
  int64_t triangles = 0;
  std::filesystem::path mesh;  // empty when the result has no triangles
  std::string name() const { return method + ":" + std::to_string(resolution); }
};

struct Open3dRun {
  std::string version;
  int views = 0, skipped_orthographic = 0;
  double import_s = 0, read_s = 0,
         wall_s = 0;  // Python's import of open3d, reading the dataset, the whole run
  std::vector<Open3dResult> results;
};

// Runs the script on `dataset` (a dataset directory with bounds and
// perspective views). Throws core::InputError with the script's message when
// it fails (python3-open3d missing, orthographic-only dataset, ...).
Open3dRun RunOpen3dPeer(const std::filesystem::path& dataset, const Open3dPeerOptions& options);

// Every result's mesh drawn from every view and measured against `truth`.
// `bounds` encloses the meshes (the dataset's bounds, padded) for near/far.
std::vector<MethodRow> EvaluatePeer(render::ProgramCache& programs, const Open3dRun& run,
                                    const std::vector<ibr::ViewCamera>& views,
                                    const std::vector<core::ImageF>& truth,
                                    const capture::Bounds& bounds, double cube_edge);

}  // namespace bench
