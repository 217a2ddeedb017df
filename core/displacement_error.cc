#include "core/displacement_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/check.h"
#include "core/error.h"
#include "core/metrics.h"

namespace core {

void DisplacementErrorOptions::Check() const {
  if (!(depth_unit > 0) || !std::isfinite(depth_unit)) {
    core::ThrowInputError("DisplacementErrorOptions", "depth_unit {} must be finite and > 0",
                          depth_unit);
  }
  if (interior_margin_px < 0 || interior_margin_px > 64) {
    core::ThrowInputError("DisplacementErrorOptions", "interior margin {} px outside 0..64",
                          interior_margin_px);
  }
  if (!(see_through_depth > 0)) {
    core::ThrowInputError("DisplacementErrorOptions", "see_through_depth {} must be > 0",
                          see_through_depth);
  }
}

DisplacementError CompareToGroundTruth(const core::Image8& color, const core::ImageF& depth,
                                       const core::Image8& truth_color,
                                       const core::ImageF& truth_depth,
                                       const DisplacementErrorOptions& options) {
  options.Check();
  const int w = truth_color.width(), h = truth_color.height();
  if (color.width() != w || color.height() != h || depth.width() != w || depth.height() != h ||
      truth_depth.width() != w || truth_depth.height() != h || color.channels() != 4 ||
      truth_color.channels() != 4) {
    core::ThrowInputError("CompareToGroundTruth", "images differ in size or are not RGBA + depth");
  }
  auto covered = [](const core::Image8& c, int x, int y) { return c.at(x, y, 3) == 255; };
  const core::ViewMetrics m = core::CompareFrames(color, depth, truth_color, truth_depth,
                                                  static_cast<double>(options.depth_unit));
  DisplacementError e;
  e.truth_pixels = static_cast<int>(m.truth_pixels);
  e.rendered_pixels = static_cast<int>(m.rendered_pixels);
  e.both_pixels = static_cast<int>(m.both_pixels);
  e.coverage_iou = m.iou;
  e.mean_depth_error = m.depth.mean;
  e.p95_depth_error = m.depth.p95;
  e.max_depth_error = m.depth.max;
  // See-through (the paper's Figure 4): interior truth pixels left empty or
  // showing something far behind.
  const int m_px = options.interior_margin_px;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool t = covered(truth_color, x, y), r = covered(color, x, y);
      const bool behind =
          t && r &&
          depth.at(x, y) - truth_depth.at(x, y) > options.see_through_depth * options.depth_unit;
      if ((t && !r) || behind) {
        bool interior = x >= m_px && y >= m_px && x < w - m_px && y < h - m_px;
        for (int dy = -m_px; interior && dy <= m_px; ++dy) {
          for (int dx = -m_px; interior && dx <= m_px; ++dx)
            interior = covered(truth_color, x + dx, y + dy);
        }
        e.see_through_pixels += interior;
      }
    }
  }
  return e;
}

float HeightTexelWorldSize(const core::TriangleMesh& base, int texels, float tiling) {
  if (texels < 1 || !(tiling > 0) || base.uvs.empty()) {
    core::ThrowInputError("HeightTexelWorldSize",
                          "need texels >= 1, tiling > 0 and a mesh with uvs");
  }
  double ratio_sum = 0;
  int edges = 0;
  for (size_t t = 0; t < base.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = base.indices[3 * t + k], b = base.indices[3 * t + (k + 1) % 3];
      const float uv_len = glm::length(base.uvs[b] - base.uvs[a]);
      if (uv_len <= 1e-9f) continue;
      ratio_sum += glm::length(base.positions[b] - base.positions[a]) / uv_len;
      ++edges;
    }
  }
  if (edges == 0)
    core::ThrowInputError("HeightTexelWorldSize", "every face has a degenerate uv layout");
  return static_cast<float>(ratio_sum / edges / (static_cast<double>(texels) * tiling));
}

}  // namespace core
