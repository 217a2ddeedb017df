// `ibr bench export --quick` (bench/export_bench.h): one row per method, every
// figure finite; our meshes closed and outward; Open3D's TSDF of the cube
// maps read as far pinhole cameras (open3d_peer.py --orthographic
// far-pinhole) lies on the sphere within 1 % of its diagonal, which checks
// that conversion against a surface whose position is known (PEERS.md).
// Speed is printed, never asserted.
#include "bench/export_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/support/gl_test.h"

namespace bench {
namespace {

class ExportBenchTest : public test_support::GlTest {};

TEST_F(ExportBenchTest, QuickRunMeasuresEveryMethod) {
  const ExportBenchResult r =
      RunExportBench(programs(), ExportBenchOptions::Quick(), test_support::TestOutputDir());
  std::printf("%s\n", r.table.Format().c_str());
  const Table& t = r.table;
  ASSERT_EQ(t.rows().size(), 4u);  // ours, ours unrefined, CGAL, Open3D TSDF
  for (const auto& row : t.rows()) {
    const std::string& method = row[t.Column("method")];
    for (const char* c : {"to_truth_mean", "to_truth_p95", "from_truth_mean", "from_truth_p95",
                          "normal_consistency", "time_s"}) {
      EXPECT_TRUE(std::isfinite(CellNumber(row[t.Column(c)]))) << method << " " << c;
    }
    EXPECT_LT(CellNumber(row[t.Column("to_truth_p95")]), 0.01) << method;
    EXPECT_LT(CellNumber(row[t.Column("from_truth_p95")]), 0.01) << method;
    if (method.rfind("ibr ", 0) == 0) EXPECT_EQ(row[t.Column("closed_outward")], "1") << method;
  }
}

}  // namespace
}  // namespace bench
