#include "render/handles.h"

#include "core/check.h"

namespace render {

Buffer Buffer::Create() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  IBR_CHECK_NE(id, 0u);
  return Buffer(id);
}

Buffer Buffer::CreateWithData(const void* data, GLsizeiptr bytes, GLbitfield flags) {
  Buffer buffer = Create();
  glNamedBufferStorage(buffer.id(), bytes, data, flags);
  return buffer;
}

Texture Texture::Create(GLenum target) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  IBR_CHECK_NE(id, 0u);
  return Texture(id, target);
}

namespace {
void DefaultSampling(GLuint id) {
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
}
}  // namespace

Texture Texture::Create2D(GLenum internal_format, int width, int height) {
  IBR_CHECK(width > 0 && height > 0);
  Texture texture = Create(GL_TEXTURE_2D);
  glTextureStorage2D(texture.id(), 1, internal_format, width, height);
  DefaultSampling(texture.id());
  return texture;
}

Texture Texture::Create3D(GLenum internal_format, int width, int height, int depth) {
  IBR_CHECK(width > 0 && height > 0 && depth > 0);
  Texture texture = Create(GL_TEXTURE_3D);
  glTextureStorage3D(texture.id(), 1, internal_format, width, height, depth);
  DefaultSampling(texture.id());
  return texture;
}

Renderbuffer Renderbuffer::Create(GLenum internal_format, int width, int height) {
  GLuint id = 0;
  glCreateRenderbuffers(1, &id);
  IBR_CHECK_NE(id, 0u);
  glNamedRenderbufferStorage(id, internal_format, width, height);
  return Renderbuffer(id);
}

Framebuffer Framebuffer::Create() {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  IBR_CHECK_NE(id, 0u);
  return Framebuffer(id);
}

VertexArray VertexArray::Create() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  IBR_CHECK_NE(id, 0u);
  return VertexArray(id);
}

Query Query::Create(GLenum target) {
  GLuint id = 0;
  glCreateQueries(target, 1, &id);
  IBR_CHECK_NE(id, 0u);
  return Query(id);
}

}  // namespace render
