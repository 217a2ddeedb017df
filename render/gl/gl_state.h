// Scoped fixed-function state and the one full-screen draw.
//
// GlState describes the depth, stencil, blend and cull state a draw needs;
// ScopedGlState applies it and restores what was there before when it goes
// out of scope, so a pass that needs stencil counting or additive blending
// (depth objects, volumes) leaves the frame's compositing state (depth test
// LESS, render/passes/pass.h) as it found it.
#pragma once

#include <optional>

#include "render/gl/gl.h"
#include "render/gl/handles.h"

namespace render {

struct StencilState {
  GLenum func = GL_ALWAYS;
  GLint ref = 0;
  GLuint func_mask = 0xFF;
  GLenum stencil_fail = GL_KEEP, depth_fail = GL_KEEP, depth_pass = GL_KEEP;
  GLuint write_mask = 0xFF;
};

struct BlendState {
  GLenum src_rgb = GL_ONE, dst_rgb = GL_ZERO, src_alpha = GL_ONE, dst_alpha = GL_ZERO;
  GLenum equation = GL_FUNC_ADD;
};

struct GlState {
  bool depth_test = true;
  GLenum depth_func = GL_LESS;
  bool depth_write = true;
  std::optional<StencilState> stencil;  // nullopt = stencil test off
  std::optional<BlendState> blend;      // nullopt = blending off (applies to every draw buffer)
  std::optional<GLenum> cull_face;      // nullopt = culling off; else GL_BACK / GL_FRONT
};

// Applies `state` now; the destructor restores the state found on entry.
class ScopedGlState {
 public:
  explicit ScopedGlState(const GlState& state);
  ~ScopedGlState();
  ScopedGlState(const ScopedGlState&) = delete;
  ScopedGlState& operator=(const ScopedGlState&) = delete;

 private:
  struct Saved {
    GLboolean depth_test, depth_write, stencil_test, blend, cull;
    GLint depth_func, cull_face;
    GLint stencil_func, stencil_ref, stencil_value_mask, stencil_fail, stencil_depth_fail,
        stencil_depth_pass, stencil_write_mask;
    GLint blend_src_rgb, blend_dst_rgb, blend_src_alpha, blend_dst_alpha, blend_equation;
  } saved_;
};

void ApplyGlState(const GlState& state);

// Draws one triangle covering the viewport (common/fullscreen.vert.glsl's
// gl_VertexID trick) with an empty vertex array made once per call site's
// context; the bound program and state are the caller's.
class FullScreenTriangle {
 public:
  FullScreenTriangle();
  void Draw() const;

 private:
  VertexArray vao_;
};

}  // namespace render
