#include "render/gl/handles.h"

#include <algorithm>
#include <atomic>
#include <cstring>

#include "core/check.h"
#include "render/gl/uniform.h"

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

namespace {
std::atomic<int64_t> g_textures_created{0};
}  // namespace

int64_t Texture::created_count() { return g_textures_created.load(); }

Texture Texture::Create(GLenum target) {
  ++g_textures_created;
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

Texture Texture::Create1DWithData(GLenum internal_format, int width, GLenum format, GLenum type,
                                  const void* data) {
  IBR_CHECK(width > 0);
  Texture texture = Create(GL_TEXTURE_1D);
  glTextureStorage1D(texture.id(), 1, internal_format, width);
  DefaultSampling(texture.id());
  glTextureSubImage1D(texture.id(), 0, 0, width, format, type, data);
  return texture;
}

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

Texture Texture::Create3DWithData(GLenum internal_format, const glm::ivec3& dims, GLenum format,
                                  GLenum type, const void* data) {
  Texture texture = Create3D(internal_format, dims.x, dims.y, dims.z);
  GLint alignment = 4;
  glGetIntegerv(GL_UNPACK_ALIGNMENT, &alignment);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(texture.id(), 0, 0, 0, 0, dims.x, dims.y, dims.z, format, type, data);
  glPixelStorei(GL_UNPACK_ALIGNMENT, alignment);
  return texture;
}

Texture& Texture::SetLinearFilter() {
  glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  return *this;
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

void Program::CacheUniforms() {
  locations_.clear();
  typed_.clear();
  GLint count = 0;
  glGetProgramInterfaceiv(id(), GL_UNIFORM, GL_ACTIVE_RESOURCES, &count);
  std::string name;
  for (GLint i = 0; i < count; ++i) {
    const GLenum props[] = {GL_NAME_LENGTH, GL_LOCATION};
    GLint values[2] = {0, -1};
    glGetProgramResourceiv(id(), GL_UNIFORM, static_cast<GLuint>(i), 2, props, 2, nullptr, values);
    if (values[1] < 0) continue;  // a block member: set through its buffer
    name.assign(static_cast<size_t>(std::max(values[0], 1)), '\0');
    glGetProgramResourceName(id(), GL_UNIFORM, static_cast<GLuint>(i), values[0], nullptr,
                             name.data());
    name.resize(std::strlen(name.c_str()));
    locations_[name] = values[1];
    // "u_x[0]" is also reachable as "u_x".
    if (name.size() > 3 && name.ends_with("[0]"))
      locations_[name.substr(0, name.size() - 3)] = values[1];
  }
}

GLint Program::Uniform(std::string_view name) const {
  const std::string key(name);
  auto it = locations_.find(key);
  if (it != locations_.end()) return it->second;
  // Not active, or an array element past [0]: ask GL once and remember.
  const GLint location = glGetUniformLocation(id(), key.c_str());
  locations_.emplace(key, location);
  return location;
}

void Program::Set(std::string_view n, int v) const { uniform_detail::Set(id(), Uniform(n), v); }
void Program::Set(std::string_view n, unsigned v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, float v) const { uniform_detail::Set(id(), Uniform(n), v); }
void Program::Set(std::string_view n, const glm::vec2& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, const glm::vec3& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, const glm::vec4& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, const glm::ivec2& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, const glm::ivec3& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, const glm::mat3& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, const glm::mat4& v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, std::span<const glm::vec4> v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}
void Program::Set(std::string_view n, std::span<const glm::mat4> v) const {
  uniform_detail::Set(id(), Uniform(n), v);
}

}  // namespace render
