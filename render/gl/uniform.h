// Typed uniforms (the Magnum pattern, as its PhongGL caches every location in
// its constructor): a program's uniform locations are looked up once per
// linked program and set through typed setters, never by name on every draw.
// Outside render/gl this is the only way to set a uniform
// (tests/render/gl/uniform_rule_test enforces it; docs/decisions/typed-programs.md).
//
// A pass declares one small struct per program (or per group of uniforms that
// several programs share, like the ray core's), whose members are Uniform<T>
// handles looked up in its constructor:
//
//   struct MeshUniforms {
//     explicit MeshUniforms(const Program& p)
//         : world_from_object(p, "u_world_from_object"), base_color(p, "u_base_color") {}
//     Uniform<glm::mat4> world_from_object;
//     Uniform<glm::vec4> base_color;
//   };
//   const auto& u = program.Typed<MeshUniforms>();  // built on the first call, then cached
//   u.base_color.Set(options.base_color);
//
// Program::Typed keeps the struct with the linked program, so programs that
// ProgramCache hands out by desc are looked up once each, however many passes
// draw with them. A uniform the linker removed (location -1: the variant does
// not use it) gives a handle whose Set does nothing, as glProgramUniform* does
// with -1: a struct may name every uniform of every variant of its shader.
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <string_view>

#include "render/gl/handles.h"

namespace render {

namespace uniform_detail {
// The C++ value types a uniform handle sets, and the GLSL types each may set.
enum class ValueKind {
  kNone,
  kInt,
  kUnsigned,
  kFloat,
  kVec2,
  kVec3,
  kVec4,
  kIvec2,
  kIvec3,
  kMat3,
  kMat4
};
template <typename T>
inline constexpr ValueKind kKindOf = ValueKind::kNone;  // no handle for T
template <>
inline constexpr ValueKind kKindOf<int> = ValueKind::kInt;
template <>
inline constexpr ValueKind kKindOf<unsigned> = ValueKind::kUnsigned;
template <>
inline constexpr ValueKind kKindOf<float> = ValueKind::kFloat;
template <>
inline constexpr ValueKind kKindOf<glm::vec2> = ValueKind::kVec2;
template <>
inline constexpr ValueKind kKindOf<glm::vec3> = ValueKind::kVec3;
template <>
inline constexpr ValueKind kKindOf<glm::vec4> = ValueKind::kVec4;
template <>
inline constexpr ValueKind kKindOf<glm::ivec2> = ValueKind::kIvec2;
template <>
inline constexpr ValueKind kKindOf<glm::ivec3> = ValueKind::kIvec3;
template <>
inline constexpr ValueKind kKindOf<glm::mat3> = ValueKind::kMat3;
template <>
inline constexpr ValueKind kKindOf<glm::mat4> = ValueKind::kMat4;

// `name`'s location in `program` (-1: not active). An active uniform whose
// GLSL type `kind` cannot set (a float handle on an int uniform, which GL
// would reject on every Set with GL_INVALID_OPERATION) is a programming error:
// it fails a CHECK naming the uniform, once, when the struct is built.
GLint Locate(const Program& program, std::string_view name, ValueKind kind);

// glProgramUniform* for one value (count 1) or an array (count = size).
// Location -1 is skipped.
void Set(GLuint program, GLint location, int value);
void Set(GLuint program, GLint location, unsigned value);
void Set(GLuint program, GLint location, float value);
void Set(GLuint program, GLint location, const glm::vec2& value);
void Set(GLuint program, GLint location, const glm::vec3& value);
void Set(GLuint program, GLint location, const glm::vec4& value);
void Set(GLuint program, GLint location, const glm::ivec2& value);
void Set(GLuint program, GLint location, const glm::ivec3& value);
void Set(GLuint program, GLint location, const glm::mat3& value);
void Set(GLuint program, GLint location, const glm::mat4& value);
void Set(GLuint program, GLint location, std::span<const glm::vec4> values);
void Set(GLuint program, GLint location, std::span<const glm::mat4> values);
}  // namespace uniform_detail

// The location of one uniform of one linked program, looked up once, and the
// program it belongs to; what Uniform<T> and UniformArray<T> set.
class UniformLocation {
 public:
  // No program: every Set is a no-op.
  UniformLocation() = default;
  // `name` as GLSL spells it, array elements as "u_x[3]"; `kind` the value
  // type a handle will set (checked against the GLSL type, see Locate).
  UniformLocation(const Program& program, std::string_view name, uniform_detail::ValueKind kind)
      : program_(program.id()), location_(uniform_detail::Locate(program, name, kind)) {}
  // -1 when the program has no such active uniform.
  GLint location() const { return location_; }
  bool active() const { return location_ >= 0; }

 protected:
  GLuint program_ = 0;
  GLint location_ = -1;
};

// One uniform of type T: int (also GLSL bool, samplers and image units),
// unsigned, float, glm::vec2/3/4, glm::ivec2/3, glm::mat3/4.
template <typename T>
class Uniform : public UniformLocation {
  static_assert(uniform_detail::kKindOf<T> != uniform_detail::ValueKind::kNone);

 public:
  Uniform() = default;
  Uniform(const Program& program, std::string_view name)
      : UniformLocation(program, name, uniform_detail::kKindOf<T>) {}
  void Set(const T& value) const { uniform_detail::Set(program_, location_, value); }
};

// A uniform array `T name[N]` set from its first element on (values.size()
// elements). T: glm::vec4, glm::mat4.
template <typename T>
class UniformArray : public UniformLocation {
 public:
  UniformArray() = default;
  UniformArray(const Program& program, std::string_view name)
      : UniformLocation(program, name, uniform_detail::kKindOf<T>) {}
  void Set(std::span<const T> values) const { uniform_detail::Set(program_, location_, values); }
};

}  // namespace render
