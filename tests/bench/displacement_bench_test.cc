// `ibr bench displacement --quick` as a smoke test: it runs, and its CSV has
// the expected columns with finite values and plausible ranges (speed itself
// is printed by the benchmark, never asserted).
#include "bench/displacement_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "tests/support/gl_test.h"

namespace {

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) out.push_back(cell);
  return out;
}

TEST(DisplacementBench, QuickRunWritesAFiniteTable) {
  bench::DisplacementBenchOptions options;
  options.csv = test_support::TestOutputDir() / "displacement.csv";
  options.out = test_support::TestOutputDir() / "plots";
  options.quick = true;
  const bench::DisplacementBenchResult result = bench::RunDisplacementBench(options);
  std::ifstream csv(options.csv);
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> expected = {"family",
                                             "slices",
                                             "elevation_deg",
                                             "size_px",
                                             "ms_per_frame",
                                             "fragments_M",
                                             "fill_fraction",
                                             "coverage_iou",
                                             "mean_depth_error_texels",
                                             "p95_depth_error_texels",
                                             "see_through_pixels",
                                             "truth_ms_per_frame",
                                             "time_vs_truth"};
  ASSERT_EQ(Split(line), expected);
  int rows = 0;
  while (std::getline(csv, line)) {
    const auto cells = Split(line);
    ASSERT_EQ(cells.size(), expected.size()) << line;
    for (size_t c = 1; c < cells.size(); ++c) {
      const double v = std::strtod(cells[c].c_str(), nullptr);
      EXPECT_TRUE(std::isfinite(v)) << expected[c] << " in " << line;
      EXPECT_GE(v, 0) << expected[c] << " in " << line;
    }
    const double iou = std::strtod(cells[7].c_str(), nullptr);
    EXPECT_GT(iou, 0.5) << line;  // every family draws the bumps where the truth is
    EXPECT_LE(iou, 1.0) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 4 * 3 * 3);  // families x slice counts x elevations, one size
  EXPECT_EQ(static_cast<int>(result.table.rows().size()), rows);
  EXPECT_TRUE(std::filesystem::exists(options.out / "grazing_contact_sheet.png"));
  EXPECT_TRUE(std::filesystem::exists(options.out / "error_vs_time_elev60.png"));
}

}  // namespace
