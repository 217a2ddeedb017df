#include "bench/tradeoff.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>

#include "core/check.h"

namespace bench {
namespace {

// Positive values of `values` span more than a decade.
bool SpansADecade(const std::vector<double>& values) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (double v : values) {
    if (std::isfinite(v) && v > 0) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  return hi > 0 && hi > 10 * lo;
}

}  // namespace

std::vector<bool> ParetoFront(const std::vector<TradeoffRow>& rows, bool count_truth) {
  std::vector<bool> front(rows.size(), false);
  auto finite = [&](const TradeoffRow& r) {
    return std::isfinite(r.ms) && std::isfinite(r.error) && (count_truth || !r.truth);
  };
  for (size_t i = 0; i < rows.size(); ++i) {
    if (!finite(rows[i])) continue;
    bool dominated = false;
    for (size_t j = 0; j < rows.size() && !dominated; ++j) {
      const TradeoffRow &a = rows[j], &b = rows[i];
      dominated = j != i && finite(a) && a.panel == b.panel && a.ms <= b.ms && a.error <= b.error &&
                  (a.ms < b.ms || a.error < b.error);
    }
    front[i] = !dominated;
  }
  return front;
}

Table TradeoffTable(const TradeoffFamily& family) {
  Table t(
      {"panel", "method", "knob", "ms_per_frame", "error", "truth", "pareto", "pareto_methods"});
  const std::vector<bool> front = ParetoFront(family.rows),
                          methods = ParetoFront(family.rows, false);
  for (size_t i = 0; i < family.rows.size(); ++i) {
    const TradeoffRow& r = family.rows[i];
    IBR_CHECK(r.panel.find(',') == std::string::npos && r.method.find(',') == std::string::npos &&
              r.knob.find(',') == std::string::npos);
    // Enough digits that the CSV reproduces the front (the test recomputes it).
    t.AddRow({r.panel, r.method, r.knob, fmt::format("{:.6g}", r.ms),
              fmt::format("{:.6g}", r.error), r.truth ? "1" : "0", front[i] ? "1" : "0",
              methods[i] ? "1" : "0"});
  }
  return t;
}

void PlotTradeoff(const TradeoffFamily& family, const std::filesystem::path& png) {
  Table table = TradeoffTable(family);
  std::vector<double> ms, error;
  std::vector<std::string> panels;
  for (const TradeoffRow& r : family.rows) {
    ms.push_back(r.ms);
    error.push_back(r.error);
    if (std::find(panels.begin(), panels.end(), r.panel) == panels.end()) panels.push_back(r.panel);
  }
  const bool log_x = SpansADecade(ms), log_y = SpansADecade(error);
  std::string title = family.title + ": error vs time";
  if (log_y) {
    // The truth's error of 0 has no place on a log axis: drawn at a floor.
    double floor = std::numeric_limits<double>::infinity();
    for (double e : error) {
      if (std::isfinite(e) && e > 0) floor = std::min(floor, 0.5 * e);
    }
    bool any_zero = false;
    Table drawn(table.columns());
    const int ei = table.Column("error");
    for (auto row : table.rows()) {
      if (CellNumber(row[ei]) == 0) {
        row[ei] = fmt::format("{:.6g}", floor);
        any_zero = true;
      }
      drawn.AddRow(row);
    }
    table = std::move(drawn);
    if (any_zero) title += fmt::format("; error 0 drawn at {:.3g}", floor);
  }
  if (std::any_of(family.rows.begin(), family.rows.end(),
                  [](const TradeoffRow& r) { return r.truth; }))
    title += "; circled: the methods' front, the truth aside";
  const int columns = panels.size() <= 1 ? 1 : (panels.size() <= 4 ? 2 : 3);
  const int rows = (static_cast<int>(panels.size()) + columns - 1) / columns;
  PlotPng(table,
          {.title = title,
           .x_column = "ms_per_frame",
           .y_column = "error",
           .series_column = "method",
           .x_label = "ms per frame (median)",
           .y_label = family.error_label,
           .log_x = log_x,
           .log_y = log_y,
           .width_px = columns == 1 ? 1000 : 560 * columns,
           .height_px = columns == 1 ? 600 : 60 + 500 * rows,
           .panel_column = "panel",
           .panel_columns = columns,
           .order_column = "knob",
           .highlight_column = "pareto_methods"},
          png);
}

TradeoffFamily DisplacementTradeoff(const Table& t) {
  TradeoffFamily f{"displacement",
                   "Displacement by slicing (Kautz-Seidel 2001, sec. 3)",
                   "p95 depth error (height texels)",
                   "slices",
                   {}};
  const int family = t.Column("family"), slices = t.Column("slices"),
            elevation = t.Column("elevation_deg"), size = t.Column("size_px"),
            ms = t.Column("ms_per_frame"), error = t.Column("p95_depth_error_texels"),
            truth_ms = t.Column("truth_ms_per_frame");
  std::map<std::string, double> truth;  // panel -> the truth's time (one value per panel)
  for (const auto& r : t.rows()) {
    const std::string panel = fmt::format("elevation {} deg / {} px", r[elevation], r[size]);
    f.rows.push_back(
        {panel, "slices " + r[family], r[slices], CellNumber(r[ms]), CellNumber(r[error])});
    truth.emplace(panel, CellNumber(r[truth_ms]));
  }
  std::vector<std::string> panels;
  for (const TradeoffRow& r : f.rows) {
    if (std::find(panels.begin(), panels.end(), r.panel) == panels.end()) panels.push_back(r.panel);
  }
  for (const std::string& panel : panels)
    f.rows.push_back({panel, "tessellated (truth)", "", truth[panel], 0.0, true});
  return f;
}

TradeoffFamily NcsTradeoff(const Table& t) {
  TradeoffFamily f{"ncs",
                   "NCS, relief mapping, POM (Chen-Chang)",
                   "silhouette error 1 - IoU",
                   "linear-search steps",
                   {}};
  const int method = t.Column("method"), view = t.Column("view"), tiling = t.Column("tiling"),
            steps = t.Column("steps"), c = t.Column("c"), ms = t.Column("ms_per_frame"),
            iou = t.Column("silhouette_iou");
  for (const auto& r : t.rows()) {
    const std::string name = r[c].empty() ? r[method] : r[method] + " c=" + r[c];
    f.rows.push_back({fmt::format("{} view / tiling {}", r[view], r[tiling]), name, r[steps],
                      CellNumber(r[ms]), 1.0 - CellNumber(r[iou]), r[method] == "tessellated"});
  }
  return f;
}

namespace {

// The depth-object rows with `error` from one column (`one_minus`: 1 - it).
TradeoffFamily DepthObjectRows(const Table& t, TradeoffFamily f, const std::string& column,
                               bool one_minus) {
  const int object = t.Column("object"), method = t.Column("method"), slices = t.Column("slices"),
            size = t.Column("size"), ms = t.Column("ms_per_frame"), error = t.Column(column);
  for (const auto& r : t.rows()) {
    std::string name = r[method], knob = r[slices];
    // A peer names its resolution after a colon ("open3d tsdf:128"): that is its knob.
    const size_t colon = name.rfind(':');
    if (colon != std::string::npos && std::isfinite(CellNumber(name.substr(colon + 1)))) {
      knob = name.substr(colon + 1);
      name = name.substr(0, colon);
    }
    const double e = CellNumber(r[error]);
    f.rows.push_back({fmt::format("{} / {} px", r[object], r[size]), name, knob, CellNumber(r[ms]),
                      one_minus ? 1.0 - e : e});
  }
  return f;
}

}  // namespace

TradeoffFamily DepthObjectTradeoff(const Table& t) {
  return DepthObjectRows(t,
                         {"depth_object",
                          "Depth objects and peers (Kautz-Seidel 2001, sec. 4)",
                          "p95 depth error (cube edges)",
                          "slices (peers: resolution)",
                          {}},
                         "p95_depth_error", false);
}

TradeoffFamily VolumeTradeoff(const Table& t) {
  TradeoffFamily f{"volume",
                   "Volume displacement (Correa, Silver, Chen 2006)",
                   "p95 colour error against the finest setting (1/255)",
                   "sampling distance (voxels) or map size (texels per axis)",
                   {}};
  const int sweep = t.Column("sweep"), volume = t.Column("volume"),
            sampling = t.Column("sampling_voxels"), map_size = t.Column("map_size"),
            size = t.Column("size_px"), ms = t.Column("ms_per_frame"),
            error = t.Column("p95_color_error_vs_finest");
  for (const auto& r : t.rows()) {
    const std::string panel = fmt::format("{} / {} px", r[volume], r[size]);
    if (r[sweep] == "sampling") {
      f.rows.push_back({panel, "sampling distance (map 64^3)", r[sampling], CellNumber(r[ms]),
                        CellNumber(r[error])});
    } else if (r[sweep] == "map_size") {
      f.rows.push_back({panel, "map size (sampling 1 voxel)", r[map_size], CellNumber(r[ms]),
                        CellNumber(r[error])});
    } else if (r[sweep] == "finest") {
      f.rows.push_back({panel,
                        fmt::format("finest (map {}^3 at {} voxel)", r[map_size], r[sampling]), "",
                        CellNumber(r[ms]), 0.0, true});
    }
  }
  return f;
}

namespace {

// The deformation rows with `error` from one column (`one_minus`: 1 - it).
TradeoffFamily DeformRows(const Table& t, TradeoffFamily f, const std::string& column,
                          bool one_minus) {
  const int mesh = t.Column("mesh"), size = t.Column("size_px"), knob = t.Column("knob"),
            value = t.Column("value"), mode = t.Column("mode"), resolution = t.Column("resolution"),
            step = t.Column("step_voxels"), ms = t.Column("ms_per_frame"), error = t.Column(column);
  for (const auto& r : t.rows()) {
    // What stays fixed along the line is in the method's name.
    const std::string method =
        r[knob] == "resolution"
            ? fmt::format("field resolution ({} step {} voxels)", r[mode], r[step])
            : fmt::format("{} step (field {})", r[mode], r[resolution]);
    const double e = CellNumber(r[error]);
    f.rows.push_back({fmt::format("{} knife cut / {} px", r[mesh], r[size]), method, r[value],
                      CellNumber(r[ms]), one_minus ? 1.0 - e : e});
  }
  return f;
}

}  // namespace

TradeoffFamily DeformTradeoff(const Table& t) {
  return DeformRows(t,
                    {"deform",
                     "Deformation and cut shaders (Correa, Silver, Chen 2007)",
                     "p95 depth error against the double sphere tracer (mesh sizes)",
                     "field resolution (samples per axis) or step (voxels)",
                     {}},
                    "p95_depth_error", false);
}

TradeoffFamily DeformSilhouetteTradeoff(const Table& t) {
  return DeformRows(t,
                    {"deform_silhouette",
                     "Deformation and cut shaders: silhouettes (Correa, Silver, Chen 2007)",
                     "silhouette error 1 - IoU against the double sphere tracer",
                     "field resolution (samples per axis) or step (voxels)",
                     {}},
                    "silhouette_iou", true);
}

TradeoffFamily DepthObjectSilhouetteTradeoff(const Table& t) {
  return DepthObjectRows(t,
                         {"depth_object_silhouette",
                          "Depth objects and peers: silhouettes (Kautz-Seidel 2001, sec. 4)",
                          "silhouette error 1 - mean IoU",
                          "slices (peers: resolution)",
                          {}},
                         "iou_mean", true);
}

}  // namespace bench
