// `ibr bench volume`: what discontinuous displacement of volumes costs
// (Correa, Silver, Chen 2006, Tables 1-2 analogues) on this machine, with the
// VTK GPU ray caster as the peer in the same run (bench/vtk_volume_peer.py).
#pragma once

#include <filesystem>

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

// Needs a current GL context. Prints the table, writes CSV (and plots), and
// returns the table: sweep, volume, variant, sampling_voxels, map_size,
// size_px, slices, ms_per_frame, area_Mpx, fill_fraction, ratio_to_plain,
// vtk_ms, vtk_min_ms.
Table RunVolumeBench(const VolumeBenchOptions& options);

}  // namespace bench
