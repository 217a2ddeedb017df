// Smoke test of `ibr bench scene`'s driver (bench/scene_bench.h) on its
// --quick run: the documented columns, finite positive times, and what each
// configuration compiled: a disabled effect compiles exactly what the scene
// without it compiles, an enabled one more. Times are printed, not asserted.
#include "bench/scene_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "tests/support/gl_test.h"

namespace bench {
namespace {

class SceneBenchTest : public test_support::GlTest {};

double Value(const Table& t, const std::vector<std::string>& row, const char* column) {
  const std::string& text = row[t.Column(column)];
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  EXPECT_TRUE(end != text.c_str() && std::isfinite(v)) << column << " = '" << text << "'";
  return v;
}

TEST_F(SceneBenchTest, QuickRunMeasuresEveryConfigurationAndDisabledCompilesNothingMore) {
  SceneBenchOptions options;
  options.quick = true;
  const SceneBenchResult result = RunSceneBench(options);
  const std::vector<std::string> expected = {"effect",
                                             "on_ms",
                                             "disabled_ms",
                                             "absent_ms",
                                             "on_over_absent",
                                             "disabled_over_absent",
                                             "absent_again_over_absent",
                                             "on_over_absent_cpu",
                                             "disabled_over_absent_cpu",
                                             "absent_again_over_absent_cpu",
                                             "disabled_over_absent_lo",
                                             "disabled_over_absent_hi",
                                             "absent_again_over_absent_lo",
                                             "absent_again_over_absent_hi",
                                             "disabled_over_absent_cpu_lo",
                                             "disabled_over_absent_cpu_hi",
                                             "absent_again_over_absent_cpu_lo",
                                             "absent_again_over_absent_cpu_hi",
                                             "interval_coverage",
                                             "programs_on",
                                             "programs_disabled",
                                             "programs_absent",
                                             "samples_on",
                                             "samples_disabled",
                                             "samples_absent",
                                             "primitives_on",
                                             "primitives_disabled",
                                             "primitives_absent"};
  EXPECT_EQ(result.table.columns(), expected);
  ASSERT_EQ(result.table.rows().size(), 2u);
  for (const auto& row : result.table.rows()) {
    for (const char* c : {"on_ms", "disabled_ms", "absent_ms", "on_over_absent",
                          "disabled_over_absent", "absent_again_over_absent", "on_over_absent_cpu",
                          "disabled_over_absent_cpu", "absent_again_over_absent_cpu"}) {
      EXPECT_GT(Value(result.table, row, c), 0) << row[0] << " " << c;
    }
    EXPECT_EQ(Value(result.table, row, "programs_disabled"),
              Value(result.table, row, "programs_absent"))
        << row[0];
    EXPECT_GT(Value(result.table, row, "programs_on"), Value(result.table, row, "programs_absent"))
        << row[0];
    // The GL work of a frame: a disabled effect draws nothing, so its frame
    // passes exactly the absent scene's fragments and primitives; an enabled
    // one draws more.
    EXPECT_EQ(Value(result.table, row, "samples_disabled"),
              Value(result.table, row, "samples_absent"))
        << row[0];
    EXPECT_EQ(Value(result.table, row, "primitives_disabled"),
              Value(result.table, row, "primitives_absent"))
        << row[0];
    EXPECT_GT(Value(result.table, row, "samples_absent"), 0) << row[0];
    EXPECT_GT(Value(result.table, row, "primitives_on"),
              Value(result.table, row, "primitives_absent"))
        << row[0];
    // One round (quick): too few for a 95 % interval of the median.
    EXPECT_EQ(row[result.table.Column("disabled_over_absent_hi")], "nan") << row[0];
  }
  const std::filesystem::path dir = test_support::TestOutputDir();
  WriteSceneBench(result, dir / "scene.csv", dir);
  EXPECT_TRUE(std::filesystem::exists(dir / "scene.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "scene_bench.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "scene_bench_disabled.png"));
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
