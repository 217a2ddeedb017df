// The report's headline rows: CSVs read back as written, each row computed
// from known cells, summary.md written only into a report folder.
#include "bench/report_summary.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/support/gl_test.h"

namespace bench {
namespace {
namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(ReportSummary, CsvRoundTripsQuotedCells) {
  Table t({"variant", "note", "x"});
  t.AddRow({"default (ray, skip 64)", "say \"hi\"", "1.5"});
  t.AddRow({"line\nbreak", "", "nan"});
  const fs::path path = test_support::TestOutputDir() / "round.csv";
  t.WriteCsv(path);
  const Table back = ReadCsv(path);
  EXPECT_EQ(back.columns(), t.columns());
  EXPECT_EQ(back.rows(), t.rows());
}

TEST(ReportSummary, RaggedOrUnterminatedCsvIsRefusedNamingTheFile) {
  std::stringstream ragged("a,b\n1,2\n3\n");
  try {
    ReadCsv(ragged, "x.csv");
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'x.csv': row 3 has 1 cells"), std::string::npos)
        << e.what();
  }
  std::stringstream open_quote("a\n\"never closed\n");
  EXPECT_THROW(ReadCsv(open_quote, "y.csv"), core::InputError);
  std::stringstream empty("");
  EXPECT_THROW(ReadCsv(empty, "z.csv"), core::InputError);
}

// A report folder with two of the benches' CSVs, cells chosen so each
// figure of the rows is known.
fs::path FakeReport(const std::string& name) {
  const fs::path dir = test_support::TestOutputDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir / "depth_object");
  fs::create_directories(dir / "deform");
  Table d({"object", "method", "slices", "size", "ms_per_frame", "iou_min", "p95_depth_error"});
  d.AddRow({"bunny", "depth-object ray-skip-subtexel", "256", "512", "100", "0.9950", "0.0040"});
  d.AddRow({"cow", "depth-object ray-skip-subtexel", "256", "512", "300", "0.9900", "0.0020"});
  d.AddRow({"cow", "depth-object ray-skip-subtexel", "64", "512", "50", "0.5000", "0.9"});
  d.AddRow({"bunny", "open3d tsdf:256", "0", "512", "50", "0.99", "0.0050"});
  d.WriteCsv(dir / "depth_object" / "depth_object.csv");
  Table c({"mesh", "mode", "over_continuous"});
  c.AddRow({"spot", "continuous", "1.000"});
  c.AddRow({"spot", "cut", "0.98"});
  c.AddRow({"cow", "cut", "1.15"});
  c.AddRow({"spot", "cut_skip", "1.2"});
  c.AddRow({"cow", "cut_skip", "1.2"});
  c.WriteCsv(dir / "deform" / "deform_summary.csv");
  std::ofstream(dir / core::kOutputMarker)
      << "ibr output: ibr report --out x\ndepth_object/depth_object.csv\n"
         "deform/deform_summary.csv\n";
  return dir;
}

TEST(ReportSummary, RowsComeFromTheCsvCells) {
  const fs::path dir = FakeReport("summary_rows");
  const std::vector<SummaryRow> rows = SummaryRows(dir);
  ASSERT_EQ(rows.size(), 3u);  // accuracy, beside TSDF, cut; the rest have no CSV here
  EXPECT_NE(rows[0].what.find("2 objects"), std::string::npos) << rows[0].what;
  EXPECT_EQ(rows[0].result,
            "silhouette IoU >= 0.9900, p95 depth error <= 0.0040 cube edges, 200 ms a frame "
            "(median)");
  EXPECT_EQ(rows[1].result,
            "p95 depth error 0.0040 against 0.0050; a still frame takes 2.00x the TSDF mesh's");
  EXPECT_EQ(rows[2].result, "0.98-1.15x per mesh; with the cut's empty-space skipping 1.20x");
  EXPECT_EQ(rows[2].data, "deform/deform_summary.csv");
  const std::string md = SummaryMarkdown(rows);
  EXPECT_NE(md.find("| what | result | data |"), std::string::npos);
  EXPECT_NE(md.find("[deform/deform_summary.csv](deform/deform_summary.csv)"), std::string::npos);
}

TEST(ReportSummary, VolumeGoalsRowStatesEachGoalBesideItsMeasure) {
  const fs::path dir = FakeReport("summary_volume_goals");
  fs::create_directories(dir / "volume");
  Table g({"quantity", "goal", "measured", "met", "note"});
  g.AddRow({"eq. 6+7 frame / displaced floor frame", "<= 2", "tooth 1.40x, bucky 2.10x", "no", ""});
  g.AddRow({"unsplit displaced / plain DVR, per fragment", "<= 2.5", "tooth 1.90x", "yes", ""});
  g.AddRow({"displaced / plain DVR, per frame", "stated", "tooth 1.30x", "-", ""});
  g.AddRow({"ours displaced frame / VTK prewarped frame", "<= 1", "tooth 0.40x", "yes", ""});
  g.WriteCsv(dir / "volume" / "volume_goals.csv");
  const std::vector<SummaryRow> rows = SummaryRows(dir);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[3].data, "volume/volume_goals.csv");
  EXPECT_EQ(rows[3].result,
            "eq. 6+7 frame / displaced floor: tooth 1.40x, bucky 2.10x (goal <= 2, met: no); "
            "unsplit displaced / plain per fragment: tooth 1.90x (goal <= 2.5, met: yes); ours / "
            "VTK on the prewarped volume: tooth 0.40x (goal <= 1, met: yes)");
}

TEST(ReportSummary, WritesIntoAReportFolderAndListsItInTheMarker) {
  const fs::path dir = FakeReport("summary_write");
  WriteSummary(dir);
  EXPECT_NE(Slurp(dir / "summary.md").find("# Headline results"), std::string::npos);
  const std::string marker = Slurp(dir / core::kOutputMarker);
  EXPECT_NE(marker.find("\nsummary.md\n"), std::string::npos) << marker;
  WriteSummary(dir);  // again: listed once, replaced
  const std::string again = Slurp(dir / core::kOutputMarker);
  EXPECT_EQ(again.find("summary.md"), again.rfind("summary.md"));
}

TEST(ReportSummary, NeverTouchesAFolderOrFileIbrDidNotWrite) {
  const fs::path plain = test_support::TestOutputDir() / "summary_plain";
  fs::remove_all(plain);
  fs::create_directories(plain);
  EXPECT_THROW(WriteSummary(plain), core::InputError);
  EXPECT_FALSE(fs::exists(plain / "summary.md"));

  const fs::path dir = FakeReport("summary_foreign");
  std::ofstream(dir / "summary.md") << "mine";
  EXPECT_THROW(WriteSummary(dir), core::InputError);
  EXPECT_EQ(Slurp(dir / "summary.md"), "mine");

  const fs::path empty = test_support::TestOutputDir() / "summary_empty";
  fs::remove_all(empty);
  fs::create_directories(empty);
  std::ofstream(empty / core::kOutputMarker) << "ibr output: x\n";
  EXPECT_THROW(WriteSummary(empty), core::InputError);
  EXPECT_FALSE(fs::exists(empty / "summary.md"));
}

}  // namespace
}  // namespace bench
