#include "bench/report_page.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include "bench/deform_bench.h"
#include "bench/depth_object_bench.h"
#include "bench/displacement_bench.h"
#include "bench/gallery.h"
#include "bench/kautz_seidel_experiments.h"
#include "bench/ncs_bench.h"
#include "bench/paper_tables.h"
#include "bench/peer.h"
#include "bench/report.h"
#include "bench/report_summary.h"
#include "bench/scene_bench.h"
#include "bench/tradeoff.h"
#include "bench/volume_bench.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_compose.h"
#include "core/image_io.h"
#include "ibr/jobs/demo_job.h"
#include "render/gl/context.h"

namespace bench {
namespace fs = std::filesystem;

void ReportOptions::Check() const {
  if (out.empty()) core::ThrowInputError("ibr report", "--out DIR is required");
}

double EstimateSecondsLeft(const std::vector<std::string>& names, size_t index,
                           const std::vector<double>& done,
                           const std::map<std::string, double>& previous) {
  double from_previous = 0;
  bool complete = true;
  for (size_t i = index; i < names.size(); ++i) {
    auto it = previous.find(names[i]);
    if (it == previous.end()) {
      complete = false;
      break;
    }
    from_previous += it->second;
  }
  if (complete) return from_previous;
  if (done.empty()) return std::nan("");
  double sum = 0;
  for (double d : done) sum += d;
  return sum / static_cast<double>(done.size()) * static_cast<double>(names.size() - index);
}

std::map<std::string, double> ReadStepTimings(const fs::path& file, const std::string& mode) {
  std::map<std::string, double> out;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line) || line != "step,mode,seconds") return {};
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string step, m, seconds;
    if (!std::getline(s, step, ',') || !std::getline(s, m, ',') || !std::getline(s, seconds))
      return {};
    char* end = nullptr;
    const double v = std::strtod(seconds.c_str(), &end);
    if (end == seconds.c_str() || !std::isfinite(v) || v < 0) return {};
    if (m == mode) out[step] = v;
  }
  return out;
}

namespace {

// ----------------------------------------------------------- the page ----

// A page as blocks, written both as Markdown and as HTML.
struct Block {
  enum Kind { kHeading, kText, kTable, kImage } kind;
  std::string text;  // heading / paragraph / image caption
  int level = 2;
  std::optional<Table> table;
  std::string image;  // path relative to the report folder
};

class Page {
 public:
  void Heading(std::string text, int level = 2) {
    blocks_.push_back({Block::kHeading, std::move(text), level, {}, {}});
  }
  void Text(std::string text) { blocks_.push_back({Block::kText, std::move(text), 0, {}, {}}); }
  void AddTable(Table table) { blocks_.push_back({Block::kTable, {}, 0, std::move(table), {}}); }
  void Image(std::string path, std::string caption) {
    blocks_.push_back({Block::kImage, std::move(caption), 0, {}, std::move(path)});
  }
  std::string Markdown() const;
  std::string Html(const fs::path& dir) const;

 private:
  std::vector<Block> blocks_;
};

std::string MarkdownCell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string Page::Markdown() const {
  std::string md;
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::kHeading:
        md += std::string(b.level, '#') + " " + b.text + "\n\n";
        break;
      case Block::kText:
        md += b.text + "\n\n";
        break;
      case Block::kTable: {
        const Table& t = *b.table;
        auto line = [&](const std::vector<std::string>& cells) {
          md += "|";
          for (const auto& c : cells) {
            md += ' ';
            md += MarkdownCell(c);
            md += " |";
          }
          md += "\n";
        };
        line(t.columns());
        md += "|";
        for (size_t c = 0; c < t.columns().size(); ++c) md += "---|";
        md += "\n";
        for (const auto& r : t.rows()) line(r);
        md += "\n";
        break;
      }
      case Block::kImage:
        md += fmt::format("![{}]({})\n\n", b.text, b.image);
        if (!b.text.empty()) md += "*" + b.text + "*\n\n";
        break;
    }
  }
  return md;
}

std::string HtmlEscaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Escaped text with the Markdown the page uses: `code` spans as <code>,
// **bold** as <b>.
std::string HtmlText(const std::string& s) {
  std::string out;
  bool code = false, bold = false;
  const std::string escaped = HtmlEscaped(s);
  for (size_t i = 0; i < escaped.size(); ++i) {
    const char c = escaped[i];
    if (c == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else if (!code && c == '*' && i + 1 < escaped.size() && escaped[i + 1] == '*') {
      out += bold ? "</b>" : "<b>";
      bold = !bold;
      ++i;
    } else {
      out += c;
    }
  }
  if (code) out += "</code>";
  if (bold) out += "</b>";
  return out;
}

// A paragraph, or a list when every line starts with "- ".
std::string HtmlParagraph(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const bool list = !lines.empty() && std::all_of(lines.begin(), lines.end(),
                                                  [](auto& l) { return l.rfind("- ", 0) == 0; });
  if (!list) return "<p>" + HtmlText(text) + "</p>\n";
  std::string out = "<ul>\n";
  for (const std::string& l : lines) out += "<li>" + HtmlText(l.substr(2)) + "</li>\n";
  return out + "</ul>\n";
}

std::string Base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < bytes.size()) {
    uint32_t v = uint8_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= uint8_t(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string Page::Html(const fs::path& dir) const {
  std::string h =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>ibr report</title>\n"
      "<style>body{font-family:sans-serif;max-width:1900px;margin:1em auto;padding:0 1em}"
      "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:2px "
      "6px;font-size:90%}th{background:#eee}img{max-width:100%}figcaption{font-style:italic;"
      "font-size:90%}</style>\n</head><body>\n";
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::kHeading:
        h += fmt::format("<h{0}>{1}</h{0}>\n", b.level, HtmlText(b.text));
        break;
      case Block::kText:
        h += HtmlParagraph(b.text);
        break;
      case Block::kTable: {
        h += "<table><tr>";
        for (const auto& c : b.table->columns()) h += "<th>" + HtmlEscaped(c) + "</th>";
        h += "</tr>\n";
        for (const auto& r : b.table->rows()) {
          h += "<tr>";
          for (const auto& c : r) h += "<td>" + HtmlEscaped(c) + "</td>";
          h += "</tr>\n";
        }
        h += "</table>\n";
        break;
      }
      case Block::kImage: {
        std::ifstream in(dir / b.image, std::ios::binary);
        std::stringstream bytes;
        bytes << in.rdbuf();
        if (!in) core::ThrowFileError("ibr report", dir / b.image, "cannot read the image");
        h += fmt::format(
            "<figure><img alt=\"{}\" src=\"data:image/png;base64,{}\"><figcaption>{}"
            "</figcaption></figure>\n",
            HtmlEscaped(b.text), Base64(bytes.str()), HtmlText(b.text));
        break;
      }
    }
  }
  return h + "</body></html>\n";
}

// ------------------------------------------------------------ machine ----

std::string FirstLineOf(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return "";
  char buffer[512] = {};
  if (!fgets(buffer, sizeof(buffer), pipe.get())) return "";
  std::string line = buffer;
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  return line;
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  }
  return "unknown";
}

// The commit of the source tree this binary was built from, when it is a
// git checkout here.
std::string SourceCommit() {
  const fs::path source = fs::path(IBR_BENCH_SOURCE_DIR).parent_path();
  const std::string git = fmt::format("git -C '{}' ", source.string());
  const std::string commit = FirstLineOf(git + "rev-parse --short HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  const bool dirty =
      !FirstLineOf(git + "status --porcelain --untracked-files=no 2>/dev/null").empty();
  return dirty ? commit + " (with uncommitted changes)" : commit;
}

Table MachineTable(const render::GlInfo& gl) {
  Table t({"what", "value"});
  std::ifstream load("/proc/loadavg");
  std::string l1, l5, l15;
  load >> l1 >> l5 >> l15;
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  t.AddRow({"CPU", CpuModel()});
  t.AddRow({"cores", std::to_string(std::thread::hardware_concurrency())});
  t.AddRow(
      {"load average at start (1, 5, 15 min)", l1.empty() ? "unknown" : l1 + " " + l5 + " " + l15});
  t.AddRow({"GL_RENDERER", gl.renderer});
  t.AddRow({"GL_VERSION", gl.version});
  t.AddRow({"date", date});
  t.AddRow({"commit", SourceCommit()});
  return t;
}

// ------------------------------------------------------------ helpers ----

void RemoveByExtension(const fs::path& dir, const std::string& suffix) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      fs::remove(e.path());
  }
}

std::string Seconds(double s) { return std::isfinite(s) ? fmt::format("{:.0f}s", s) : "?"; }

// The Pareto front of each panel's methods, one line per panel, and where
// the truth itself is faster than the front's fastest point, that too.
std::vector<std::string> FrontLines(const TradeoffFamily& family) {
  const std::vector<bool> front = ParetoFront(family.rows, false);
  std::vector<std::string> panels;
  std::map<std::string, std::vector<const TradeoffRow*>> by_panel, truth;
  for (size_t i = 0; i < family.rows.size(); ++i) {
    const TradeoffRow& r = family.rows[i];
    if (!by_panel.count(r.panel)) panels.push_back(r.panel);
    by_panel[r.panel];
    if (front[i]) by_panel[r.panel].push_back(&r);
    if (r.truth) truth[r.panel].push_back(&r);
  }
  std::vector<std::string> lines;
  for (const std::string& p : panels) {
    auto& rows = by_panel[p];
    std::sort(rows.begin(), rows.end(), [](auto* a, auto* b) { return a->ms < b->ms; });
    std::string line = p + ": ";
    for (size_t i = 0; i < rows.size(); ++i) {
      line += fmt::format("{}{}{} ({:.3g} ms, {:.3g})", i ? "; " : "", rows[i]->method,
                          rows[i]->knob.empty() ? "" : " " + rows[i]->knob, rows[i]->ms,
                          rows[i]->error);
    }
    for (const TradeoffRow* t : truth[p]) {
      if (!rows.empty() && t->ms < rows.front()->ms)
        line += fmt::format(" (the truth, {}, is faster still: {:.3g} ms)", t->method, t->ms);
    }
    lines.push_back(line);
  }
  return lines;
}

// `ibr bench viewer` in a child under `xvfb-run -a` (the viewer needs a
// window; the bench library does not link the optional viewer). nullopt
// with the reason in `note` when the binary is not `ibr`, xvfb-run is
// missing or the child fails.
std::optional<Table> RunViewerBenchChild(const fs::path& out, bool quick, std::string& note) {
  const fs::path self = fs::read_symlink("/proc/self/exe");
  if (self.filename() != "ibr") {
    note = "only the ibr binary runs it";
    return std::nullopt;
  }
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) {
    note = "xvfb-run is not installed (scripts/install-deps.sh)";
    return std::nullopt;
  }
  const fs::path csv = out / "viewer.csv";
  const std::string command = fmt::format(
      "xvfb-run -a -s '-screen 0 1280x1024x24' {} --log-level warn bench viewer "
      "--csv {} --out {}{} > {} 2>&1",
      ShellQuote(self.string()), ShellQuote(csv.string()), ShellQuote(out.string()),
      quick ? " --quick" : "", ShellQuote((out / "viewer.log").string()));
  if (std::system(command.c_str()) != 0 || !fs::exists(csv)) {
    note = fmt::format("`{}` failed (see viewer/viewer.log)", command);
    return std::nullopt;
  }
  return ReadCsv(csv);
}

// ------------------------------------------------------------ the steps ----

// The benches' results, filled by the steps.
struct ReportData {
  std::optional<DisplacementBenchResult> displacement;
  std::optional<NcsBenchResult> ncs;
  std::optional<DepthObjectBenchResult> depth_object;
  std::optional<KautzSeidelResult> kautz_seidel;
  std::optional<DeformBenchResult> deform;
  std::optional<Table> volume;
  std::optional<SceneBenchResult> scene;
  std::optional<Table> viewer;
  std::string viewer_note;  // why the viewer bench did not run
  std::vector<GalleryEntry> gallery;
};

struct Step {
  std::string name;
  std::function<void()> run;
};

// Every bench in the order they run, each writing its files under `dir`
// and its results into `data`.
std::vector<Step> ReportSteps(const ReportOptions& options, const fs::path& dir,
                              const fs::path& shared, ReportData& data) {
  return {
      {"displacement",
       [&] {
         fs::create_directories(dir / "displacement");
         data.displacement = RunDisplacementBench(
             {.csv = dir / "displacement" / "displacement.csv", .quick = options.quick});
         data.displacement->summary.WriteCsv(dir / "displacement" / "displacement_summary.csv");
       }},
      {"ncs",
       [&] {
         auto context = render::HeadlessContext::Create();
         render::ProgramCache programs;
         data.ncs =
             RunNcsBench(programs, options.quick ? NcsBenchOptions::Quick() : NcsBenchOptions{});
         fs::create_directories(dir / "ncs");
         WriteNcsBench(*data.ncs, dir / "ncs" / "ncs.csv", dir / "ncs");
       }},
      {"depth objects",
       [&] {
         fs::create_directories(dir / "depth_object");
         DepthObjectBenchOptions o;
         o.csv = dir / "depth_object" / "depth_object.csv";
         o.quick = options.quick;
         data.depth_object = RunDepthObjectBench(o);
       }},
      {"kautz seidel",
       [&] {
         auto context = render::HeadlessContext::Create();
         render::ProgramCache programs;
         KautzSeidelOptions o;
         o.quick = options.quick;
         data.kautz_seidel = RunKautzSeidelExperiments(programs, o);
         fs::create_directories(dir / "kautz_seidel");
         WriteKautzSeidelExperiments(*data.kautz_seidel, dir / "kautz_seidel" / "kautz_seidel.csv",
                                     dir / "kautz_seidel");
       }},
      {"deformation",
       [&] {
         auto context = render::HeadlessContext::Create();
         render::ProgramCache programs;
         DeformBenchOptions o;
         o.shared_data = shared;
         o.out = dir / "deform";
         o.csv = o.out / "deform.csv";
         o.quick = options.quick;
         data.deform = RunDeformBench(programs, o);
         WriteDeformBench(*data.deform, o);
         RemoveByExtension(o.out, "_closed.obj");  // the peer's inputs
       }},
      {"volume",
       [&] {
         auto context = render::HeadlessContext::Create();
         VolumeBenchOptions o;
         o.shared_data = shared;
         o.out = dir / "volume";
         o.csv = o.out / "volume.csv";
         o.quick = options.quick;
         data.volume = RunVolumeBench(o);
         RemoveByExtension(o.out, ".tf.json");  // the peer's inputs
       }},
      {"scene",
       [&] {
         auto context = render::HeadlessContext::Create();
         SceneBenchOptions o;
         o.quick = options.quick;
         data.scene = RunSceneBench(o);
         fs::create_directories(dir / "scene");
         WriteSceneBench(*data.scene, dir / "scene" / "scene.csv", dir / "scene");
       }},
      {"viewer",
       [&] {
         fs::create_directories(dir / "viewer");
         data.viewer = RunViewerBenchChild(dir / "viewer", options.quick, data.viewer_note);
       }},
      {"gallery",
       [&] {
         auto context = render::HeadlessContext::Create();
         render::ProgramCache programs;
         GalleryOptions o;
         o.quick = options.quick;
         o.size = options.quick ? 160 : 384;
         o.map_size = options.quick ? 128 : 256;
         data.gallery = RenderGallery(programs, o);
       }},
  };
}

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Runs `steps` in order, each announced on stderr with the time left as
// estimated from the steps done and `previous` (a run of the same mode).
ReportResult RunSteps(const std::vector<Step>& steps, const std::map<std::string, double>& previous,
                      Clock::time_point start) {
  std::vector<std::string> names;
  for (const Step& s : steps) names.push_back(s.name);
  std::vector<double> done;
  ReportResult result;
  for (size_t i = 0; i < steps.size(); ++i) {
    std::fprintf(stderr, "step %zu of %zu: %s, elapsed %s, estimated %s left\n", i + 1,
                 steps.size(), steps[i].name.c_str(), Seconds(SecondsSince(start)).c_str(),
                 Seconds(EstimateSecondsLeft(names, i, done, previous)).c_str());
    std::fflush(stderr);
    const auto step_start = Clock::now();
    steps[i].run();
    done.push_back(SecondsSince(step_start));
    result.steps.push_back({steps[i].name, done.back()});
  }
  return result;
}

// ------------------------------------------------------- the sections ----

void AddIntroSection(Page& page, const ReportOptions& options, const std::string& mode,
                     const Table& machine) {
  page.Heading("What accuracy costs in time: every technique, beside the papers and the peers", 1);
  page.Text(fmt::format(
      "Written by `ibr report{}` ({} run: {}). Every number below was measured in this run on "
      "the machine named here, except the papers' own figures, which are quoted with their "
      "section, figure or table from the texts in `../shared/papers/`. The papers ran on "
      "2001-2008 GPUs, so they are compared as ratios (a method's cost against its baseline "
      "in the same paper), never as absolute times.",
      options.quick ? " --quick" : "", mode,
      options.quick ? "every bench's small sweep, a smoke test: the figures are not for quoting"
                    : "every bench's full sweep"));
  page.Heading("Machine");
  page.AddTable(machine);
}

// The error-vs-time families, in the closing note's order; each written as
// `ID_tradeoff.csv` and `ID_tradeoff.png` into `dir`.
std::vector<TradeoffFamily> WriteTradeoffs(const ReportData& data, const fs::path& dir) {
  std::vector<TradeoffFamily> families = {DisplacementTradeoff(data.displacement->table),
                                          NcsTradeoff(data.ncs->table),
                                          DepthObjectTradeoff(data.depth_object->table),
                                          DepthObjectSilhouetteTradeoff(data.depth_object->table),
                                          VolumeTradeoff(*data.volume),
                                          DeformTradeoff(data.deform->accuracy),
                                          DeformSilhouetteTradeoff(data.deform->accuracy)};
  for (const TradeoffFamily& f : families) {
    TradeoffTable(f).WriteCsv(dir / (f.id + "_tradeoff.csv"));
    PlotTradeoff(f, dir / (f.id + "_tradeoff.png"));
  }
  return families;
}

// A family's plot explained. `panel`: what one panel holds; `table`: the
// bench's own table, below the report.
std::string TradeoffText(const TradeoffFamily& f, const std::string& panel,
                         const std::string& table) {
  return fmt::format(
      "Error ({}) against time per frame, one panel per {}, every method and peer on the same "
      "axes; a method's points are joined only along its {} (nothing else varies along a "
      "line); circled points are the panel's Pareto front of the methods (no other method's "
      "point is both faster and more accurate; the truth, where a family has one, is drawn "
      "but set aside, since it is exact by construction). Data: `{}_tradeoff.csv` "
      "(pareto_methods = 1 on that front; pareto = 1 on the front with the truth counted); "
      "the bench's table: `{}`.",
      f.error_label, panel, f.knob_label, f.id, table);
}

void AddDisplacementSection(Page& page, const TradeoffFamily& family,
                            const DisplacementBenchResult& displacement) {
  page.Heading(family.title);
  page.Text(TradeoffText(family, "view elevation and image size", "displacement/displacement.csv"));
  page.Image("displacement_tradeoff.png", "displacement by slicing: error vs time");
  page.Text("The paper's figures beside ours (Kautz-Seidel 2001):");
  page.AddTable(KautzSeidelSlicingTable(displacement.table));
  page.Text("Slices needed for a p95 depth error under one height texel (the bench's summary):");
  page.AddTable(displacement.summary);
}

void AddNcsSection(Page& page, const TradeoffFamily& family, const NcsBenchResult& ncs) {
  page.Heading(family.title);
  page.Text(TradeoffText(family, "view and tiling", "ncs/ncs.csv"));
  page.Image("ncs_tradeoff.png", "NCS, relief mapping, POM: silhouette error vs time");
  page.Image("ncs/ncs_time_vs_tiling.png",
             "cost against tiling (the analogue of Chen-Chang Fig. 6)");
  page.Text("The paper's figures beside ours (Chen-Chang):");
  page.AddTable(ChenChangTable(ncs.table));
}

// Also plots the Fig. 12 analogues into `dir`/depth_object.
void AddDepthObjectSection(Page& page, const TradeoffFamily& family,
                           const TradeoffFamily& silhouette_family,
                           const DepthObjectBenchResult& depth_object, const fs::path& dir) {
  page.Heading(family.title);
  page.Text(TradeoffText(family, "object and image size", "depth_object/depth_object.csv") +
            " The peers (Open3D TSDF fusion and voxel carving, `bench/open3d_peer.py`) are "
            "judged from the same views; their knob is the voxel resolution, their time the "
            "frame time of drawing their mesh (building it is in the bench's "
            "time_to_first_image_s column).");
  page.Image("depth_object_tradeoff.png", "depth objects and peers: error vs time");
  page.Text(
      TradeoffText(silhouette_family, "object and image size", "depth_object/depth_object.csv"));
  page.Image("depth_object_silhouette_tradeoff.png",
             "depth objects and peers: silhouette error vs time");
  fs::create_directories(dir / "depth_object");
  PlotPng(depth_object.fig_coverage,
          {.title = "Fig. 12 analogue: time vs covered pixels, 128 slices (bunny; quick: cup)",
           .x_column = "covered_pixels",
           .y_column = "ms_per_frame",
           .series_column = "family",
           .x_label = "object pixels",
           .y_label = "ms per frame",
           .order_column = "covered_pixels"},
          dir / "depth_object" / "fig12_time_vs_coverage.png");
  PlotPng(depth_object.fig_slices,
          {.title = "Fig. 12 analogue: time vs slices at a fixed size",
           .x_column = "slices",
           .y_column = "ms_per_frame",
           .series_column = "family",
           .x_label = "slices",
           .y_label = "ms per frame",
           .order_column = "slices"},
          dir / "depth_object" / "fig12_time_vs_slices.png");
  page.Image("depth_object/fig12_time_vs_coverage.png", "Kautz-Seidel Fig. 12 (upper) analogue");
  page.Image("depth_object/fig12_time_vs_slices.png", "Kautz-Seidel Fig. 12 (lower) analogue");
  page.Text("The paper's figures beside ours (Kautz-Seidel 2001, sec. 6 and Fig. 12):");
  page.AddTable(KautzSeidelDepthObjectTable(depth_object.fig_coverage, depth_object.fig_slices));
  page.Text("Every path at its default slice count (sec. 3.4's rule) against the true mesh:");
  page.AddTable(depth_object.accuracy);
  page.Text(
      "Where the default path's time goes: the ray path at its defaults (empty-space skipping, "
      "sub-texel depth, one step per depth texel) at the largest size, against the same frame "
      "with one part taken away or reduced, in the same run:");
  page.AddTable(depth_object.profile);
  if (!depth_object.first_image.rows().empty()) {
    page.Text(
        "Time to first image (fresh processes; cold, warm and binaries-only caches) beside "
        "the TSDF peer's:");
    page.AddTable(depth_object.first_image);
  }
  if (!depth_object.peer_goals.rows().empty()) {
    page.Text(
        "The default path against the TSDF peer at 1/256 in the same run (issue 36): the still "
        "frame's goal is a ratio <= 1 at a better p95 depth error, the first image's <= 0.1, "
        "cold (empty caches) and warm (`depth_object/depth_object_peer_goals.csv`):");
    page.AddTable(depth_object.peer_goals);
  }
  if (!depth_object.maps.cost.rows().empty()) {
    page.Text(
        "The cost per map (ring captures of the first object, one view; "
        "`depth_object/depth_object_maps.csv`) and what a frame's nearest-maps subset "
        "costs in error (`depth_object/depth_object_maps_subset.csv`):");
    page.AddTable(depth_object.maps.cost);
    page.AddTable(depth_object.maps.subset);
  }
}

void AddKautzSeidelSection(Page& page, const KautzSeidelResult& kautz_seidel) {
  page.Heading("Kautz-Seidel 2001: the paper's own experiments");
  page.Text(fmt::format(
      "`ibr bench kautz-seidel` on {} (cube-rig maps): Fig. 12 for depth objects and visual "
      "hulls of the same object and views, sec. 6's viewing-angle claim, its two quality points "
      "and the donut at 15-25 orthogonal slices. Each table carries the paper's figure and its "
      "source beside ours. Data: `kautz_seidel/`.",
      kautz_seidel.object));
  page.Image("kautz_seidel/ks_fig12_time_vs_coverage.png",
             "Fig. 12 (upper): time vs covered pixels, depth object and visual hull");
  page.Image("kautz_seidel/ks_fig12_time_vs_slices.png",
             "Fig. 12 (lower): time vs slices, depth object and visual hull");
  page.Image("kautz_seidel/ks_time_vs_angle.png", "sec. 6: time against the viewing angle");
  page.Text("Time against the viewing angle (sec. 6: up to 20 % faster at oblique views):");
  page.AddTable(kautz_seidel.angle);
  page.Text("The quality points (sec. 6: ~150 x 150 px at 70 slices, 400 x 400 at 150):");
  page.AddTable(kautz_seidel.points);
  page.Text(
      "The donut by orthogonal slicing (sec. 6, Figs. 1, 17, 18) against the tessellated "
      "truth:");
  page.AddTable(kautz_seidel.donut);
}

void AddDeformSection(Page& page, const TradeoffFamily& family,
                      const TradeoffFamily& silhouette_family, const DeformBenchResult& deform) {
  page.Heading(family.title);
  page.Text(TradeoffText(family, "mesh and image size", "deform/deform_accuracy.csv") +
            " Spot cut by the solid knife (eq. 6) from the gallery's oblique view; the error is "
            "measured against the double-precision sphere tracer of `core/deform_reference.h` "
            "(the exact mesh distance, the analytic deformation and cut) traced through every "
            "pixel centre once, on the CPU, so it has no frame time and no truth row. One knob "
            "moves at a time: the distance field's resolution at a fixed step of one voxel, and "
            "each step policy's step (fixed; threshold-adaptive, Hadwiger 2005; Jacobian, eq. 4) "
            "at resolution 128.");
  page.Image("deform_tradeoff.png", "deformation and cut shaders: depth error vs time");
  page.Text(TradeoffText(silhouette_family, "mesh and image size", "deform/deform_accuracy.csv") +
            " The same frames, judged by their silhouettes.");
  page.Image("deform_silhouette_tradeoff.png",
             "deformation and cut shaders: silhouette error vs time");
  page.Text(
      "The cost sweep: ms per frame against the deformed screen area, the paper's Fig. 7 axis, "
      "one line per mesh and mode joined along the region scale (the paper_* modes, without "
      "the skipping by the object's distance, are in the CSV, not on the plot). The OpenVDB "
      "peer builds the distance field beside ours. Data: `deform/`.");
  page.Image("deform/deform_ms_vs_area.png", "ms per frame against the deformed screen area");
  page.Image("deform/deform_sdf_build.png", "distance-field build time, ours and OpenVDB");
  page.Text(
      "The paper's Table 1 beside ours (weighted average time sum(a t) / sum(a), as ratios "
      "to the continuous deformation of the same model); the rows 'ours, no object skipping' "
      "run the paper's shader, which skips by the cut's distance only (sec. 6.2), each "
      "over its own continuous deformation without the skipping:");
  page.AddTable(Correa2007Table(deform.summary, deform.frames));
  page.Text(
      "The goals of the cut, peer and spread workloads beside the paper's figures. The wedge "
      "cut-away (D = 0, its alpha a signed distance) sits in a box enclosing the object, so no "
      "face of the box meets it (sec. 3), and is opened towards the view so that a large share "
      "of the rays march through the removed material; its baseline is the same D without its "
      "alpha, in interleaved rounds (the median of per-round ratios and its 95 % interval). The "
      "forward-mesh peer twists the vertices of the subdivided mesh and rasterises it (what the "
      "paper argues against), beside the ray pass of the same twist at equal p95 depth error "
      "against the double reference. The spread: the capped bunny simplified by meshoptimizer "
      "and (full sweep) split 1:16 at edge midpoints to 1.1M triangles, past Table 1's dragon, "
      "the same surface, twist, box and view. Data: `deform/deform.csv` (workload wedge and "
      "forward), "
      "`deform/deform_spread.csv`, `deform/deform_goals.csv`.");
  page.AddTable(Correa2007GoalsTable(deform.wedge, deform.forward, deform.spread_figures));
  page.AddTable(deform.spread);
  page.Text(deform.pull_figures.Line() +
            " (Fig. 3 (b)-(d) counted against the double reference; `deform/deform_pull.csv`).");
  page.AddTable(deform.pull);
}

void AddVolumeSection(Page& page, const TradeoffFamily& family, const Table& volume) {
  page.Heading("Volume displacement (Correa, Silver, Chen 2006)");
  page.Text(TradeoffText(family, "volume and image size", "volume/volume.csv") +
            " The two knobs of the peeled tooth are swept one at a time, each image compared with "
            "the finest setting's (the pass itself agrees with a double CPU reference at its own "
            "slices to 0.006/255 in the tests, and in the gallery below). The VTK GPU ray caster, "
            "the peer, is timed on the same volume, transfer function and sampling, but its image "
            "is not ours to compare pixel by pixel (its own classification and shading), so it is "
            "in the table, not on the error axis. Data: `volume/volume.csv`.");
  page.Image("volume_tradeoff.png", "volume displacement: error vs time");
  page.Image("volume/volume_time_vs_sampling.png", "peeled tooth: time vs sampling distance");
  page.Image("volume/volume_time_vs_map_size.png", "peeled tooth: time vs map size");
  page.Image("volume/volume_time_vs_area.png", "plain DVR: time vs rasterised slice area");
  page.Text("The paper's figures beside ours (Correa 2006, Tables 1-2, sec. 8):");
  page.AddTable(Correa2006Table(volume));
  page.Text(
      "The goals of issue 35 (`volume/volume_goals.csv`): the eq. 6+7 frame against the displaced "
      "floor on the same slices, the displaced fragment against the plain one, and our displaced "
      "frame against VTK ray casting the volume warped once by the same map, whose resample is "
      "what each edit of the map would cost that way:");
  page.AddTable(VolumeGoalsTable(volume));
  page.AddTable(Filtered(volume, [&](const auto& r) { return r[0] == "volume"; }));
}

void AddSceneSection(Page& page, const SceneBenchResult& scene) {
  page.Heading("Scene overhead (no paper)");
  page.Text(
      "What an effect costs a scene file when on, named but disabled, and absent. Ratios to "
      "absent are medians of per-round ratios (rounds interleaved in rotated order, so load "
      "changes cancel); "
      "disabled should be 1 (only enabled objects build passes), read against "
      "absent_again_over_absent, a second scene without the effect timed the same way: what "
      "identical work measures as on this machine. The `_cpu` columns are the same ratios of the "
      "process's CPU time per frame (llvmpipe renders in its threads): the work done, which "
      "other processes' load on the machine moves far less than the wall clock. `_lo` / `_hi`: "
      "the distribution-free 95 % interval of each median (order statistics of the per-round "
      "ratios; `interval_coverage` its exact coverage): a disabled effect is shown to cost "
      "within 2 % when its `_hi` is at most 1.02. `samples_*` and `primitives_*`: the GL work "
      "of one frame (GL_SAMPLES_PASSED, GL_PRIMITIVES_GENERATED queries): equal for disabled "
      "and absent when nothing of the effect is drawn. Data: `scene/scene.csv`.");
  page.Image("scene/scene_bench.png", "the effect on: ratios to absent per effect");
  page.Image("scene/scene_bench_disabled.png",
             "the effect disabled: ratios to absent with their 95 % intervals");
  page.AddTable(scene.table);
}

// `viewer`: the viewer bench's table, nullopt when it did not run (`note` says why).
void AddViewerSection(Page& page, const std::optional<Table>& viewer, const std::string& note) {
  page.Heading("Interactive viewing (no paper)");
  page.Text(
      "`ibr view` in a real window under Xvfb (`ibr bench viewer`): a scripted orbit and a "
      "scripted parameter drag per scene. While anything moves, frames render at a reduced "
      "resolution (`mean_divisor`: window size over frame size, adapted to a frame-time aim) "
      "and are scaled up; `motion_fps` counts whole frames (render, panel, buffer swap). At "
      "rest the exact frame follows: `seconds_to_exact` from the last moving frame to it shown, "
      "`exact_equals_render` whether it equals, pixel for pixel, what `ibr render` writes from "
      "the same camera for the scene as edited. `psnr_motion_db`: the moving frames as shown "
      "against the exact frames of their cameras. `load_avg_1min`: the machine's load when the "
      "scene started (other work shares the CPU). Data: `viewer/viewer.csv`.");
  if (viewer) {
    page.Image("viewer/viewer_motion.png", "moving frames: frame rate and PSNR against exact");
    page.AddTable(*viewer);
  } else {
    page.Text("Not run: " + note);
  }
}

// Also writes each entry's contact sheet into `dir`/gallery.
void AddGallerySection(Page& page, const std::vector<GalleryEntry>& gallery, const fs::path& dir) {
  page.Heading("Gallery: hard views beside their truth");
  page.Text(
      "Left to right: the method, the truth rendered in the same run (the tessellated surface; "
      "the true mesh; for the cut, the double sphere tracer of `core/deform_reference.h`; for the "
      "volume, the double DVR reference of `verify/volume_reference.h` at the pass's own slices), "
      "and the depth error heat map: |depth - true depth| on a black - red - "
      "yellow - white ramp (black = exact, white = at or beyond the scale given), magenta = "
      "surface only the method draws, cyan = surface it misses, grey = background in both. The "
      "translucent volume has no single depth: its heat map is of the colour error, the largest "
      "premultiplied RGBA channel difference, on the same ramp.");
  fs::create_directories(dir / "gallery");
  for (size_t i = 0; i < gallery.size(); ++i) {
    const GalleryEntry& g = gallery[i];
    const std::string name = fmt::format("gallery/{:02d}_{}.png", i, g.family);
    core::WriteImage(dir / name, core::ContactSheet({g.render, g.truth, g.heat}, 3));
    page.Image(name, g.title + ": " + g.caption);
  }
  page.Image("ncs/ncs_silhouettes_grazing.png",
             "the NCS bench's grazing silhouettes: truth, then each method; below, coverage "
             "against the truth (red: extra, green: missing)");
}

void AddFrontSection(Page& page, const std::vector<TradeoffFamily>& families) {
  page.Heading("Closing note: the Pareto front of each family");
  for (const TradeoffFamily& f : families) {
    page.Text(fmt::format("**{}** (method knob (ms per frame, {})):", f.title, f.error_label));
    std::string list;
    for (const std::string& line : FrontLines(f)) list += "- " + line + "\n";
    page.Text(list.empty() ? "(no rows)" : list.substr(0, list.size() - 1));
  }
}

std::string RunTimeLine(const ReportResult& result) {
  std::string timing = fmt::format("Run time {:.0f} s:", result.seconds);
  for (const ReportStep& s : result.steps)
    timing += fmt::format(" {} {:.0f} s;", s.name, s.seconds);
  timing.back() = '.';
  return timing;
}

// The step timings, report.md, summary.md (when a headline row was made)
// and report.html into `dir`.
void WritePageFiles(const Page& page, const fs::path& dir, const ReportResult& result,
                    const std::string& mode) {
  Table timings({"step", "mode", "seconds"});
  for (const ReportStep& s : result.steps) timings.AddRow({s.name, mode, Num(s.seconds, 1)});
  timings.WriteCsv(dir / "report_timings.csv");
  core::AtomicWriteStream(dir / "report.md", [&](std::ostream& out) { out << page.Markdown(); });
  // The headline rows README.md links; a run that made none writes none.
  if (const std::vector<SummaryRow> rows = SummaryRows(dir); !rows.empty()) {
    core::AtomicWriteStream(dir / "summary.md",
                            [&](std::ostream& out) { out << SummaryMarkdown(rows); });
  }
  const std::string html = page.Html(dir);
  core::AtomicWriteStream(dir / "report.html", [&](std::ostream& out) { out << html; });
}

}  // namespace

ReportResult WriteReport(const ReportOptions& options) {
  options.Check();
  const std::string mode = options.quick ? "quick" : "full";
  const std::map<std::string, double> previous =
      fs::is_directory(options.out) ? ReadStepTimings(options.out / "report_timings.csv", mode)
                                    : std::map<std::string, double>{};
  // Refuses, before minutes of measuring, a folder that is not ours to replace.
  core::StagedDirectory staged(options.out);
  const fs::path dir = staged.path();
  const fs::path shared = ibr::SharedDataDir();

  render::GlInfo gl;
  {
    auto context = render::HeadlessContext::Create();
    gl = context->info();
  }
  const Table machine = MachineTable(gl);
  ReportData data;
  const std::vector<Step> steps = ReportSteps(options, dir, shared, data);
  const Clock::time_point start = Clock::now();
  ReportResult result = RunSteps(steps, previous, start);

  // The page: one section per step, in the steps' order, then the fronts.
  Page page;
  AddIntroSection(page, options, mode, machine);
  const std::vector<TradeoffFamily> families = WriteTradeoffs(data, dir);
  AddDisplacementSection(page, families[0], *data.displacement);
  AddNcsSection(page, families[1], *data.ncs);
  AddDepthObjectSection(page, families[2], families[3], *data.depth_object, dir);
  AddKautzSeidelSection(page, *data.kautz_seidel);
  AddDeformSection(page, families[5], families[6], *data.deform);
  AddVolumeSection(page, families[4], *data.volume);
  AddSceneSection(page, *data.scene);
  AddViewerSection(page, data.viewer, data.viewer_note);
  AddGallerySection(page, data.gallery, dir);
  AddFrontSection(page, families);
  result.seconds = SecondsSince(start);
  page.Text(RunTimeLine(result));
  WritePageFiles(page, dir, result, mode);
  staged.Commit();
  std::fprintf(stderr, "report: done in %.0f s, wrote %s\n", result.seconds,
               (options.out / "report.md").c_str());
  return result;
}

}  // namespace bench
