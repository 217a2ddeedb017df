// Smoke test of `ibr bench deform`'s driver (bench/deform_bench.h) on its
// --quick run: every mesh, mode and region scale measured with finite
// positive times, areas growing with the region, a summary per mesh and mode,
// distance-field times and accuracy for ours and the OpenVDB peers, the
// accuracy sweep against the double sphere tracer (finite errors within
// bounds, the finer field no worse than the coarse one), the workloads (the
// wedge cut against the double reference and its ray fraction against a CPU
// count, the forward-mesh peer's levels, the spread's tessellations), the CSV
// with its columns and forward-mesh rows, and plots written; FitLine against
// an exact line. Times are printed, not asserted.
#include "bench/deform_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>

#include "bench/paper_tables.h"
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

// The goals table: the paper's Table 1 figures computed from its ms (ESK /
// continuous 75.77 / 89.79 to 126.00 / 83.89; the share of the cut's extra
// time ESK removes, (cut - ESK) / (cut - continuous), 76 % for the
// armadillo to 110 % for the hand), ours and whether each goal is met.
TEST(DeformGoals, PaperFiguresOursAndWhetherMet) {
  DeformWedgeFigures w;
  w.mesh = "spot";
  w.opening_rad = M_PI / 2;
  w.ratio = 1.25, w.ratio_lo = 1.2, w.ratio_hi = 1.31;
  w.skip_removes_percent = 40;
  w.agree_fraction = 0.999;
  DeformForwardFigures f;
  f.ray_ms = 10, f.ray_p95 = 0.002;
  f.equal_level = 2, f.equal_ms = 5, f.equal_triangles = 1000, f.interpolated_ms = 4;
  DeformSpreadFigures sp;
  sp.ray_spread = 1.05, sp.mesh_over_plain_max = 1.5, sp.rounds = 6;
  const Table t = Correa2007GoalsTable(w, f, sp);
  ASSERT_EQ(t.rows().size(), 6u);
  const int paper = t.Column("paper"), met = t.Column("met");
  EXPECT_EQ(t.rows()[0][paper].rfind("0.84-1.50", 0), 0u) << t.rows()[0][paper];
  EXPECT_EQ(t.rows()[1][paper].rfind("76-110 %", 0), 0u) << t.rows()[1][paper];
  EXPECT_EQ(t.rows()[0][met], "yes");  // 1.25 <= 1.3
  EXPECT_EQ(t.rows()[1][met], "no");   // 40 % < 50 %
  EXPECT_EQ(t.rows()[2][met], "yes");  // 99.9 % >= 99.5 %
  EXPECT_NE(t.rows()[3][t.Column("note")].find("the forward mesh wins"), std::string::npos);
  EXPECT_EQ(t.rows()[4][met], "yes");  // 1.05 <= 1.1
  EXPECT_EQ(t.rows()[5][met], "no");   // 1.5 > 1.2
}

// The workloads of issue 35 in a quick run: the wedge, the forward mesh and
// the spread, their values finite and consistent with what they count.
void CheckWorkloads(const DeformBenchResult& result) {
  const Table& f = result.frames;
  const Table wedge = Filtered(
      f, [&](const std::vector<std::string>& r) { return r[f.Column("workload")] == "wedge"; });
  ASSERT_EQ(wedge.rows().size(), 8u);
  std::map<std::string, std::vector<std::string>> by_mode;
  for (const auto& row : wedge.rows()) {
    by_mode[row[f.Column("mode")]] = row;
    EXPECT_GT(Value(wedge, row, "ms"), 0);
    EXPECT_GT(Value(wedge, row, "samples_per_ray"), 0);
    EXPECT_GE(Value(wedge, row, "rejected_per_ray"), 0);
  }
  for (const char* mode : {"baseline", "cut", "cut_skip", "cut_csg"})
    ASSERT_TRUE(by_mode.count(mode)) << mode;
  // Without a cut nothing is rejected; the search rejects the hits inside
  // the wedge, on a share of the rays the bench placed it for.
  EXPECT_EQ(Value(wedge, by_mode["baseline"], "rejected_per_ray"), 0);
  // The cut's shader without the cut marches the baseline's rays: the same
  // samples, nothing rejected (what makes it the per-sample cost's measure).
  ASSERT_TRUE(by_mode.count("cut_skip_shader_no_cut"));
  EXPECT_EQ(Value(wedge, by_mode["cut_skip_shader_no_cut"], "rejected_per_ray"), 0);
  EXPECT_NEAR(Value(wedge, by_mode["cut_skip_shader_no_cut"], "samples_per_ray"),
              Value(wedge, by_mode["baseline"], "samples_per_ray"), 0.05);
  EXPECT_GT(Value(wedge, by_mode["cut_skip"], "rejected_per_ray"), 0);
  const double fraction = Value(wedge, by_mode["cut_skip"], "cut_ray_fraction");
  EXPECT_GT(fraction, 0.0);
  EXPECT_LE(fraction, 1.0);
  // The same share from the CPU: the baseline's hit points where the
  // analytic alpha is > 0 (each such ray rejects its first hit).
  const DeformWedgeFigures& w = result.wedge;
  EXPECT_NEAR(w.ray_fraction, w.ray_fraction_cpu, 0.05);
  EXPECT_NEAR(w.ray_fraction, fraction, 1e-4);  // the CSV rounds it
  // The cut's skip only ever lengthens steps: no more samples than without.
  EXPECT_LE(w.samples_skip, w.samples_cut);
  EXPECT_GT(w.samples_cut, w.samples_baseline);
  EXPECT_TRUE(std::isfinite(w.ratio) && w.ratio > 0) << w.ratio;
  EXPECT_TRUE(w.skip_removes_percent >= 0 && w.skip_removes_percent <= 100)
      << w.skip_removes_percent;
  // Every cut mode draws the wedge where the double reference does.
  for (const char* mode : {"cut", "cut_skip", "cut_csg"}) {
    EXPECT_GE(Value(wedge, by_mode[mode], "agree_fraction"), 0.995) << mode;
    EXPECT_LT(Value(wedge, by_mode[mode], "p95_depth_error"), 0.05) << mode;
  }
  EXPECT_EQ(w.Line().rfind("wedge: cut_skip/baseline ", 0), 0u) << w.Line();

  // The forward mesh: the ray pass, then subdivision levels 0, 1, 2, each
  // four times the triangles of the last and no further from the reference.
  const Table forward = Filtered(
      f, [&](const std::vector<std::string>& r) { return r[f.Column("workload")] == "forward"; });
  ASSERT_EQ(forward.rows().size(), 4u);
  EXPECT_EQ(forward.rows()[0][f.Column("mode")], "continuous");
  for (size_t r = 1; r < forward.rows().size(); ++r) {
    const auto& row = forward.rows()[r];
    EXPECT_EQ(row[f.Column("mode")], "forward-mesh");
    EXPECT_GT(Value(forward, row, "ms"), 0);
    EXPECT_GT(Value(forward, row, "agree_fraction"), 0.95);
    EXPECT_LT(Value(forward, row, "p95_depth_error"), 0.05);
    if (r > 1) {
      EXPECT_EQ(Value(forward, row, "triangles"),
                4 * Value(forward, forward.rows()[r - 1], "triangles"));
      EXPECT_LE(Value(forward, row, "p95_depth_error"),
                Value(forward, forward.rows()[r - 1], "p95_depth_error") * 1.05 + 1e-4);
    }
  }

  // The spread: four tessellations of the capped bunny, coarse to fine; the
  // finest is its own ratio's baseline.
  const Table& sp = result.spread;
  ASSERT_EQ(sp.rows().size(), 4u);
  for (size_t r = 0; r < sp.rows().size(); ++r) {
    const auto& row = sp.rows()[r];
    EXPECT_GT(Value(sp, row, "ray_ms"), 0);
    EXPECT_GT(Value(sp, row, "plain_mesh_ms"), 0);
    EXPECT_GT(Value(sp, row, "ray_over_scan"), 0);
    EXPECT_GT(Value(sp, row, "samples_per_ray"), 0);
    if (r > 0) {
      EXPECT_GT(Value(sp, row, "triangles"), Value(sp, sp.rows()[r - 1], "triangles"));
    }
  }
  EXPECT_NEAR(Value(sp, sp.rows()[0], "triangles"), 6000, 600);
  EXPECT_EQ(Value(sp, sp.rows()[3], "ray_over_scan"), 1.0);
  EXPECT_TRUE(std::isfinite(result.spread_figures.ray_spread));
}

// Correa 2007 Fig. 3 (b)-(d) as counts: on the narrow pull, the Jacobian
// step (eq. 4) misses fewer rays of the pulled column than the fixed and
// threshold steps do (the figure's claim), counted against the double reference; every policy's
// counts are consistent and its table row complete. A counted result, not
// speed (the ms column is printed only).
TEST_F(DeformBenchTest, NarrowPullJacobianStepMissesFewerRaysThanTheFixedStep) {
  DeformPullFigures figures;
  const Table t = RunDeformNarrowPull(programs(), 128, figures);
  std::printf("%s\n%s\n", t.Format().c_str(), figures.Line().c_str());
  EXPECT_EQ(t.columns(),
            (std::vector<std::string>{"policy", "size_px", "field_resolution", "step_voxels",
                                      "misses", "wrong_pixels", "compared_pixels",
                                      "samples_per_ray", "ms_per_frame"}));
  ASSERT_EQ(t.rows().size(), 3u);
  for (const auto& row : t.rows()) {
    for (const char* c : {"misses", "wrong_pixels", "samples_per_ray", "ms_per_frame"})
      EXPECT_GE(Value(t, row, c), 0) << c;
    EXPECT_GT(Value(t, row, "compared_pixels"), 1000);
  }
  const auto* fixed = figures.Find("fixed");
  const auto* threshold = figures.Find("threshold");
  const auto* jacobian = figures.Find("jacobian");
  ASSERT_TRUE(fixed && threshold && jacobian);
  for (const auto* p : {fixed, threshold, jacobian}) {
    EXPECT_LE(p->misses, p->wrong) << p->name;  // a miss is a wrong pixel
    EXPECT_GT(p->samples_per_ray, 0) << p->name;
  }
  // The fixed step misses part of the column, the threshold step too (Fig.
  // 3 (b), (c)); the Jacobian step fewer than either (d).
  EXPECT_GT(fixed->misses, 0);
  EXPECT_LT(jacobian->misses, fixed->misses);
  EXPECT_LT(jacobian->misses, threshold->misses);
  EXPECT_NO_GL_ERROR();
}

TEST_F(DeformBenchTest, QuickRunMeasuresEveryMeshModeAndScale) {
  DeformBenchOptions options;
  options.quick = true;
  options.shared_data = test_support::SharedData("meshes").parent_path();
  const std::filesystem::path dir = test_support::TestOutputDir();
  options.csv = dir / "deform.csv";
  options.out = dir;
  const DeformBenchResult result = RunDeformBench(programs(), options);
  const Table sweep = Filtered(result.frames, [&](const std::vector<std::string>& r) {
    return r[result.frames.Column("workload")] == "sweep";
  });
  // 2 meshes x 7 modes x 2 scales.
  ASSERT_EQ(sweep.rows().size(), 28u);
  for (size_t r = 0; r < sweep.rows().size(); r += 2) {
    const auto& small = sweep.rows()[r];
    const auto& large = sweep.rows()[r + 1];
    EXPECT_GT(Value(sweep, small, "ms"), 0);
    // The ray stage is part of the frame.
    EXPECT_GE(Value(sweep, small, "ray_ms"), 0);
    EXPECT_LE(Value(sweep, small, "ray_ms"), Value(sweep, small, "ms"));
    EXPECT_GT(Value(sweep, large, "area_fraction"), Value(sweep, small, "area_fraction"))
        << small[1] << " " << small[3];
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
  CheckWorkloads(result);
  WriteDeformBench(result, options);
  for (const char* f : {"deform.csv", "deform_summary.csv", "deform_sdf.csv", "deform_accuracy.csv",
                        "deform_implicit.csv", "deform_spread.csv", "deform_ms_vs_area.png",
                        "deform_sdf_build.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  // The CSV as written: the columns and the peer's rows.
  std::ifstream csv(dir / "deform.csv");
  std::string header, line;
  std::getline(csv, header);
  for (const char* column : {"samples_per_ray", "rejected_per_ray", "cut_ray_fraction"})
    EXPECT_NE(header.find(column), std::string::npos) << column;
  int forward_rows = 0;
  while (std::getline(csv, line)) forward_rows += line.find(",forward-mesh,") != std::string::npos;
  EXPECT_GE(forward_rows, 3);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
