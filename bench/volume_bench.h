// `ibr bench volume`: what discontinuous displacement of volumes costs
// (Correa, Silver, Chen 2006, Tables 1-2 analogues) on this machine, with the
// VTK GPU ray caster as the peer in the same run (bench/vtk_volume_peer.py).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"

namespace bench {

struct VolumeBenchOptions {
  std::filesystem::path csv;          // required: the table as CSV
  std::filesystem::path out;          // optional directory: plots (PNG) and the peer's TF files
  std::filesystem::path shared_data;  // ../shared/data (the three shared volumes)
  int size = 512;                     // image size, pixels (Table 1: 512)
  bool quick = false;                 // a small sweep for smoke runs (128 px, fewer rows)
  bool peer = true;                   // run the VTK peer (needs xvfb-run and python3-vtk9)
  void Check() const;
};

// The columns of the bench's table (VolumeBenchColumns): sweep, volume,
// variant, sampling_voxels, map_size, map_bits, bytes_per_map (the map's
// (D, alpha) texture as uploaded), size_px, slices, ms_per_frame, area_Mpx,
// ns_per_fragment, fill_fraction, map_coverage (share of the slice area the
// displaced shader draws), ratio_to_plain, vtk_ms, vtk_min_ms,
// vtk_resample_ms (the "vtk prewarped" peer's CPU warp), vtk_warp_p95_error
// (its warped volume against core::Displace, 1/255), p95 colour errors
// against the finest setting and against the 32-bit map (1/255).
std::vector<std::string> VolumeBenchColumns();

// Needs a current GL context. Prints the table and the goals, writes the CSV,
// the goals beside it (VolumeGoalsPath) and plots, and returns the table.
Table RunVolumeBench(const VolumeBenchOptions& options);

// Issue 35's goals for displaced volumes from the bench's table: quantity,
// goal, measured (per volume), met (yes / no / "-" for stated figures / n/a
// when not measured), note. The eq. 6+7 frame over the displaced floor
// (<= 2), unsplit over plain per fragment (<= 2.5), displaced over plain
// per frame at the map's coverage, ours over VTK prewarped (<= 1), VTK's
// resample time.
Table VolumeGoalsTable(const Table& volume);
// CSV.csv -> CSV_goals.csv beside it.
inline std::filesystem::path VolumeGoalsPath(const std::filesystem::path& csv) {
  return csv.parent_path() / (csv.stem().string() + "_goals.csv");
}

}  // namespace bench
