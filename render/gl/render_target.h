// An offscreen framebuffer: colour attachments (textures) plus a
// DEPTH24_STENCIL8 texture, and readback into CPU images. Readback flips rows
// so that row 0 is the TOP of the image, matching core::Image.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"
#include "render/gl/handles.h"

namespace render {

struct RenderTargetOptions {
  int width = 512;   // pixels
  int height = 512;  // pixels
  // One texture per colour attachment, in attachment order. GL_RGBA8 for
  // pictures, GL_RGBA32F / GL_R32F for data (depth, ids, errors).
  std::vector<GLenum> color_formats = {GL_RGBA8};
  bool depth_stencil = true;  // DEPTH24_STENCIL8, sampleable

  void Check() const;
};

class RenderTarget {
 public:
  explicit RenderTarget(const RenderTargetOptions& options);

  int width() const { return options_.width; }
  int height() const { return options_.height; }
  const Framebuffer& framebuffer() const { return framebuffer_; }
  const Texture& color(int attachment = 0) const { return colors_.at(attachment); }
  const Texture& depth_stencil() const { return depth_stencil_; }

  // Binds as the draw framebuffer, enables all colour attachments, sets the viewport.
  void Bind() const;
  // Clears colour attachment 0..n to `rgba`, depth to `depth`, stencil to `stencil`.
  void Clear(const float rgba[4], float depth = 1.0f, int stencil = 0) const;

  core::Image8 ReadColor8(int attachment = 0) const;  // 4 channels
  core::ImageF ReadColorF(int attachment = 0) const;  // 4 channels
  // The first `channels` (1..4) channels of a float attachment (e.g. 1 for an
  // R32F camera-z attachment, 3 for normals).
  core::ImageF ReadChannelsF(int attachment, int channels) const;
  core::Image<uint32_t> ReadUint32(int attachment) const;  // 1 channel of an R32UI attachment
  core::ImageF ReadDepth() const;                          // window depth in [0, 1]
  core::Image8 ReadStencil() const;                        // 1 channel

 private:
  RenderTargetOptions options_;
  Framebuffer framebuffer_;
  std::vector<Texture> colors_;
  Texture depth_stencil_;
};

// GPU memory of one pixel of a target made with `options`: the sum of its
// colour formats' sizes plus 4 bytes for DEPTH24_STENCIL8 (an estimate: the
// driver may pad). InputError for a format this table does not know.
int64_t TargetBytesPerPixel(const RenderTargetOptions& options);

// The current GL implementation's size limits for a render target (a context
// must be current): every side of a target must be within all of them.
struct GlSizeLimits {
  int max_renderbuffer_size = 0;  // GL_MAX_RENDERBUFFER_SIZE, pixels
  int max_texture_size = 0;       // GL_MAX_TEXTURE_SIZE, pixels
  int max_viewport_width = 0;     // GL_MAX_VIEWPORT_DIMS[0], pixels
  int max_viewport_height = 0;    // GL_MAX_VIEWPORT_DIMS[1], pixels
  int MaxWidth() const;           // the least of the width limits
  int MaxHeight() const;          // the least of the height limits
};
GlSizeLimits QueryGlSizeLimits();

// Binds the default framebuffer 0 (the window in the viewer).
void BindDefaultFramebuffer(int width, int height);

}  // namespace render
