// The depth-object CPU reference reproduces the GPU bit for bit only if the
// shader's `precise` float arithmetic is IEEE single precision, correctly
// rounded, evaluated in source order, with no fused multiply-add and exact
// division. This test checks exactly those operations on this driver, over
// random operands of many magnitudes, so a driver that breaks the assumption
// is named here rather than as a mysterious stencil mismatch.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "render/gl/render_target.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

render::ShaderSources ProbeSources() {
  return render::ShaderSources({
      {"probe.vert.glsl", R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)"},
      {"probe.frag.glsl", R"(#version 450 core
uniform sampler2D u_operands;  // RGBA32F: a, b, c, d per pixel
uniform float u_h;
layout(location = 0) out vec4 o_result;
void main() {
  ivec2 ij = ivec2(gl_FragCoord.xy);
  vec4 x = texelFetch(u_operands, ij, 0);
  precise float q = x.x / x.y;
  precise float fm = x.x * x.y + x.z;
  precise float chain = (x.x / x.y) * x.z + x.w;
  precise float fc = u_h - gl_FragCoord.y;
  o_result = vec4(q, fm, chain, fc);
}
)"},
  });
}

class ShaderArithmeticTest : public test_support::GlTest {};

TEST_F(ShaderArithmeticTest, PreciseDivisionAndMulAddMatchCpuBitForBit) {
  constexpr int kW = 128, kH = 96;
  const render::ShaderSources sources = ProbeSources();
  render::ProgramCache cache(sources);
  const render::Program& program =
      cache.Get({.vertex = "probe.vert.glsl", .fragment = "probe.frag.glsl"});
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> mant(-1.0f, 1.0f);
  std::uniform_int_distribution<int> expo(-20, 20);
  std::vector<float> operands(static_cast<size_t>(kW) * kH * 4);
  for (float& v : operands) v = std::ldexp(mant(rng), expo(rng));
  render::Texture tex = render::Texture::Create2D(GL_RGBA32F, kW, kH);
  glTextureSubImage2D(tex.id(), 0, 0, 0, kW, kH, GL_RGBA, GL_FLOAT, operands.data());
  render::RenderTarget target({kW, kH, {GL_RGBA32F}, false});
  target.Bind();
  program.Use();
  glBindTextureUnit(0, tex.id());
  glUniform1i(program.Uniform("u_operands"), 0);
  glUniform1f(program.Uniform("u_h"), static_cast<float>(kH));
  render::VertexArray vao = render::VertexArray::Create();
  glBindVertexArray(vao.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  const core::ImageF result = target.ReadColorF(0);  // rows top-first
  int mismatches[4] = {0, 0, 0, 0};
  for (int gl_row = 0; gl_row < kH; ++gl_row) {
    for (int col = 0; col < kW; ++col) {
      const float* x = &operands[(static_cast<size_t>(gl_row) * kW + col) * 4];
      volatile float q = x[0] / x[1];
      volatile float prod = x[0] * x[1];
      volatile float fm = prod + x[2];
      volatile float qc = q * x[2];
      volatile float chain = qc + x[3];
      const float fc = static_cast<float>(kH) - (static_cast<float>(gl_row) + 0.5f);
      const int row = kH - 1 - gl_row;
      const float expected[4] = {q, fm, chain, fc};
      for (int c = 0; c < 4; ++c) {
        if (std::bit_cast<uint32_t>(result.at(col, row, c)) !=
            std::bit_cast<uint32_t>(expected[c])) {
          ++mismatches[c];
        }
      }
    }
  }
  EXPECT_EQ(mismatches[0], 0) << "division a / b is not correctly rounded";
  EXPECT_EQ(mismatches[1], 0) << "a * b + c is fused or reordered";
  EXPECT_EQ(mismatches[2], 0) << "(a / b) * c + d differs";
  EXPECT_EQ(mismatches[3], 0) << "gl_FragCoord.y is not the pixel centre";
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
