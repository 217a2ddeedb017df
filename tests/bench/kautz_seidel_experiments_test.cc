// Smoke test of `ibr bench kautz-seidel`'s driver
// (bench/kautz_seidel_experiments.h) on its --quick sweep: every table has
// its rows, every measured value is finite, the renders match their truths,
// and the visual hull shades fewer slice fragments than the depth object
// (the cube rig's opposite silhouettes are skipped, Kautz-Seidel sec. 6).
#include "bench/kautz_seidel_experiments.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "tests/support/gl_test.h"

namespace bench {
namespace {

class KautzSeidelTest : public test_support::GlTest {};

double Value(const Table& t, const std::vector<std::string>& row, const std::string& column) {
  const std::string& text = row[t.Column(column)];
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  EXPECT_TRUE(end != text.c_str() && std::isfinite(v)) << column << " = '" << text << "'";
  return v;
}

TEST_F(KautzSeidelTest, QuickRunFillsEveryTable) {
  KautzSeidelOptions options;
  options.quick = true;
  options.timer = {.warmup_frames = 0, .timed_frames = 1};
  const KautzSeidelResult r = RunKautzSeidelExperiments(programs(), options);
  EXPECT_EQ(r.object, "cup");
  // Fig. 12: 2 sizes + 2 slice counts, both methods.
  ASSERT_EQ(r.fig12.rows().size(), 8u);
  for (const auto& row : r.fig12.rows()) {
    EXPECT_GT(Value(r.fig12, row, "ms_per_frame"), 0);
    EXPECT_GT(Value(r.fig12, row, "covered_pixels"), 0);
  }
  // Angle: 2 methods x 2 elevations x 2 azimuths; the face-on view is 1.
  ASSERT_EQ(r.angle.rows().size(), 8u);
  for (size_t i = 0; i < r.angle.rows().size(); ++i) {
    const auto& row = r.angle.rows()[i];
    EXPECT_GT(Value(r.angle, row, "ms_over_face_on"), 0);
    EXPECT_GT(Value(r.angle, row, "slice_fragments"), 0);
    if (i % 4 == 0) {
      EXPECT_EQ(row[r.angle.Column("fragments_over_face_on")], "1.000");
    }
    // Rows 0..3 the depth object, 4..7 the hull at the same views: the hull
    // tests three silhouettes per slice where the depth object tests six maps.
    if (i < 4) {
      EXPECT_LT(Value(r.angle, r.angle.rows()[i + 4], "slice_fragments"),
                0.75 * Value(r.angle, row, "slice_fragments"));
    }
  }
  // The two quality points: the object drawn at about its target size, close to the truth.
  ASSERT_EQ(r.points.rows().size(), 2u);
  for (const auto& row : r.points.rows()) {
    const double target = Value(r.points, row, "target_object_px");
    EXPECT_NEAR(Value(r.points, row, "object_px"), target, 0.1 * target + 2);
    EXPECT_GT(Value(r.points, row, "iou"), 0.9);
  }
  EXPECT_EQ(r.points.rows()[1][r.points.Column("paper_ms_over_first")], "8.889");
  // The donut at 15, 20, 25 slices against its tessellated truth.
  ASSERT_EQ(r.donut.rows().size(), 3u);
  for (const auto& row : r.donut.rows()) {
    EXPECT_GT(Value(r.donut, row, "coverage_iou"), 0.9);
    EXPECT_EQ(row[r.donut.Column("base_triangles")], "1250");  // the paper's 625 quads
  }
  const auto dir = test_support::TestOutputDir();
  WriteKautzSeidelExperiments(r, dir / "ks.csv", dir);
  for (const char* f : {"ks.csv", "ks_fig12.csv", "ks_angle.csv", "ks_donut.csv",
                        "ks_fig12_time_vs_coverage.png", "ks_time_vs_angle.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
