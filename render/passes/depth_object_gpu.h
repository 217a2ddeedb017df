// The GL side of depth objects and visual hulls (Kautz-Seidel 2001, sec. 4-5):
// the map texture arrays and table buffers of one map set, the paper's
// stencil slice passes, the fast one-draw slice batch, the full-screen ray
// and resolve draws, and the slice coverage the CPU reference takes from the
// rasteriser. ibr/depth_object.cc decides every number a frame uses
// (PrepareFrame) and which program draws; this file owns the GL objects and
// issues the draws and state changes, so no GL call is made above render/.
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/image.h"
#include "render/cores/slice_buffer.h"
#include "render/cores/slicing.h"
#include "render/gl/handles.h"
#include "render/gl/render_target.h"
#include "render/passes/depth_object_uniforms.h"

namespace render {

// One map's row of the GPU table (std430 storage buffer of
// shaders/passes/depth_object_core.glsl; the same layout as std140, which the
// slice passes' one-record uniform block uses).
struct DepthMapRecord {
  glm::vec4 m0, m1, m2, m3;  // columns of map_cam_from_view_cam (xyz)
  glm::vec4 proj;            // fx, fy, cx, cy
  glm::ivec4 info;           // width, height, orthographic, layer
  glm::vec4 extra;           // view-dependent weight, record j: active[j], unused, unused
  glm::vec4 centre_in_view;  // map centre in view camera space, w = 1 if orthographic
  glm::vec4 axis_in_view;    // map +z in view camera space
};
static_assert(sizeof(DepthMapRecord) == 9 * 16, "std140 layout");

// The paper's stencil scheme for one frame (DepthObjectGpu::DrawStencilSlices).
struct StencilSlices {
  std::span<const glm::vec4> planes;  // per slice: the plane the fragment shader tests against
  std::span<const int> active;        // maps in loop order (record indices)
  int required = 0;                   // robust: the count a pixel needs (N - k)
  bool robust = false;                // counting scheme (bit 7 marks finished pixels)
};

class DepthObjectGpu {
 public:
  // Checks this GL implementation's limits against `map_count` maps of at
  // most `width` x `height` texels (one InputError naming `where` per
  // failure, before anything is allocated), then allocates the table buffers.
  DepthObjectGpu(int map_count, int width, int height, std::string where);

  // The table as a uniform block of the maps rounded up to 64 where it fits
  // (llvmpipe reads a uniform block far faster in the ray loop than a storage
  // buffer: docs/decisions/map-table-storage.md; the rounding keeps one
  // shader variant per 64 maps): its record count, else 0 (a storage buffer).
  int uniform_maps() const { return uniform_maps_; }

  // A map texture array (one layer per map, nearest, clamped) of
  // `internal_format`; InputError naming the maps when GL is out of memory.
  Texture CreateMapArray(GLenum internal_format, int bytes_per_texel) const;
  // `w` x `h` texels of tightly packed `data` into layer `layer`.
  static void UploadLayer(const Texture& array, int layer, int w, int h, GLenum format, GLenum type,
                          const void* data);

  // The frame's records (every map), its active maps, and each record at the
  // uniform-offset stride the slice passes bind one at a time.
  void UploadFrame(std::span<const DepthMapRecord> maps, std::span<const int> active);
  // Depth codes on unit 0, colours on unit 2, the table on its binding(s).
  void BindMaps(const Texture& depth, const Texture& color) const;
  static void BindTexture(int unit, const Texture& texture);

  // Steps 1-2 of sec. 4.1 into `accum` (cleared first): per slice, every
  // active map's pass with stencil EQUAL j / INCR (robust: counting), colour
  // accumulated (ONE, ONE); then the pass that clears what fell short. The
  // bound program is the slice pass; `u` its uniforms (slice plane, clear pass).
  void DrawStencilSlices(const SliceStack& stack, const StencilSlices& frame,
                         const DepthObjectUniforms& u, const RenderTarget& accum);
  // Every slice as its own one-slice stack in one draw, front to back, depth
  // test LESS written, no stencil or blending; `loop`: the active maps'
  // records in loop order (binding 3 UBO), `planes` one per slice (binding 3 SSBO).
  void DrawFastSlices(const SliceStack& stack, std::span<const DepthMapRecord> loop,
                      std::span<const glm::vec4> planes, const RenderTarget& accum);
  // One full-screen triangle with no stencil or blending, depth-tested (LESS,
  // written) or not: the ray pass and the resolve pass.
  void DrawFullScreen(bool depth_test) const;
  // Which pixels each slice polygon covers (1 per covered pixel, row 0 on
  // top), counted in a stencil with the bound program (which must not discard).
  std::vector<core::Image8> SliceCoverage(const SliceStack& stack, int width, int height);

 private:
  std::string where_;
  int map_count_ = 0, width_ = 0, height_ = 0;
  int uniform_maps_ = 0;
  Buffer map_ssbo_;     // the whole table (ray and resolve passes)
  Buffer active_ssbo_;  // the frame's maps as ints
  Buffer current_ubo_;  // one record per map at an aligned stride (map passes)
  GLint current_stride_ = 0;
  std::vector<uint8_t> strided_;  // UploadFrame's staging, kept between frames
  SliceBuffer slice_buffer_;
  VertexArray empty_vao_;
  Buffer fast_planes_, fast_maps_;
  std::vector<SliceStack> fast_stacks_;
};

// Saves the depth test, mask and function on construction and restores them
// on destruction (a pass drawing into a frame leaves its compositing state).
class SavedDepthState {
 public:
  SavedDepthState();
  ~SavedDepthState();
  SavedDepthState(const SavedDepthState&) = delete;
  SavedDepthState& operator=(const SavedDepthState&) = delete;

 private:
  GLboolean test_ = GL_FALSE, mask_ = GL_TRUE;
  GLint func_ = GL_LESS;
};

}  // namespace render
