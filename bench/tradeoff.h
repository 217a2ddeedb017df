// What accuracy costs in time, per technique family, read from the benches'
// tables by column name: one row per measured configuration (a method or a
// peer at one setting of the knob that trades accuracy for time, in one
// panel = one object / view and image size), the Pareto front of each panel,
// and the error-vs-time plot `ibr report` draws (bench/report_page.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"

namespace bench {

struct TradeoffRow {
  std::string panel;   // what is compared: "bunny / 256 px", "grazing view / tiling 4"
  std::string method;  // a method or peer; its points are joined along `knob`
  std::string knob;    // the knob's value ("64" slices, "128" voxels); "" = none (a lone point)
  double ms = 0.0;     // time per frame (median), milliseconds
  double error = 0.0;  // lower is better (the family's unit); 0 = the truth itself
  bool truth = false;  // the reference the errors are measured against (error 0 by construction)
};

// Whether each row is on the Pareto front of its panel: no other row of the
// same panel is at most as slow and at most as wrong, and strictly better in
// one. Rows with a non-finite time or error are never on it and dominate
// nothing. Equal rows do not dominate each other (both are on the front).
// Without `count_truth`, truth rows are never on it and dominate nothing:
// the front of the approximations alone (where the truth itself is the
// fastest, as the tessellated mesh is on llvmpipe, the front with it is the
// truth alone and says nothing about the methods).
std::vector<bool> ParetoFront(const std::vector<TradeoffRow>& rows, bool count_truth = true);

// A technique family's rows with what they mean.
struct TradeoffFamily {
  std::string id;           // file names: <id>_tradeoff.csv, <id>_tradeoff.png
  std::string title;        // "Displacement by slicing (Kautz-Seidel 2001, sec. 3)"
  std::string error_label;  // "p95 depth error (height texels)"
  std::string knob_label;   // "slices"
  std::vector<TradeoffRow> rows;
};

// The rows as a table: panel, method, knob, ms_per_frame, error, truth ("1"
// for the reference), pareto ("1" on the front of its panel, else "0") and
// pareto_methods (the same without the truth rows). Names hold no commas (the
// benches' CSV is not quoted): CHECKed.
Table TradeoffTable(const TradeoffFamily& family);

// The family's plot: one panel per `panel` (in first appearance order), every
// method in the same axes, points joined only along the knob, the Pareto
// front of the methods (pareto_methods) circled; an axis is logarithmic where its positive values
// span more than a decade. Errors of 0 (the truth) are drawn at a floor of half the smallest
// positive error on a log axis (said in the title).
void PlotTradeoff(const TradeoffFamily& family, const std::filesystem::path& png);

// The families, from the benches' tables (columns by name):
// `ibr bench displacement`: panel = elevation and size, method = slicing
// family, knob = slices, error = p95 depth error in height texels; the
// tessellated truth (truth_ms_per_frame) as a truth row.
TradeoffFamily DisplacementTradeoff(const Table& table);
// `ibr bench ncs`: panel = view and tiling, method = method (NCS with its c),
// knob = steps, error = 1 - silhouette IoU against the tessellated truth
// (its row is a truth row).
TradeoffFamily NcsTradeoff(const Table& table);
// `ibr bench depth-object`: panel = object and size, method = path (knob =
// slices) or peer ("open3d tsdf:128": method "open3d tsdf", knob 128),
// error = p95 depth error in cube edges.
TradeoffFamily DepthObjectTradeoff(const Table& table);
// The same rows with error = 1 - the mean silhouette IoU over the views.
TradeoffFamily DepthObjectSilhouetteTradeoff(const Table& table);
// `ibr bench volume`: the peeled volume's two accuracy knobs, panel = volume
// and size, method = the knob swept (sampling distance at map 64^3, map size
// at 1 voxel), error = p95 colour error against the finest setting (its row,
// sweep "finest", is the truth).
TradeoffFamily VolumeTradeoff(const Table& table);
// `ibr bench deform`'s accuracy sweep (deform_accuracy.csv): the solid knife
// cut through Spot, panel = mesh and size, method = the knob swept (the
// distance field's resolution at its step policy and step, or one step
// policy's step at its resolution), knob = its value, error = p95 depth
// error in mesh sizes against the double sphere tracer; no truth row (the
// tracer runs on the CPU: its time is not a frame time).
TradeoffFamily DeformTradeoff(const Table& table);
// The same rows with error = 1 - silhouette IoU.
TradeoffFamily DeformSilhouetteTradeoff(const Table& table);

}  // namespace bench
