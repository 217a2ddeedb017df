// `ibr bench kautz-seidel`: the experiments of Kautz-Seidel 2001 sec. 5-6
// that `ibr bench depth-object` does not run, with the paper's figures
// beside ours as ratios (a GeForce 2 GTS then, llvmpipe here). Printed and
// written, never asserted.
//
//  - Fig. 12, both graphs for depth objects AND visual hulls of the same
//    object and views (the paper: hulls are faster, as a cube rig needs only
//    the three front silhouettes): time against covered pixels at 128
//    slices, and against slice count at 300 x 300;
//  - sec. 6, "the more the slicing polygons are viewed at an angle, the
//    better the frame rate (up to 20 % faster)": a sweep of elevations and
//    azimuths at a fixed frame size and slice count, time and the fragments
//    the slice passes shade relative to the face-on view;
//  - sec. 6, the quality points: the object covering about 150 x 150 pixels
//    at 70 slices (24 fps in the paper) and 400 x 400 at 150 (2.7 fps);
//  - sec. 6, Figs. 1, 17, 18: the 625-polygon donut by orthogonal slicing at
//    15-25 slices (35-41 Hz in the paper), with its error against the
//    tessellated truth (core::CompareToGroundTruth).
// Every renderer and metric is the project's own: ibr::DepthObjectRenderer
// (ibr/depth_object.h), ibr::DisplacedMeshRenderer (ibr/displaced_mesh.h),
// the true-mesh depth and metrics of bench/peer.h.
#pragma once

#include <filesystem>
#include <string>

#include "bench/report.h"
#include "render/gl/frame_timer.h"
#include "render/gl/shader_program.h"

namespace bench {

struct KautzSeidelOptions {
  // The depth object's mesh, a name of ../shared/data/meshes (bunny, cow,
  // spot, teapot) or an analytic shape (cup); the paper's "creature" is not
  // published, Spot is a creature of similar build. Absent meshes fall back
  // to the cup with a message.
  std::string object = "spot";
  int map_size = 256;  // cube-rig maps, pixels (the paper's creature: six orthographic maps)
  bool quick = false;  // CI smoke: the cup, small frames and sweeps (seconds)
  render::FrameTimerOptions timer{.warmup_frames = 1, .timed_frames = 3};
  void Check() const;
};

struct KautzSeidelResult {
  std::string object;  // the object actually used
  // sweep ("coverage" | "slices"), method, size, slices, covered_pixels,
  // ms_per_frame, ms_over_depth_object (same sweep point), source.
  Table fig12;
  // method, elevation_deg, azimuth_deg, size, slices, covered_pixels,
  // active_maps, slice_fragments, ms_per_frame, ms_over_face_on, fragments_over_face_on,
  // paper_best_speedup, source.
  Table angle;
  // The two quality points: target_object_px, size, slices, object_px,
  // covered_pixels, ms_per_frame, fps, paper_fps, ms_over_first,
  // paper_ms_over_first, iou, p95_depth_error (cube edges), source.
  Table points;
  // The donut: slices, size, ms_per_frame, fps, paper_fps_min/max,
  // ms_over_first, paper_ms_over_first_min/max, coverage_iou, mean/p95
  // depth error (height texels), see_through_px, truth_ms, source.
  Table donut;
};

// Needs a current context (the command makes one); ../shared/data for meshes.
KautzSeidelResult RunKautzSeidelExperiments(render::ProgramCache& programs,
                                            const KautzSeidelOptions& options);

// `csv` = the quality points; beside it FILE_fig12.csv, FILE_angle.csv,
// FILE_donut.csv; plots (Fig. 12 analogues, time vs angle) into `out_dir`.
void WriteKautzSeidelExperiments(const KautzSeidelResult& result, const std::filesystem::path& csv,
                                 const std::filesystem::path& out_dir);

}  // namespace bench
