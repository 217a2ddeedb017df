// The depth object or visual hull of a dataset as a mesh, and the fused point
// cloud of its maps (issue 37): what `ibr export mesh` and `ibr export points`
// write.
//
// The surface is the zero set of the renderer's own object field
// (shaders/passes/depth_object_core.glsl, ObjectField): per map, the signed
// distance along its z axis from the point to the depth the map saw
// (depth - z, <= 0 behind the surface; sub-texel depth as on the ray path);
// carved outside a silhouette, free outside an image (--outside pass); the
// object is where the largest map field is <= 0 (Kautz-Seidel 2001, sec.
// 4.1: the intersection of the maps' half-spaces), with --robust K where the
// (K + 1)-th largest is (at least N - K maps accept). Visual hulls (sec. 5)
// test the silhouettes alone. The field is evaluated in double precision on
// a voxel grid, clamped to a narrow band of kBandVoxels, and meshed by
// OpenVDB's volumeToMesh (docs/decisions/mesh-extraction.md); each vertex is
// then moved onto the field's zero set by bisection of the inside test along
// its normal, so the surface is sub-voxel where the field is a step (a
// silhouette, a hull).
//
// Vertex colours: the renderer's view-dependent texturing (sec. 4.2 weights,
// ibr/view_weights.h) for a view looking straight at the vertex (along its
// inward normal), each map weighted by how much of its bilinear footprint saw
// the vertex (depth within a tolerance), as the resolve pass does.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/mesh.h"
#include "ibr/depth_object.h"
#include "ibr/image_maps.h"

namespace ibr {

enum class MeshColouring {
  kViewDependent,  // the renderer's VDT with visibility (default)
  kNone,           // no colours written
};
inline constexpr core::EnumName<MeshColouring> kMeshColouringNames[] = {
    {MeshColouring::kViewDependent, "vdt"},
    {MeshColouring::kNone, "none"},
};
static_assert(core::EnumNamesUnique(kMeshColouringNames));
MeshColouring MeshColouringFromName(const std::string& name);  // "vdt", "none"

struct MeshExportOptions {
  Method method = Method::kDepthObject;
  // Voxels along the largest edge of the dataset's bounds: the voxel is that
  // edge / resolution, the size `ibr bench export` gives Open3D's TSDF. 256
  // puts a voxel on each texel of 256 px cube maps.
  int resolution = 256;
  // The voxel in scene units; 0 = the box's largest edge / resolution (the
  // dataset-level calls set it from the unpadded bounds).
  double voxel_size = 0;
  int robust_k = 0;  // maps that may reject a point that is kept (0 = exact intersection)
  // Points outside a map's image: nullopt = ChooseOutsidePolicy, as `ibr render`.
  std::optional<OutsidePolicy> outside;
  InvalidDepthPolicy invalid_depth = InvalidDepthPolicy::kEmpty;
  // Depth objects: bilinear depth inside the silhouette (the ray path's
  // default; docs/decisions/subtexel-depth.md), else the nearest texel's.
  bool subtexel_depth = true;
  float subtexel_edge = 4.0f;  // texel widths, as DepthObjectOptions::subtexel_edge
  // Bisection steps moving each vertex onto the zero set (0 = volumeToMesh's
  // interpolated vertex): 8 narrow a bracket of one or two voxels to 1/128
  // of a voxel, then the field is interpolated linearly within it.
  int refine_steps = 8;
  MeshColouring colouring = MeshColouring::kViewDependent;
  void Check() const;
};

// Narrow band of the clamped field, in voxels each side of the surface:
// volumeToMesh only needs the sign change and one voxel of slope.
inline constexpr double kBandVoxels = 3.0;

// A triangle mesh (or a point cloud: no indices) with per-vertex colours.
struct ColouredMesh {
  core::TriangleMesh mesh;           // world frame; outward normals, CCW seen from outside
  std::vector<glm::u8vec3> colours;  // one per vertex, or empty
};

struct MeshExportStats {
  glm::ivec3 grid{0};                                             // samples per axis
  double voxel_size = 0;                                          // scene units
  double field_s = 0, extract_s = 0, refine_s = 0, colour_s = 0;  // wall time of each stage
  int64_t refined = 0;  // vertices bracketed and moved onto the zero set
  std::string outside;  // the outside policy's reason (ChooseOutsidePolicy) or "given"
  double total_s() const { return field_s + extract_s + refine_s + colour_s; }
};

// Bytes the extraction needs (dense field, OpenVDB grid, mesh) for
// core::CheckMemory.
uint64_t EstimateMeshExportBytes(const MapSet& maps, const MeshExportOptions& options);

// The field ExtractObjectMesh meshes (<= 0 inside, clamped to +-band scene
// units), for other extractors to be measured on (bench/export_bench.h).
// `maps` must outlive it.
std::function<double(const glm::dvec3&)> MakeObjectField(const MapSet& maps,
                                                         const MeshExportOptions& options,
                                                         double band);

// The object's surface: closed (every edge shared by two triangles),
// oriented outwards. InputError when the maps lack what the method needs
// (depth objects: depth in every map) or the object is empty.
ColouredMesh ExtractObjectMesh(const MapSet& maps, const MeshExportOptions& options,
                               MeshExportStats* stats = nullptr);

// Every valid depth texel of every map as a world point with the map's
// colour and a normal from the depth neighbours (facing the map), kept where
// the object field (the other maps) accepts it within `tolerance_texels`
// texel widths: points another map carves are dropped (the fusion).
// InputError when no map has depth.
ColouredMesh FusedPointCloud(const MapSet& maps, const MeshExportOptions& options,
                             double tolerance_texels = 2.0);

// The commands' single calls: read DATASET, extract, write OUT (.ply, or .obj
// with a .mtl beside it for meshes) atomically. Checks OUT's extension and
// folder before any work.
struct ExportSummary {
  int views = 0;
  int64_t vertices = 0, triangles = 0;
  double volume = 0;  // signed volume of the mesh (scene units cubed; 0 for points)
  MeshExportStats stats;
};
ExportSummary ExportDatasetMesh(const std::filesystem::path& dataset,
                                const std::filesystem::path& out, MeshExportOptions options);
ExportSummary ExportDatasetPoints(const std::filesystem::path& dataset,
                                  const std::filesystem::path& out);

// The voxel size for `resolution` over a dataset's bounds (largest edge / N).
double DatasetVoxelSize(const glm::dvec3& bounds_extent, int resolution);

}  // namespace ibr
