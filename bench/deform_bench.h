// `ibr deform`: a mesh deformed and cut by the deform pass (Correa, Silver,
// Chen 2007; render/passes/deform_pass.h), from flags to one library call.
// The mesh is normalised into the unit cube centred at the origin (longest
// side 1), so regions, thicknesses and the threshold are in those units.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/report.h"
#include "core/deformation.h"
#include "core/distance_field.h"
#include "render/gl/shader_program.h"
#include "render/passes/deform_pass.h"
#include "render/passes/pass.h"

namespace bench {

struct DeformRunOptions {
  std::filesystem::path mesh;  // OBJ/PLY/... (assimp)
  bool cap_holes = false;      // fill the boundary loops of an open mesh
  core::DeformationSum deformation;
  // Region box in normalised units; empty = the mesh's bounds grown by 0.05.
  std::optional<core::Box3d> region;
  glm::dvec3 rotation_deg{0.0};  // placement: Euler angles about the region's centre
  double scale = 1.0;            // placement: scale about the region's centre
  glm::dvec3 translation{0.0};   // placement: translation (normalised units)
  render::DeformPassOptions pass;
  int sdf_resolution = 128;         // distance-field samples along the longest axis
  int deformation_resolution = 64;  // deformation texture nodes per axis
  int size = 512;                   // image width = height, pixels
  double azimuth_deg = 30.0;        // camera orbit about +y (OBJ up)
  double elevation_deg = 20.0;
  // A dataset whose cameras to render from instead of the orbit view (its
  // world frame is the mesh file's, as `ibr capture` writes it).
  std::filesystem::path cameras;
  // FILE.png: one colour PNG, camera z as <stem>.depth.exr beside it (one
  // view only); otherwise a dataset folder as `ibr render` writes (colour,
  // camera z, mask, normals; dataset.json), staged.
  std::filesystem::path out;
  void Check() const;
  bool WritesDataset() const { return out.extension() != ".png"; }
};

// Per-pixel outcome counts of one frame (render/passes/deform_pass.h bits).
struct DeformOutcomes {
  int64_t mesh_pixels = 0, hit_pixels = 0, cut_face_pixels = 0, exited_pixels = 0, early_pixels = 0;
  int64_t rays = 0;           // pixels where a ray was cast
  double mean_samples = 0.0;  // field samples per cast ray
  void Add(const DeformOutcomes& other);
};
DeformOutcomes CountDeformOutcomes(const render::Frame& frame);

struct DeformViewReport {
  std::string name;
  DeformOutcomes outcomes;
};

struct DeformRunReport {
  double sdf_seconds = 0.0;
  glm::ivec3 sdf_size{0};
  int64_t distance_queries = 0;
  double max_displacement = 0.0;  // normalised units
  std::vector<DeformViewReport> views;
  DeformOutcomes total;   // over every view
  double frame_ms = 0.0;  // median frame time of the first view after warm-up
};

// Loads, normalises, builds the distance field and the deformation texture,
// renders every view and writes the outputs (staged: nothing partial on error).
DeformRunReport RunDeform(render::ProgramCache& programs, const DeformRunOptions& options);

// Centres the mesh at the origin and scales its longest side to 1 (the
// normalised units of `ibr deform`); InputError for a mesh without extent.
void NormaliseMesh(core::TriangleMesh& mesh);

// The deformation box of a run (normalised units) and its placement.
core::Placement DeformPlacement(const DeformRunOptions& options, const core::Box3d& mesh_bounds);

}  // namespace bench

namespace bench {

// `ibr bench deform`: the cost of deformation and cut shaders (Correa,
// Silver, Chen 2007, sec. 6.2, Table 1 and Fig. 7 analogues) on Spot,
// fandisk, the cow and the capped Stanford bunny (normalised, one orbit view):
//  - per mesh and mode (continuous = twist; cut = solid knife without
//    empty-space skipping; cut_skip = the same with skipping) and region
//    scale: ms per frame (median) against the deformed region's relative
//    screen area a (pixels where a ray was cast / all pixels);
//  - the paper's weighted average sum(a t) / sum(a) per mesh and mode, the
//    ratios cut / continuous and cut_skip / continuous, a least-squares line
//    of ms against a with its R^2, and the spread across meshes of the
//    fitted ms at one area;
//  - the distance-field build time per resolution (ours: exact within the
//    band, bench/openvdb_peer.py: OpenVDB's createLevelSetFromPolygons with
//    the same voxel size and half width, timed in Python) and their ratio.
struct DeformBenchOptions {
  std::filesystem::path shared_data = "../shared/data";  // meshes/*.obj
  std::filesystem::path csv;                             // the frame table
  std::filesystem::path out;                             // plots, the other tables, the peer's mesh
  int size = 512;                                        // image width = height, pixels
  bool quick = false;  // 128 px, two meshes, two region scales, SDF 32/64
  bool peer = true;    // time OpenVDB beside our distance field
  void Check() const;
};

struct DeformBenchResult {
  Table frames;   // mesh, triangles, mode, region_scale, area_fraction, ms, samples_per_ray
  Table summary;  // mesh, mode, weighted_ms, over_continuous, slope_ms, intercept_ms, r2
  Table sdf;      // mesh, resolution, builder, seconds, queries_or_active
};

DeformBenchResult RunDeformBench(render::ProgramCache& programs, const DeformBenchOptions& options);
// The tables as CSV (frames at options.csv, the others beside it in out)
// and the gnuplot PNGs in out.
void WriteDeformBench(const DeformBenchResult& result, const DeformBenchOptions& options);

}  // namespace bench
