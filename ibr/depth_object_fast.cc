// The fast slice path of depth objects and visual hulls (issue 12, item 3):
// the slices and map tests of Kautz-Seidel 2001, sec. 4.1 (and sec. 5 for
// hulls), without the per-slice, per-map stencil passes.
//
// The exact path (DrawSlices) draws every slice n + 1 times (one pass per
// active map, stencil EQUAL j / INCR and the map test as an alpha test, then
// a pass that clears what fell short), with a uniform and a buffer range
// switch per pass: thousands of draw calls a frame, and every fragment of
// every pass shaded, finished pixels included (stencil writes make llvmpipe
// test late). Here:
// - all slices go into one vertex buffer as one-slice stacks of the slicing
//   core (render::SliceBuffer::UploadVolumes: a_volume = the slice index) and
//   are drawn in ONE call, front to back;
// - the fragment shader runs the map loop itself (the same MapAccepts, the
//   same texels) on the point recomputed from the pixel centre and the slice's
//   plane (read from a storage buffer by index), leaving at the first map
//   that rejects (robust: counting up to N - k), and sums w_i * colour_i in
//   the map order of the exact path's additive blending;
// - the depth test (LESS, depth written) keeps the front slice a pixel
//   reached; with no stencil writes llvmpipe tests depth before shading, so
//   fragments behind a finished pixel cost no map test.
// Output: the accumulation target of DrawSlices (RGBA32F sum w c and sum w,
// RG32F camera z and covered), resolved by the same resolve pass. The colour
// sum is formed in registers and written once per pixel, so the RGBA8
// accumulation of the paper (blending per map pass) would buy nothing here.
// Differences from the exact path: along a ray that crosses the slices out
// of drawing order (perspective views with the eye between orthogonal slice
// planes) this keeps the nearest accepted slice, the exact path the first
// drawn; and the comparison is not mirrored by verify/reference.h's bit-exact
// replay (tests/ibr/depth_object_fast_test.cc compares it with the exact
// path and the CPU reference instead).
#include <fmt/format.h>

#include "core/check.h"
#include "core/error.h"
#include "ibr/depth_object.h"

namespace ibr {

SlicePath SlicePathFromName(const std::string& name) {
  return core::EnumFromName(kSlicePathNames, name, "SlicePathFromName", "slice path");
}

std::string SlicePathName(SlicePath p) { return std::string(core::EnumToName(kSlicePathNames, p)); }

void DepthObjectRenderer::DrawSlicesFast(const FrameParams& frame,
                                         const DepthObjectOptions& options,
                                         const render::RenderTarget& accum) {
  IBR_CHECK(options.slicing != Slicing::kRay);
  IBR_CHECK_EQ(frame.planes.size(), frame.stack.slices.size());
  // The whole table too: the resolve pass reads it.
  BindFrame(frame, options, accum);

  // The active maps' records in loop order: a block indexed by the unrolled
  // loop's constant (a dynamic index into the whole table gathers per lane).
  const int n = static_cast<int>(frame.active.size());
  std::vector<MapRecord> loop;
  loop.reserve(frame.active.size());
  for (int i : frame.active) loop.push_back(frame.maps.at(static_cast<size_t>(i)));

  std::vector<std::string> defines = Defines(frame, options);
  defines.push_back(fmt::format("FAST_MAP_COUNT {}", n));
  if (frame.robust) defines.push_back("ROBUST_COUNT");
  const render::Program& pass = programs_->Get({.vertex = "passes/depth_object_fast.vert.glsl",
                                                .fragment = "passes/depth_object_fast.frag.glsl",
                                                .defines = defines});
  SetCommonUniforms(pass, frame, true).required.Set(frame.required);

  gpu_->DrawFastSlices(frame.stack, loop, frame.planes, accum);
}

}  // namespace ibr
