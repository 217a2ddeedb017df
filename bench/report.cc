#include "bench/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"

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
    auto line = [&](const std::vector<std::string>& v) {
      for (size_t c = 0; c < v.size(); ++c) out << v[c] << (c + 1 < v.size() ? "," : "\n");
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

void PlotPng(const Table& table, const PlotOptions& options, const fs::path& png) {
  const int xi = table.Column(options.x_column), yi = table.Column(options.y_column);
  const int si = options.series_column.empty() ? -1 : table.Column(options.series_column);
  std::map<std::string, std::vector<std::pair<double, double>>> series;
  for (const auto& r : table.rows()) {
    const double x = std::strtod(r[xi].c_str(), nullptr), y = std::strtod(r[yi].c_str(), nullptr);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    if ((options.log_x && x <= 0) || (options.log_y && y <= 0)) continue;
    series[si < 0 ? options.y_column : r[si]].emplace_back(x, y);
  }
  if (series.empty()) core::ThrowFileError("PlotPng", png, "no finite points to plot");
  const fs::path dir = png.parent_path().empty() ? fs::path(".") : png.parent_path();
  const fs::path data = dir / (png.stem().string() + ".plotdata.tmp");
  const fs::path script = dir / (png.stem().string() + ".gnuplot.tmp");
  {
    std::ofstream out(data);
    for (auto& [name, points] : series) {
      std::sort(points.begin(), points.end());
      out << "# " << name << "\n";
      for (const auto& [x, y] : points) out << fmt::format("{:.9g} {:.9g}\n", x, y);
      out << "\n\n";
    }
  }
  core::AtomicWrite(png, [&](const fs::path& tmp) {
    std::ofstream gp(script);
    gp << fmt::format("set terminal pngcairo size {},{} noenhanced\n", options.width_px,
                      options.height_px);
    gp << "set output '" << tmp.string() << "'\n";
    gp << "set title '" << options.title << "'\n";
    gp << "set xlabel '" << (options.x_label.empty() ? options.x_column : options.x_label) << "'\n";
    gp << "set ylabel '" << (options.y_label.empty() ? options.y_column : options.y_label) << "'\n";
    gp << "set grid\nset key outside right\n";
    if (options.log_x) gp << "set logscale x\n";
    if (options.log_y) gp << "set logscale y\n";
    gp << "plot ";
    int index = 0;
    for (const auto& [name, points] : series) {
      gp << (index ? ", " : "") << "'" << data.string() << "' index " << index
         << " using 1:2 with linespoints pointtype 7 title '" << name << "'";
      ++index;
    }
    gp << "\n";
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
  });
}

core::Image8 ContactSheet(const std::vector<core::Image8>& images, int columns, int gap_px) {
  IBR_CHECK(!images.empty() && columns >= 1 && gap_px >= 0);
  int cell_w = 0, cell_h = 0;
  for (const auto& im : images) {
    cell_w = std::max(cell_w, im.width());
    cell_h = std::max(cell_h, im.height());
  }
  const int cols = std::min<int>(columns, static_cast<int>(images.size()));
  const int rows = (static_cast<int>(images.size()) + cols - 1) / cols;
  core::Image8 sheet(gap_px + cols * (cell_w + gap_px), gap_px + rows * (cell_h + gap_px), 4, 0);
  for (int y = 0; y < sheet.height(); ++y) {
    for (int x = 0; x < sheet.width(); ++x) {
      for (int c = 0; c < 3; ++c) sheet.at(x, y, c) = 40;
      sheet.at(x, y, 3) = 255;
    }
  }
  for (size_t i = 0; i < images.size(); ++i) {
    const core::Image8& im = images[i];
    const int ox = gap_px + static_cast<int>(i % cols) * (cell_w + gap_px);
    const int oy = gap_px + static_cast<int>(i / cols) * (cell_h + gap_px);
    for (int y = 0; y < im.height(); ++y) {
      for (int x = 0; x < im.width(); ++x) {
        // Composite over a light grey so transparent backgrounds read as such.
        const float a = im.channels() == 4 ? im.at(x, y, 3) / 255.0f : 1.0f;
        for (int c = 0; c < 3; ++c) {
          const float v = im.at(x, y, std::min(c, im.channels() - 1));
          sheet.at(ox + x, oy + y, c) = static_cast<uint8_t>(std::lround(a * v + (1 - a) * 200));
        }
      }
    }
  }
  return sheet;
}

}  // namespace bench
