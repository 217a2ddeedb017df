// The viewer's transfer-function editor model
// (apps/viewer/transfer_function_editor.h), CPU only: window/level against
// the analytic ramp, the shape of a preset kept under a new window, control
// point edits, the histogram against a direct count, and the inline JSON a
// saved scene holds read back bit for bit.
#include <gtest/gtest.h>

#include <sstream>

#include "apps/viewer/transfer_function_editor.h"
#include "core/error.h"

namespace viewer {
namespace {

const glm::dvec2 kRange(0, 255);  // a uint8 volume's normalisation range

TEST(TransferEditor, WindowLevelOfALinearRampIsTheRadiologistsRamp) {
  TransferEditor editor(core::TransferPreset("ramp"), kRange, {0, 255});
  EXPECT_EQ(editor.window().centre, 127.5);
  EXPECT_EQ(editor.window().width, 255);
  editor.SetWindow({100, 50});
  const core::TransferFunction& tf = editor.transfer();
  EXPECT_EQ(tf.units, core::TransferUnits::kData);
  // Transparent below level - width/2, opaque above level + width/2, linear between.
  for (double v : {0.0, 60.0, 75.0}) EXPECT_EQ(tf.Evaluate(v).a, 0.0) << v;
  for (double v : {125.0, 200.0, 255.0}) EXPECT_EQ(tf.Evaluate(v).a, 1.0) << v;
  for (double v : {80.0, 100.0, 112.5}) EXPECT_NEAR(tf.Evaluate(v).a, (v - 75) / 50, 1e-12) << v;
  EXPECT_EQ(editor.window().centre, 100);
  EXPECT_EQ(editor.window().width, 50);
  EXPECT_THROW(editor.SetWindow({100, 0}), core::InputError);
}

TEST(TransferEditor, ANewWindowKeepsAPresetsShape) {
  const core::TransferFunction tooth = core::TransferPreset("tooth");
  TransferEditor editor(tooth, kRange, {0, 255});
  ASSERT_EQ(editor.transfer().points.size(), tooth.points.size());
  for (size_t i = 0; i < tooth.points.size(); ++i)
    EXPECT_DOUBLE_EQ(editor.transfer().points[i].s, 255 * tooth.points[i].s);
  editor.SetWindow({40, 20});  // [30, 50]
  for (size_t i = 0; i < tooth.points.size(); ++i) {
    EXPECT_NEAR(editor.transfer().points[i].s, 30 + 20 * tooth.points[i].s, 1e-12) << i;
    EXPECT_EQ(editor.transfer().points[i].rgba, tooth.points[i].rgba) << i;
  }
}

TEST(TransferEditor, DragMovesWidthAlongXAndLevelAlongY) {
  const WindowLevel wl = DragWindowLevel({100, 50}, {10, -4}, 2);
  EXPECT_EQ(wl.width, 70);
  EXPECT_EQ(wl.centre, 92);
  EXPECT_EQ(DragWindowLevel({100, 50}, {-100, 0}, 2).width, 2);  // never below a pixel
}

TEST(TransferEditor, ControlPointsAreAddedMovedAndDeleted) {
  TransferEditor editor(core::TransferPreset("ramp"), kRange, {0, 255});
  const size_t i = editor.AddPoint(51);
  ASSERT_EQ(i, 1u);
  ASSERT_EQ(editor.transfer().points.size(), 3u);
  EXPECT_NEAR(editor.transfer().points[1].rgba.a, 0.2, 1e-12);  // the curve's value there
  EXPECT_NEAR(editor.transfer().points[1].rgba.r, 0.2, 1e-12);
  EXPECT_EQ(editor.AddPoint(51), 1u);  // already there
  EXPECT_EQ(editor.AddPoint(200, 0.9), 2u);
  EXPECT_EQ(editor.transfer().points[2].rgba.a, 0.9);
  // Moved past its right neighbour: stops just before it; opacity clamped.
  editor.MovePoint(1, 300, 1.5);
  EXPECT_LT(editor.transfer().points[1].s, 200);
  EXPECT_GT(editor.transfer().points[1].s, 199.9);
  EXPECT_EQ(editor.transfer().points[1].rgba.a, 1.0);
  editor.SetColour(1, {1, 0, 0.5});
  EXPECT_EQ(editor.transfer().points[1].rgba, glm::dvec4(1, 0, 0.5, 1));
  EXPECT_NO_THROW(editor.transfer().Check("edited"));
  // Picked within the tolerance, in pixels of a 255 x 1 canvas of 255 x 100 px.
  EXPECT_EQ(editor.Pick(197, 0.88, {1, 0.01}, 6), std::optional<size_t>(2));
  EXPECT_EQ(editor.Pick(150, 0.5, {1, 0.01}, 6), std::nullopt);
  EXPECT_TRUE(editor.DeletePoint(1));
  EXPECT_TRUE(editor.DeletePoint(0));
  EXPECT_TRUE(editor.DeletePoint(0));
  EXPECT_FALSE(editor.DeletePoint(0));  // the last point stays
  EXPECT_EQ(editor.transfer().points.size(), 1u);
}

TEST(TransferEditor, PresetsIncludeTheCoreOnesAndALinearRampOverTheData) {
  TransferEditor editor(core::TransferPreset("ramp"), kRange, {10, 90});
  for (const std::string& name : EditorPresetNames()) {
    editor.ApplyPreset(name);
    EXPECT_NO_THROW(editor.transfer().Check(name));
  }
  editor.ApplyPreset("linear ramp");
  EXPECT_EQ(editor.transfer().Evaluate(10).a, 0.0);
  EXPECT_EQ(editor.transfer().Evaluate(50).a, 0.5);
  EXPECT_EQ(editor.transfer().Evaluate(90).a, 1.0);
  EXPECT_THROW(editor.ApplyPreset("no such preset"), core::InputError);
}

TEST(TransferEditor, HistogramCountsEveryVoxelInItsBin) {
  core::Volume v = core::Volume::Zeros({7, 5, 3}, core::ScalarType::kInt16);
  std::vector<double> values;
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 7; ++x) {
        const double value = -100 + 13 * ((x + 3 * y + 5 * z) % 17);
        v.SetValue(x, y, z, value);
        values.push_back(value);
      }
  const int bins = 8;
  const Histogram h = VolumeHistogram(v, bins);
  EXPECT_EQ(h.lo, -100);
  EXPECT_EQ(h.hi, -100 + 13 * 16);
  std::vector<int64_t> expected(bins, 0);
  for (double value : values) {
    // Bin i: [lo + i w, lo + (i + 1) w), the maximum in the last bin.
    int b = 0;
    while (b + 1 < bins && value >= h.lo + (b + 1) * (h.hi - h.lo) / bins) ++b;
    ++expected[static_cast<size_t>(b)];
  }
  EXPECT_EQ(h.counts, expected);
  int64_t total = 0;
  for (int64_t c : h.counts) total += c;
  EXPECT_EQ(total, 7 * 5 * 3);
  for (size_t i = 0; i < h.counts.size(); ++i) {
    EXPECT_GE(h.LogHeight(i), 0.0);
    EXPECT_LE(h.LogHeight(i), 1.0);
  }
}

TEST(TransferEditor, InlineJsonReadsBackBitForBit) {
  TransferEditor editor(core::TransferPreset("tooth"), glm::dvec2(-1024, 3071), {-1024, 3071});
  editor.SetWindow({40.1, 400.3});
  editor.SetColour(2, {0.1, 0.2, 0.3});
  std::istringstream in(core::TransferFunctionJson(editor.transfer()));
  EXPECT_EQ(core::ReadTransferFunction(in, "inline"), editor.transfer());
}

}  // namespace
}  // namespace viewer
