// Typed uniforms (render/gl/uniform.h) against a real context: every handle
// type sets what glGetUniform* reads back, a uniform the program lacks is a
// harmless no-op, Program::Typed builds a struct once per linked program, and
// a handle whose type cannot set its GLSL uniform fails at lookup.
#include "render/gl/uniform.h"

#include <gtest/gtest.h>

#include <array>
#include <glm/gtc/matrix_transform.hpp>
#include <vector>

#include "render/gl/shader_program.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

ShaderSources TestSources() {
  return ShaderSources({
      {"full.vert.glsl", R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)"},
      // Every uniform type a handle sets, each used so the linker keeps it.
      {"all.frag.glsl", R"(#version 330 core
uniform int u_int;
uniform uint u_uint;
uniform float u_float;
uniform vec2 u_vec2;
uniform vec3 u_vec3;
uniform vec4 u_vec4;
uniform ivec2 u_ivec2;
uniform ivec3 u_ivec3;
uniform mat3 u_mat3;
uniform mat4 u_mat4;
uniform bool u_bool;
uniform sampler2D u_sampler;
uniform vec4 u_vec4_array[3];
uniform mat4 u_mat4_array[2];
uniform float u_float_array[4];
#ifdef UNUSED_TOO
uniform float u_only_in_variant;
#endif
out vec4 o_color;
void main() {
  float s = float(u_int) + float(u_uint) + u_float + u_vec2.x + u_vec3.y + u_vec4.z +
            float(u_ivec2.x + u_ivec3.z) + u_mat3[1][2] + u_mat4[3][0] + (u_bool ? 1.0 : 0.0) +
            texture(u_sampler, vec2(0.5)).r + u_vec4_array[0].x + u_vec4_array[2].w +
            u_mat4_array[0][0][0] + u_mat4_array[1][3][3] + u_float_array[0] + u_float_array[3];
#ifdef UNUSED_TOO
  s += u_only_in_variant;
#endif
  o_color = vec4(s);
}
)"},
  });
}

// The program's uniforms as one typed struct, the way a pass declares them.
struct AllUniforms {
  explicit AllUniforms(const Program& p)
      : i(p, "u_int"),
        u(p, "u_uint"),
        f(p, "u_float"),
        v2(p, "u_vec2"),
        v3(p, "u_vec3"),
        v4(p, "u_vec4"),
        iv2(p, "u_ivec2"),
        iv3(p, "u_ivec3"),
        m3(p, "u_mat3"),
        m4(p, "u_mat4"),
        b(p, "u_bool"),
        sampler(p, "u_sampler"),
        v4_array(p, "u_vec4_array"),
        m4_array(p, "u_mat4_array"),
        float_element(p, "u_float_array[3]"),
        only_in_variant(p, "u_only_in_variant"),
        absent(p, "u_not_in_any_variant") {
    ++constructed;
  }
  Uniform<int> i;
  Uniform<unsigned> u;
  Uniform<float> f;
  Uniform<glm::vec2> v2;
  Uniform<glm::vec3> v3;
  Uniform<glm::vec4> v4;
  Uniform<glm::ivec2> iv2;
  Uniform<glm::ivec3> iv3;
  Uniform<glm::mat3> m3;
  Uniform<glm::mat4> m4;
  Uniform<int> b;  // GLSL bool: set as int
  Uniform<int> sampler;
  UniformArray<glm::vec4> v4_array;
  UniformArray<glm::mat4> m4_array;
  Uniform<float> float_element;
  Uniform<float> only_in_variant;
  Uniform<float> absent;
  static inline int constructed = 0;
};

class UniformTest : public test_support::GlTest {
 protected:
  const Program& Get(bool variant) {
    ProgramDesc desc{.vertex = "full.vert.glsl", .fragment = "all.frag.glsl"};
    if (variant) desc.defines.push_back("UNUSED_TOO");
    return cache_.Get(desc);
  }
  ShaderSources sources_ = TestSources();
  ProgramCache cache_{sources_, {}};
};

template <int N>
std::array<float, N> ReadFloats(const Program& p, GLint location) {
  std::array<float, N> out{};
  glGetUniformfv(p.id(), location, out.data());
  return out;
}

TEST_F(UniformTest, EveryTypeReadsBackWhatWasSet) {
  const Program& p = Get(false);
  const AllUniforms& u = p.Typed<AllUniforms>();
  for (const GLint location :
       {u.i.location(), u.u.location(), u.f.location(), u.v2.location(), u.v3.location(),
        u.v4.location(), u.iv2.location(), u.iv3.location(), u.m3.location(), u.m4.location(),
        u.b.location(), u.sampler.location(), u.v4_array.location(), u.m4_array.location(),
        u.float_element.location()}) {
    EXPECT_GE(location, 0);
  }
  // Each handle's location is the one GL reports for the name.
  EXPECT_EQ(u.m4.location(), glGetUniformLocation(p.id(), "u_mat4"));
  EXPECT_EQ(u.float_element.location(), glGetUniformLocation(p.id(), "u_float_array[3]"));

  u.i.Set(-7);
  u.u.Set(4000000000u);
  u.f.Set(0.375f);
  u.v2.Set({1.5f, -2.5f});
  u.v3.Set({3, 4, 5});
  u.v4.Set({6, 7, 8, 9});
  u.iv2.Set({-1, 2});
  u.iv3.Set({10, 20, 30});
  glm::mat3 m3(0.0f);
  glm::mat4 m4(0.0f);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m3[c][r] = static_cast<float>(10 * c + r);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m4[c][r] = static_cast<float>(100 + 10 * c + r);
  u.m3.Set(m3);
  u.m4.Set(m4);
  u.b.Set(1);
  u.sampler.Set(5);
  const std::vector<glm::vec4> v4s = {{1, 2, 3, 4}, {5, 6, 7, 8}, {9, 10, 11, 12}};
  u.v4_array.Set(v4s);
  const std::vector<glm::mat4> m4s = {glm::mat4(2.0f), glm::translate(glm::mat4(1.0f), {1, 2, 3})};
  u.m4_array.Set(m4s);
  u.float_element.Set(-0.5f);

  GLint ints[3] = {};
  glGetUniformiv(p.id(), u.i.location(), ints);
  EXPECT_EQ(ints[0], -7);
  GLuint uint_value = 0;
  glGetUniformuiv(p.id(), u.u.location(), &uint_value);
  EXPECT_EQ(uint_value, 4000000000u);
  EXPECT_EQ(ReadFloats<1>(p, u.f.location())[0], 0.375f);
  EXPECT_EQ(ReadFloats<2>(p, u.v2.location()), (std::array<float, 2>{1.5f, -2.5f}));
  EXPECT_EQ(ReadFloats<3>(p, u.v3.location()), (std::array<float, 3>{3, 4, 5}));
  EXPECT_EQ(ReadFloats<4>(p, u.v4.location()), (std::array<float, 4>{6, 7, 8, 9}));
  glGetUniformiv(p.id(), u.iv2.location(), ints);
  EXPECT_EQ(ints[0], -1);
  EXPECT_EQ(ints[1], 2);
  glGetUniformiv(p.id(), u.iv3.location(), ints);
  EXPECT_EQ(ints[0], 10);
  EXPECT_EQ(ints[1], 20);
  EXPECT_EQ(ints[2], 30);
  const auto m3_read = ReadFloats<9>(p, u.m3.location());
  const auto m4_read = ReadFloats<16>(p, u.m4.location());
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) EXPECT_EQ(m3_read[3 * c + r], m3[c][r]) << c << " " << r;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_EQ(m4_read[4 * c + r], m4[c][r]) << c << " " << r;
  glGetUniformiv(p.id(), u.b.location(), ints);
  EXPECT_EQ(ints[0], 1);
  glGetUniformiv(p.id(), u.sampler.location(), ints);
  EXPECT_EQ(ints[0], 5);
  for (int k = 0; k < 3; ++k) {
    const std::string name = "u_vec4_array[" + std::to_string(k) + "]";
    const auto read = ReadFloats<4>(p, glGetUniformLocation(p.id(), name.c_str()));
    for (int c = 0; c < 4; ++c) EXPECT_EQ(read[c], v4s[k][c]) << name;
  }
  const auto m4_1 = ReadFloats<16>(p, glGetUniformLocation(p.id(), "u_mat4_array[1]"));
  EXPECT_EQ(m4_1[12], 1.0f);  // the translation column
  EXPECT_EQ(m4_1[13], 2.0f);
  EXPECT_EQ(m4_1[14], 3.0f);
  EXPECT_EQ(ReadFloats<1>(p, u.float_element.location())[0], -0.5f);
  EXPECT_EQ(ReadFloats<1>(p, glGetUniformLocation(p.id(), "u_float_array[0]"))[0], 0.0f);
  EXPECT_NO_GL_ERROR();
}

TEST_F(UniformTest, AMissingUniformIsANoOp) {
  const Program& p = Get(false);
  const AllUniforms& u = p.Typed<AllUniforms>();
  EXPECT_EQ(u.absent.location(), -1);
  EXPECT_FALSE(u.absent.active());
  EXPECT_EQ(u.only_in_variant.location(), -1);  // declared only under UNUSED_TOO
  u.f.Set(0.25f);
  u.absent.Set(123.0f);
  u.only_in_variant.Set(456.0f);
  UniformArray<glm::vec4> absent_array(p, "u_no_such_array");
  absent_array.Set(std::vector<glm::vec4>{{1, 2, 3, 4}});
  Uniform<glm::mat4>().Set(glm::mat4(1.0f));  // no program at all
  EXPECT_NO_GL_ERROR();
  // Nothing else changed.
  EXPECT_EQ(ReadFloats<1>(p, u.f.location())[0], 0.25f);
  // In the variant that declares it, the same struct finds it.
  const AllUniforms& w = Get(true).Typed<AllUniforms>();
  ASSERT_GE(w.only_in_variant.location(), 0);
  w.only_in_variant.Set(456.0f);
  EXPECT_EQ(ReadFloats<1>(Get(true), w.only_in_variant.location())[0], 456.0f);
  EXPECT_NO_GL_ERROR();
}

TEST_F(UniformTest, TypedIsBuiltOncePerLinkedProgram) {
  AllUniforms::constructed = 0;
  const Program& a = Get(false);
  const AllUniforms* first = &a.Typed<AllUniforms>();
  EXPECT_EQ(AllUniforms::constructed, 1);
  // Later calls, and the same desc from the cache again, reuse it.
  EXPECT_EQ(&a.Typed<AllUniforms>(), first);
  EXPECT_EQ(&Get(false).Typed<AllUniforms>(), first);
  EXPECT_EQ(AllUniforms::constructed, 1);
  // Another variant is another program: its own struct.
  const AllUniforms* second = &Get(true).Typed<AllUniforms>();
  EXPECT_NE(second, first);
  EXPECT_EQ(AllUniforms::constructed, 2);
  // A re-link (CacheUniforms) drops the structs of the old link.
  Program relinked =
      BuildProgram(sources_, {.vertex = "full.vert.glsl", .fragment = "all.frag.glsl"});
  relinked.Typed<AllUniforms>();
  EXPECT_EQ(AllUniforms::constructed, 3);
  relinked.CacheUniforms();
  relinked.Typed<AllUniforms>();
  EXPECT_EQ(AllUniforms::constructed, 4);
  EXPECT_NO_GL_ERROR();
}

struct WrongType {
  explicit WrongType(const Program& p) : f(p, "u_int") {}
  Uniform<float> f;  // u_int is an int: glProgramUniform1f would fail on every Set
};

TEST_F(UniformTest, AHandleOfTheWrongTypeFailsAtLookup) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(Get(false).Typed<WrongType>(), "u_int");
}

}  // namespace
}  // namespace render
