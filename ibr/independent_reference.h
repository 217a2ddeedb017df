// An independent CPU reference of the depth object and the visual hull
// (Kautz-Seidel 2001, sec. 4-5), in double precision, built from the plain
// inputs (MapSet: cameras, poses, depth, masks) and the view directly. It
// shares no code with the GPU setup (PrepareFrame, the slicing core,
// ibr/reference.h): its own slice planes (sec. 3.2 orthogonal and sec. 3.3
// screen slicing, computed here from the box and the view), its own
// transforms, silhouette/depth codes and comparison. A mistake shared by the
// GPU path and its bit-exact mirror (ibr/reference.h) shows up here.
//
// Per pixel it traces the ray through the pixel centre, visits the slice
// planes front to back and evaluates every active map's test at the ray's
// point on each plane: the first slice where all maps accept (robust: at
// least N - k) is the pixel's front slice, its point the first-surface depth
// and the accepting count its stencil (sec. 4.1, steps 2(a)-(f), which leave
// exactly that in the stencil buffer).
//
// Tolerance band. The GPU evaluates the same tests in single precision; a
// decision whose margin is smaller than the float rounding of the GPU's chain
// may go either way there. Every decision carries a first-order running error
// bound of that chain (Higham 2002, ch. 3: each correctly rounded operation
// adds u |result|, u = 2^-24; GLSL division 2.5 ULP <= 5 u; inputs rounded to
// float add u per entry; the bound is doubled for second-order terms):
//  - the view point p on a plane: the plane's float rounding (offset and
//    normal, scaled by the condition of dot(n, dir)), the ray's mul-adds and
//    the division;
//  - q = map_cam_from_view_cam p + t, texel coordinates u, v (another
//    division for pinhole maps);
//  - depth objects: |q.z - depth| < eps_z; texel choice: u or v within
//    eps_uv of an integer (then both texels are tried; uncertain only if
//    they disagree); pinhole "in front": |q.z| < eps_z;
//  - coverage: the ray's point within 2^-subpixel_bits pixels (+ float
//    slack) of a slice polygon's edge (a box face), where rasterisation
//    snapping may include or exclude the pixel.
// A pixel is in the band when some slice up to its front slice (every slice
// if it has none) has an outcome (finished or not, and the count) that an
// uncertain decision could change.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "ibr/depth_object.h"
#include "ibr/image_maps.h"

namespace ibr {

struct IndependentOptions {
  // Rasterisation snapping of slice polygon vertices (GL_SUBPIXEL_BITS; the
  // GL minimum is 4): coverage within 2^-bits pixels of an edge is uncertain.
  int subpixel_bits = 4;
  // Orthogonal slicing: when the two best axes score within this (relative),
  // the choice is a tie a float implementation may break either way; if
  // `tie_axis` >= 0 it is used (the GPU's choice), else the lowest tied axis.
  double axis_tie = 1e-5;
  int tie_axis = -1;
};

struct IndependentPixel {
  int stencil = 0;         // the stencil byte steps 2(a)-(f) leave (robust: 0x80 | count)
  int count = 0;           // maps accepting at the front slice (0 if none)
  int front_slice = -1;    // index in this reference's front-to-back order, -1 = empty
  double depth = 0;        // view camera z of the front slice's point, 0 = empty
  double depth_bound = 0;  // error bound of the GPU's float depth at that point (scene units)
  bool band = false;       // some decision up to the front slice lies inside the tolerance band
};

struct IndependentFrame {
  int width = 0, height = 0;
  int axis = -1;          // orthogonal slicing axis (box), -1 for screen slices
  bool axis_tie = false;  // the axis choice was within IndependentOptions::axis_tie
  int required = 0;       // accepting maps a pixel needs (N - k)
  bool robust = false;
  std::vector<int> active;           // maps in loop order
  std::vector<double> plane_values;  // per slice: box coordinate (orthogonal) or camera z (screen)
  std::vector<IndependentPixel> pixels;  // row-major, row 0 on top
  int64_t uncertain_decisions = 0;       // map decisions inside the band
  int64_t decisions = 0;                 // map decisions evaluated
  const IndependentPixel& at(int col, int row) const {
    return pixels[static_cast<size_t>(row) * width + col];
  }
  // View camera z of slice `s`'s plane on the ray through pixel (col, row),
  // NaN where the ray misses the plane (behind the eye / parallel).
  std::vector<double> slice_depths;  // [pixel][slice], row-major pixels
  double SliceDepth(int col, int row, int s) const {
    return slice_depths[(static_cast<size_t>(row) * width + col) * plane_values.size() + s];
  }
};

// Slicing::kOrthogonal or kScreen (kRay is not a slicing: InputError).
IndependentFrame RenderIndependent(const MapSet& maps, const ViewCamera& view,
                                   const DepthObjectOptions& options,
                                   const IndependentOptions& independent = {});

// A GPU frame (DepthObjectRenderer::DrawSlices' stencil and (z, covered)
// attachment) against the independent reference.
struct IndependentComparison {
  int64_t pixels = 0;
  int64_t agree = 0;           // stencil, front slice and depth (within its bound) equal
  int64_t band = 0;            // pixels inside the tolerance band (agreeing or not)
  int64_t band_disagree = 0;   // ... of which the GPU decided the other way
  int64_t real_errors = 0;     // disagreements outside the band
  int64_t covered = 0;         // object pixels in the reference
  double max_depth_error = 0;  // |GPU z - reference z| over agreeing object pixels (scene units)
  double max_depth_error_over_bound = 0;
  core::Image8 diff;  // 255 real error, 128 band disagreement, 0 else
};
IndependentComparison CompareWithIndependent(const IndependentFrame& reference,
                                             const core::Image8& gpu_stencil,
                                             const core::ImageF& gpu_depth_covered);

}  // namespace ibr
