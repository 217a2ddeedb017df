// Error of a displacement rendering against the tessellated ground truth
// rendered from the same view (CPU only: images in, numbers out).
#pragma once

#include "core/image.h"
#include "core/mesh.h"

namespace core {

struct DisplacementErrorOptions {
  // Scene units per reported depth unit: HeightTexelWorldSize() reports depth
  // errors in texels of the height map as laid on the surface.
  float depth_unit = 1.0f;
  // A ground-truth pixel counts for see-through only if every pixel within
  // this many pixels is also covered (silhouette pixels differ by
  // rasterisation, not by looking through slices).
  int interior_margin_px = 1;
  // ... and counts if the rendering leaves it empty or shows a point more than
  // this many depth units behind the truth: something behind the surface seen
  // through the gaps between slices.
  float see_through_depth = 4.0f;
  void Check() const;
};

struct DisplacementError {
  int truth_pixels = 0;     // covered in the ground truth
  int rendered_pixels = 0;  // covered in the rendering
  int both_pixels = 0;
  double coverage_iou = 1;  // both / union; 1 when both are empty
  // |camera z - truth camera z| / depth_unit over pixels covered in both
  // (core/metrics.h: nearest-rank p95; NaN when there are none).
  double mean_depth_error = 0;
  double p95_depth_error = 0;
  double max_depth_error = 0;
  // Interior ground-truth pixels (see interior_margin_px) where the rendering
  // is empty or more than see_through_depth behind: looking through the
  // slices (the paper's Figure 4).
  int see_through_pixels = 0;
};

// Coverage is alpha == 255 (both passes write opaque pixels only).
DisplacementError CompareToGroundTruth(const core::Image8& color, const core::ImageF& depth,
                                       const core::Image8& truth_color,
                                       const core::ImageF& truth_depth,
                                       const DisplacementErrorOptions& options = {});

// Scene units of one height-map texel on the surface: the mean over faces of
// (world edge length / uv edge length), divided by texels * tiling.
float HeightTexelWorldSize(const core::TriangleMesh& base, int texels, float tiling);

}  // namespace core
