#include "bench/report_summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace bench {
namespace fs = std::filesystem;

Table ReadCsv(std::istream& in, const std::string& name) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row;
  std::string cell;
  bool quoted = false, cell_started = false;
  int line = 1;
  auto end_cell = [&] {
    row.push_back(std::move(cell));
    cell.clear();
    cell_started = false;
  };
  auto end_row = [&] {
    end_cell();
    rows.push_back(std::move(row));
    row.clear();
    ++line;
  };
  char c = 0;
  while (in.get(c)) {
    if (quoted) {
      if (c != '"') {
        if (c == '\n') ++line;
        cell += c;
      } else if (in.peek() == '"') {
        in.get(c);
        cell += '"';
      } else {
        quoted = false;
      }
    } else if (c == '"' && !cell_started) {
      quoted = cell_started = true;
    } else if (c == ',') {
      end_cell();
    } else if (c == '\n') {
      end_row();
    } else if (c != '\r') {
      cell += c;
      cell_started = true;
    }
  }
  if (quoted) core::ThrowFileError("ReadCsv", name, "line {}: unterminated quoted cell", line);
  if (cell_started || !row.empty()) end_row();
  if (rows.empty()) core::ThrowFileError("ReadCsv", name, "empty file (no header)");
  Table table(rows.front());
  for (size_t r = 1; r < rows.size(); ++r) {
    if (rows[r].size() != rows.front().size()) {
      core::ThrowFileError("ReadCsv", name, "row {} has {} cells, the header {}", r + 1,
                           rows[r].size(), rows.front().size());
    }
    table.AddRow(rows[r]);
  }
  return table;
}

Table ReadCsv(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) core::ThrowFileError("ReadCsv", path, "cannot open");
  return ReadCsv(in, path.string());
}

namespace {

// A report CSV if the run wrote it (a quick or partial run may not have).
std::optional<Table> Load(const fs::path& dir, const std::string& rel) {
  if (!fs::is_regular_file(dir / rel)) return std::nullopt;
  return ReadCsv(dir / rel);
}

// The rows whose named columns hold exactly the given values.
Table Where(const Table& t, const std::vector<std::pair<std::string, std::string>>& equal) {
  std::vector<std::pair<int, std::string>> index;
  for (const auto& [column, value] : equal) {
    if (!t.HasColumn(column)) return Table(t.columns());
    index.emplace_back(t.Column(column), value);
  }
  return Filtered(t, [&](const std::vector<std::string>& r) {
    return std::all_of(index.begin(), index.end(),
                       [&](const auto& iv) { return r[iv.first] == iv.second; });
  });
}

// The finite numbers of one column.
std::vector<double> Values(const Table& t, const std::string& column) {
  if (!t.HasColumn(column)) return {};
  std::vector<double> out;
  const int i = t.Column(column);
  for (const auto& r : t.rows()) {
    const double v = CellNumber(r[i]);
    if (std::isfinite(v)) out.push_back(v);
  }
  return out;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// "0.98-1.15", or one number when the range is a point.
std::string Range(const std::vector<double>& v, int digits) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const std::string a = Num(*lo, digits), b = Num(*hi, digits);
  return a == b ? a : a + "-" + b;
}

using RowMaker = std::function<std::optional<SummaryRow>(const fs::path&)>;

std::optional<SummaryRow> DepthObjectAccuracy(const fs::path& dir) {
  const std::string rel = "depth_object/depth_object.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const Table rows =
      Where(*t, {{"method", "depth-object ray-skip-subtexel"}, {"slices", "256"}, {"size", "512"}});
  const auto iou = Values(rows, "iou_min"), p95 = Values(rows, "p95_depth_error"),
             ms = Values(rows, "ms_per_frame");
  if (iou.empty() || p95.empty() || ms.empty()) return std::nullopt;
  return SummaryRow{
      fmt::format("Depth object, default path (ray, sub-texel depth), {} objects at 512 px "
                  "from 256 px cube maps",
                  rows.rows().size()),
      fmt::format("silhouette IoU >= {}, p95 depth error <= {} cube edges, {} ms a frame (median)",
                  Num(*std::min_element(iou.begin(), iou.end()), 4),
                  Num(*std::max_element(p95.begin(), p95.end()), 4), Num(Median(ms), 0)),
      rel};
}

std::optional<SummaryRow> DepthObjectVsTsdf(const fs::path& dir) {
  const std::string rel = "depth_object/depth_object.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const Table ours = Where(*t, {{"object", "bunny"},
                                {"method", "depth-object ray-skip-subtexel"},
                                {"slices", "256"},
                                {"size", "512"}});
  const Table tsdf = Where(*t, {{"object", "bunny"}, {"method", "open3d tsdf:256"}});
  const auto p95_ours = Values(ours, "p95_depth_error"), p95_tsdf = Values(tsdf, "p95_depth_error");
  const auto ms_ours = Values(ours, "ms_per_frame"), ms_tsdf = Values(tsdf, "ms_per_frame");
  if (p95_ours.empty() || p95_tsdf.empty() || ms_ours.empty() || ms_tsdf.empty())
    return std::nullopt;
  return SummaryRow{
      "Beside Open3D's TSDF at 1/256 of the same maps (bunny, 512 px)",
      fmt::format("p95 depth error {} against {}; a still frame takes {}x the TSDF mesh's",
                  Num(p95_ours[0], 4), Num(p95_tsdf[0], 4), Num(ms_ours[0] / ms_tsdf[0], 2)),
      rel};
}

std::optional<SummaryRow> FirstImage(const fs::path& dir) {
  const std::string rel = "depth_object/depth_object_first_image.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const auto cold = Values(
      Where(*t, {{"method", "depth-object ray-skip-subtexel"}, {"cache", "cold"}}), "over_tsdf");
  const auto warm = Values(
      Where(*t, {{"method", "depth-object ray-skip-subtexel"}, {"cache", "warm"}}), "over_tsdf");
  if (cold.empty() || warm.empty()) return std::nullopt;
  return SummaryRow{"Time to first image, default path, over the TSDF 1/256 pipeline's",
                    fmt::format("{}x with shaders compiled in the run, {}x from the program cache",
                                Num(cold[0], 2), Num(warm[0], 2)),
                    rel};
}

std::optional<SummaryRow> SlicingDisplacement(const fs::path& dir) {
  const std::string rel = "displacement/displacement_summary.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const Table rows = Where(*t, {{"elevation_deg", "60"}, {"family", "surface"}});
  const auto slices = Values(rows, "slices_for_p95_under_1_texel"),
             ratio = Values(rows, "time_vs_truth");
  if (slices.empty() || ratio.empty()) return std::nullopt;
  return SummaryRow{"Displacement by slicing (Kautz-Seidel 2001), view at 60 degrees, 512 px",
                    fmt::format("{} slices keep the p95 depth error under one height texel, at {}x "
                                "the tessellated truth's frame time",
                                Num(slices[0], 0), Num(ratio[0], 2)),
                    rel};
}

std::optional<SummaryRow> Ncs(const fs::path& dir) {
  const std::string rel = "ncs/ncs_summary.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const auto relief = Values(*t, "ncs_over_relief"), truth = Values(*t, "ncs_over_tessellated");
  if (relief.empty() || truth.empty()) return std::nullopt;
  return SummaryRow{"NCS curved silhouettes (Chen-Chang) over relief mapping, same steps",
                    fmt::format("{}x the time (median; {} over views, tilings and steps); {}x the "
                                "tessellated truth's (median)",
                                Num(Median(relief), 2), Range(relief, 2), Num(Median(truth), 2)),
                    rel};
}

std::optional<SummaryRow> DeformCut(const fs::path& dir) {
  const std::string rel = "deform/deform_summary.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const auto cut = Values(Where(*t, {{"mode", "cut"}}), "over_continuous");
  const auto skip = Values(Where(*t, {{"mode", "cut_skip"}}), "over_continuous");
  if (cut.empty() || skip.empty()) return std::nullopt;
  return SummaryRow{"A cut over the continuous deformation (Correa 2007, Table 1 analogue)",
                    fmt::format("{}x per mesh; with the cut's empty-space skipping {}x",
                                Range(cut, 2), Range(skip, 2)),
                    rel};
}

std::optional<SummaryRow> DeformWedge(const fs::path& dir) {
  const std::string rel = "deform/deform_goals.csv";
  const auto t = Load(dir, rel);
  if (!t || t->rows().size() < 3) return std::nullopt;
  const int ours = t->Column("ours"), goal = t->Column("goal");
  const auto& r = t->rows();
  return SummaryRow{
      "A wedge cut-away with skipping over the same deformation without its cut (Correa 2007, "
      "sec. 3 and 6.2)",
      fmt::format("{} (goal {}); the skip removes {} of the cut's extra samples (goal {}); {} of "
                  "the pixels agree with the double reference (goal {})",
                  r[0][ours], r[0][goal], r[1][ours], r[1][goal], r[2][ours], r[2][goal]),
      rel};
}

std::optional<SummaryRow> VolumeDisplacement(const fs::path& dir) {
  const std::string rel = "volume/volume.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const Table rows = Where(*t, {{"sweep", "volume"}});
  std::vector<double> peel, vtk;
  const int variant = rows.Column("variant");
  const int ratio = rows.Column("ratio_to_plain");
  const int ms = rows.Column("ms_per_frame"), vtk_ms = rows.Column("vtk_ms");
  for (const auto& r : rows.rows()) {
    if (r[variant].rfind("peel", 0) == 0 && std::isfinite(CellNumber(r[ratio])))
      peel.push_back(CellNumber(r[ratio]));
    const double ours = CellNumber(r[ms]), theirs = CellNumber(r[vtk_ms]);
    if (r[variant].rfind("plain DVR", 0) == 0 && std::isfinite(ours) && std::isfinite(theirs) &&
        theirs > 0)
      vtk.push_back(ours / theirs);
  }
  if (peel.empty()) return std::nullopt;
  std::string result =
      fmt::format("a peeled volume (eq. 6+7, 64^3 map) costs {}x plain DVR over {} volumes",
                  Range(peel, 2), peel.size());
  if (!vtk.empty())
    result += fmt::format("; plain DVR takes {}x VTK's GPU ray caster", Range(vtk, 2));
  return SummaryRow{"Displaced volume rendering (Correa 2006), 512 px", result, rel};
}

// Issue 35's goals for displaced DVR, as bench/volume_bench.cc's
// VolumeGoalsTable states them (quantity, goal, measured, met, note).
std::optional<SummaryRow> VolumeGoals(const fs::path& dir) {
  const std::string rel = "volume/volume_goals.csv";
  const auto t = Load(dir, rel);
  if (!t || t->rows().size() < 4) return std::nullopt;
  const int measured = t->Column("measured"), goal = t->Column("goal"), met = t->Column("met");
  const auto& r = t->rows();
  auto part = [&](size_t i, const char* what) {
    return fmt::format("{}: {} (goal {}, met: {})", what, r[i][measured], r[i][goal], r[i][met]);
  };
  return SummaryRow{"Displaced DVR against its floor and a warped-volume peer (Correa 2006)",
                    part(0, "eq. 6+7 frame / displaced floor") + "; " +
                        part(1, "unsplit displaced / plain per fragment") + "; " +
                        part(3, "ours / VTK on the prewarped volume"),
                    rel};
}

std::optional<SummaryRow> SceneOverhead(const fs::path& dir) {
  const std::string rel = "scene/scene.csv";
  const auto t = Load(dir, rel);
  if (!t) return std::nullopt;
  const auto hi = Values(*t, "disabled_over_absent_hi");
  const auto mid = Values(*t, "disabled_over_absent");
  if (hi.empty() || mid.empty()) return std::nullopt;
  return SummaryRow{
      "An effect named in a scene but disabled, over the scene without it",
      fmt::format("{}x the frame time (medians over {} effects; upper 95 % interval "
                  "ends <= {})",
                  Range(mid, 3), mid.size(), Num(*std::max_element(hi.begin(), hi.end()), 3)),
      rel};
}

}  // namespace

std::vector<SummaryRow> SummaryRows(const fs::path& report_dir) {
  static const std::vector<RowMaker> kRows = {
      DepthObjectAccuracy, DepthObjectVsTsdf,  FirstImage,  SlicingDisplacement, Ncs, DeformCut,
      DeformWedge,         VolumeDisplacement, VolumeGoals, SceneOverhead};
  std::vector<SummaryRow> out;
  for (const RowMaker& make : kRows) {
    if (auto row = make(report_dir)) out.push_back(std::move(*row));
  }
  return out;
}

std::string SummaryMarkdown(const std::vector<SummaryRow>& rows) {
  std::string md =
      "# Headline results\n\n"
      "Written by `ibr report` from the CSVs of this report folder (`report.md` holds every "
      "figure, the machine and the papers' own figures beside ours). Measured on a CPU "
      "rasteriser (see the machine table in `report.md`): compare ratios, not absolute times.\n\n"
      "| what | result | data |\n|---|---|---|\n";
  auto cell = [](std::string s) {
    std::string out;
    for (char c : s) out += (c == '|') ? std::string("\\|") : std::string(1, c);
    return out;
  };
  for (const SummaryRow& r : rows)
    md += fmt::format("| {} | {} | [{}]({}) |\n", cell(r.what), cell(r.result), r.data, r.data);
  return md;
}

void WriteSummary(const fs::path& dir) {
  const fs::path marker = dir / core::kOutputMarker;
  std::ifstream in(marker);
  if (!in)
    core::ThrowFileError("WriteSummary", dir, "not an ibr report folder (no {})",
                         core::kOutputMarker);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  in.close();
  const bool listed = std::find(lines.begin(), lines.end(), "summary.md") != lines.end();
  if (fs::exists(dir / "summary.md") && !listed) {
    core::ThrowFileError("WriteSummary", dir / "summary.md",
                         "exists and was not written by ibr; move it away first");
  }
  const std::vector<SummaryRow> rows = SummaryRows(dir);
  if (rows.empty()) {
    core::ThrowFileError("WriteSummary", dir, "no report CSV to summarise (run ibr report first)");
  }
  core::AtomicWriteStream(dir / "summary.md",
                          [&](std::ostream& out) { out << SummaryMarkdown(rows); });
  if (!listed) {
    lines.push_back("summary.md");
    core::AtomicWriteStream(marker, [&](std::ostream& out) {
      for (const std::string& l : lines) out << l << '\n';
    });
  }
}

}  // namespace bench
