#include "render/gl/gl_debug.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "render/gl/gl.h"

namespace render {
namespace {

void GLAPIENTRY OnDebugMessage(GLenum /*source*/, GLenum type, GLuint id, GLenum severity,
                               GLsizei /*length*/, const GLchar* message, const void* /*user*/) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) {
    spdlog::trace("GL: {}", message);
  } else if (type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH) {
    spdlog::error("GL error {}: {}", id, message);
  } else {
    spdlog::debug("GL {}: {}", id, message);
  }
}

const char* ErrorName(GLenum error) {
  switch (error) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    default:
      return "GL_UNKNOWN_ERROR";
  }
}

}  // namespace

bool InstallDebugCallback() {
  if (!(epoxy_gl_version() >= 43 || epoxy_has_gl_extension("GL_KHR_debug"))) return false;
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(OnDebugMessage, nullptr);
  return true;
}

std::string DrainGlErrors() {
  std::string errors;
  // Bounded: a lost context can return errors forever.
  for (int i = 0; i < 64; ++i) {
    const GLenum error = glGetError();
    if (error == GL_NO_ERROR) break;
    if (!errors.empty()) errors += ", ";
    errors += ErrorName(error);
  }
  return errors;
}

}  // namespace render
