// The papers' reported figures beside ours, as ratios (the papers ran on
// 2001-2008 GPUs, we run on whatever this machine has): each table has the
// columns quantity, paper, ours, note; the paper's numbers are quoted from
// the texts in ../shared/papers/ with their section, figure or table, ours
// are computed from the benches' tables (columns read by name).
#pragma once

#include "bench/report.h"

namespace bench {

// Kautz-Seidel 2001, sec. 6 (Figs. 17-18: the donut at 15 and 20 slices)
// and sec. 3.3 (screen-space slicing costs more), from `ibr bench
// displacement`'s table.
Table KautzSeidelSlicingTable(const Table& displacement);

// Kautz-Seidel 2001, sec. 6 (the creature at ~150x150 px / 70 slices and
// ~400x400 px / 150 slices; Fig. 12), from `ibr bench depth-object`'s
// Fig. 12 analogues (time vs covered pixels at 128 slices, vs slices).
Table KautzSeidelDepthObjectTable(const Table& fig_coverage, const Table& fig_slices);

// Chen-Chang, Table 1 and sec. 4 (NCS vs CRM), Fig. 6 (vs the tessellated
// truth over tilings), Fig. 7 (early termination against c), from `ibr
// bench ncs`'s table. The CRM baseline is the method named "crm" when the
// table has it, relief mapping otherwise (said in the note).
Table ChenChangTable(const Table& ncs);

// Correa, Silver, Chen 2006, Tables 1-2 and sec. 8, from `ibr bench
// volume`'s table.
Table Correa2006Table(const Table& volume);

// Correa, Silver, Chen 2007, Table 1 (weighted average time of continuous
// deformations, cuts without and with empty-space skipping): the paper's
// four models, then ours from `ibr bench deform`'s summary, then ours with
// the paper's shader (no skipping by the object's distance; its paper_*
// modes, over paper_continuous). Columns: source, model, triangles,
// continuous_ms, cut_over_continuous, cut_skip_over_continuous,
// cut_csg_over_continuous.
Table Correa2007Table(const Table& deform_summary, const Table& deform_frames);

// The goals of `ibr bench deform`'s workloads (issue 35) beside the paper's
// figures (Correa, Silver, Chen 2007, Table 1 and sec. 6.2): the wedge's cut
// with skipping over the same D without its alpha, the share of the cut's
// extra samples the skip removes, agreement with the double reference, the
// forward-mesh peer at equal p95 depth error, and the spread across
// tessellations. Columns: quantity, goal, paper, ours, met, note.
struct DeformWedgeFigures;
struct DeformForwardFigures;
struct DeformSpreadFigures;
Table Correa2007GoalsTable(const DeformWedgeFigures& wedge, const DeformForwardFigures& forward,
                           const DeformSpreadFigures& spread);

// Linear interpolation of y at x over (x, y) points sorted by x, in log-log
// space when `log` (both positive); outside the range, the nearest
// segment's line is extended. Needs at least two points with distinct x.
double Interpolate(std::vector<std::pair<double, double>> points, double x, bool log);

}  // namespace bench
