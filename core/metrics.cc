#include "core/metrics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "core/error.h"

namespace core {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void CheckSameSize(const Image8& a, const ImageF& b) {
  IBR_CHECK_EQ(a.width(), b.width());
  IBR_CHECK_EQ(a.height(), b.height());
}

}  // namespace

double Percentile(std::vector<double> values, double q) {
  IBR_CHECK(q >= 0.0 && q <= 1.0);
  if (values.empty()) return kNaN;
  // Nearest rank: the ceil(q n)-th smallest, 1-based; q = 0 -> the smallest.
  const double rank = std::ceil(q * static_cast<double>(values.size()));
  const size_t k = rank < 1 ? 0 : std::min(values.size() - 1, static_cast<size_t>(rank) - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double Median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t n = v.size(), k = n / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  const double upper = v[k];
  if (n % 2 == 1) return upper;
  // The lower middle: the largest of the k values nth_element left before it.
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k));
  return 0.5 * (lower + upper);
}

MedianInterval MedianConfidenceInterval(std::vector<double> values, double level) {
  IBR_CHECK(level > 0.0 && level < 1.0);
  const size_t n = values.size();
  // P(Binomial(n, 1/2) = k) in logs (n may be large enough for 2^-n to underflow).
  const auto pmf = [n](size_t k) {
    const double nd = static_cast<double>(n), kd = static_cast<double>(k);
    return std::exp(std::lgamma(nd + 1) - std::lgamma(kd + 1) - std::lgamma(nd - kd + 1) -
                    nd * std::log(2.0));
  };
  // tail = P(X < j) for the candidate rank j (1-based).
  size_t j = 0;
  double tail = 0, below = 0;
  for (size_t r = 1; 2 * r <= n + 1; ++r) {
    below += pmf(r - 1);  // P(X < r)
    if (below > 0.5 * (1.0 - level)) break;
    j = r;
    tail = below;
  }
  if (j == 0) return {kNaN, kNaN, 0.0};
  std::sort(values.begin(), values.end());
  return {values[j - 1], values[n - j], 1.0 - 2.0 * tail};
}

ErrorStats SummarizeErrors(std::vector<double> errors) {
  ErrorStats s;
  s.count = static_cast<int64_t>(errors.size());
  if (errors.empty()) {
    s.mean = s.p95 = s.max = kNaN;
    return s;
  }
  double sum = 0;
  for (double e : errors) sum += e;
  s.mean = sum / static_cast<double>(errors.size());
  s.max = *std::max_element(errors.begin(), errors.end());
  s.p95 = Percentile(std::move(errors), 0.95);
  return s;
}

std::string HeavyTailNote(const ErrorStats& stats, int digits) {
  if (!(stats.mean > stats.p95)) return "";
  return fmt::format(" / max {:.{}f} (heavy tail: the mean exceeds the p95)", stats.max, digits);
}

Image8 CoverageFromAlpha(const Image8& rgba) {
  IBR_CHECK_EQ(rgba.channels(), 4);
  Image8 c(rgba.width(), rgba.height(), 1);
  for (size_t p = 0; p < rgba.pixel_count(); ++p) c.data()[p] = rgba.data()[4 * p + 3] == 255;
  return c;
}

Image8 CoverageFromDepth(const ImageF& depth) {
  IBR_CHECK_EQ(depth.channels(), 1);
  Image8 c(depth.width(), depth.height(), 1);
  for (size_t p = 0; p < depth.pixel_count(); ++p) {
    const float z = depth.data()[p];
    c.data()[p] = std::isfinite(z) && z > 0;
  }
  return c;
}

ViewMetrics CompareView(const Image8& coverage, const ImageF& depth, const Image8& truth_coverage,
                        const ImageF& truth_depth, double depth_unit) {
  CheckSameSize(coverage, depth);
  CheckSameSize(truth_coverage, truth_depth);
  CheckSameSize(coverage, truth_depth);
  IBR_CHECK(coverage.channels() == 1 && truth_coverage.channels() == 1);
  IBR_CHECK(depth.channels() == 1 && truth_depth.channels() == 1);
  IBR_CHECK(depth_unit > 0 && std::isfinite(depth_unit));
  ViewMetrics m;
  for (size_t p = 0; p < coverage.pixel_count(); ++p) {
    const bool r = coverage.data()[p] != 0, t = truth_coverage.data()[p] != 0;
    m.rendered_pixels += r;
    m.truth_pixels += t;
    m.wrong_pixels += r != t;
    if (r && t) {
      m.depth_errors.push_back(std::abs(static_cast<double>(depth.data()[p]) -
                                        static_cast<double>(truth_depth.data()[p])) /
                               depth_unit);
    }
  }
  m.both_pixels = static_cast<int64_t>(m.depth_errors.size());
  const int64_t uni = m.both_pixels + m.wrong_pixels;
  m.iou = uni == 0 ? 1.0 : static_cast<double>(m.both_pixels) / static_cast<double>(uni);
  m.depth = SummarizeErrors(m.depth_errors);
  return m;
}

ViewMetrics CompareDepth(const ImageF& depth, const ImageF& truth_depth, double depth_unit) {
  return CompareView(CoverageFromDepth(depth), depth, CoverageFromDepth(truth_depth), truth_depth,
                     depth_unit);
}

ViewMetrics CompareFrames(const Image8& color, const ImageF& depth, const Image8& truth_color,
                          const ImageF& truth_depth, double depth_unit) {
  return CompareView(CoverageFromAlpha(color), depth, CoverageFromAlpha(truth_color), truth_depth,
                     depth_unit);
}

void CheckMeasurable(int64_t rendered_pixels, int64_t truth_pixels, int64_t both_pixels,
                     std::string_view where, std::string_view view) {
  if (both_pixels > 0) return;
  if (rendered_pixels == 0 && truth_pixels == 0) {
    ThrowInputError(where,
                    "view '{}': the rendering and the truth are both empty: no silhouette IoU or "
                    "depth error can be measured (is the object in this camera's view?)",
                    view);
  }
  if (truth_pixels == 0) {
    ThrowInputError(where,
                    "view '{}': the truth is empty while the rendering covers {} pixels: no "
                    "depth error can be measured (is the truth in the same frame?)",
                    view, rendered_pixels);
  }
  if (rendered_pixels == 0) {
    ThrowInputError(where,
                    "view '{}': the rendering is empty while the truth covers {} pixels: nothing "
                    "was drawn, no depth error can be measured",
                    view, truth_pixels);
  }
  ThrowInputError(where,
                  "view '{}': the rendering ({} pixels) and the truth ({} pixels) share no "
                  "pixel: no depth error can be measured",
                  view, rendered_pixels, truth_pixels);
}

void CheckMeasurable(const ViewMetrics& metrics, std::string_view where, std::string_view view) {
  CheckMeasurable(metrics.rendered_pixels, metrics.truth_pixels, metrics.both_pixels, where, view);
}

PooledMetrics Pool(const std::vector<ViewMetrics>& views) {
  PooledMetrics p;
  p.views = static_cast<int>(views.size());
  std::vector<double> all;
  if (views.empty()) {
    p.iou_mean = p.iou_min = kNaN;
  } else {
    p.iou_min = 1;
    for (const ViewMetrics& v : views) {
      p.iou_mean += v.iou / static_cast<double>(views.size());
      p.iou_min = std::min(p.iou_min, v.iou);
      all.insert(all.end(), v.depth_errors.begin(), v.depth_errors.end());
    }
  }
  p.depth = SummarizeErrors(std::move(all));
  return p;
}

double Psnr(const Image8& image, const Image8& truth, const Image8& mask, int channels) {
  IBR_CHECK(image.width() == truth.width() && image.height() == truth.height());
  IBR_CHECK(mask.width() == image.width() && mask.height() == image.height() &&
            mask.channels() == 1);
  IBR_CHECK(channels >= 1 && channels <= image.channels() && channels <= truth.channels());
  double se = 0;
  int64_t n = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      if (!mask.at(x, y)) continue;
      for (int c = 0; c < channels; ++c) {
        const double e =
            static_cast<double>(image.at(x, y, c)) - static_cast<double>(truth.at(x, y, c));
        se += e * e;
      }
      n += channels;
    }
  }
  if (n == 0) return kNaN;
  const double mse = se / static_cast<double>(n);
  return mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : std::numeric_limits<double>::infinity();
}

Image8 BothCovered(const Image8& a, const Image8& b) {
  IBR_CHECK(a.width() == b.width() && a.height() == b.height() && a.channels() == 1 &&
            b.channels() == 1);
  Image8 m(a.width(), a.height(), 1);
  for (size_t p = 0; p < a.pixel_count(); ++p) m.data()[p] = a.data()[p] != 0 && b.data()[p] != 0;
  return m;
}

}  // namespace core
