// Accuracy of a rendered depth image against a true one (both camera z,
// 0 = empty): silhouette IoU and depth error over the pixels both cover. One
// definition for the benchmarks, the demo and `ibr render --truth-mesh`.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"

namespace core {

// One view against the truth (both: camera z, 0 = empty).
struct ViewAccuracy {
  double iou = 1;                // silhouettes (depth > 0); 1 when both are empty
  double mean_depth_error = 0;   // |z - z_true| over pixels both cover, / cube edge
  double p95_depth_error = 0;    // its 95th percentile, / cube edge
  int64_t both = 0;              // pixels both cover
  std::vector<float> errors;     // every |z - z_true| / cube edge (for pooling)
};
ViewAccuracy CompareDepth(const core::ImageF& depth, const core::ImageF& truth, double cube_edge);

// Over all views: IoU mean and worst view; depth errors pooled over every
// pixel of every view.
struct Accuracy {
  double iou_mean = 1, iou_min = 1;
  double mean_depth_error = 0, p95_depth_error = 0;  // cube-edge units
};
Accuracy Pool(const std::vector<ViewAccuracy>& views);

}  // namespace core
