#include "render/passes/pass.h"

#include <fmt/format.h>

#include <cstdint>

#include "core/error.h"
#include "core/memory_budget.h"
#include "render/gl/uniform.h"

namespace render {

namespace {

// The view uniforms every pass's vertex stage may read.
struct ViewUniforms {
  explicit ViewUniforms(const Program& p)
      : cam_from_world(p, "u_cam_from_world"), clip_from_cam(p, "u_clip_from_cam") {}
  Uniform<glm::mat4> cam_from_world;
  Uniform<glm::mat4> clip_from_cam;
};

}  // namespace

RenderTargetOptions FrameTargetOptions(int width, int height) {
  RenderTargetOptions options;
  options.width = width;
  options.height = height;
  options.color_formats = {GL_RGBA8, GL_R32F, GL_RGBA16F, GL_R32UI};
  options.depth_stencil = true;
  return options;
}

int64_t FrameBytesPerPixel() { return TargetBytesPerPixel(FrameTargetOptions(1, 1)); }

void CheckFrameSize(std::string_view where, std::string_view flag, int width, int height,
                    const GlSizeLimits& limits, int min_side) {
  if (width < 1 || height < 1) {
    core::ThrowInputError(where, "{}: a {}x{} frame is empty (at least 1x1)", flag, width, height);
  }
  if (width < min_side || height < min_side) {
    core::ThrowInputError(where, "{}: a {}x{} frame is below the minimum {}x{}", flag, width,
                          height, min_side, min_side);
  }
  if (width > limits.MaxWidth() || height > limits.MaxHeight()) {
    core::ThrowInputError(where,
                          "{}: a {}x{} frame is larger than this GL implementation's largest, "
                          "{}x{} (GL_MAX_RENDERBUFFER_SIZE {}, GL_MAX_TEXTURE_SIZE {}, "
                          "GL_MAX_VIEWPORT_DIMS {}x{})",
                          flag, width, height, limits.MaxWidth(), limits.MaxHeight(),
                          limits.max_renderbuffer_size, limits.max_texture_size,
                          limits.max_viewport_width, limits.max_viewport_height);
  }
  // The target (llvmpipe keeps it in system memory) and as much again for its
  // readback and the images written from it. Pixels first (at most 2^62),
  // then bytes, saturating: no overflow.
  const auto pixels = static_cast<uint64_t>(int64_t{width} * height);
  const auto per_pixel = 2 * static_cast<uint64_t>(FrameBytesPerPixel());
  const uint64_t bytes = pixels > UINT64_MAX / per_pixel ? UINT64_MAX : pixels * per_pixel;
  core::CheckMemory(bytes, where,
                    fmt::format("{}: a {}x{} frame ({} bytes per pixel with its readback)", flag,
                                width, height, per_pixel));
}

void CheckFrameSize(std::string_view where, std::string_view flag, int width, int height,
                    int min_side) {
  CheckFrameSize(where, flag, width, height, QueryGlSizeLimits(), min_side);
}

void UseProgram(const RenderTarget& target, const Program& program, const ViewSetup& view) {
  target.Bind();
  program.Use();
  const auto& u = program.Typed<ViewUniforms>();
  u.cam_from_world.Set(view.cam_from_world);
  u.clip_from_cam.Set(view.clip_from_cam);
}

void BeginFrame(const RenderTarget& target) {
  target.Bind();
  // The previous frame left the outcome attachment masked, and clears obey
  // colour masks: unmask it first, or a reused target keeps its old bits.
  glColorMaski(kFrameOutcome, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  const float background[4] = {0, 0, 0, 0};
  target.Clear(background);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glColorMaski(kFrameOutcome, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
}

void BindOutcomeImage(const RenderTarget& target, GLuint unit) {
  glBindImageTexture(unit, target.color(kFrameOutcome).id(), 0, GL_FALSE, 0, GL_READ_WRITE,
                     GL_R32UI);
}

Frame ReadFrame(const RenderTarget& target) {
  // Image stores (outcome bits) must land before the readback.
  glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_PIXEL_BUFFER_BARRIER_BIT);
  Frame frame;
  frame.color = target.ReadColor8(kFrameColor);
  frame.depth = target.ReadChannelsF(kFrameCameraZ, 1);
  frame.normal = target.ReadChannelsF(kFrameNormal, 3);
  frame.outcome = target.ReadUint32(kFrameOutcome);
  return frame;
}

int64_t Frame::CountOutcome(uint32_t bits) const {
  int64_t n = 0;
  for (uint32_t v : outcome.values()) n += (v & bits) != 0;
  return n;
}

int64_t Frame::CoveredPixels() const {
  int64_t n = 0;
  for (size_t p = 0; p < color.pixel_count(); ++p)
    n += color.data()[p * color.channels() + 3] == 255;
  return n;
}

core::Image8 CoverageMask(const Frame& frame) {
  core::Image8 mask(frame.color.width(), frame.color.height(), 1, 0);
  for (int y = 0; y < mask.height(); ++y)
    for (int x = 0; x < mask.width(); ++x) mask.at(x, y) = frame.Covered(x, y) ? 255 : 0;
  return mask;
}

void DrawFrame(const RenderTarget& target, Pass& pass, const ViewSetup& view) {
  BeginFrame(target);
  pass.Draw(target, view);
}

Frame RenderFrame(Pass& pass, const ViewSetup& view, int width, int height) {
  RenderTarget target(FrameTargetOptions(width, height));
  DrawFrame(target, pass, view);
  return ReadFrame(target);
}

}  // namespace render
