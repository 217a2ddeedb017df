// `ibr bench depth-object`: what accuracy costs in time for image-based depth
// objects (Kautz-Seidel 2001, sec. 4), printed and written, never asserted.
//
// Sweep: path (orthogonal, screen slices; the ray path with and without
// empty-space skipping) x slices x output size x object (bunny, cow, spot,
// teapot from ../shared/data/meshes, the analytic cup and mug), each
// object captured with the paper's cube rig (six orthographic maps, 256 px).
// Per configuration: median frame time after warm-up (glFinish, wall clock;
// render::TimeFrames), the fraction of the fill rate calibrated in the same
// run (render::MeasureFillRate) that the slice passes reach, and against
// the true mesh rendered from the same novel views (bench/peer.h metrics):
// silhouette IoU, mean and 95th-percentile depth error in cube-edge units,
// colour PSNR on the object pixels for textured objects (Spot).
// The Open3D peer (bench/peer.h) runs in the same sweep on a perspective
// capture of the bunny (sphere:6, Open3D has no orthographic camera) with
// time to first image and the same metrics.
// Also the paper's Figure 12 analogues on the bunny: time against pixel
// coverage at 128 slices, and against slice count at 300x300.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/map_count_bench.h"
#include "bench/report.h"

namespace bench {

struct DepthObjectBenchOptions {
  std::filesystem::path
      csv;  // required: the sweep table; fig12 tables go beside it (*_fig12_*.csv)
  std::filesystem::path out;  // optional: PNG plots (error vs time, Fig. 12 analogues)
  // Small sweep (smoke test, ~30 s): the cup only, two slice counts, 128 px,
  // TSDF at 64 for the peer.
  bool quick = false;
  // Restrict the full sweep (empty = all): object names (cup, mug, bunny,
  // cow, spot, teapot), output sizes in pixels, slice counts. The Fig. 12
  // analogues and the peer run when the bunny is in the sweep.
  std::vector<std::string> objects;
  std::vector<int> sizes;
  std::vector<int> slices;
  // The Fig. 12 analogues (bunny; minutes of the full run).
  bool figures = true;
  // The cost per map (bench/map_count_bench.h) on the sweep's first object:
  // ring captures of these map counts (empty = the sweep's defaults; quick:
  // MapCountSweepOptions::Quick); off with maps_sweep = false.
  bool maps_sweep = true;
  std::vector<int> map_counts;
  void Check() const;
};

struct DepthObjectBenchResult {
  Table table;     // the sweep (object, method, slices, size, ms_per_frame, ..., p95_depth_error)
  Table accuracy;  // every path at slices auto (the accuracy check)
  Table fig_coverage;        // Fig. 12 analogue: family, slices, size, covered_pixels, ms_per_frame
  Table fig_slices;          // Fig. 12 analogue: family, slices, size, ms_per_frame
  Table first_image;         // cold / warm time to first image per path, and the TSDF peer's
  MapCountSweepResult maps;  // cost per map, the nearest-maps subset's error
  // Where the default path's time goes: per object at the largest size, the
  // ray path at its defaults against variants with one part taken away
  // (object, size, auto_steps, variant, ms_per_frame, ratio_to_default)
  Table profile;
  // Issue 36, item 3: the default path against the TSDF peer at the largest
  // size: still frame (goal: ratio <= 1 at a better p95) and time to first
  // image cold and warm (goal: ratio <= 0.1); object, size, measure,
  // depth_object_ms, peer, peer_ms, ratio, goal_ratio, depth_object_p95,
  // peer_p95, goal_met
  Table peer_goals;
};

// Time to first image in a fresh process (issue 12, item 4): `ibr bench
// first-image` creates its context and reads a cube-rig dataset (neither
// timed), then times the map upload (DepthObjectRenderer) and the program
// builds + first frame with readback (RenderFrame) from the sweep's first
// novel view. RunDepthObjectBench spawns it with a temporary cache folder
// (ibr's program binaries and Mesa's shader cache both in it): empty = cold,
// filled by the previous run = warm.
struct FirstImageOptions {
  std::filesystem::path dataset;  // a cube-rig dataset directory
  std::string slicing = "ray";    // orthogonal | screen | ray
  int skip_grid = 0;              // DepthObjectOptions::skip_grid (0: none)
  bool subtexel = false;          // DepthObjectOptions::subtexel_depth
  int size = 512;                 // output pixels a side
  void Check() const;
};

struct FirstImageTimes {
  double upload_ms = 0;        // DepthObjectRenderer construction
  double first_frame_ms = 0;   // the first RenderFrame: program builds, draw, readback
  double second_frame_ms = 0;  // the same frame again (no builds): what the first's rest costs
  int programs = 0;            // programs the first image needed
  int programs_loaded = 0;     // of them, loaded from binaries of an earlier run
  double total_ms() const { return upload_ms + first_frame_ms; }
};

// In this process (makes its own context).
FirstImageTimes MeasureFirstImage(const FirstImageOptions& options);
// The one stdout line `ibr bench first-image` prints and the bench parses.
std::string FormatFirstImageLine(const FirstImageTimes& t);

// Needs ../shared/data for the meshes (the cup is analytic); objects whose
// mesh is absent are skipped with a message. Creates its own GL context.
// Prints and writes the tables (and plots), and returns them.
DepthObjectBenchResult RunDepthObjectBench(const DepthObjectBenchOptions& options);

}  // namespace bench
