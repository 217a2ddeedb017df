// Benchmark reporting: CSV round trip, gnuplot really draws a PNG, contact
// sheet placement.
#include "bench/report.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"

namespace bench {
namespace {

Table SampleTable() {
  Table t({"family", "ms_per_frame", "p95_error"});
  t.AddRow({"orthogonal", Num(10.0), Num(0.5)});
  t.AddRow({"orthogonal", Num(20.0), Num(0.25)});
  t.AddRow({"screen", Num(12.0), Num(0.4)});
  t.AddRow({"screen", Num(30.0), "nan"});
  return t;
}

TEST(Report, CsvHasHeaderAndRows) {
  const auto path = test_support::TestOutputDir() / "t.csv";
  SampleTable().WriteCsv(path);
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(),
            "family,ms_per_frame,p95_error\northogonal,10.000,0.500\northogonal,20.000,0.250\n"
            "screen,12.000,0.400\nscreen,30.000,nan\n");
  EXPECT_NE(SampleTable().Format().find("orthogonal"), std::string::npos);
}

TEST(Report, HasColumnNamesExactlyTheColumns) {
  const Table t = SampleTable();
  for (const std::string& c : t.columns()) EXPECT_TRUE(t.HasColumn(c)) << c;
  EXPECT_FALSE(t.HasColumn("p95"));
  EXPECT_FALSE(t.HasColumn(""));
}

TEST(Report, CsvQuotesCellsWithCommasQuotesAndLineBreaks) {
  const auto path = test_support::TestOutputDir() / "q.csv";
  Table t({"variant", "note"});
  t.AddRow({"default (ray, skip 64)", "say \"hi\""});
  t.AddRow({"two\nlines", "plain"});
  t.WriteCsv(path);
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(),
            "variant,note\n\"default (ray, skip 64)\",\"say \"\"hi\"\"\"\n\"two\nlines\",plain\n");
}

TEST(Report, GnuplotWritesADecodablePng) {
  const auto path = test_support::TestOutputDir() / "plot.png";
  PlotPng(SampleTable(),
          {.title = "error vs time",
           .x_column = "ms_per_frame",
           .y_column = "p95_error",
           .series_column = "family",
           .log_y = true},
          path);
  const auto header = core::ReadImageHeader(path);
  EXPECT_EQ(header.width, 900);
  EXPECT_EQ(header.height, 600);
  // Nothing but the PNG is left behind.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(path.parent_path()))
    ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(Report, PlotWithoutFinitePointsIsAnInputError) {
  Table t({"x", "y"});
  t.AddRow({"nan", "1"});
  EXPECT_THROW(
      PlotPng(t, {.x_column = "x", .y_column = "y"}, test_support::TestOutputDir() / "p.png"),
      core::InputError);
}

}  // namespace
}  // namespace bench
