// Stencil readback equals a CPU count exactly: plain INCR counting and the
// Kautz-Seidel ordered rule (pass map i only where stencil == i-1).
#include <gtest/gtest.h>

#include <random>

#include "render/gl/render_target.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

struct Rect {
  int x0, y0, x1, y1;  // pixel edges, [x0, x1) x [y0, y1), rows from the TOP
  bool Contains(int col, int row) const { return col >= x0 && col < x1 && row >= y0 && row < y1; }
};

ShaderSources RectSources() {
  return ShaderSources({
      {"rect.vert.glsl", R"(#version 330 core
uniform vec4 u_rect;     // x0, y0, x1, y1 in pixels, y from the top
uniform vec2 u_size;     // target size in pixels
void main() {
  vec2 corner = vec2(gl_VertexID & 1, (gl_VertexID >> 1) & 1);
  vec2 p = mix(u_rect.xy, u_rect.zw, corner);
  gl_Position = vec4(p.x / u_size.x * 2.0 - 1.0, 1.0 - p.y / u_size.y * 2.0, 0.0, 1.0);
}
)"},
      {"rect.frag.glsl",
       "#version 330 core\nout vec4 o_color;\nvoid main() { o_color = vec4(1.0); }\n"},
  });
}

class StencilTest : public test_support::GlTest {};

TEST_F(StencilTest, ReadbackEqualsCpuCountForIncrAndOrderedRule) {
  constexpr int kW = 97, kH = 61;  // odd sizes catch row/stride mistakes
  const ShaderSources sources = RectSources();
  ProgramCache cache(sources);
  const Program& program = cache.Get({.vertex = "rect.vert.glsl", .fragment = "rect.frag.glsl"});
  RenderTarget target({kW, kH, {GL_RGBA8}, true});
  VertexArray vao = VertexArray::Create();
  std::mt19937 rng(1234);
  std::vector<Rect> rects;
  for (int i = 0; i < 12; ++i) {
    int xa = rng() % kW, xb = rng() % kW, ya = rng() % kH, yb = rng() % kH;
    rects.push_back(
        {std::min(xa, xb), std::min(ya, yb), std::max(xa, xb) + 1, std::max(ya, yb) + 1});
  }
  auto draw_rect = [&](const Rect& r) {
    glUniform4f(program.Uniform("u_rect"), r.x0, r.y0, r.x1, r.y1);
    glUniform2f(program.Uniform("u_size"), kW, kH);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  };
  for (bool ordered : {false, true}) {
    target.Bind();
    const float black[4] = {0, 0, 0, 0};
    target.Clear(black, 1.0f, 0);
    program.Use();
    glBindVertexArray(vao.id());
    glEnable(GL_STENCIL_TEST);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    for (size_t i = 0; i < rects.size(); ++i) {
      if (ordered)
        glStencilFunc(GL_EQUAL, static_cast<GLint>(i), 0xFF);
      else
        glStencilFunc(GL_ALWAYS, 0, 0xFF);
      draw_rect(rects[i]);
    }
    glDisable(GL_STENCIL_TEST);
    glBindVertexArray(0);
    const core::Image8 stencil = target.ReadStencil();
    int mismatches = 0;
    for (int row = 0; row < kH; ++row) {
      for (int col = 0; col < kW; ++col) {
        int count = 0;
        for (size_t i = 0; i < rects.size(); ++i) {
          if (!rects[i].Contains(col, row)) continue;
          if (!ordered)
            ++count;
          else if (count == static_cast<int>(i))
            count = static_cast<int>(i) + 1;
        }
        if (stencil.at(col, row) != count) ++mismatches;
      }
    }
    EXPECT_EQ(mismatches, 0) << (ordered ? "ordered" : "incr");
  }
}

}  // namespace
}  // namespace render
