// core/metrics: every figure checked against an answer computed by hand.
#include "core/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/timing.h"
#include "tests/support/input_error.h"

namespace core {
namespace {

TEST(Percentile, NearestRankOnHandCountedSets) {
  std::vector<double> one_to_twenty;
  for (int i = 20; i >= 1; --i) one_to_twenty.push_back(i);  // unsorted on purpose
  EXPECT_EQ(Percentile(one_to_twenty, 0.95), 19);            // ceil(0.95 * 20) = 19th smallest
  EXPECT_EQ(Percentile(one_to_twenty, 0.5), 10);             // ceil(10) = 10th
  EXPECT_EQ(Percentile(one_to_twenty, 0.0), 1);              // the smallest
  EXPECT_EQ(Percentile(one_to_twenty, 1.0), 20);             // the largest
  std::vector<double> hundred;
  for (int i = 1; i <= 100; ++i) hundred.push_back(i);
  EXPECT_EQ(Percentile(hundred, 0.95), 95);  // not 96 (the floor(0.95 n) index rule)
  EXPECT_EQ(Percentile({7.0}, 0.95), 7);
  EXPECT_EQ(Percentile({3.0, 1.0, 2.0}, 0.95), 3);  // ceil(2.85) = 3rd
  EXPECT_EQ(Percentile({3.0, 1.0, 2.0}, 0.6), 2);   // ceil(1.8) = 2nd
  EXPECT_TRUE(std::isnan(Percentile({}, 0.95)));
}

TEST(Median, MiddleValueOrMeanOfTheTwoMiddleOnes) {
  EXPECT_EQ(Median({5.0, 1.0, 3.0, 9.0, 7.0}), 5);  // odd: the 3rd smallest
  EXPECT_EQ(Median({4.0, 2.0}), 3);                 // even: (2 + 4) / 2
  EXPECT_EQ(Median({10.0, 1.0, 3.0, 2.0}), 2.5);    // (2 + 3) / 2, unsorted
  EXPECT_EQ(Median({2.0, 2.0, 9.0, 2.0}), 2);       // ties
  EXPECT_EQ(Median({7.0}), 7);
  EXPECT_TRUE(std::isnan(Median(std::vector<double>{})));
  // The rule frame times use (core::Summarize) is this one.
  std::vector<double> times;
  for (int i = 1; i <= 10; ++i) times.push_back(11 - i);
  EXPECT_EQ(Summarize(times).median_ms, Median(times));
  EXPECT_EQ(Median(times), 5.5);
}

TEST(MedianConfidenceInterval, OrderStatisticRanksFromTheBinomialByHand) {
  // n = 16: P(X <= 3) = (1 + 16 + 120 + 560) / 65536 = 0.0106 <= 0.025 but
  // P(X <= 4) = 2517 / 65536 = 0.0384 > 0.025: the 4th and 13th smallest,
  // coverage 1 - 2 * 697 / 65536 = 0.97873.
  std::vector<double> sixteen;
  for (int i = 16; i >= 1; --i) sixteen.push_back(10.0 * i);  // unsorted on purpose
  MedianInterval m = MedianConfidenceInterval(sixteen);
  EXPECT_EQ(m.lo, 40);
  EXPECT_EQ(m.hi, 130);
  EXPECT_NEAR(m.coverage, 1.0 - 2.0 * 697.0 / 65536.0, 1e-12);
  // n = 6: P(X = 0) = 1/64 = 0.0156 <= 0.025, P(X <= 1) = 7/64 > 0.025: min and max.
  m = MedianConfidenceInterval({6, 1, 5, 2, 4, 3});
  EXPECT_EQ(m.lo, 1);
  EXPECT_EQ(m.hi, 6);
  EXPECT_NEAR(m.coverage, 1.0 - 2.0 / 64.0, 1e-12);
  // n = 5: even the extremes cover only 1 - 2/32 = 0.9375 < 0.95.
  m = MedianConfidenceInterval({1, 2, 3, 4, 5});
  EXPECT_TRUE(std::isnan(m.lo) && std::isnan(m.hi));
  EXPECT_EQ(m.coverage, 0);
  // ... but reach an 80 % level: P(X = 0) = 1/32 <= 0.1, P(X <= 1) = 6/32 > 0.1.
  m = MedianConfidenceInterval({1, 2, 3, 4, 5}, 0.8);
  EXPECT_EQ(m.lo, 1);
  EXPECT_EQ(m.hi, 5);
  EXPECT_TRUE(std::isnan(MedianConfidenceInterval({}).lo));
  // Large n stays finite (2^-1000 in logs): the ranks close in on the median.
  std::vector<double> thousand;
  for (int i = 1; i <= 1000; ++i) thousand.push_back(i);
  m = MedianConfidenceInterval(thousand);
  EXPECT_GT(m.lo, 460);
  EXPECT_LT(m.hi, 540);
  EXPECT_EQ(m.lo + m.hi, 1001);  // symmetric ranks
  EXPECT_GE(m.coverage, 0.95);
}

TEST(SummarizeErrors, MeanP95MaxAndEmptyIsNaN) {
  const ErrorStats s = SummarizeErrors({0.5, 0.25, 1.0, 0.25});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 0.5);  // 2 / 4
  EXPECT_EQ(s.p95, 1.0);          // ceil(3.8) = 4th smallest
  EXPECT_EQ(s.max, 1.0);
  const ErrorStats e = SummarizeErrors({});
  EXPECT_EQ(e.count, 0);
  EXPECT_TRUE(std::isnan(e.mean) && std::isnan(e.p95) && std::isnan(e.max));
}

// 96 small errors and 4 large ones (a few pixels on the wrong surface):
// the mean, 0.04096, is above the p95 (the 95th smallest, 0.001), so the
// line says why and prints the max; a light tail prints nothing extra.
TEST(HeavyTailNote, SaysWhyAndPrintsTheMaxWhenTheMeanExceedsTheP95) {
  std::vector<double> errors(96, 0.001);
  errors.insert(errors.end(), 4, 1.0);
  const ErrorStats heavy = SummarizeErrors(errors);
  EXPECT_DOUBLE_EQ(heavy.mean, (96 * 0.001 + 4) / 100);
  EXPECT_EQ(heavy.p95, 0.001);
  EXPECT_GT(heavy.mean, heavy.p95);
  const std::string line = HeavyTailNote(heavy, 5);
  std::printf("heavy tail: mean %.5f p95 %.5f ->%s\n", heavy.mean, heavy.p95, line.c_str());
  EXPECT_EQ(line, " / max 1.00000 (heavy tail: the mean exceeds the p95)");
  EXPECT_EQ(HeavyTailNote(SummarizeErrors({0.5, 0.25, 1.0, 0.25}), 3), "");  // mean 0.5 < p95 1
  EXPECT_EQ(HeavyTailNote(SummarizeErrors({}), 3), "");                      // NaN: no claim
}

// 4 x 1 images: rendered covers pixels 0,1,2; truth covers 1,2,3.
TEST(CompareView, SilhouetteAndDepthErrorsByHand) {
  ImageF depth(4, 1, 1), truth(4, 1, 1);
  depth.values() = {1.0f, 2.0f, 3.0f, 0.0f};
  truth.values() = {0.0f, 2.5f, 2.0f, 4.0f};
  const ViewMetrics m = CompareDepth(depth, truth, 0.5);
  EXPECT_EQ(m.rendered_pixels, 3);
  EXPECT_EQ(m.truth_pixels, 3);
  EXPECT_EQ(m.both_pixels, 2);
  EXPECT_EQ(m.wrong_pixels, 2);
  EXPECT_DOUBLE_EQ(m.iou, 0.5);  // 2 / 4
  ASSERT_EQ(m.depth_errors.size(), 2u);
  EXPECT_DOUBLE_EQ(m.depth_errors[0], 1.0);  // |2 - 2.5| / 0.5
  EXPECT_DOUBLE_EQ(m.depth_errors[1], 2.0);  // |3 - 2| / 0.5
  EXPECT_DOUBLE_EQ(m.depth.mean, 1.5);
  EXPECT_EQ(m.depth.p95, 2.0);
  EXPECT_EQ(m.depth.max, 2.0);
}

TEST(CompareView, NonFiniteDepthIsEmptyAndBothEmptyAgree) {
  ImageF depth(2, 1, 1), truth(2, 1, 1, 0.0f);
  depth.values() = {std::numeric_limits<float>::quiet_NaN(),
                    std::numeric_limits<float>::infinity()};
  const ViewMetrics m = CompareDepth(depth, truth);
  EXPECT_EQ(m.rendered_pixels, 0);
  EXPECT_EQ(m.iou, 1.0);
  EXPECT_EQ(m.depth.count, 0);
  EXPECT_TRUE(std::isnan(m.depth.mean));
}

TEST(CompareView, AlphaCoverageIsOpaqueOnly) {
  Image8 rgba(3, 1, 4, 0);
  rgba.at(0, 0, 3) = 255;
  rgba.at(1, 0, 3) = 254;
  rgba.at(2, 0, 3) = 255;
  const Image8 c = CoverageFromAlpha(rgba);
  EXPECT_EQ(c.values(), (std::vector<uint8_t>{1, 0, 1}));
  ImageF z(3, 1, 1, 1.0f);
  Image8 truth(3, 1, 1, 1);
  const ViewMetrics m = CompareView(c, z, truth, z);
  EXPECT_EQ(m.wrong_pixels, 1);
  EXPECT_NEAR(m.iou, 2.0 / 3.0, 1e-15);
  EXPECT_EQ(m.depth.max, 0.0);
}

TEST(Pool, PoolsPixelsNotViewMeans) {
  ImageF a(2, 1, 1), ta(2, 1, 1), b(1, 1, 1), tb(1, 1, 1);
  a.values() = {1, 1};
  ta.values() = {1, 1};  // errors 0, 0; IoU 1
  b.values() = {4};
  tb.values() = {1};                           // error 3; IoU 1
  ImageF c(1, 1, 1, 1.0f), tc(1, 1, 1, 0.0f);  // IoU 0, no errors
  const PooledMetrics p = Pool({CompareDepth(a, ta), CompareDepth(b, tb), CompareDepth(c, tc)});
  EXPECT_EQ(p.views, 3);
  EXPECT_DOUBLE_EQ(p.iou_mean, 2.0 / 3.0);
  EXPECT_EQ(p.iou_min, 0.0);
  EXPECT_EQ(p.depth.count, 3);
  EXPECT_DOUBLE_EQ(p.depth.mean, 1.0);  // (0 + 0 + 3) / 3, not the mean of view means (1.5)
  EXPECT_EQ(p.depth.p95, 3.0);
  const PooledMetrics none = Pool({});
  EXPECT_TRUE(std::isnan(none.iou_mean) && std::isnan(none.iou_min) && std::isnan(none.depth.mean));
}

TEST(Psnr, HandComputedMseOverTheMask) {
  Image8 a(2, 1, 3, 100), b(2, 1, 3, 100), mask(2, 1, 1, 1);
  b.at(0, 0, 0) = 110;  // squared errors: 100, then 5 zeros over 6 samples -> MSE 100/6
  const double want = 10.0 * std::log10(255.0 * 255.0 / (100.0 / 6.0));
  EXPECT_NEAR(Psnr(a, b, mask), want, 1e-12);
  mask.at(0, 0) = 0;  // only the identical pixel left
  EXPECT_EQ(Psnr(a, b, mask), std::numeric_limits<double>::infinity());
  mask.at(1, 0) = 0;
  EXPECT_TRUE(std::isnan(Psnr(a, b, mask)));
  Image8 c1(1, 1, 1, 1), c2(1, 1, 1, 0);
  EXPECT_EQ(BothCovered(c1, c2).at(0, 0), 0);
  EXPECT_EQ(BothCovered(c1, c1).at(0, 0), 1);
}

TEST(CheckMeasurable, AViewWithoutSharedPixelsIsAnErrorNamingItsEmptySide) {
  // Depth images, 0 = empty: one pixel at (0, 0), another at (3, 3).
  const ImageF empty(4, 4, 1);
  ImageF a(4, 4, 1), b(4, 4, 1);
  a.at(0, 0) = 1.0f;
  b.at(3, 3) = 2.0f;
  auto error = [](const ImageF& rendered, const ImageF& truth) {
    return test_support::InputErrorOf(
        [&] { CheckMeasurable(CompareDepth(rendered, truth), "ibr test", "v1"); });
  };
  EXPECT_EQ(error(a, a), "");  // one shared pixel: IoU 1, depth error 0
  EXPECT_EQ(error(empty, empty),
            "ibr test: view 'v1': the rendering and the truth are both empty: no silhouette IoU "
            "or depth error can be measured (is the object in this camera's view?)");
  EXPECT_EQ(error(a, empty),
            "ibr test: view 'v1': the truth is empty while the rendering covers 1 pixels: no "
            "depth error can be measured (is the truth in the same frame?)");
  EXPECT_EQ(error(empty, b),
            "ibr test: view 'v1': the rendering is empty while the truth covers 1 pixels: "
            "nothing was drawn, no depth error can be measured");
  EXPECT_EQ(error(a, b),
            "ibr test: view 'v1': the rendering (1 pixels) and the truth (1 pixels) share no "
            "pixel: no depth error can be measured");
}

}  // namespace
}  // namespace core
