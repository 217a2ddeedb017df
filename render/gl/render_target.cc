#include "render/gl/render_target.h"

#include <algorithm>

#include "core/check.h"
#include "core/error.h"
#include "render/gl/window_frame.h"

namespace render {

void RenderTargetOptions::Check() const {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    core::ThrowInputError("RenderTargetOptions", "size {}x{} is outside 1..16384", width, height);
  }
  if (color_formats.size() > 8) {
    core::ThrowInputError("RenderTargetOptions", "{} colour attachments (at most 8)",
                          color_formats.size());
  }
}

int64_t TargetBytesPerPixel(const RenderTargetOptions& options) {
  int64_t bytes = options.depth_stencil ? 4 : 0;
  for (GLenum format : options.color_formats) {
    switch (format) {
      case GL_R8:
        bytes += 1;
        break;
      case GL_RGBA8:
      case GL_R32F:
      case GL_R32UI:
      case GL_RG16F:
        bytes += 4;
        break;
      case GL_RG32F:
      case GL_RG32UI:
      case GL_RGBA16F:
        bytes += 8;
        break;
      case GL_RGBA32F:
      case GL_RGBA32UI:
        bytes += 16;
        break;
      default:
        core::ThrowInputError("TargetBytesPerPixel", "unknown colour format 0x{:x}", format);
    }
  }
  return bytes;
}

int GlSizeLimits::MaxWidth() const {
  return std::min({max_renderbuffer_size, max_texture_size, max_viewport_width});
}

int GlSizeLimits::MaxHeight() const {
  return std::min({max_renderbuffer_size, max_texture_size, max_viewport_height});
}

GlSizeLimits QueryGlSizeLimits() {
  GlSizeLimits limits;
  GLint viewport[2] = {0, 0};
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &limits.max_renderbuffer_size);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &limits.max_texture_size);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
  limits.max_viewport_width = viewport[0];
  limits.max_viewport_height = viewport[1];
  IBR_CHECK_GT(limits.MaxWidth(), 0);
  IBR_CHECK_GT(limits.MaxHeight(), 0);
  return limits;
}

RenderTarget::RenderTarget(const RenderTargetOptions& options) : options_(options) {
  options_.Check();
  framebuffer_ = Framebuffer::Create();
  for (size_t i = 0; i < options_.color_formats.size(); ++i) {
    colors_.push_back(
        Texture::Create2D(options_.color_formats[i], options_.width, options_.height));
    glNamedFramebufferTexture(framebuffer_.id(), GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i),
                              colors_.back().id(), 0);
  }
  if (options_.depth_stencil) {
    depth_stencil_ = Texture::Create2D(GL_DEPTH24_STENCIL8, options_.width, options_.height);
    glNamedFramebufferTexture(framebuffer_.id(), GL_DEPTH_STENCIL_ATTACHMENT, depth_stencil_.id(),
                              0);
  }
  std::vector<GLenum> draw_buffers;
  for (size_t i = 0; i < colors_.size(); ++i)
    draw_buffers.push_back(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i));
  if (draw_buffers.empty()) {
    glNamedFramebufferDrawBuffer(framebuffer_.id(), GL_NONE);
  } else {
    glNamedFramebufferDrawBuffers(framebuffer_.id(), static_cast<GLsizei>(draw_buffers.size()),
                                  draw_buffers.data());
  }
  const GLenum status = glCheckNamedFramebufferStatus(framebuffer_.id(), GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    core::ThrowInputError("RenderTarget", "framebuffer incomplete (status 0x{:x}) for {}x{}",
                          status, options_.width, options_.height);
  }
}

void RenderTarget::Bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
  glViewport(0, 0, options_.width, options_.height);
}

void RenderTarget::Clear(const float rgba[4], float depth, int stencil) const {
  for (size_t i = 0; i < colors_.size(); ++i) {
    const GLenum format = options_.color_formats[i];
    if (format == GL_R32UI || format == GL_RG32UI || format == GL_RGBA32UI) {
      // Integer attachments take an integer clear; a float one is undefined.
      const GLuint zero[4] = {0, 0, 0, 0};
      glClearNamedFramebufferuiv(framebuffer_.id(), GL_COLOR, static_cast<GLint>(i), zero);
    } else {
      glClearNamedFramebufferfv(framebuffer_.id(), GL_COLOR, static_cast<GLint>(i), rgba);
    }
  }
  if (options_.depth_stencil) {
    glClearNamedFramebufferfi(framebuffer_.id(), GL_DEPTH_STENCIL, 0, depth, stencil);
  }
}

namespace {

// Reads the bound READ framebuffer into `image` and flips rows to top-first.
template <typename T>
void ReadPixels(GLuint framebuffer, GLenum read_buffer, GLenum format, GLenum type,
                core::Image<T>& image) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glNamedFramebufferReadBuffer(framebuffer, read_buffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, image.width(), image.height(), format, type, image.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  for (int y = 0; y < image.height() / 2; ++y) {
    auto top = image.row(y);
    auto bottom = image.row(image.height() - 1 - y);
    std::swap_ranges(top.begin(), top.end(), bottom.begin());
  }
}

}  // namespace

// window_frame.h: the window's back buffer through the same readback.
core::Image8 ReadBackBuffer(int width, int height) {
  core::Image8 image(width, height, 4);
  ReadPixels(0, GL_BACK, GL_RGBA, GL_UNSIGNED_BYTE, image);
  return image;
}

core::Image8 RenderTarget::ReadColor8(int attachment) const {
  core::Image8 image(options_.width, options_.height, 4);
  ReadPixels(framebuffer_.id(), GL_COLOR_ATTACHMENT0 + attachment, GL_RGBA, GL_UNSIGNED_BYTE,
             image);
  return image;
}

core::ImageF RenderTarget::ReadColorF(int attachment) const {
  core::ImageF image(options_.width, options_.height, 4);
  ReadPixels(framebuffer_.id(), GL_COLOR_ATTACHMENT0 + attachment, GL_RGBA, GL_FLOAT, image);
  return image;
}

core::ImageF RenderTarget::ReadChannelsF(int attachment, int channels) const {
  IBR_CHECK(channels >= 1 && channels <= 4);
  const core::ImageF rgba = ReadColorF(attachment);
  if (channels == 4) return rgba;
  core::ImageF out(options_.width, options_.height, channels);
  for (int y = 0; y < options_.height; ++y) {
    for (int x = 0; x < options_.width; ++x) {
      for (int c = 0; c < channels; ++c) out.at(x, y, c) = rgba.at(x, y, c);
    }
  }
  return out;
}

core::Image<uint32_t> RenderTarget::ReadUint32(int attachment) const {
  core::Image<uint32_t> image(options_.width, options_.height, 1);
  ReadPixels(framebuffer_.id(), GL_COLOR_ATTACHMENT0 + attachment, GL_RED_INTEGER, GL_UNSIGNED_INT,
             image);
  return image;
}

core::ImageF RenderTarget::ReadDepth() const {
  IBR_CHECK(options_.depth_stencil);
  core::ImageF image(options_.width, options_.height, 1);
  ReadPixels(framebuffer_.id(), GL_NONE, GL_DEPTH_COMPONENT, GL_FLOAT, image);
  return image;
}

core::Image8 RenderTarget::ReadStencil() const {
  IBR_CHECK(options_.depth_stencil);
  core::Image8 image(options_.width, options_.height, 1);
  ReadPixels(framebuffer_.id(), GL_NONE, GL_STENCIL_INDEX, GL_UNSIGNED_BYTE, image);
  return image;
}

void BindDefaultFramebuffer(int width, int height) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, width, height);
}

}  // namespace render
