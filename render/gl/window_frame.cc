#include "render/gl/window_frame.h"

#include <algorithm>

#include "render/gl/gl.h"

namespace render {

void ClearBoundFramebuffer(const glm::vec4& rgba) {
  glClearColor(rgba.r, rgba.g, rgba.b, rgba.a);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
}

core::Image8 ReadBackBuffer(int width, int height) {
  core::Image8 image(width, height, 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, image.data());
  for (int y = 0; y < height / 2; ++y) {  // GL rows start at the bottom
    auto top = image.row(y);
    auto bottom = image.row(height - 1 - y);
    std::swap_ranges(top.begin(), top.end(), bottom.begin());
  }
  return image;
}

void UsePremultipliedBlend() { glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA); }

}  // namespace render
