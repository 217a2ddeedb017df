// Is a dataset's depth in the units its cameras and poses are in? An RGB-D
// frame imported at 1000 units per metre instead of the 5000 its sensor
// wrote (TUM RGB-D) is 5x too deep and otherwise valid: nothing downstream
// fails, the object is just misplaced against the cameras. CPU-only.
#pragma once

#include <string>

#include "capture/dataset.h"

namespace capture {

struct DepthScaleReport {
  size_t views = 0;       // views with depth that were sampled
  size_t samples = 0;     // valid depth pixels sampled
  double median = 0;      // median sampled depth (dataset units)
  size_t pairs = 0;       // view pairs compared by reprojection
  double agreement = -1;  // fraction of reprojected samples that agree, -1: no pair
  // One map's depth noise as the views' agreement shows it (dataset units):
  // the robust deviation (1.4826 MAD) of the reprojected samples that agree
  // with the other view's bilinear depth, each scaled by 1 / sqrt(1 + the
  // interpolation's squared weights) to one map's noise; -1 with fewer than
  // 100 such samples. Depth maps from COLMAP or a sensor state no noise
  // of their own: this is what a tolerance can be set from.
  double noise_sigma = -1;
  size_t noise_samples = 0;
  // Empty when the depths look plausible; else one line saying why.
  std::string warning;
  // The factor (depth * factor) that would make them plausible; 0 when none
  // of the usual unit confusions does.
  double suggested_factor = 0;
};

// Two tests on a sample of every view with depth (at most `max_views`):
// - metric depth (depth_units "m"): the median depth must lie within the
//   working range of RGB-D sensors, 0.3-5 m (Kinect v1 0.8-4 m, Kinect v2
//   0.5-4.5 m, RealSense D4xx 0.3-10 m; a frame's median is well inside);
// - any units, the first view against each later one with a baseline (>= 2 %
//   of its median depth):
//   a point unprojected from one view's depth, reprojected into the other,
//   meets that view's depth (within 3 %) where both see it; a scale is
//   wrong when a usual factor meets it clearly more often (>= 60 % and 20
//   points more). A wrong scale moves the points along their rays, off the other
//   view's surface, once the baseline is not negligible.
// The suggestion is the usual confusion (5: mm vs TUM's 1/5000 m, 10, 1000:
// mm vs m, and their inverses) that passes both tests.
DepthScaleReport CheckDepthScale(const Dataset& dataset, size_t max_views = 16);

}  // namespace capture
