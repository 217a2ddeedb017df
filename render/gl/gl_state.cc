#include "render/gl/gl_state.h"

namespace render {

namespace {
void SetEnabled(GLenum cap, bool on) {
  if (on) {
    glEnable(cap);
  } else {
    glDisable(cap);
  }
}
GLint GetInt(GLenum name) {
  GLint v = 0;
  glGetIntegerv(name, &v);
  return v;
}
}  // namespace

void ApplyGlState(const GlState& state) {
  SetEnabled(GL_DEPTH_TEST, state.depth_test);
  glDepthFunc(state.depth_func);
  glDepthMask(state.depth_write ? GL_TRUE : GL_FALSE);
  SetEnabled(GL_STENCIL_TEST, state.stencil.has_value());
  if (state.stencil) {
    const StencilState& s = *state.stencil;
    glStencilFunc(s.func, s.ref, s.func_mask);
    glStencilOp(s.stencil_fail, s.depth_fail, s.depth_pass);
    glStencilMask(s.write_mask);
  }
  SetEnabled(GL_BLEND, state.blend.has_value());
  if (state.blend) {
    const BlendState& b = *state.blend;
    glBlendFuncSeparate(b.src_rgb, b.dst_rgb, b.src_alpha, b.dst_alpha);
    glBlendEquation(b.equation);
  }
  SetEnabled(GL_CULL_FACE, state.cull_face.has_value());
  if (state.cull_face) glCullFace(*state.cull_face);
}

ScopedGlState::ScopedGlState(const GlState& state) {
  Saved& s = saved_;
  s.depth_test = glIsEnabled(GL_DEPTH_TEST);
  glGetBooleanv(GL_DEPTH_WRITEMASK, &s.depth_write);
  s.stencil_test = glIsEnabled(GL_STENCIL_TEST);
  s.blend = glIsEnabled(GL_BLEND);
  s.cull = glIsEnabled(GL_CULL_FACE);
  s.depth_func = GetInt(GL_DEPTH_FUNC);
  s.cull_face = GetInt(GL_CULL_FACE_MODE);
  s.stencil_func = GetInt(GL_STENCIL_FUNC);
  s.stencil_ref = GetInt(GL_STENCIL_REF);
  s.stencil_value_mask = GetInt(GL_STENCIL_VALUE_MASK);
  s.stencil_fail = GetInt(GL_STENCIL_FAIL);
  s.stencil_depth_fail = GetInt(GL_STENCIL_PASS_DEPTH_FAIL);
  s.stencil_depth_pass = GetInt(GL_STENCIL_PASS_DEPTH_PASS);
  s.stencil_write_mask = GetInt(GL_STENCIL_WRITEMASK);
  s.blend_src_rgb = GetInt(GL_BLEND_SRC_RGB);
  s.blend_dst_rgb = GetInt(GL_BLEND_DST_RGB);
  s.blend_src_alpha = GetInt(GL_BLEND_SRC_ALPHA);
  s.blend_dst_alpha = GetInt(GL_BLEND_DST_ALPHA);
  s.blend_equation = GetInt(GL_BLEND_EQUATION_RGB);
  ApplyGlState(state);
}

ScopedGlState::~ScopedGlState() {
  const Saved& s = saved_;
  SetEnabled(GL_DEPTH_TEST, s.depth_test);
  glDepthFunc(static_cast<GLenum>(s.depth_func));
  glDepthMask(s.depth_write);
  SetEnabled(GL_STENCIL_TEST, s.stencil_test);
  glStencilFunc(static_cast<GLenum>(s.stencil_func), s.stencil_ref,
                static_cast<GLuint>(s.stencil_value_mask));
  glStencilOp(static_cast<GLenum>(s.stencil_fail), static_cast<GLenum>(s.stencil_depth_fail),
              static_cast<GLenum>(s.stencil_depth_pass));
  glStencilMask(static_cast<GLuint>(s.stencil_write_mask));
  SetEnabled(GL_BLEND, s.blend);
  glBlendFuncSeparate(static_cast<GLenum>(s.blend_src_rgb), static_cast<GLenum>(s.blend_dst_rgb),
                      static_cast<GLenum>(s.blend_src_alpha),
                      static_cast<GLenum>(s.blend_dst_alpha));
  glBlendEquation(static_cast<GLenum>(s.blend_equation));
  SetEnabled(GL_CULL_FACE, s.cull);
  glCullFace(static_cast<GLenum>(s.cull_face));
}

FullScreenTriangle::FullScreenTriangle() : vao_(VertexArray::Create()) {}

void FullScreenTriangle::Draw() const {
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
}

}  // namespace render
