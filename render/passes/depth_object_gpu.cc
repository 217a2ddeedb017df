#include "render/passes/depth_object_gpu.h"

#include <algorithm>
#include <cstring>

#include "core/check.h"
#include "core/error.h"
#include "render/gl/gl_state.h"

namespace render {

namespace {

// Storage binding points of the fast pass (the map table is 0, the exact
// path's current map 1).
constexpr GLuint kFastMapsBinding = 3;    // UBO: the active maps in loop order
constexpr GLuint kFastPlanesBinding = 3;  // SSBO: one plane per slice

int64_t GetInteger(GLenum e) {
  GLint v = 0;
  glGetIntegerv(e, &v);
  return static_cast<int64_t>(v);
}

// The GL implementation's limits on what the maps need, checked before
// anything is allocated; each failure is one InputError naming the maps.
void CheckMapLimits(const std::string& where, int64_t n, int64_t w, int64_t h) {
  const int64_t layers = GetInteger(GL_MAX_ARRAY_TEXTURE_LAYERS);
  if (n > layers) {
    core::ThrowInputError(where,
                          "{} maps; this GL implementation holds at most {} in a texture array "
                          "(GL_MAX_ARRAY_TEXTURE_LAYERS)",
                          n, layers);
  }
  const int64_t size = GetInteger(GL_MAX_TEXTURE_SIZE);
  if (w > size || h > size) {
    core::ThrowInputError(where,
                          "maps of {}x{} pixels; this GL implementation's textures are at most "
                          "{} pixels wide and high (GL_MAX_TEXTURE_SIZE)",
                          w, h, size);
  }
  const int64_t block = GetInteger(GL_MAX_SHADER_STORAGE_BLOCK_SIZE);
  const int64_t table = n * static_cast<int64_t>(sizeof(DepthMapRecord));
  if (GetInteger(GL_MAX_FRAGMENT_SHADER_STORAGE_BLOCKS) < 2 || table > block) {
    core::ThrowInputError(
        where,
        "the map table of {} maps takes {} bytes; this GL implementation's "
        "fragment shaders read storage blocks of at most {} bytes "
        "(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, GL_MAX_FRAGMENT_SHADER_STORAGE_BLOCKS "
        "{})",
        n, table, block, GetInteger(GL_MAX_FRAGMENT_SHADER_STORAGE_BLOCKS));
  }
}

// Replaces `buffer`'s contents, growing its mutable storage when needed.
void UploadBuffer(Buffer& buffer, const void* data, size_t bytes) {
  if (!buffer) buffer = Buffer::Create();
  GLint64 capacity = 0;
  glGetNamedBufferParameteri64v(buffer.id(), GL_BUFFER_SIZE, &capacity);
  const size_t need = std::max<size_t>(bytes, 16);
  if (static_cast<size_t>(capacity) < need) {
    glNamedBufferData(buffer.id(), static_cast<GLsizeiptr>(need), nullptr, GL_STREAM_DRAW);
  }
  if (bytes > 0) glNamedBufferSubData(buffer.id(), 0, static_cast<GLsizeiptr>(bytes), data);
}

}  // namespace

DepthObjectGpu::DepthObjectGpu(int map_count, int width, int height, std::string where)
    : where_(std::move(where)), map_count_(map_count), width_(width), height_(height) {
  CheckMapLimits(where_, map_count, width, height);
  const size_t n = static_cast<size_t>(map_count);
  const size_t rounded = (n + 63) / 64 * 64;
  const int64_t max_block = GetInteger(GL_MAX_UNIFORM_BLOCK_SIZE);
  uniform_maps_ = static_cast<int64_t>(rounded * sizeof(DepthMapRecord)) <= max_block
                      ? static_cast<int>(rounded)
                      : 0;
  map_ssbo_ = Buffer::Create();
  glNamedBufferData(map_ssbo_.id(),
                    static_cast<GLsizeiptr>(sizeof(DepthMapRecord) * std::max<size_t>(n, rounded)),
                    nullptr, GL_DYNAMIC_DRAW);
  active_ssbo_ = Buffer::Create();
  glNamedBufferData(active_ssbo_.id(), static_cast<GLsizeiptr>(sizeof(GLint) * n), nullptr,
                    GL_DYNAMIC_DRAW);
  GLint align = static_cast<GLint>(GetInteger(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT));
  align = std::max(align, 1);
  current_stride_ = static_cast<GLint>((sizeof(DepthMapRecord) + align - 1) / align * align);
  current_ubo_ = Buffer::Create();
  glNamedBufferData(current_ubo_.id(), static_cast<GLsizeiptr>(current_stride_) * n, nullptr,
                    GL_DYNAMIC_DRAW);
  empty_vao_ = VertexArray::Create();
}

Texture DepthObjectGpu::CreateMapArray(GLenum internal_format, int bytes_per_texel) const {
  Texture t = Texture::Create(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(t.id(), 1, internal_format, width_, height_, map_count_);
  // The one GL error an allocation within the queried limits can still
  // meet: memory (llvmpipe caps one texture's size).
  if (const GLenum e = glGetError(); e == GL_OUT_OF_MEMORY) {
    core::ThrowInputError(
        where_,
        "{} maps of {}x{} pixels need a texture array of {:.0f} MB; this GL "
        "implementation is out of memory for it (GL_OUT_OF_MEMORY): use fewer "
        "or smaller maps",
        map_count_, width_, height_,
        static_cast<double>(map_count_) * width_ * height_ * bytes_per_texel / (1 << 20));
  } else {
    IBR_CHECK_EQ(e, static_cast<GLenum>(GL_NO_ERROR));
  }
  glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

void DepthObjectGpu::UploadLayer(const Texture& array, int layer, int w, int h, GLenum format,
                                 GLenum type, const void* data) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(array.id(), 0, 0, 0, layer, w, h, 1, format, type, data);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
}

void DepthObjectGpu::UploadFrame(std::span<const DepthMapRecord> maps,
                                 std::span<const int> active) {
  IBR_CHECK_EQ(maps.size(), static_cast<size_t>(map_count_));
  glNamedBufferSubData(map_ssbo_.id(), 0, static_cast<GLsizeiptr>(maps.size_bytes()), maps.data());
  static_assert(sizeof(int) == sizeof(GLint));
  IBR_CHECK_LE(active.size(), maps.size());
  if (!active.empty()) {
    glNamedBufferSubData(active_ssbo_.id(), 0, static_cast<GLsizeiptr>(active.size_bytes()),
                         active.data());
  }
  strided_.assign(static_cast<size_t>(current_stride_) * maps.size(), 0);
  for (size_t i = 0; i < maps.size(); ++i) {
    std::memcpy(strided_.data() + i * current_stride_, &maps[i], sizeof(DepthMapRecord));
  }
  glNamedBufferSubData(current_ubo_.id(), 0, static_cast<GLsizeiptr>(strided_.size()),
                       strided_.data());
}

void DepthObjectGpu::BindMaps(const Texture& depth, const Texture& color) const {
  glBindTextureUnit(0, depth.id());
  glBindTextureUnit(2, color.id());
  if (uniform_maps_ > 0) {
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, map_ssbo_.id());
  } else {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, map_ssbo_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, active_ssbo_.id());
  }
}

void DepthObjectGpu::BindTexture(int unit, const Texture& texture) {
  glBindTextureUnit(static_cast<GLuint>(unit), texture.id());
}

void DepthObjectGpu::DrawStencilSlices(const SliceStack& stack, const StencilSlices& frame,
                                       const DepthObjectUniforms& u, const RenderTarget& accum) {
  // Step 1: clear the frame buffer, no depth test.
  accum.Bind();
  const float zero[4] = {0, 0, 0, 0};
  accum.Clear(zero, 1.0f, 0);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glEnable(GL_STENCIL_TEST);
  // Attachment 0 accumulates (ONE, ONE) in the map passes and is overwritten
  // (ZERO, ZERO) in the clear passes: switching the blend function is
  // cheaper than toggling blending. Attachment 1 is never blended.
  glBlendEquation(GL_FUNC_ADD);
  glEnablei(GL_BLEND, 0);
  glDisablei(GL_BLEND, 1);
  slice_buffer_.Upload(stack);
  slice_buffer_.Bind();
  const int n = static_cast<int>(frame.active.size());
  const int required = frame.required;
  for (int s = 0; s < slice_buffer_.size(); ++s) {
    // Step 2(a): every base polygon (map) in turn, accumulating colour.
    u.slice_plane.Set(frame.planes[s]);
    u.clear_pass.Set(0);
    glBlendFunci(0, GL_ONE, GL_ONE);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    for (int j = 0; j < n; ++j) {
      if (!frame.robust) {
        // (a)i: pass and increment iff stencil == i - 1 (0-based: j).
        glStencilMask(0xFF);
        glStencilFunc(GL_EQUAL, j, 0xFF);
      } else {
        // Robust: count every map that passes, for pixels not yet finished
        // (bit 7 marks finished pixels; counts stay below 128).
        glStencilMask(0x7F);
        glStencilFunc(GL_EQUAL, 0, 0x80);
      }
      glBindBufferRange(GL_UNIFORM_BUFFER, 1, current_ubo_.id(),
                        static_cast<GLintptr>(current_stride_) * frame.active[j],
                        sizeof(DepthMapRecord));
      slice_buffer_.DrawSlice(s);  // (a)ii, with the alpha test (discard)
    }
    // Steps (c)-(f): clear colour and stencil where the count falls short.
    u.clear_pass.Set(1);
    glBlendFunci(0, GL_ZERO, GL_ZERO);
    if (!frame.robust) {
      glStencilMask(0xFF);
      glStencilFunc(GL_NOTEQUAL, n, 0xFF);
      glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
      slice_buffer_.DrawSlice(s);
    } else {
      // Unfinished pixels whose count < required: ref > stencil.
      glStencilMask(0xFF);
      glStencilFunc(GL_GREATER, required, 0xFF);
      glStencilOp(GL_KEEP, GL_KEEP, GL_ZERO);
      slice_buffer_.DrawSlice(s);
      // Count >= required: set the finished bit (colour untouched).
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      glStencilMask(0x80);
      glStencilFunc(GL_LEQUAL, 0x80 | required, 0x7F);
      glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
      slice_buffer_.DrawSlice(s);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }
  }
  slice_buffer_.Unbind();
  glStencilMask(0xFF);
  glDisable(GL_STENCIL_TEST);
  glDisablei(GL_BLEND, 0);
  glBlendFunci(0, GL_ONE, GL_ZERO);
}

void DepthObjectGpu::DrawFastSlices(const SliceStack& stack, std::span<const DepthMapRecord> loop,
                                    std::span<const glm::vec4> planes, const RenderTarget& accum) {
  IBR_CHECK_EQ(planes.size(), stack.slices.size());
  UploadBuffer(fast_maps_, loop.data(), loop.size_bytes());
  UploadBuffer(fast_planes_, planes.data(), planes.size_bytes());
  glBindBufferBase(GL_UNIFORM_BUFFER, kFastMapsBinding, fast_maps_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFastPlanesBinding, fast_planes_.id());
  // One stack per slice: the slicing core's buffer tags each vertex with its
  // stack (a_volume), which is the slice index the shader reads its plane by.
  fast_stacks_.resize(stack.slices.size());
  for (size_t s = 0; s < stack.slices.size(); ++s) {
    SliceStack& one = fast_stacks_[s];
    one.family = stack.family;
    one.axis = stack.axis;
    one.normal_in_box = stack.normal_in_box;
    one.slices.assign(1, stack.slices[s]);
  }
  slice_buffer_.UploadVolumes(fast_stacks_);
  // Depth test LESS, written (ties of window depth keep the slice drawn
  // first); no stencil, blending or culling. Restored on return.
  const ScopedGlState state(GlState{});
  accum.Bind();
  const float zero[4] = {0, 0, 0, 0};
  accum.Clear(zero, 1.0f, 0);
  slice_buffer_.DrawAllBatched();
}

void DepthObjectGpu::DrawFullScreen(bool depth_test) const {
  if (depth_test) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_BLEND);
  glBindVertexArray(empty_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
}

std::vector<core::Image8> DepthObjectGpu::SliceCoverage(const SliceStack& stack, int width,
                                                        int height) {
  RenderTarget target({width, height, {GL_R8}, true});
  slice_buffer_.Upload(stack);
  std::vector<core::Image8> coverage;
  const float zero[4] = {0, 0, 0, 0};
  target.Bind();
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glEnable(GL_STENCIL_TEST);
  glStencilMask(0xFF);
  glStencilFunc(GL_ALWAYS, 0, 0xFF);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  slice_buffer_.Bind();
  for (int s = 0; s < slice_buffer_.size(); ++s) {
    target.Clear(zero, 1.0f, 0);
    slice_buffer_.DrawSlice(s);
    coverage.push_back(target.ReadStencil());
  }
  slice_buffer_.Unbind();
  glDisable(GL_STENCIL_TEST);
  return coverage;
}

SavedDepthState::SavedDepthState() {
  glGetBooleanv(GL_DEPTH_TEST, &test_);
  glGetBooleanv(GL_DEPTH_WRITEMASK, &mask_);
  glGetIntegerv(GL_DEPTH_FUNC, &func_);
}

SavedDepthState::~SavedDepthState() {
  if (test_)
    glEnable(GL_DEPTH_TEST);
  else
    glDisable(GL_DEPTH_TEST);
  glDepthMask(mask_);
  glDepthFunc(static_cast<GLenum>(func_));
}

}  // namespace render
