// Smoke test of `ibr bench ncs`'s driver (bench/ncs_bench.h) on its --quick
// sweep: the CSV has the documented columns, every measured value is finite,
// every method and the ground truth appear, and the strip has all methods.
#include "bench/ncs_bench.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "tests/support/gl_test.h"

namespace bench {
namespace {

class NcsBenchTest : public test_support::GlTest {};

TEST_F(NcsBenchTest, QuickSweepWritesFiniteRowsForEveryMethod) {
  const NcsBenchOptions options = NcsBenchOptions::Quick();
  const NcsBenchResult result = RunNcsBench(programs(), options);
  const std::vector<std::string> expected = {"method",
                                             "view",
                                             "tiling",
                                             "steps",
                                             "c",
                                             "ms_per_frame",
                                             "min_ms_per_frame",
                                             "silhouette_iou",
                                             "wrong_silhouette_px",
                                             "mean_depth_error",
                                             "p95_depth_error",
                                             "early_termination_px",
                                             "truth_px",
                                             "triangles",
                                             "truth_subdivisions",
                                             "truth_subdivisions_wanted"};
  EXPECT_EQ(result.table.columns(), expected);
  // Per view x tiling: the truth + NCS (steps x c) + relief, POM and CRM (steps).
  const size_t per = 1 + options.steps.size() * (options.step_enlargements.size() + 3);
  EXPECT_EQ(result.table.rows().size(), per * options.views.size() * options.tilings.size());
  std::set<std::string> methods;
  for (const auto& row : result.table.rows()) {
    methods.insert(row[0]);
    for (const char* column :
         {"ms_per_frame", "min_ms_per_frame", "silhouette_iou", "wrong_silhouette_px",
          "mean_depth_error", "p95_depth_error", "early_termination_px", "truth_px", "triangles"}) {
      const std::string& text = row[result.table.Column(column)];
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      EXPECT_TRUE(end != text.c_str() && std::isfinite(v)) << column << " = '" << text << "'";
      EXPECT_GE(v, 0) << column;
    }
    const double iou = std::strtod(row[result.table.Column("silhouette_iou")].c_str(), nullptr);
    EXPECT_LE(iou, 1.0);
    EXPECT_GT(iou, 0.5) << row[0];  // every method draws the torus
  }
  EXPECT_EQ(methods, (std::set<std::string>{"ncs", "relief", "pom", "crm", "tessellated"}));
  // Fig. 7: one row per NCS setting; the truth's subdivisions at most the cap.
  EXPECT_EQ(result.fig7.rows().size(), options.steps.size() * options.step_enlargements.size() *
                                           options.views.size() * options.tilings.size());
  for (const auto& row : result.table.rows()) {
    const int used = std::stoi(row[result.table.Column("truth_subdivisions")]);
    const int wanted = std::stoi(row[result.table.Column("truth_subdivisions_wanted")]);
    EXPECT_EQ(used, std::min(wanted, options.max_truth_subdivisions));
  }
  EXPECT_EQ(result.summary.rows().size(),
            options.steps.size() * options.views.size() * options.tilings.size());
  EXPECT_FALSE(result.strip.empty());

  // The CSV round trip: header line equals the columns.
  const auto csv = test_support::TestOutputDir() / "ncs.csv";
  WriteNcsBench(result, csv, test_support::TestOutputDir());
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  std::string joined;
  for (size_t i = 0; i < expected.size(); ++i) joined += (i ? "," : "") + expected[i];
  EXPECT_EQ(header, joined);
  EXPECT_TRUE(
      std::filesystem::exists(test_support::TestOutputDir() / "ncs_silhouettes_grazing.png"));
  EXPECT_TRUE(std::filesystem::exists(test_support::TestOutputDir() / "ncs_fig7.csv"));
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
