#include "core/depth_metrics.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace core {
namespace {

double Percentile(std::vector<float> values, double q) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

}  // namespace

ViewAccuracy CompareDepth(const core::ImageF& depth, const core::ImageF& truth, double cube_edge) {
  IBR_CHECK_EQ(depth.width(), truth.width());
  IBR_CHECK_EQ(depth.height(), truth.height());
  IBR_CHECK_GT(cube_edge, 0.0);
  ViewAccuracy a;
  int64_t inter = 0, uni = 0;
  double sum = 0;
  for (size_t p = 0; p < depth.pixel_count(); ++p) {
    const float z = depth.data()[p], t = truth.data()[p];
    const bool in = std::isfinite(z) && z > 0, in_truth = t > 0;
    inter += in && in_truth;
    uni += in || in_truth;
    if (in && in_truth) {
      const float e = static_cast<float>(std::abs(z - t) / cube_edge);
      a.errors.push_back(e);
      sum += e;
    }
  }
  a.iou = uni ? static_cast<double>(inter) / static_cast<double>(uni) : 1.0;
  a.both = static_cast<int64_t>(a.errors.size());
  a.mean_depth_error = a.errors.empty() ? 0 : sum / static_cast<double>(a.errors.size());
  a.p95_depth_error = Percentile(a.errors, 0.95);
  return a;
}

Accuracy Pool(const std::vector<ViewAccuracy>& views) {
  Accuracy a;
  if (views.empty()) return a;
  a.iou_mean = 0;
  std::vector<float> all;
  double sum = 0;
  for (const ViewAccuracy& v : views) {
    a.iou_mean += v.iou / static_cast<double>(views.size());
    a.iou_min = std::min(a.iou_min, v.iou);
    for (float e : v.errors) sum += e;
    all.insert(all.end(), v.errors.begin(), v.errors.end());
  }
  a.mean_depth_error = all.empty() ? 0 : sum / static_cast<double>(all.size());
  a.p95_depth_error = Percentile(std::move(all), 0.95);
  return a;
}

}  // namespace core
