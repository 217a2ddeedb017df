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
                                             "programs_on",
                                             "programs_disabled",
                                             "programs_absent"};
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
  }
  const std::filesystem::path dir = test_support::TestOutputDir();
  WriteSceneBench(result, dir / "scene.csv", dir);
  EXPECT_TRUE(std::filesystem::exists(dir / "scene.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "scene_bench.png"));
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
