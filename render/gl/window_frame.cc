#include "render/gl/window_frame.h"

#include "render/gl/gl.h"

namespace render {

void ClearBoundFramebuffer(const glm::vec4& rgba) {
  glClearColor(rgba.r, rgba.g, rgba.b, rgba.a);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
}

void UsePremultipliedBlend() { glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA); }

}  // namespace render
