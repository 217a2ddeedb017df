// The default framebuffer (the viewer's window) beyond binding it
// (render_target.h: BindDefaultFramebuffer): clearing, reading back the back
// buffer, and the blend that composites premultiplied frames over it.
#pragma once

#include <glm/glm.hpp>

#include "core/image.h"

namespace render {

// Clears the bound framebuffer's colour to `rgba`, depth to 1, stencil to 0.
void ClearBoundFramebuffer(const glm::vec4& rgba);
// The default framebuffer's back buffer, width x height RGBA8, row 0 at the
// top (the viewer's screenshot, GUI included).
core::Image8 ReadBackBuffer(int width, int height);  // render_target.cc: the one readback
// Blending of premultiplied colour over what is drawn (ONE, ONE_MINUS_SRC_ALPHA).
void UsePremultipliedBlend();

}  // namespace render
