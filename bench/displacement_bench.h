// The displacement scenes (base meshes, height maps, orbit cameras) shared by
// `ibr displace`, `ibr demo` and `ibr bench displacement`, and the benchmark
// itself: slicing family x slice count x view elevation x resolution against
// the tessellated ground truth rendered in the same run (Kautz-Seidel 2001,
// sec. 3.4, measured).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"
#include "core/heightfield.h"
#include "core/image.h"
#include "core/mesh.h"
#include "ibr/displaced_mesh.h"
#include "render/passes/mesh_pass.h"

namespace bench {

// The built-in base meshes and generated height maps: ibr/displaced_mesh.h.
using ibr::DisplacementBaseMesh;
using ibr::DisplacementHeightMap;

struct DisplacementBenchOptions {
  std::filesystem::path csv;  // required: the table as CSV
  std::filesystem::path out;  // optional directory: plot PNG + contact sheet
  bool quick = false;         // a small sweep for CI smoke runs (seconds)
  void Check() const;
};

struct DisplacementBenchResult {
  Table table;
  // Per family at the "needed slices" view: the smallest slice count with p95
  // depth error < 1 texel, and its time / the ground truth's (-1 if none).
  Table summary;
};

// Needs no context (creates one). Prints the tables, writes the CSV (and plot
// + contact sheet into `out`).
DisplacementBenchResult RunDisplacementBench(const DisplacementBenchOptions& options);

}  // namespace bench
