// Smoke test of `ibr bench deform`'s driver (bench/deform_bench.h) on its
// --quick run: every mesh, mode and region scale measured with finite
// positive times, areas growing with the region, a summary per mesh and mode,
// distance-field times for ours and the OpenVDB peer, the CSV and plots
// written; FitLine against an exact line. Times are printed, not asserted.
#include "bench/deform_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "tests/support/gl_test.h"

namespace bench {
namespace {

class DeformBenchTest : public test_support::GlTest {};

double Value(const Table& t, const std::vector<std::string>& row, const char* column) {
  const std::string& text = row[t.Column(column)];
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  EXPECT_TRUE(end != text.c_str() && std::isfinite(v)) << column << " = '" << text << "'";
  return v;
}

TEST(DeformBenchFit, FitLineRecoversAnExactLineAndItsR2) {
  const LineFit exact = FitLine({0.1, 0.2, 0.4}, {3.2, 5.4, 9.8});  // y = 22 x + 1
  EXPECT_NEAR(exact.slope, 22.0, 1e-9);
  EXPECT_NEAR(exact.intercept, 1.0, 1e-9);
  EXPECT_NEAR(exact.r2, 1.0, 1e-12);
  const LineFit noisy = FitLine({0, 1, 2, 3}, {0, 2, 0, 2});  // slope 0.4, r2 0.2
  EXPECT_NEAR(noisy.slope, 0.4, 1e-12);
  EXPECT_NEAR(noisy.r2, 0.2, 1e-12);
}

TEST_F(DeformBenchTest, QuickRunMeasuresEveryMeshModeAndScale) {
  DeformBenchOptions options;
  options.quick = true;
  options.shared_data = test_support::SharedData("meshes").parent_path();
  const std::filesystem::path dir = test_support::TestOutputDir();
  options.csv = dir / "deform.csv";
  options.out = dir;
  const DeformBenchResult result = RunDeformBench(programs(), options);
  // 2 meshes x 3 modes x 2 scales.
  ASSERT_EQ(result.frames.rows().size(), 12u);
  for (size_t r = 0; r < result.frames.rows().size(); r += 2) {
    const auto& small = result.frames.rows()[r];
    const auto& large = result.frames.rows()[r + 1];
    EXPECT_GT(Value(result.frames, small, "ms"), 0);
    EXPECT_GT(Value(result.frames, large, "area_fraction"),
              Value(result.frames, small, "area_fraction"))
        << small[0] << " " << small[2];
  }
  // 2 x 3 summaries and one across-mesh row per mode.
  EXPECT_EQ(result.summary.rows().size(), 9u);
  // Ours and OpenVDB at two resolutions per mesh.
  ASSERT_EQ(result.sdf.rows().size(), 8u);
  for (const auto& row : result.sdf.rows()) EXPECT_GT(Value(result.sdf, row, "seconds"), 0);
  WriteDeformBench(result, options);
  for (const char* f : {"deform.csv", "deform_summary.csv", "deform_sdf.csv",
                        "deform_ms_vs_area.png", "deform_sdf_build.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
