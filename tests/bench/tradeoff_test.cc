// The report's analysis with analytic answers: the Pareto front, the
// plotter's series (points joined only along the knob, one set per panel),
// the families read from bench tables by column name, the progress
// estimate, the papers' interpolation and the heat maps' colours.
#include "bench/tradeoff.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "bench/gallery.h"
#include "bench/paper_tables.h"
#include "bench/report.h"
#include "bench/report_page.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"

namespace bench {
namespace {

TEST(ParetoFront, KeepsExactlyTheNonDominatedRowsOfEachPanel) {
  const double nan = std::nan("");
  const std::vector<TradeoffRow> rows = {
      {"a", "m", "1", 1.0, 10.0},  // fastest: front
      {"a", "m", "2", 2.0, 5.0},   // front
      {"a", "n", "1", 2.0, 6.0},   // dominated by (2, 5): same time, more error
      {"a", "n", "2", 3.0, 5.0},   // dominated by (2, 5): slower, same error
      {"a", "p", "", 4.0, 1.0},    // most accurate: front
      {"a", "q", "", 4.0, 1.0},    // equal to the row before: both on the front
      {"a", "r", "", nan, 0.0},    // not finite: never on it, dominates nothing
      {"b", "m", "1", 9.0, 9.0},   // alone in its panel: front, though worse than all of "a"
      {"b", "m", "2", 9.5, 9.5},   // dominated within "b"
  };
  const std::vector<bool> expected = {true, true, false, false, true, true, false, true, false};
  EXPECT_EQ(ParetoFront(rows), expected);
}

TEST(ParetoFront, TheTruthSetAsideLeavesTheMethodsFront) {
  // The truth is fastest and exact: with it counted it is the whole front.
  std::vector<TradeoffRow> rows = {
      {"a", "m", "8", 2.0, 0.3}, {"a", "m", "16", 3.0, 0.1}, {"a", "n", "8", 2.5, 0.4}};
  rows.push_back({"a", "truth", "", 1.0, 0.0, true});
  EXPECT_EQ(ParetoFront(rows), (std::vector<bool>{false, false, false, true}));
  EXPECT_EQ(ParetoFront(rows, false), (std::vector<bool>{true, true, false, false}));
  const Table t = TradeoffTable({"f", "f", "e", "k", rows});
  EXPECT_EQ(t.rows()[3][t.Column("truth")], "1");
  EXPECT_EQ(t.rows()[0][t.Column("pareto")], "0");
  EXPECT_EQ(t.rows()[0][t.Column("pareto_methods")], "1");
}

TEST(ParetoFront, EmptyAndSingleRows) {
  EXPECT_TRUE(ParetoFront({}).empty());
  EXPECT_EQ(ParetoFront({{"p", "m", "", 1.0, 1.0}}), std::vector<bool>{true});
}

TEST(PlotSeries, JoinsPointsAlongTheKnobNotAlongTime) {
  // Within panel "p", method "m": the knob orders 8 -> 16 -> 32 while the
  // times are not monotone in it (16 slices measured slower than 32); rows
  // come shuffled. Method "n" has no knob: lone points. Panel "q" holds the
  // same method name: a separate polyline.
  Table t({"panel", "method", "knob", "ms", "error", "front"});
  t.AddRow({"p", "m", "32", "3", "0.5", "1"});
  t.AddRow({"q", "m", "8", "10", "10", "1"});
  t.AddRow({"p", "m", "8", "1", "4", "1"});
  t.AddRow({"p", "n", "", "2", "3", "0"});
  t.AddRow({"p", "m", "16", "5", "2", "0"});
  t.AddRow({"q", "m", "16", "20", "5", "1"});
  t.AddRow({"p", "m", "64", "nan", "0.1", "0"});  // not drawn
  const std::vector<PlotSeries> s = PlotSeriesOf(t, {.x_column = "ms",
                                                     .y_column = "error",
                                                     .series_column = "method",
                                                     .panel_column = "panel",
                                                     .order_column = "knob",
                                                     .highlight_column = "front"});
  ASSERT_EQ(s.size(), 5u);
  using P = std::vector<std::pair<double, double>>;
  EXPECT_EQ(s[0].panel, "p");
  EXPECT_EQ(s[0].name, "m");
  EXPECT_TRUE(s[0].joined);
  EXPECT_EQ(s[0].points, (P{{1, 4}, {5, 2}, {3, 0.5}}));  // knob order 8, 16, 32
  EXPECT_EQ(s[1].name, "n");
  EXPECT_FALSE(s[1].joined);
  EXPECT_EQ(s[1].points, (P{{2, 3}}));
  EXPECT_TRUE(s[2].highlight);  // the front of "p", in time order
  EXPECT_EQ(s[2].points, (P{{1, 4}, {3, 0.5}}));
  EXPECT_EQ(s[3].panel, "q");
  EXPECT_EQ(s[3].points, (P{{10, 10}, {20, 5}}));
  EXPECT_TRUE(s[4].highlight);
  EXPECT_EQ(s[4].panel, "q");
}

TEST(PlotSeries, WithoutAKnobJoinsInXOrderAndLogAxesDropNonPositive) {
  Table t({"x", "y"});
  t.AddRow({"3", "1"});
  t.AddRow({"1", "2"});
  t.AddRow({"2", "0"});
  const auto s = PlotSeriesOf(t, {.x_column = "x", .y_column = "y", .log_y = true});
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].points, (std::vector<std::pair<double, double>>{{1, 2}, {3, 1}}));
}

TEST(Tradeoff, PanelsAndPlotWithTheFront) {
  TradeoffFamily f{"t", "test family", "error", "steps", {}};
  f.rows = {{"panel one", "m", "8", 1, 2},
            {"panel one", "m", "16", 2, 1},
            {"panel one", "truth", "", 5, 0, true},
            {"panel two", "m", "8", 10, 3}};
  const Table t = TradeoffTable(f);
  ASSERT_EQ(t.rows().size(), 4u);
  for (const auto& r : t.rows()) EXPECT_EQ(r[t.Column("pareto")], "1");
  const auto png = test_support::TestOutputDir() / "tradeoff.png";
  PlotTradeoff(f, png);  // the truth's 0 on a log axis is drawn at a floor
  EXPECT_GT(std::filesystem::file_size(png), 0u);
}

TEST(Tradeoff, ManyPanelsGoThreeToARow) {
  // 5 objects x 3 sizes, 6 methods each with 3 knob values: a 3 x 5 grid.
  TradeoffFamily f{"many", "many panels", "error", "slices", {}};
  for (int object = 0; object < 5; ++object) {
    for (int size : {128, 256, 512}) {
      for (int method = 0; method < 6; ++method) {
        for (int knob : {16, 64, 256}) {
          f.rows.push_back(
              {"object " + std::to_string(object) + " / " + std::to_string(size) + " px",
               "method " + std::to_string(method), std::to_string(knob),
               size * knob * (1 + method) * 1e-3, (1.0 + method) / knob});
        }
      }
    }
  }
  const auto png = test_support::TestOutputDir() / "many.png";
  PlotTradeoff(f, png);
  const auto header = core::ReadImageHeader(png);
  EXPECT_EQ(header.width, 3 * 560);
  EXPECT_EQ(header.height, 60 + 5 * 500);
}

TEST(Tradeoff, FamiliesReadByColumnName) {
  Table d({"object", "method", "slices", "size", "ms_per_frame", "p95_depth_error", "iou_mean"});
  d.AddRow({"bunny", "depth-object orthogonal", "64", "256", "10.5", "0.01", "0.9900"});
  d.AddRow({"bunny", "open3d tsdf:128", "0", "256", "2", "0.05", "0.9500"});
  const TradeoffFamily f = DepthObjectTradeoff(d);
  ASSERT_EQ(f.rows.size(), 2u);
  EXPECT_EQ(f.rows[0].panel, "bunny / 256 px");
  EXPECT_EQ(f.rows[0].knob, "64");
  EXPECT_EQ(f.rows[1].method, "open3d tsdf");  // the peer's resolution is its knob
  EXPECT_EQ(f.rows[1].knob, "128");
  EXPECT_DOUBLE_EQ(f.rows[1].error, 0.05);
  EXPECT_FALSE(f.rows[0].truth);
  Table v({"sweep", "volume", "variant", "sampling_voxels", "map_size", "size_px", "ms_per_frame",
           "p95_color_error_vs_finest"});
  v.AddRow({"volume", "tooth", "plain DVR (shaded)", "1.00", "0", "512", "100", ""});
  v.AddRow({"finest", "tooth", "peel 128^3 at 0.25 voxel", "0.25", "128", "512", "900", "0.000"});
  v.AddRow({"sampling", "tooth", "peel 64^3", "2.00", "64", "512", "150", "3.500"});
  v.AddRow({"map_size", "tooth", "peel", "1.00", "32", "512", "250", "1.250"});
  const TradeoffFamily vf = VolumeTradeoff(v);
  ASSERT_EQ(vf.rows.size(), 3u);  // the plain row has no error: not on this axis
  EXPECT_TRUE(vf.rows[0].truth);
  EXPECT_EQ(vf.rows[0].method, "finest (map 128^3 at 0.25 voxel)");
  EXPECT_EQ(vf.rows[1].knob, "2.00");  // sampling: the distance is the knob
  EXPECT_DOUBLE_EQ(vf.rows[1].error, 3.5);
  EXPECT_EQ(vf.rows[2].knob, "32");  // map size: the size is the knob
  EXPECT_EQ(vf.rows[2].panel, "tooth / 512 px");
  const TradeoffFamily silhouette = DepthObjectSilhouetteTradeoff(d);
  ASSERT_EQ(silhouette.rows.size(), 2u);
  EXPECT_NEAR(silhouette.rows[0].error, 0.01, 1e-12);  // 1 - IoU
  EXPECT_NEAR(silhouette.rows[1].error, 0.05, 1e-12);
  EXPECT_EQ(silhouette.rows[1].knob, "128");

  Table n({"method", "view", "tiling", "steps", "c", "ms_per_frame", "silhouette_iou"});
  n.AddRow({"tessellated", "grazing", "1", "", "", "4", "1.0000"});
  n.AddRow({"ncs", "grazing", "1", "16", "2.5", "6", "0.9750"});
  const TradeoffFamily g = NcsTradeoff(n);
  EXPECT_EQ(g.rows[1].method, "ncs c=2.5");
  EXPECT_EQ(g.rows[0].error, 0.0);
  EXPECT_TRUE(g.rows[0].truth);
  EXPECT_FALSE(g.rows[1].truth);
  EXPECT_NEAR(g.rows[1].error, 0.025, 1e-12);
}

TEST(Tradeoff, DeformFamiliesNameTheKnobSweptAndWhatStaysFixed) {
  Table t({"mesh", "size_px", "knob", "value", "mode", "resolution", "step_voxels", "ms_per_frame",
           "samples_per_ray", "silhouette_iou", "wrong_pixels", "mean_depth_error",
           "p95_depth_error"});
  t.AddRow({"spot", "512", "resolution", "32", "fixed", "32", "1.00", "20.5", "40.0", "0.98000",
            "120", "0.002", "0.010000"});
  t.AddRow({"spot", "512", "resolution", "128", "fixed", "128", "1.00", "60", "150.0", "0.99900",
            "8", "0.0001", "0.000500"});
  t.AddRow({"spot", "512", "step", "4.00", "jacobian", "128", "4.00", "25", "45.0", "0.99000", "50",
            "0.001", "0.004000"});
  const TradeoffFamily f = DeformTradeoff(t);
  ASSERT_EQ(f.rows.size(), 3u);
  EXPECT_EQ(f.id, "deform");
  EXPECT_EQ(f.rows[0].panel, "spot knife cut / 512 px");
  EXPECT_EQ(f.rows[0].method, "field resolution (fixed step 1.00 voxels)");
  EXPECT_EQ(f.rows[1].method, f.rows[0].method);  // one line along the resolution
  EXPECT_EQ(f.rows[1].knob, "128");
  EXPECT_DOUBLE_EQ(f.rows[1].ms, 60.0);
  EXPECT_DOUBLE_EQ(f.rows[1].error, 0.0005);
  EXPECT_EQ(f.rows[2].method, "jacobian step (field 128)");
  EXPECT_EQ(f.rows[2].knob, "4.00");
  for (const TradeoffRow& r : f.rows) EXPECT_FALSE(r.truth);  // the tracer is not timed
  // No truth: the front is that of the methods; 32 (fastest) and 128 (most accurate) are on it,
  // the Jacobian step is neither faster than 32 nor more accurate than 128 but between both.
  EXPECT_EQ(ParetoFront(f.rows), (std::vector<bool>{true, true, true}));
  const TradeoffFamily s = DeformSilhouetteTradeoff(t);
  EXPECT_EQ(s.id, "deform_silhouette");
  ASSERT_EQ(s.rows.size(), 3u);
  EXPECT_NEAR(s.rows[0].error, 0.02, 1e-12);  // 1 - IoU
  EXPECT_NEAR(s.rows[1].error, 0.001, 1e-12);
  EXPECT_EQ(s.rows[2].method, f.rows[2].method);
}

TEST(ReportProgress, EstimateFromThePreviousRunElseFromStepsDone) {
  const std::vector<std::string> names = {"a", "b", "c"};
  EXPECT_TRUE(std::isnan(EstimateSecondsLeft(names, 0, {}, {})));
  EXPECT_DOUBLE_EQ(EstimateSecondsLeft(names, 1, {4.0}, {}), 8.0);  // 4 s a step, 2 left
  const std::map<std::string, double> previous = {{"a", 1}, {"b", 2}, {"c", 3}};
  EXPECT_DOUBLE_EQ(EstimateSecondsLeft(names, 0, {}, previous), 6.0);
  EXPECT_DOUBLE_EQ(EstimateSecondsLeft(names, 2, {10, 10}, previous), 3.0);
  // A previous run without step "c": the steps done decide.
  EXPECT_DOUBLE_EQ(EstimateSecondsLeft(names, 2, {10, 20}, {{"a", 1}, {"b", 2}}), 15.0);
}

TEST(ReportProgress, ReadsTheTimingsOfOneMode) {
  const auto file = test_support::TestOutputDir() / "report_timings.csv";
  {
    std::ofstream out(file);
    out << "step,mode,seconds\na,quick,1.5\na,full,30\nb,full,40\n";
  }
  EXPECT_EQ(ReadStepTimings(file, "full"), (std::map<std::string, double>{{"a", 30}, {"b", 40}}));
  EXPECT_EQ(ReadStepTimings(file, "quick"), (std::map<std::string, double>{{"a", 1.5}}));
  {
    std::ofstream out(file);
    out << "step,mode,seconds\na,full,-3\n";
  }
  EXPECT_TRUE(ReadStepTimings(file, "full").empty());
  EXPECT_TRUE(ReadStepTimings(file.string() + ".absent", "full").empty());
}

TEST(PaperTables, InterpolatesLinearlyOrInLogLog) {
  // y = x^2 sampled at 10 and 40: log-log gives 20^2 exactly, linear the chord.
  EXPECT_NEAR(Interpolate({{40, 1600}, {10, 100}}, 20, true), 400.0, 1e-9);
  EXPECT_NEAR(Interpolate({{10, 100}, {40, 1600}}, 20, false), 600.0, 1e-9);
  EXPECT_NEAR(Interpolate({{10, 100}, {40, 1600}}, 80, true), 6400.0, 1e-6);  // extended
  EXPECT_TRUE(std::isnan(Interpolate({{10, 100}}, 20, false)));
}

TEST(HeatMap, RampEndsAndCoverageColours) {
  uint8_t rgb[3];
  HeatRamp(0.0, rgb);
  EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 0);
  HeatRamp(1.0 / 3.0, rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_EQ(rgb[1], 0);
  HeatRamp(5.0, rgb);  // clamped: white
  EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 3 * 255);
  core::Image8 a(4, 1, 1, 0), b(4, 1, 1, 0);
  core::ImageF da(4, 1, 1, 0.0f), db(4, 1, 1, 0.0f);
  a.at(0, 0, 0) = b.at(0, 0, 0) = 255;  // both: |2.5 - 2| / 1.5 = 1/3 -> red
  da.at(0, 0, 0) = 2.5f, db.at(0, 0, 0) = 2.0f;
  a.at(1, 0, 0) = 255;  // extra
  b.at(2, 0, 0) = 255;  // missing
  const core::Image8 h = DepthErrorHeatMap(a, da, b, db, 1.5);
  EXPECT_EQ(h.at(0, 0, 0), 255);
  EXPECT_EQ(h.at(0, 0, 1), 0);
  EXPECT_EQ(h.at(1, 0, 0), 255);  // magenta
  EXPECT_EQ(h.at(1, 0, 1), 0);
  EXPECT_EQ(h.at(1, 0, 2), 255);
  EXPECT_EQ(h.at(2, 0, 0), 0);  // cyan
  EXPECT_EQ(h.at(2, 0, 1), 255);
  EXPECT_EQ(h.at(3, 0, 0), 40);  // neither
}

TEST(HeatMap, ColorErrorIsTheWorstPremultipliedChannel) {
  core::ImageF a(4, 1, 4, 0.0f), b(4, 1, 4, 0.0f);
  for (int c = 0; c < 4; ++c) a.at(0, 0, c) = b.at(0, 0, c) = 0.5f;
  b.at(0, 0, 2) = 0.5f + 1.0f / 255;  // 1/255 at a scale of 3/255: t = 1/3 -> red
  a.at(2, 0, 3) = 1.0f;               // alpha only, far beyond the scale: white
  for (int c = 0; c < 4; ++c) a.at(3, 0, c) = b.at(3, 0, c) = 0.25f;  // equal: black
  const core::Image8 h = ColorErrorHeatMap(a, b, 3.0 / 255);
  EXPECT_EQ(h.at(0, 0, 0), 255);
  EXPECT_EQ(h.at(0, 0, 1), 0);
  EXPECT_EQ(h.at(0, 0, 2), 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(h.at(1, 0, c), 40) << "empty in both: dark grey";
    EXPECT_EQ(h.at(2, 0, c), 255);
    EXPECT_EQ(h.at(3, 0, c), 0);
  }
  EXPECT_EQ(h.at(0, 0, 3), 255);  // opaque
}

}  // namespace
}  // namespace bench
