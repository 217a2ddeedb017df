// The cost per map of depth objects (issue 12, item 8), a part of `ibr bench
// depth-object`: one mesh captured by ring rigs of a growing number of maps
// (ring:6 ... ring:256, 256 px maps, in memory), each drawn from one novel
// view (512 px) by the ray path with empty-space skipping (slices auto) and
// by orthogonal slicing (64 slices: its auto count times hundreds of maps
// takes minutes a frame). Per map count: the upload time (renderer + the
// maps' texture arrays, glFinish), the first frame (program, skip grid),
// the median frame after warm-up, ms per map, and IoU / p95 depth error
// against the true mesh. Then, at the largest count, the frame's subset of
// maps (DepthObjectOptions::max_maps: the nearest maps to the view
// direction) swept: its time and its error against the frame from every
// map and against the mesh. Printed, written, plotted; never asserted.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"
#include "capture/synthetic.h"
#include "render/gl/shader_program.h"

namespace bench {

struct MapCountSweepOptions {
  std::vector<int> counts = {6, 24, 64, 128, 256};  // ring maps
  std::vector<int> subsets = {6, 12, 24, 48, 96};   // max_maps at the largest count (and all)
  int map_size = 256;                               // pixels per map
  int view_size = 512;                              // output pixels, square
  int ortho_slices = 64;
  static MapCountSweepOptions Quick();  // ring:6 and ring:24, 64 px maps, 128 px view
};

struct MapCountSweepResult {
  // object, maps, map_size, size, path, slices, upload_ms, first_frame_ms,
  // ms_per_frame, ms_per_map, iou, p95_depth_error (cube edges)
  Table cost;
  // object, maps, max_maps, size, ms_per_frame, iou_vs_all, p95_vs_all,
  // iou_vs_mesh, p95_vs_mesh (depth errors in cube edges)
  Table subset;
};

// Needs a current context. Prints as it goes.
MapCountSweepResult RunMapCountSweep(render::ProgramCache& programs, const std::string& object,
                                     const capture::SceneMesh& scene,
                                     const MapCountSweepOptions& options);

// STEM_maps.csv, STEM_maps_subset.csv; with `out`, maps_cost.png and
// maps_subset_error.png there.
void WriteMapCountSweep(const MapCountSweepResult& result, const std::filesystem::path& stem,
                        const std::filesystem::path& out);

}  // namespace bench
