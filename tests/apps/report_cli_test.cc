// `ibr report --quick` end to end: both pages, every family's section and
// plot, the machine's GL renderer, every method of each family's bench table
// in its plot's data, a Pareto front recomputed here from that data, the
// progress lines; and a folder that is not ibr's is refused untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A CSV without quoting (the benches write none): header + rows by name.
std::vector<std::map<std::string, std::string>> ReadCsv(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::map<std::string, std::string>> rows;
  std::string line;
  std::vector<std::string> header;
  auto split = [](const std::string& l) {
    std::vector<std::string> cells;
    std::string cell;
    std::stringstream s(l);
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    if (!l.empty() && l.back() == ',') cells.push_back("");
    return cells;
  };
  if (!std::getline(in, line)) return rows;
  header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size(); ++i) row[header[i]] = i < cells.size() ? cells[i] : "";
    rows.push_back(row);
  }
  return rows;
}

class ReportCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_support::TestOutputDir().parent_path() / "report_cli";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    run_ = test_support::RunCommand(test_support::IbrBinary() + " report --quick --out " +
                                    (dir_ / "report").string());
  }
  static fs::path dir_;
  static test_support::CommandResult run_;
};
fs::path ReportCliTest::dir_;
test_support::CommandResult ReportCliTest::run_;

TEST_F(ReportCliTest, WritesBothPagesWithTheMachine) {
  ASSERT_EQ(run_.exit_code, 0) << run_.err;
  const fs::path out = dir_ / "report";
  ASSERT_TRUE(fs::is_regular_file(out / "report.md"));
  ASSERT_TRUE(fs::is_regular_file(out / "report.html"));
  const std::string md = ReadText(out / "report.md");
  const std::string html = ReadText(out / "report.html");
  // The GL renderer has a name in both.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(md, m, std::regex(R"(\| GL_RENDERER \| ([^|\n]+) \|)")));
  EXPECT_FALSE(m[1].str().empty());
  EXPECT_NE(html.find("<td>" + m[1].str() + "</td>"), std::string::npos);
  for (const char* row : {"| CPU |", "| cores |", "| GL_VERSION |", "| date |", "| commit |"})
    EXPECT_NE(md.find(row), std::string::npos) << row;
  // The HTML stands alone: every image is embedded.
  size_t images = 0;
  for (size_t at = html.find("<img "); at != std::string::npos; at = html.find("<img ", at + 1)) {
    ++images;
    EXPECT_EQ(html.compare(html.find("src=\"", at), 27, "src=\"data:image/png;base64,"), 0);
  }
  EXPECT_GE(images, 10u);
}

TEST_F(ReportCliTest, EveryFamilyHasItsSectionAndPlot) {
  ASSERT_EQ(run_.exit_code, 0) << run_.err;
  const fs::path out = dir_ / "report";
  const std::string md = ReadText(out / "report.md");
  const std::vector<std::pair<std::string, std::string>> families = {
      {"## Displacement by slicing", "displacement_tradeoff.png"},
      {"## NCS, relief mapping, POM", "ncs_tradeoff.png"},
      {"## Depth objects and peers", "depth_object_tradeoff.png"},
      {"## Kautz-Seidel 2001: the paper's own experiments", "kautz_seidel/ks_time_vs_angle.png"},
      {"## Deformation and cut shaders", "deform_tradeoff.png"},
      {"## Deformation and cut shaders", "deform_silhouette_tradeoff.png"},
      {"## Deformation and cut shaders", "deform/deform_ms_vs_area.png"},
      {"## Volume displacement", "volume_tradeoff.png"},
      {"## Scene overhead", "scene/scene_bench.png"},
      {"## Gallery", "gallery/00_displacement.png"}};
  for (size_t i = 0; i < families.size(); ++i) {
    const auto& [heading, png] = families[i];
    const size_t at = md.find(heading);
    ASSERT_NE(at, std::string::npos) << heading;
    // The plot is linked inside its own section and exists.
    const size_t next = md.find("\n## ", at + 1);
    const size_t link = md.find("](" + png + ")", at);
    EXPECT_TRUE(link != std::string::npos && link < next) << png;
    EXPECT_GT(fs::file_size(out / png), 1000u) << png;
  }
  EXPECT_NE(md.find("## Closing note: the Pareto front of each family"), std::string::npos);
  // The papers' tables, with their citations.
  for (const char* cited : {"Figs. 17-18", "Table 1: 350 vs > 999 fps", "Fig. 7", "24 vs 2.7 fps",
                            "paper (Table 1)", "Table 1, d = 1, 512 px"})
    EXPECT_NE(md.find(cited), std::string::npos) << cited;
}

TEST_F(ReportCliTest, EveryMethodOfEachBenchTableIsInItsPlotData) {
  ASSERT_EQ(run_.exit_code, 0) << run_.err;
  const fs::path out = dir_ / "report";
  auto plotted = [&](const std::string& family) {
    std::set<std::string> methods;
    for (const auto& r : ReadCsv(out / (family + "_tradeoff.csv"))) methods.insert(r.at("method"));
    return methods;
  };
  // The bench tables name methods their own way; each must be in the plot.
  const std::set<std::string> displacement = plotted("displacement");
  const auto displacement_rows = ReadCsv(out / "displacement" / "displacement.csv");
  ASSERT_FALSE(displacement_rows.empty());
  for (const auto& r : displacement_rows)
    EXPECT_TRUE(displacement.count("slices " + r.at("family"))) << r.at("family");
  const std::set<std::string> ncs = plotted("ncs");
  const auto ncs_rows = ReadCsv(out / "ncs" / "ncs.csv");
  ASSERT_FALSE(ncs_rows.empty());
  for (const auto& r : ncs_rows) {
    const std::string name =
        r.at("c").empty() ? r.at("method") : r.at("method") + " c=" + r.at("c");
    EXPECT_TRUE(ncs.count(name)) << name;
  }
  const std::set<std::string> depth = plotted("depth_object");
  const auto depth_rows = ReadCsv(out / "depth_object" / "depth_object.csv");
  ASSERT_FALSE(depth_rows.empty());
  bool peer = false;
  for (const auto& r : depth_rows) {
    std::string name = r.at("method");
    if (name.rfind("open3d", 0) == 0) {
      peer = true;
      name = name.substr(0, name.rfind(':'));  // the peer's resolution is its knob
    }
    EXPECT_TRUE(depth.count(name)) << name;
  }
  EXPECT_TRUE(peer) << "the Open3D peer's rows are missing";
  // The deformation's accuracy sweep: every row plotted, in both families,
  // none of them a truth (the sphere tracer is not timed).
  const auto accuracy_rows = ReadCsv(out / "deform" / "deform_accuracy.csv");
  ASSERT_FALSE(accuracy_rows.empty());
  for (const std::string family : {"deform", "deform_silhouette"}) {
    const auto rows = ReadCsv(out / (family + "_tradeoff.csv"));
    EXPECT_EQ(rows.size(), accuracy_rows.size()) << family;
    for (const auto& r : rows) EXPECT_EQ(r.at("truth"), "0") << family;
  }
}

TEST_F(ReportCliTest, ParetoFrontRecomputedFromThePlotData) {
  ASSERT_EQ(run_.exit_code, 0) << run_.err;
  const fs::path out = dir_ / "report";
  for (const std::string family : {"displacement", "ncs", "depth_object", "depth_object_silhouette",
                                   "volume", "deform", "deform_silhouette"}) {
    const auto rows = ReadCsv(out / (family + "_tradeoff.csv"));
    ASSERT_FALSE(rows.empty()) << family;
    // Both fronts: every row counted ("pareto"), the truth set aside ("pareto_methods").
    for (const bool count_truth : {true, false}) {
      const std::string column = count_truth ? "pareto" : "pareto_methods";
      int front = 0;
      auto counted = [&](size_t i) { return count_truth || rows[i].at("truth") == "0"; };
      for (size_t i = 0; i < rows.size(); ++i) {
        const double ms = std::stod(rows[i].at("ms_per_frame")),
                     error = std::stod(rows[i].at("error"));
        bool dominated = !std::isfinite(ms) || !std::isfinite(error) || !counted(i);
        for (size_t j = 0; j < rows.size() && !dominated; ++j) {
          if (j == i || rows[j].at("panel") != rows[i].at("panel") || !counted(j)) continue;
          const double ms_j = std::stod(rows[j].at("ms_per_frame")),
                       error_j = std::stod(rows[j].at("error"));
          dominated = std::isfinite(ms_j) && std::isfinite(error_j) && ms_j <= ms &&
                      error_j <= error && (ms_j < ms || error_j < error);
        }
        EXPECT_EQ(rows[i].at(column), dominated ? "0" : "1")
            << family << " " << column << " row " << i << ": " << rows[i].at("panel") << " "
            << rows[i].at("method");
        front += !dominated;
      }
      EXPECT_GT(front, 0) << family << " " << column;
    }
  }
  // The truth rows are the tessellated surfaces (displacement and NCS) and the finest volume
  // setting.
  for (const std::string family : {"displacement", "ncs", "volume"}) {
    int truths = 0;
    for (const auto& r : ReadCsv(out / (family + "_tradeoff.csv")))
      truths += r.at("truth") == "1" && (r.at("method").rfind("tessellated", 0) == 0 ||
                                         r.at("method").rfind("finest", 0) == 0);
    EXPECT_GT(truths, 0) << family;
  }
}

TEST_F(ReportCliTest, PrintsProgressPerStep) {
  ASSERT_EQ(run_.exit_code, 0) << run_.err;
  const std::regex line(R"(step (\d) of (\d): ([a-z ]+), elapsed \d+s, estimated (\d+s|\?) left)");
  std::vector<std::string> steps;
  for (std::sregex_iterator it(run_.err.begin(), run_.err.end(), line), end; it != end; ++it)
    steps.push_back((*it)[3]);
  EXPECT_EQ(steps,
            (std::vector<std::string>{"displacement", "ncs", "depth objects", "kautz seidel",
                                      "deformation", "volume", "scene", "viewer", "gallery"}));
  // Per-step durations are kept for the next run's estimate.
  const auto timings = ReadCsv(dir_ / "report" / "report_timings.csv");
  EXPECT_EQ(timings.size(), steps.size());
}

TEST_F(ReportCliTest, RefusesAFolderItDidNotWrite) {
  const fs::path foreign = dir_ / "foreign";
  fs::create_directories(foreign);
  { std::ofstream(foreign / "notes.txt") << "mine"; }
  const auto r = test_support::RunCommand(test_support::IbrBinary() + " report --quick --out " +
                                          foreign.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(test_support::CountLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.find("step 1"), std::string::npos);  // refused before any bench ran
  EXPECT_EQ(ReadText(foreign / "notes.txt"), "mine");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 2);  // report, foreign: no staging folder left
}

}  // namespace
