// The frame timer and the fill-rate calibration produce well-formed figures.
// (Speeds are printed by `ibr bench fillrate`, never asserted.)
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "render/gl/fill_rate.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

class TimingTest : public test_support::GlTest {};

TEST_F(TimingTest, TimeFramesRunsWarmupPlusTimedFrames) {
  int calls = 0;
  const core::TimingStats stats = TimeFrames([&] { ++calls; }, {3, 5});
  EXPECT_EQ(calls, 8);
  EXPECT_EQ(stats.samples, 5);
  EXPECT_LE(stats.min_ms, stats.median_ms);
  EXPECT_LE(stats.median_ms, stats.max_ms);
}

TEST_F(TimingTest, FillRateIsFiniteAndPositive) {
  FillRateOptions options;
  options.width = options.height = 64;
  options.layers_per_frame = 8;
  options.timer = {1, 3};
  using Work = FillRateOptions::Work;
  for (const Work work :
       {Work::kTexture2DAlphaTest, Work::kVolumeBlend, Work::kDisplacedVolumeBlend}) {
    options.work = work;
    const FillRate rate = MeasureFillRate(programs(), options);
    EXPECT_EQ(rate.fragments_per_frame, 64.0 * 64 * 8);
    EXPECT_TRUE(std::isfinite(rate.fragments_per_second));
    EXPECT_GT(rate.fragments_per_second, 0);
  }
  EXPECT_NO_GL_ERROR();
}

TEST(FillRateOptions, AbsurdOptionsAreRejected) {
  FillRateOptions options;
  options.layers_per_frame = 0;
  EXPECT_THROW(options.Check(), core::InputError);
  options = {};
  options.width = -5;
  EXPECT_THROW(options.Check(), core::InputError);
}

}  // namespace
}  // namespace render
