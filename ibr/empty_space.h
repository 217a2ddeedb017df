// Empty-space skipping for the depth-object / visual-hull ray path: a
// conservative occupancy grid over the box, built once from the maps on the
// CPU, and its chessboard distance transform, which the ray pass reads in
// RaySkip (shaders/cores/ray_core.glsl's skip hook) to jump over space that
// the maps prove empty and march finely only near surfaces.
//
// Proof (per voxel, per map): map i rejects every point p of a voxel when,
// for every texel the voxel can project into, the point lies in front of the
// surface map i saw (camera z < depth; Kautz-Seidel 2001 sec. 4.1: the
// displacement does not reach the ramp) or outside its silhouette (sec. 5).
// With a min-pyramid of each map's acceptance threshold (Tevs et al. 2008's
// maximum mipmaps, here of "the nearest z a texel accepts") this is one
// comparison: max z of the voxel's corners < min threshold over the
// footprint of its projected corners. A voxel is empty when at least k + 1
// of the active maps reject it (robust intersection: a point needs N - k
// accepting maps). The test is padded (one texel around the footprint, a
// small depth tolerance) so float rounding on the GPU never makes a skipped
// point one the fine march would have found inside.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "ibr/image_maps.h"

namespace ibr {

// What the map test of shaders/passes/depth_object_core.glsl decides, as
// far as the grid needs it (the same policies as DepthObjectOptions).
struct SkipGridPolicy {
  bool visual_hull = false;           // silhouettes only (sec. 5)
  bool outside_passes = true;         // points outside a map's image are not constrained by it
  bool invalid_depth_passes = false;  // depth 0 inside the silhouette carves nothing
  int rejections_needed = 1;          // maps that must reject a voxel (robust_k + 1)
};

struct SkipGrid {
  int resolution = 0;  // voxels per box axis
  // Per voxel (x fastest, box coordinates): L-infinity distance in voxels to
  // the nearest voxel that is not proven empty, capped at 255; 0 = maybe
  // occupied. Every voxel within distance - 1 of a voxel is proven empty.
  std::vector<uint8_t> distance;
  int64_t empty_voxels = 0;
  size_t Index(int x, int y, int z) const {
    return (static_cast<size_t>(z) * resolution + y) * resolution + x;
  }
};

// `depth_codes`: one R32F layer per map as uploaded (MapTables::depth:
// < 0 outside the silhouette, 0 invalid, else camera z), `layer_width` x
// `layer_height` texels per layer; `active`: the maps the frame tests.
// `resolution` in 1..255.
SkipGrid BuildSkipGrid(const MapSet& maps, const std::vector<float>& depth_codes, int layer_width,
                       int layer_height, const std::vector<int>& active,
                       const SkipGridPolicy& policy, int resolution);
// The same from each active map's codes made on demand, one map at a time:
// `codes_of(map_index, codes)` fills `codes` with that map's width x height
// codes (rows width apart); no table of every map is needed.
SkipGrid BuildSkipGrid(
    const MapSet& maps,
    const std::function<void(int map_index, std::vector<float>& codes)>& codes_of,
    const std::vector<int>& active, const SkipGridPolicy& policy, int resolution);

// In-place chessboard (L-infinity) distance transform of an occupancy grid
// (input: 0 = maybe occupied, anything else = empty), capped at 255: two
// raster passes over the 26-neighbourhood, exact for this metric.
void ChessboardDistance(int resolution, std::vector<uint8_t>& grid);

}  // namespace ibr
