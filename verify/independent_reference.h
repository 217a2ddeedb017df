// An independent CPU reference of the depth object and the visual hull
// (Kautz-Seidel 2001, sec. 4-5), in double precision, built from the plain
// inputs (MapSet: cameras, poses, depth, masks) and the view directly. It
// shares no code with the GPU setup (PrepareFrame, the slicing core,
// verify/reference.h): its own slice planes (sec. 3.2 orthogonal and sec. 3.3
// screen slicing, computed here from the box and the view), its own
// transforms, silhouette/depth codes and comparison. A mistake shared by the
// GPU path and its bit-exact mirror (verify/reference.h) shows up here.
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
//
// Colour (sec. 4.2). The view-dependent weights are derived here again from
// the maps' poses and the view (the unstructured-lumigraph penalty with k = 3
// that ibr/view_weights.h states: theta_i = angle between map i's and the
// view's direction towards the box centre, orthographic: the camera axis;
// w'_i = (1 - theta_i / theta_4) / theta_i for the three smallest over every
// map (a hull's skipped opposite maps included), normalised;
// theta_i = 0 gives weight 1). The accumulated colour of a pixel is
// sum_i w_i c_i over the maps that accept the front point (slices) or that
// see the hit point in their image (ray path), c_i the texel's RGBA / 255.
// It is an interval when the texel choice is uncertain (u or v within its
// bound of a texel edge, neighbouring texels differing); the GPU must lie in
// it within color_bound: each weight to 1e-6 (the float weights the GPU gets
// and this double ULR differ by rounding only, the weights being continuous
// in the directions), each product and blend sum rounded (u per operation).
//
// Ray path (Slicing::kRay, the one-pass march of
// shaders/passes/depth_object_ray.frag.glsl on the ray core): the pixel ray
// enters the box at t0 (perspective, the eye inside the box: t0 = dz / 2,
// where the first screen slice lies), samples camera z
// t0 + i dz (dz = the screen slices' spacing: the box's camera-z range, from
// the eye when it is inside, over the slice count; the last sample on the box
// exit; at most slices + 2 samples), stops at the first sample that is inside
// the object (the same map tests), and bisects refine_steps times between it
// and the sample before (a hit at t0 is not refined). Every decision on the
// way carries the bound above plus the accumulated rounding of the sample's
// t (one u |t| per step); the hit's depth must match within the bound of its
// position (an uncertain bisection decision widens it to that step's
// bracket). An uncertain "inside" at a sample is not a band pixel: it adds an
// alternative outcome (the hit there) the GPU may match instead; the band of
// the ray path is an uncertain box coverage or last-sample position, or more
// than 8 alternatives. Empty-space skipping only jumps whole steps the maps prove empty,
// so it is not modelled (the samples it keeps are the same). Sub-texel depth
// is not covered (InputError).
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
  int stencil = 0;  // the stencil byte steps 2(a)-(f) leave (robust: 0x80 | count); ray: 0
  int count = 0;    // maps accepting at the front slice (0 if none); ray: 1 on a hit
  // Index in this reference's front-to-back order (ray: the linear-search
  // sample that found the object), -1 = empty.
  int front_slice = -1;
  double depth = 0;        // view camera z of the front slice's point (ray: the hit), 0 = empty
  double depth_bound = 0;  // error bound of the GPU's float depth at that point (scene units)
  bool band = false;       // some decision up to the front slice lies inside the tolerance band
  // Accumulated colour sum_i w_i c_i (RGBA, c in [0, 1]): the interval over
  // uncertain texel choices, and the float bound around it.
  glm::dvec4 color_lo{0.0}, color_hi{0.0};
  double color_bound = 0;
  // False where the hit point itself is uncertain beyond its float bound (ray
  // path: an uncertain bisection decision), so its colour is not compared.
  bool color_known = true;
  // Ray path: other outcomes the GPU may take, (hit depth, bound) each: a
  // sample whose "inside" decision is uncertain lets the march stop there
  // (the nominal outcome above continues past it). Not the band: the GPU
  // must match the nominal outcome or one of these.
  std::vector<glm::dvec2> alternatives;
};

struct IndependentFrame {
  int width = 0, height = 0;
  bool ray = false;       // Slicing::kRay: pixels come from the march, not slices
  int axis = -1;          // orthogonal slicing axis (box), -1 for screen slices
  bool axis_tie = false;  // the axis choice was within IndependentOptions::axis_tie
  int required = 0;       // accepting maps a pixel needs (N - k)
  bool robust = false;
  std::vector<int> active;           // maps in loop order
  std::vector<double> weights;       // view-dependent weight per map (0 if not among the best 3)
  double ray_step = 0;               // kRay: camera z per linear-search step
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

// Slicing::kOrthogonal, kScreen or kRay; an explicit slice count (not
// kAutoSlices) and nearest-texel depth (subtexel_depth off), else InputError.
IndependentFrame RenderIndependent(const MapSet& maps, const ViewCamera& view,
                                   const DepthObjectOptions& options,
                                   const IndependentOptions& independent = {});

// A GPU frame (DepthObjectRenderer::DrawSlices' or DrawRay's accumulation:
// stencil, RGBA32F colour and the (z, covered) attachment) against the
// independent reference. A pixel agrees when the stencil (slices), the
// coverage, the front slice (ray: the coverage and the depth), the depth
// within its bound and every colour channel within [lo - bound, hi + bound]
// agree.
struct IndependentComparison {
  int64_t pixels = 0;
  int64_t agree = 0;               // everything above equal
  int64_t band = 0;                // pixels inside the tolerance band (agreeing or not)
  int64_t band_disagree = 0;       // ... of which the GPU decided the other way
  int64_t real_errors = 0;         // disagreements outside the band
  int64_t alternative_pixels = 0;  // ray: pixels outside the band with alternative outcomes
  int64_t alternative_taken = 0;   // ... where the GPU matched an alternative (counted as agreeing)
  int64_t covered = 0;             // object pixels in the reference
  int64_t color_checked = 0;       // object pixels outside the band whose colour was compared
  int64_t color_interval = 0;      // ... of which the texel choice left an interval (lo < hi)
  int64_t color_errors = 0;    // ... of which the colour lay outside it (counted in real_errors)
  double max_depth_error = 0;  // |GPU z - reference z| over agreeing object pixels (scene units)
  double max_depth_error_over_bound = 0;
  double max_color_error = 0;  // largest channel distance from [lo, hi] over checked pixels
  core::Image8 diff;           // 255 real error, 128 band disagreement, 0 else
  // Sums the counts and takes the maxima of `o` (not its diff): totals over frames.
  void Add(const IndependentComparison& o);
};
// `gpu_stencil` is ignored (may be empty) for a ray frame.
IndependentComparison CompareWithIndependent(const IndependentFrame& reference,
                                             const core::Image8& gpu_stencil,
                                             const core::ImageF& gpu_color,
                                             const core::ImageF& gpu_depth_covered);

}  // namespace ibr
