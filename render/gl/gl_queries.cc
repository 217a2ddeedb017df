#include "render/gl/gl_queries.h"

#include "render/gl/gl.h"
#include "render/gl/handles.h"

namespace render {

namespace {

std::string GlString(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? std::string(s) : std::string();
}

}  // namespace

void WaitForGpu() { glFinish(); }

DrawWork CountDrawWork(const std::function<void()>& draw) {
  const Query samples = Query::Create(GL_SAMPLES_PASSED);
  const Query primitives = Query::Create(GL_PRIMITIVES_GENERATED);
  glBeginQuery(GL_SAMPLES_PASSED, samples.id());
  glBeginQuery(GL_PRIMITIVES_GENERATED, primitives.id());
  draw();
  glEndQuery(GL_PRIMITIVES_GENERATED);
  glEndQuery(GL_SAMPLES_PASSED);
  DrawWork work;
  GLuint64 value = 0;
  glGetQueryObjectui64v(samples.id(), GL_QUERY_RESULT, &value);
  work.samples_passed = value;
  glGetQueryObjectui64v(primitives.id(), GL_QUERY_RESULT, &value);
  work.primitives_generated = value;
  return work;
}

std::string CurrentDriverName() { return GlString(GL_RENDERER) + " / " + GlString(GL_VERSION); }

int CurrentSubpixelBits() {
  GLint bits = 4;
  glGetIntegerv(GL_SUBPIXEL_BITS, &bits);
  return bits;
}

}  // namespace render
