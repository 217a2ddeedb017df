// Accuracy of a rendering against a truth seen from the same camera: one
// module for every bench, command and test (CPU only: images in, numbers out).
//
// Conventions, the same everywhere:
// - Coverage is a 1-channel Image8, non-zero = covered. CoverageFromAlpha
//   (alpha == 255: every pass writes opaque pixels only) and CoverageFromDepth
//   (finite camera z > 0; 0 = empty) make it from a frame.
// - Depth error = |z - z_true| / depth_unit over the pixels both cover.
// - Percentile rule: nearest rank. The q-quantile of n values is the
//   ceil(q n)-th smallest (1-based; q = 0 gives the smallest), so p95 of 100
//   values is the 95th smallest and p95 of 1..20 is 19. It is always one of the
//   values (no interpolation).
// - Median rule: the middle value of an odd count, the mean of the two
//   middle values of an even one (core::Median; frame times, ratios, depth
//   errors and bench tables all use it).
// - Empty input: a statistic over no values (mean, percentile, max, PSNR over
//   no pixels, pooled IoU over no views) is NaN. IoU of two empty silhouettes
//   is 1 (they agree; that is a comparison, not a statistic over pixels).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.h"

namespace core {

// Nearest-rank quantile (see above); q in [0, 1]; NaN when `values` is empty.
double Percentile(std::vector<double> values, double q);

// The one median (the rule above); NaN when `values` is empty. Linear time.
double Median(std::vector<double> values);

// Distribution-free confidence interval of the median (the order-statistic
// rule of the sign test): the j-th and (n+1-j)-th smallest of the n values,
// j the largest rank with P(Binomial(n, 1/2) < j) <= (1 - level) / 2, so the
// interval holds the population median with probability `coverage` >= level,
// whatever the distribution. NaN bounds (and coverage 0) when no rank reaches
// the level (n < 6 at 95 %) or `values` is empty. level in (0, 1).
struct MedianInterval {
  double lo = 0, hi = 0;
  double coverage = 0;
};
MedianInterval MedianConfidenceInterval(std::vector<double> values, double level = 0.95);

// Mean, p95 and max of a set of errors; NaN (and count 0) when empty.
struct ErrorStats {
  int64_t count = 0;
  double mean = 0, p95 = 0, max = 0;
};
ErrorStats SummarizeErrors(std::vector<double> errors);
// What an error line prints after "mean M / p95 P": when the mean exceeds
// the p95 (a few large errors dominate the mean, which the p95 alone would
// hide), " / max X (heavy tail: the mean exceeds the p95)" with `digits`
// after the point; else "".
std::string HeavyTailNote(const ErrorStats& stats, int digits);

// 1 where alpha == 255 (RGBA input), 0 elsewhere.
Image8 CoverageFromAlpha(const Image8& rgba);
// 1 where the camera z is finite and > 0, 0 elsewhere.
Image8 CoverageFromDepth(const ImageF& depth);

// One view against its truth.
struct ViewMetrics {
  int64_t rendered_pixels = 0;       // covered in the rendering
  int64_t truth_pixels = 0;          // covered in the truth
  int64_t both_pixels = 0;           // covered in both
  int64_t wrong_pixels = 0;          // covered in exactly one (wrong silhouette pixels)
  double iou = 1;                    // both / union; 1 when both are empty
  ErrorStats depth;                  // over depth_errors
  std::vector<double> depth_errors;  // |z - z_true| / depth_unit per pixel both cover, row-major
};

// All images the same size; depth images 1 channel (camera z), coverage 1
// channel (non-zero = covered). depth_unit > 0 (scene units per reported unit).
ViewMetrics CompareView(const Image8& coverage, const ImageF& depth, const Image8& truth_coverage,
                        const ImageF& truth_depth, double depth_unit = 1.0);
// The common case: coverage from the depth images themselves (0 = empty).
ViewMetrics CompareDepth(const ImageF& depth, const ImageF& truth_depth, double depth_unit = 1.0);

// Frames drawn by the passes: coverage = alpha 255 of the RGBA8 colours.
ViewMetrics CompareFrames(const Image8& color, const ImageF& depth, const Image8& truth_color,
                          const ImageF& truth_depth, double depth_unit = 1.0);

// The rule for reporting a view's accuracy: the rendering and the truth must
// share at least one covered pixel. Otherwise its IoU compares an empty
// silhouette (0, or 1 for two empty ones) and its depth error is over no
// pixel (NaN): numbers that would only hide that nothing was drawn. Throws
// InputError("where: view 'VIEW': ...") saying which side is empty.
void CheckMeasurable(int64_t rendered_pixels, int64_t truth_pixels, int64_t both_pixels,
                     std::string_view where, std::string_view view);
void CheckMeasurable(const ViewMetrics& metrics, std::string_view where, std::string_view view);

// Over several views: IoU mean and worst view, depth errors pooled over every
// pixel of every view (not a mean of per-view means).
struct PooledMetrics {
  int views = 0;
  double iou_mean = 0, iou_min = 0;  // NaN for no views
  ErrorStats depth;
};
PooledMetrics Pool(const std::vector<ViewMetrics>& views);

// PSNR in dB of the first `channels` channels (8-bit, peak 255) over the
// pixels where `mask` is non-zero: 10 log10(255^2 / MSE). NaN when the mask is
// empty, +infinity when the images agree exactly there.
double Psnr(const Image8& image, const Image8& truth, const Image8& mask, int channels = 3);

// Pixels where both coverages are set (a mask for Psnr).
Image8 BothCovered(const Image8& a, const Image8& b);

}  // namespace core
