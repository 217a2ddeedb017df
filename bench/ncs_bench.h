// `ibr bench ncs`: accuracy and cost of NCS (Chen-Chang), relief mapping,
// POM and curved relief mapping (CRM, Oliveira-Policarpo 2005, the paper's
// baseline) against the tessellated ground truth (a vertex per height-map texel,
// core::TessellateDisplaced + render::DrawMesh) rendered in the same run, on
// a displaced torus: method x steps x c x view (including grazing views of
// the torus's inner side, the paper's Figure 2 case) x tiling (the paper's
// Figure 6). Figures are printed and written, never asserted.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"
#include "core/image.h"
#include "render/gl/frame_timer.h"
#include "render/gl/shader_program.h"

namespace bench {

struct NcsBenchOptions {
  int size = 256;  // pixels per side of every frame
  // Texels per side; the ground truth has a vertex per texel (up to
  // max_truth_subdivisions). 512: Chen-Chang's Fig. 6 (512 x 512 height map).
  int height_map_size = 512;
  std::vector<int> steps = {16, 32, 64};  // linear-search steps
  // NCS c: Chen-Chang Fig. 7's sweep (1, 1.1, 1.5, 2, 3, 10) and the paper's
  // choice 2.5 (sec. 5), which the summary and the strip use.
  std::vector<float> step_enlargements = {1.0f, 1.1f, 1.5f, 2.0f, 2.5f, 3.0f, 10.0f};
  std::vector<int> tilings = {1, 2, 4, 8, 16};
  std::vector<std::string> views = {"oblique", "grazing", "edge"};  // see NcsBenchViewNames()
  // Caps the ground truth's subdivisions per base triangle (memory: 64 gives
  // 4096 triangles per base triangle, 9.4M for the torus); the CSV reports
  // the count wanted (a vertex per texel) and the count used.
  int max_truth_subdivisions = 64;
  render::FrameTimerOptions timer{.warmup_frames = 1, .timed_frames = 3};
  void Check() const;
  static NcsBenchOptions Quick();  // CI smoke: one view, two tilings, one setting per method
};

// "oblique" (30 deg above the torus plane), "grazing" (9 deg: the far inner
// side through the hole at a grazing angle), "edge" (4 deg).
std::vector<std::string> NcsBenchViewNames();

struct NcsBenchResult {
  Table table;  // one row per (method, view, tiling, steps, c)
  // Chen-Chang Fig. 7: NCS's early-terminated pixels against c, per view,
  // tiling and step count (the table's rows, pivoted).
  Table fig7;
  // NCS cost relative to relief mapping, to the ground truth and to CRM per
  // view, tiling and step count, from the fastest timed frame (min_ms_per_frame).
  Table summary;
  // Silhouettes at the grazing view and the first tiling, left to right:
  // tessellated truth, NCS, relief mapping, POM, CRM (middle step count, c = 2.5);
  // below each, its coverage against the truth (red: extra, green: missing).
  core::Image8 strip;
  std::string strip_view;
  int strip_tiling = 1;
};

NcsBenchResult RunNcsBench(render::ProgramCache& programs, const NcsBenchOptions& options);

// Writes the CSV to `csv` and plots + strip into `out_dir`.
void WriteNcsBench(const NcsBenchResult& result, const std::filesystem::path& csv,
                   const std::filesystem::path& out_dir);

}  // namespace bench
