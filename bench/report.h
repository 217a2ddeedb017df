// Shared benchmark reporting: a table printed to the terminal and written as
// CSV, PNG plots drawn by gnuplot (a Debian tool; never drawn by hand), and
// contact sheets of images. Every benchmark (`ibr bench ...`) uses these.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/image.h"

namespace bench {

// A table of rows; every value is kept as text exactly as printed.
class Table {
 public:
  explicit Table(std::vector<std::string> columns);
  // Adds a row; its size must equal the column count.
  void AddRow(std::vector<std::string> values);
  const std::vector<std::string>& columns() const { return columns_; }
  const std::vector<std::vector<std::string>>& rows() const { return rows_; }
  // Column index by name (CHECK-fails for an unknown name).
  int Column(const std::string& name) const;
  bool HasColumn(const std::string& name) const;
  // Aligned text for the terminal.
  std::string Format() const;
  // Atomic CSV write (header + rows).
  void WriteCsv(const std::filesystem::path& path) const;

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<std::string>> rows_;
};

// The rows of `t` that `keep` accepts, same columns.
Table Filtered(const Table& t, const std::function<bool(const std::vector<std::string>&)>& keep);

// "1.234" with `digits` decimals; "nan"/"inf" spelled out.
std::string Num(double value, int digits = 3);
// A cell's number: the whole text parsed as a double, NaN if it is not one
// (empty, "n/a", "12 ms").
double CellNumber(const std::string& text);

// Least-squares line y = slope x + intercept and its coefficient of
// determination. Fewer than two points or no spread in x: all zero; no
// spread in y (but in x): r2 = 1.
struct LineFit {
  double slope = 0.0, intercept = 0.0, r2 = 0.0;
};
LineFit FitLine(const std::vector<double>& x, const std::vector<double>& y);

struct PlotOptions {
  std::string title;
  std::string x_column;       // e.g. "ms_per_frame"
  std::string y_column;       // e.g. "p95_depth_error_texels"
  std::string series_column;  // one line per distinct value, e.g. "family"
  std::string x_label;
  std::string y_label;
  bool log_x = false;
  bool log_y = false;
  int width_px = 900;  // the whole image (all panels)
  int height_px = 600;
  // One panel per distinct value of this column (gnuplot multiplot, in order
  // of first appearance, each titled by its value); empty = one panel. A
  // series keeps its colour in every panel.
  std::string panel_column;
  int panel_columns = 2;  // panels per row
  // The order a series' points are joined in: this column's numeric value
  // (the knob that trades accuracy for time: slices, steps, resolution).
  // Rows whose value is empty or not a number are drawn as lone points, not
  // joined. Empty = joined in x order (one point per x is assumed).
  std::string order_column;
  // Rows whose value here is "1" are drawn again, per panel, as one overlay
  // series `highlight_title` (open circles joined in x order, dashed): the
  // Pareto front.
  std::string highlight_column;
  std::string highlight_title = "Pareto front";
};

// One polyline (or set of lone points) of a plot, as PlotPng draws it.
struct PlotSeries {
  std::string panel;  // "" without panel_column
  std::string name;   // the series value ("Pareto front" for the overlay)
  std::vector<std::pair<double, double>> points;  // (x, y) in the order they are joined
  bool joined = true;                             // false: lone points
  bool highlight = false;                         // the overlay
};

// What PlotPng draws, without drawing it: per panel (first appearance
// order), the series in name order (joined part, then lone points), then
// the overlay. Points with a non-finite coordinate, or <= 0 on a log axis,
// are left out.
std::vector<PlotSeries> PlotSeriesOf(const Table& table, const PlotOptions& options);

// Scatter-with-lines plot of `table` (PlotSeriesOf) into a PNG through
// gnuplot. Throws core::InputError if no point is finite or gnuplot is
// missing or fails.
void PlotPng(const Table& table, const PlotOptions& options, const std::filesystem::path& png);

}  // namespace bench
