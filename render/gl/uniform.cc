#include "render/gl/uniform.h"

#include <fmt/format.h>

#include <string>

#include "core/check.h"

namespace render {
namespace uniform_detail {

namespace {

bool IsSamplerOrImage(GLenum type) {
  switch (type) {
    case GL_SAMPLER_1D:
    case GL_SAMPLER_2D:
    case GL_SAMPLER_3D:
    case GL_SAMPLER_CUBE:
    case GL_SAMPLER_1D_SHADOW:
    case GL_SAMPLER_2D_SHADOW:
    case GL_SAMPLER_1D_ARRAY:
    case GL_SAMPLER_2D_ARRAY:
    case GL_SAMPLER_2D_MULTISAMPLE:
    case GL_SAMPLER_2D_RECT:
    case GL_SAMPLER_BUFFER:
    case GL_INT_SAMPLER_1D:
    case GL_INT_SAMPLER_2D:
    case GL_INT_SAMPLER_3D:
    case GL_INT_SAMPLER_2D_ARRAY:
    case GL_UNSIGNED_INT_SAMPLER_1D:
    case GL_UNSIGNED_INT_SAMPLER_2D:
    case GL_UNSIGNED_INT_SAMPLER_3D:
    case GL_UNSIGNED_INT_SAMPLER_2D_ARRAY:
    case GL_IMAGE_1D:
    case GL_IMAGE_2D:
    case GL_IMAGE_3D:
    case GL_IMAGE_2D_ARRAY:
    case GL_INT_IMAGE_2D:
    case GL_INT_IMAGE_3D:
    case GL_UNSIGNED_INT_IMAGE_1D:
    case GL_UNSIGNED_INT_IMAGE_2D:
    case GL_UNSIGNED_INT_IMAGE_3D:
    case GL_UNSIGNED_INT_IMAGE_2D_ARRAY:
      return true;
    default:
      return false;
  }
}

// glProgramUniform* type rules (GL 4.6 sec. 7.6.1): the 1i form sets int,
// bool and sampler/image uniforms; every other form sets its own type only
// (or bool, which we do not use).
bool Sets(ValueKind kind, GLenum type) {
  switch (kind) {
    case ValueKind::kNone:
      return false;
    case ValueKind::kInt:
      return type == GL_INT || type == GL_BOOL || IsSamplerOrImage(type);
    case ValueKind::kUnsigned:
      return type == GL_UNSIGNED_INT || type == GL_BOOL;
    case ValueKind::kFloat:
      return type == GL_FLOAT || type == GL_BOOL;
    case ValueKind::kVec2:
      return type == GL_FLOAT_VEC2;
    case ValueKind::kVec3:
      return type == GL_FLOAT_VEC3;
    case ValueKind::kVec4:
      return type == GL_FLOAT_VEC4;
    case ValueKind::kIvec2:
      return type == GL_INT_VEC2;
    case ValueKind::kIvec3:
      return type == GL_INT_VEC3;
    case ValueKind::kMat3:
      return type == GL_FLOAT_MAT3;
    case ValueKind::kMat4:
      return type == GL_FLOAT_MAT4;
  }
  return false;
}

// The GLSL type of the active uniform (array) `name` ("u_x[3]" -> u_x's
// element type); 0 if the program has no such resource.
GLenum UniformType(GLuint program, std::string_view name) {
  std::string base(name.substr(0, name.find('[')));
  GLuint index = glGetProgramResourceIndex(program, GL_UNIFORM, base.c_str());
  if (index == GL_INVALID_INDEX) {
    index = glGetProgramResourceIndex(program, GL_UNIFORM, (base + "[0]").c_str());
  }
  if (index == GL_INVALID_INDEX) return 0;
  const GLenum prop = GL_TYPE;
  GLint type = 0;
  glGetProgramResourceiv(program, GL_UNIFORM, index, 1, &prop, 1, nullptr, &type);
  return static_cast<GLenum>(type);
}

}  // namespace

GLint Locate(const Program& program, std::string_view name, ValueKind kind) {
  const GLint location = program.Uniform(name);
  if (location < 0) return -1;
  const GLenum type = UniformType(program.id(), name);
  if (!Sets(kind, type)) {
    core::internal::CheckFailed(
        __FILE__, __LINE__, "Sets(kind, type)",
        fmt::format("uniform '{}' has GLSL type {:#x}, which a handle of value kind {} cannot set",
                    name, type, static_cast<int>(kind)));
  }
  return location;
}

// GL ignores location -1 too; returning first skips the call.
void Set(GLuint p, GLint l, int v) {
  if (l >= 0) glProgramUniform1i(p, l, v);
}
void Set(GLuint p, GLint l, unsigned v) {
  if (l >= 0) glProgramUniform1ui(p, l, v);
}
void Set(GLuint p, GLint l, float v) {
  if (l >= 0) glProgramUniform1f(p, l, v);
}
void Set(GLuint p, GLint l, const glm::vec2& v) {
  if (l >= 0) glProgramUniform2fv(p, l, 1, &v[0]);
}
void Set(GLuint p, GLint l, const glm::vec3& v) {
  if (l >= 0) glProgramUniform3fv(p, l, 1, &v[0]);
}
void Set(GLuint p, GLint l, const glm::vec4& v) {
  if (l >= 0) glProgramUniform4fv(p, l, 1, &v[0]);
}
void Set(GLuint p, GLint l, const glm::ivec2& v) {
  if (l >= 0) glProgramUniform2iv(p, l, 1, &v[0]);
}
void Set(GLuint p, GLint l, const glm::ivec3& v) {
  if (l >= 0) glProgramUniform3iv(p, l, 1, &v[0]);
}
void Set(GLuint p, GLint l, const glm::mat3& v) {
  if (l >= 0) glProgramUniformMatrix3fv(p, l, 1, GL_FALSE, &v[0][0]);
}
void Set(GLuint p, GLint l, const glm::mat4& v) {
  if (l >= 0) glProgramUniformMatrix4fv(p, l, 1, GL_FALSE, &v[0][0]);
}
void Set(GLuint p, GLint l, std::span<const glm::vec4> v) {
  if (l >= 0 && !v.empty()) glProgramUniform4fv(p, l, static_cast<GLsizei>(v.size()), &v[0][0]);
}
void Set(GLuint p, GLint l, std::span<const glm::mat4> v) {
  if (l >= 0 && !v.empty()) {
    glProgramUniformMatrix4fv(p, l, static_cast<GLsizei>(v.size()), GL_FALSE, &v[0][0][0]);
  }
}

}  // namespace uniform_detail

}  // namespace render
