// Smoke test of `ibr bench deform`'s driver (bench/deform_bench.h) on its
// --quick run: every mesh, mode and region scale measured with finite
// positive times, areas growing with the region, a summary per mesh and mode,
// distance-field times and accuracy for ours and the OpenVDB peers, the
// accuracy sweep against the double sphere tracer (finite errors within bounds, the finer
// field no worse than the coarse one), the CSV and plots written; FitLine
// against an exact line. Times are printed, not asserted.
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
  // 2 meshes x 7 modes x 2 scales.
  ASSERT_EQ(result.frames.rows().size(), 28u);
  for (size_t r = 0; r < result.frames.rows().size(); r += 2) {
    const auto& small = result.frames.rows()[r];
    const auto& large = result.frames.rows()[r + 1];
    EXPECT_GT(Value(result.frames, small, "ms"), 0);
    // The ray stage is part of the frame.
    EXPECT_GE(Value(result.frames, small, "ray_ms"), 0);
    EXPECT_LE(Value(result.frames, small, "ray_ms"), Value(result.frames, small, "ms"));
    EXPECT_GT(Value(result.frames, large, "area_fraction"),
              Value(result.frames, small, "area_fraction"))
        << small[0] << " " << small[2];
  }
  // 2 x 7 summaries and one across-mesh row per mode; each continuous mode
  // is its own ratios' baseline.
  EXPECT_EQ(result.summary.rows().size(), 21u);
  const Table& s = result.summary;
  for (const auto& row : s.rows()) {
    const std::string& mode = row[s.Column("mode")];
    const bool across = row[0].rfind("across meshes", 0) == 0;
    if (!across && (mode == "continuous" || mode == "paper_continuous")) {
      EXPECT_EQ(row[s.Column("over_continuous")], "1.000") << row[0] << " " << mode;
    }
  }
  // Ours, OpenVDB in C++ and OpenVDB in Python at two resolutions per mesh;
  // ours against CGAL's exact distance at the same nodes: float rounding, no
  // sign error (OpenVDB's accuracy is measured, not asserted).
  ASSERT_EQ(result.sdf.rows().size(), 12u);
  for (const auto& row : result.sdf.rows()) {
    EXPECT_GT(Value(result.sdf, row, "seconds"), 0);
    const std::string& builder = row[result.sdf.Column("builder")];
    if (builder == "openvdb_python") continue;
    EXPECT_GT(Value(result.sdf, row, "band_samples"), 100) << row[0] << " " << builder;
    EXPECT_GT(Value(result.sdf, row, "sign_samples"), 200) << row[0] << " " << builder;
    if (builder == "ours") {
      EXPECT_EQ(Value(result.sdf, row, "sign_errors"), 0) << row[0] << " " << row[1];
      EXPECT_LE(Value(result.sdf, row, "max_error_voxels"), 1e-4) << row[0] << " " << row[1];
    }
  }
  // The accuracy sweep: field resolutions 32 and 128 at a fixed step of one
  // voxel, then steps of 1 and 4 voxels per step policy at resolution 128.
  const Table& a = result.accuracy;
  EXPECT_EQ(a.columns(), (std::vector<std::string>{
                             "mesh", "size_px", "knob", "value", "mode", "resolution",
                             "step_voxels", "ms_per_frame", "samples_per_ray", "silhouette_iou",
                             "wrong_pixels", "mean_depth_error", "p95_depth_error"}));
  ASSERT_EQ(a.rows().size(), 8u);
  for (const auto& row : a.rows()) {
    EXPECT_EQ(row[a.Column("mesh")], "spot");
    EXPECT_GT(Value(a, row, "ms_per_frame"), 0);
    EXPECT_GT(Value(a, row, "samples_per_ray"), 0);
    // Every setting draws the cut Spot where the tracer sees it, give or take
    // its silhouette: the knobs move the error, not the object.
    const double iou = Value(a, row, "silhouette_iou");
    EXPECT_GT(iou, 0.9) << row[a.Column("knob")] << " " << row[a.Column("value")];
    EXPECT_LE(iou, 1.0);
    EXPECT_GE(Value(a, row, "p95_depth_error"), 0);
    EXPECT_LT(Value(a, row, "p95_depth_error"), 0.05);  // mesh sizes
  }
  const auto& coarse = a.rows()[0];
  const auto& fine = a.rows()[1];
  ASSERT_EQ(coarse[a.Column("knob")], "resolution");
  ASSERT_EQ(coarse[a.Column("value")], "32");
  ASSERT_EQ(fine[a.Column("value")], "128");
  // A field of 128 samples per axis holds the surface at least as well as
  // one of 32 (a quarter of the interpolation error, a quarter of the step).
  EXPECT_LE(Value(a, fine, "p95_depth_error"), Value(a, coarse, "p95_depth_error"));
  EXPECT_GE(Value(a, fine, "silhouette_iou"), Value(a, coarse, "silhouette_iou"));
  for (size_t r = 2; r < a.rows().size(); ++r) {
    EXPECT_EQ(a.rows()[r][a.Column("knob")], "step");
    EXPECT_EQ(a.rows()[r][a.Column("resolution")], "128");
  }
  // The two implicits at resolution 128: the depth cube's six 128^2 R32F
  // maps against the distance field's voxels, both drawing the cut Spot.
  const Table& im = result.implicits;
  ASSERT_EQ(im.rows().size(), 2u);
  EXPECT_EQ(im.rows()[0][im.Column("implicit")], "sdf");
  EXPECT_EQ(im.rows()[1][im.Column("implicit")], "depth-cube");
  EXPECT_EQ(Value(im, im.rows()[1], "bytes"), 6.0 * 128 * 128 * 4);
  EXPECT_GT(Value(im, im.rows()[0], "bytes"), 10 * Value(im, im.rows()[1], "bytes"));
  for (const auto& row : im.rows()) {
    EXPECT_GT(Value(im, row, "ms_per_frame"), 0);
    EXPECT_GT(Value(im, row, "build_seconds"), 0);
    EXPECT_GT(Value(im, row, "silhouette_iou"), 0.9) << row[im.Column("implicit")];
    EXPECT_LT(Value(im, row, "p95_depth_error"), 0.05) << row[im.Column("implicit")];
  }
  WriteDeformBench(result, options);
  for (const char* f : {"deform.csv", "deform_summary.csv", "deform_sdf.csv", "deform_accuracy.csv",
                        "deform_implicit.csv", "deform_ms_vs_area.png", "deform_sdf_build.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
