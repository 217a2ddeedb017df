#include "bench/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"
#include "core/image_io.h"

namespace bench {
namespace fs = std::filesystem;

LineFit FitLine(const std::vector<double>& x, const std::vector<double>& y) {
  LineFit fit;
  const size_t n = std::min(x.size(), y.size());
  if (n < 2) return fit;
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (!(sxx > 0)) return fit;
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  fit.r2 = syy > 0 ? sxy * sxy / (sxx * syy) : 1.0;
  return fit;
}

Table::Table(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void Table::AddRow(std::vector<std::string> values) {
  IBR_CHECK_EQ(values.size(), columns_.size());
  rows_.push_back(std::move(values));
}

bool Table::HasColumn(const std::string& name) const {
  return std::find(columns_.begin(), columns_.end(), name) != columns_.end();
}

int Table::Column(const std::string& name) const {
  auto it = std::find(columns_.begin(), columns_.end(), name);
  IBR_CHECK(it != columns_.end());
  return static_cast<int>(it - columns_.begin());
}

std::string Table::Format() const {
  std::vector<size_t> width(columns_.size());
  for (size_t c = 0; c < columns_.size(); ++c) {
    width[c] = columns_[c].size();
    for (const auto& r : rows_) width[c] = std::max(width[c], r[c].size());
  }
  std::string out;
  auto line = [&](const std::vector<std::string>& v) {
    for (size_t c = 0; c < v.size(); ++c)
      out += fmt::format("{:>{}}{}", v[c], width[c], c + 1 < v.size() ? "  " : "\n");
  };
  line(columns_);
  for (const auto& r : rows_) line(r);
  return out;
}

void Table::WriteCsv(const fs::path& path) const {
  core::AtomicWriteStream(path, [&](std::ostream& out) {
    // RFC 4180: a cell holding a comma, a quote or a line break is quoted,
    // its quotes doubled ("default (ray, skip 64, ...)" is one cell).
    auto cell = [&](const std::string& v) {
      if (v.find_first_of(",\"\r\n") == std::string::npos) {
        out << v;
        return;
      }
      out << '"';
      for (char ch : v) out << (ch == '"' ? "\"\"" : std::string(1, ch));
      out << '"';
    };
    auto line = [&](const std::vector<std::string>& v) {
      for (size_t c = 0; c < v.size(); ++c) {
        cell(v[c]);
        out << (c + 1 < v.size() ? "," : "\n");
      }
    };
    line(columns_);
    for (const auto& r : rows_) line(r);
  });
}

std::string Num(double value, int digits) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return fmt::format("{:.{}f}", value, digits);
}

Table Filtered(const Table& t, const std::function<bool(const std::vector<std::string>&)>& keep) {
  Table out(t.columns());
  for (const auto& r : t.rows()) {
    if (keep(r)) out.AddRow(r);
  }
  return out;
}

double CellNumber(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' ? v : std::nan("");
}

std::vector<PlotSeries> PlotSeriesOf(const Table& table, const PlotOptions& options) {
  const int xi = table.Column(options.x_column), yi = table.Column(options.y_column);
  const int si = options.series_column.empty() ? -1 : table.Column(options.series_column);
  const int pi = options.panel_column.empty() ? -1 : table.Column(options.panel_column);
  const int oi = options.order_column.empty() ? -1 : table.Column(options.order_column);
  const int hi = options.highlight_column.empty() ? -1 : table.Column(options.highlight_column);
  struct Point {
    double order, x, y;
  };
  std::vector<std::string> panels;  // first appearance order
  // panel -> series -> (knob-ordered points, lone points); panel -> overlay
  std::map<std::string, std::map<std::string, std::pair<std::vector<Point>, std::vector<Point>>>>
      series;
  std::map<std::string, std::vector<Point>> overlay;
  for (const auto& r : table.rows()) {
    const double x = CellNumber(r[xi]), y = CellNumber(r[yi]);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    if ((options.log_x && x <= 0) || (options.log_y && y <= 0)) continue;
    const std::string panel = pi < 0 ? "" : r[pi];
    if (std::find(panels.begin(), panels.end(), panel) == panels.end()) panels.push_back(panel);
    const double order = oi < 0 ? x : CellNumber(r[oi]);
    auto& [ordered, lone] = series[panel][si < 0 ? options.y_column : r[si]];
    (std::isfinite(order) ? ordered : lone).push_back({order, x, y});
    if (hi >= 0 && r[hi] == "1") overlay[panel].push_back({x, x, y});
  }
  auto by_order = [](const Point& a, const Point& b) {
    return std::tie(a.order, a.x, a.y) < std::tie(b.order, b.x, b.y);
  };
  auto xy = [](const std::vector<Point>& points) {
    std::vector<std::pair<double, double>> out;
    for (const Point& p : points) out.emplace_back(p.x, p.y);
    return out;
  };
  std::vector<PlotSeries> out;
  for (const std::string& panel : panels) {
    for (auto& [name, parts] : series[panel]) {
      auto& [ordered, lone] = parts;
      std::stable_sort(ordered.begin(), ordered.end(), by_order);
      if (!ordered.empty()) out.push_back({panel, name, xy(ordered), true, false});
      if (!lone.empty()) out.push_back({panel, name, xy(lone), false, false});
    }
    auto it = overlay.find(panel);
    if (it != overlay.end()) {
      std::stable_sort(it->second.begin(), it->second.end(), by_order);
      out.push_back({panel, options.highlight_title, xy(it->second), true, true});
    }
  }
  return out;
}

namespace {

// Quotes a label for a gnuplot single-quoted string.
std::string GnuplotQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// A title as a gnuplot double-quoted string, broken into lines of at most
// `max_chars` at spaces (a long title is otherwise cut at the image's edges;
// a single panel's title is centred over the plot, which the key outside
// leaves about half the image).
std::string GnuplotTitle(const std::string& text, size_t max_chars) {
  std::string out = "\"";
  size_t line = 0;
  std::istringstream words(text);
  std::string word;
  while (words >> word) {
    if (line > 0 && line + 1 + word.size() > max_chars) {
      out += "\\n";
      line = 0;
    } else if (line > 0) {
      out += ' ';
      ++line;
    }
    for (char c : word) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
    line += word.size();
  }
  return out + "\"";
}

// Distinct colours (a series keeps its colour in every panel); point shapes
// cycle with them so that more series than colours stay apart.
constexpr const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                    "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
constexpr int kPointTypes[] = {7, 5, 9, 11, 13, 15, 4, 8, 10, 12};

}  // namespace

void PlotPng(const Table& table, const PlotOptions& options, const fs::path& png) {
  const std::vector<PlotSeries> series = PlotSeriesOf(table, options);
  if (series.empty()) core::ThrowFileError("PlotPng", png, "no finite points to plot");
  std::vector<std::string> panels, names;
  for (const PlotSeries& s : series) {
    if (std::find(panels.begin(), panels.end(), s.panel) == panels.end()) panels.push_back(s.panel);
    if (!s.highlight && std::find(names.begin(), names.end(), s.name) == names.end())
      names.push_back(s.name);
  }
  std::sort(names.begin(), names.end());
  const fs::path dir = png.parent_path().empty() ? fs::path(".") : png.parent_path();
  const fs::path data = dir / (png.stem().string() + ".plotdata.tmp");
  const fs::path script = dir / (png.stem().string() + ".gnuplot.tmp");
  {
    std::ofstream out(data);
    for (const PlotSeries& s : series) {
      out << "# " << s.panel << " | " << s.name << "\n";
      for (const auto& [x, y] : s.points) out << fmt::format("{:.9g} {:.9g}\n", x, y);
      out << "\n\n";
    }
  }
  core::AtomicWrite(png, [&](const fs::path& tmp) {
    std::ofstream gp(script);
    gp << fmt::format("set terminal pngcairo size {},{} noenhanced{}\n", options.width_px,
                      options.height_px, panels.size() > 1 ? " font ',9'" : "");
    gp << "set output " << GnuplotQuoted(tmp.string()) << "\n";
    gp << "set xlabel "
       << GnuplotQuoted(options.x_label.empty() ? options.x_column : options.x_label) << "\n";
    gp << "set ylabel "
       << GnuplotQuoted(options.y_label.empty() ? options.y_column : options.y_label) << "\n";
    // Several panels: each key below its panel, so the plots keep their width.
    gp << (panels.size() > 1 ? "set grid\nset key below horizontal maxcols 3 height 1.5\n"
                             : "set grid\nset key outside right\n");
    if (options.log_x) gp << "set logscale x\n";
    if (options.log_y) gp << "set logscale y\n";
    const bool multi = panels.size() > 1;
    if (multi) {
      const int cols = std::max(1, std::min<int>(options.panel_columns, panels.size()));
      const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
      gp << fmt::format("set multiplot layout {},{} title {}\n", rows, cols,
                        GnuplotTitle(options.title, options.width_px / 8));
    }
    int index = 0;
    for (const std::string& panel : panels) {
      gp << "set title "
         << (multi ? GnuplotQuoted(panel) : GnuplotTitle(options.title, options.width_px / 16))
         << "\n";
      gp << "plot ";
      bool first = true;
      for (const PlotSeries& s : series) {
        if (s.panel != panel) {
          continue;
        }
        const int k =
            static_cast<int>(std::find(names.begin(), names.end(), s.name) - names.begin());
        std::string style;
        if (s.highlight) {
          style = "with linespoints dashtype 2 linecolor rgb 'black' pointtype 6 pointsize 2.2";
        } else {
          style =
              fmt::format("with {} linecolor rgb '{}' pointtype {} pointsize 1.2",
                          s.joined ? "linespoints" : "points", kColours[k % std::size(kColours)],
                          kPointTypes[(k / std::size(kColours) + k) % std::size(kPointTypes)]);
        }
        // A series split into joined and lone points is named once.
        const bool titled = s.joined || s.highlight ||
                            std::none_of(series.begin(), series.end(), [&](const PlotSeries& o) {
                              return o.panel == panel && o.name == s.name && o.joined;
                            });
        gp << (first ? "" : ", ") << GnuplotQuoted(data.string()) << " index " << index
           << " using 1:2 " << style << " title "
           << (titled ? GnuplotQuoted(s.name) : std::string("''"));
        first = false;
        ++index;
      }
      gp << "\n";
    }
    if (multi) gp << "unset multiplot\n";
    gp.close();
    const std::string command = fmt::format("gnuplot '{}' 2>&1", script.string());
    FILE* pipe = popen(command.c_str(), "r");
    std::string output;
    if (pipe) {
      char buffer[256];
      while (fgets(buffer, sizeof(buffer), pipe)) output += buffer;
    }
    const int status = pipe ? pclose(pipe) : -1;
    std::error_code ignored;
    fs::remove(script, ignored);
    fs::remove(data, ignored);
    if (status != 0 || !fs::exists(tmp) || fs::file_size(tmp) == 0) {
      std::replace(output.begin(), output.end(), '\n', ' ');
      core::ThrowFileError("PlotPng", png, "gnuplot failed (is gnuplot-nox installed?): {}",
                           output);
    }
    core::MarkImageFile(tmp);  // so that the next run may replace the plot
  });
}

}  // namespace bench
