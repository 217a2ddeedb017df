// The ray core's optional hooks (shaders/cores/ray_core.glsl): RAY_REJECT,
// RAY_BOTH_CROSSINGS, RAY_SKIP and the per-ray sample count, against
// analytic answers. One pixel = one ray along +z from z = -10 through the box
// [-1.5, 1.5]^3 at lateral offset x; the field is two solid slabs,
// z in [-1, -0.5] and z in [0.5, 1], so every crossing is known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "render/cores/ray_core.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

const char* kFragment = R"(#version 450 core
uniform float u_step;        // base step, t units
uniform float u_reject_z;    // RAY_REJECT: hits with z < u_reject_z are rejected
uniform float u_skip_scale;  // RAY_SKIP: skip = scale * exact free distance
uniform float u_start_z;     // the march starts at (0, 0, u_start_z)
layout(location = 0) out vec4 o_a;
layout(location = 1) out vec4 o_b;

float Slab(float z, float lo, float hi) { return max(lo - z, z - hi); }
float Solid(vec3 p) { return min(Slab(p.z, -1.0, -0.5), Slab(p.z, 0.5, 1.0)); }
#ifdef SECOND
// The two-field search (solid cuts): the cut is z < u_cut_z (A > 0 there).
#define RAY_SECOND_FIELD
uniform float u_cut_z;
float RayFieldK(vec3 p, int k) { return k == 0 ? Solid(p) : u_cut_z - p.z; }
bool RayRejectHitK(vec3 p, int k) { return k == 0 ? u_cut_z - p.z > 0.0 : Solid(p) > 0.0; }
#else
float RayField(vec3 p) { return Solid(p); }
#endif
#ifdef REJECT
#define RAY_REJECT
bool RayRejectHit(vec3 p) { return p.z < u_reject_z; }
#endif
#ifdef BOTH
#define RAY_BOTH_CROSSINGS
#endif
#ifdef SKIP
#define RAY_SKIP
// Distance along +z to the next slab face ahead of p (every face is a crossing).
float RaySkip(vec3 p, float field) {
  float next = p.z < -1.0 ? -1.0 : p.z < -0.5 ? -0.5 : p.z < 0.5 ? 0.5 : p.z < 1.0 ? 1.0 : 1e30;
  return u_skip_scale * (next - p.z);
}
#endif
#include "cores/ray_core.glsl"

void main() {
  vec3 o = vec3(0.0, 0.0, -10.0), d = vec3(0.0, 0.0, 1.0);
  vec2 iv = RayBoxInterval(o, d, vec3(-1.5), vec3(1.5));
  iv.x = u_start_z + 10.0;
  RayMarch r;
  r.origin = o + iv.x * d;
  r.dir = d;
  r.t_max = iv.y - iv.x;
  r.step = u_step;
  RayResult res = RayMarchRun(r);
  o_a = vec4(float(res.outcome), res.t + iv.x, float(res.samples), float(res.steps));
  o_b = vec4(float(res.rejected), res.entering ? 1.0 : 0.0, float(res.field), 0.0);
}
)";

struct Hit {
  RayOutcome outcome;
  double t;  // from z = -10
  int samples, steps, rejected;
  bool entering;
  int field;
};

struct HookSetup {
  std::vector<std::string> defines;
  float step = 3.0f / 64;
  float reject_z = 0.0f;
  float skip_scale = 1.0f;
  float start_z = -1.5f;
  float cut_z = 0.0f;
  RayCoreOptions core;
};

class RayCoreHooksTest : public test_support::GlTest {
 protected:
  Hit March(const HookSetup& s) {
    const ShaderSources& embedded = ShaderSources::Embedded();
    ShaderSources sources(
        {{"cores/ray_core.glsl", *embedded.Find("cores/ray_core.glsl")},
         {"common/fullscreen.vert.glsl", *embedded.Find("common/fullscreen.vert.glsl")},
         {"hooks.frag.glsl", kFragment}});
    ProgramDesc desc{.vertex = "common/fullscreen.vert.glsl", .fragment = "hooks.frag.glsl"};
    desc.defines = RayCoreDefines(s.core);
    desc.defines.insert(desc.defines.end(), s.defines.begin(), s.defines.end());
    Program program = BuildProgram(sources, desc);
    RenderTarget target({1, 1, {GL_RGBA32F, GL_RGBA32F}, false});
    target.Bind();
    const float clear[4] = {0, 0, 0, 0};
    target.Clear(clear);
    glDisable(GL_DEPTH_TEST);
    program.Use();
    SetRayCoreUniforms(program, s.core);
    glUniform1f(program.Uniform("u_step"), s.step);
    glUniform1f(program.Uniform("u_start_z"), s.start_z);
    if (program.Uniform("u_reject_z") >= 0) glUniform1f(program.Uniform("u_reject_z"), s.reject_z);
    if (program.Uniform("u_cut_z") >= 0) glUniform1f(program.Uniform("u_cut_z"), s.cut_z);
    if (program.Uniform("u_skip_scale") >= 0)
      glUniform1f(program.Uniform("u_skip_scale"), s.skip_scale);
    VertexArray vao = VertexArray::Create();
    glBindVertexArray(vao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    const core::ImageF a = target.ReadColorF(0), b = target.ReadColorF(1);
    return {static_cast<RayOutcome>(std::lround(a.at(0, 0, 0))),
            a.at(0, 0, 1),
            static_cast<int>(std::lround(a.at(0, 0, 2))),
            static_cast<int>(std::lround(a.at(0, 0, 3))),
            static_cast<int>(std::lround(b.at(0, 0, 0))),
            b.at(0, 0, 1) > 0.5f,
            static_cast<int>(std::lround(b.at(0, 0, 2)))};
  }
  // Bisection leaves the crossing within step / 2^(n+1); plus float rounding.
  double Tolerance(const HookSetup& s) {
    return s.step / std::pow(2.0, s.core.refine_steps + 1) + 2e-5;
  }
};

TEST_F(RayCoreHooksTest, WithoutHooksTheFirstSlabIsHitAndSamplesAreCounted) {
  HookSetup s;
  Hit h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 9.0, Tolerance(s));
  EXPECT_TRUE(h.entering);
  EXPECT_EQ(h.rejected, 0);
  // origin + linear-search samples + bisection samples
  EXPECT_EQ(h.samples, 1 + h.steps + s.core.refine_steps);
  // The box entry is z = -1.5: the front face z = -1 is 0.5 / step samples in.
  EXPECT_EQ(h.steps, static_cast<int>(std::ceil(0.5 / s.step - 1e-3)));
}

TEST_F(RayCoreHooksTest, RejectedHitKeepsMarchingToTheNextEnteringCrossing) {
  HookSetup s;
  s.defines = {"REJECT"};
  Hit h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 10.5, Tolerance(s));  // second slab's front face, z = 0.5
  EXPECT_EQ(h.rejected, 1);              // z = -1; the exit at z = -0.5 is no crossing here
  EXPECT_TRUE(h.entering);
  // Everything rejected: the ray leaves the box.
  s.reject_z = 10.0f;
  h = March(s);
  EXPECT_EQ(h.outcome, RayOutcome::kExited);
  EXPECT_EQ(h.rejected, 2);
}

TEST_F(RayCoreHooksTest, BothCrossingsFindsTheExitOfARejectedSolid) {
  HookSetup s;
  s.defines = {"REJECT", "BOTH"};
  s.reject_z = -0.75f;  // rejects z = -1, accepts the exit at z = -0.5
  Hit h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 9.5, Tolerance(s));
  EXPECT_FALSE(h.entering);
  EXPECT_EQ(h.rejected, 1);
  s.reject_z = 0.0f;  // rejects both faces of the first slab
  h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 10.5, Tolerance(s));
  EXPECT_TRUE(h.entering);
  EXPECT_EQ(h.rejected, 2);
}

// Correa 2007 sec. 5.1.2 on slabs z in [-1, -0.5] and [0.5, 1] cut by
// z < cut_z: a surface hit in the cut is rejected and the search turns to the
// cut's boundary, accepted inside the solid, else back to the surface.
TEST_F(RayCoreHooksTest, SecondFieldFindsTheCutFaceInsideTheSolidOrTheNextSurface) {
  HookSetup s;
  s.defines = {"SECOND"};
  s.core.max_steps = 128;  // a switch restarts the step at the crossing: more than 3 / step
  struct Case {
    float cut_z, start_z;
    double t;  // from z = -10
    int field, rejected;
  };
  for (const Case& c : {Case{-0.75f, -1.5f, 9.25, 1, 1},  // the cut face inside slab 1
                        Case{-2.0f, -1.5f, 9.0, 0, 0},    // no cut on the ray: slab 1's face
                        Case{0.0f, -1.5f, 10.5, 0, 2},    // slab 1 cut away; boundary in the gap
                        Case{0.75f, -1.5f, 10.75, 1, 1},  // the cut face inside slab 2
                        Case{-0.75f, -0.9f, 9.25, 1, 1},  // starts in the solid, in the cut
                        Case{2.0f, -1.5f, 0.0, 0, 1}}) {  // everything cut: leaves the box
    s.cut_z = c.cut_z;
    s.start_z = c.start_z;
    const Hit h = March(s);
    SCOPED_TRACE(::testing::Message() << "cut z < " << c.cut_z << ", start " << c.start_z);
    if (c.t == 0.0) {
      EXPECT_EQ(h.outcome, RayOutcome::kExited);
      EXPECT_EQ(h.rejected, c.rejected);
      continue;
    }
    ASSERT_EQ(h.outcome, RayOutcome::kHit);
    EXPECT_NEAR(h.t, c.t, Tolerance(s));
    EXPECT_EQ(h.field, c.field);
    EXPECT_EQ(h.rejected, c.rejected);
  }
}

TEST_F(RayCoreHooksTest, StartingInsideHitsAtTheOriginUnlessBothCrossings) {
  HookSetup s;
  s.start_z = -0.75f;  // inside slab 1
  Hit h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 9.25, 1e-5);  // the origin: the existing contract
  EXPECT_EQ(h.samples, 1);
  s.defines = {"BOTH"};
  h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 9.5, Tolerance(s));  // where it leaves slab 1
  EXPECT_FALSE(h.entering);
  s.defines = {"REJECT"};  // start rejected (z < 0): on to slab 2
  h = March(s);
  ASSERT_EQ(h.outcome, RayOutcome::kHit);
  EXPECT_NEAR(h.t, 10.5, Tolerance(s));
  EXPECT_EQ(h.rejected, 1);
}

TEST_F(RayCoreHooksTest, SkippingKeepsTheHitAndSavesSamples) {
  HookSetup s;
  s.step = 3.0f / 512;
  s.core.max_steps = 1024;
  Hit plain = March(s);
  s.defines = {"SKIP", "REJECT"};
  s.reject_z = 0.0f;
  s.skip_scale = 0.9f;  // a strict lower bound (an exact one lands on the faces)
  Hit skipped = March(s);
  ASSERT_EQ(skipped.outcome, RayOutcome::kHit);
  EXPECT_NEAR(skipped.t, 10.5, Tolerance(s));
  EXPECT_EQ(skipped.rejected, 1);
  // Unskipped, the same hit needs 2 / step linear samples; the skip lands on
  // every face in a couple of samples each (plus the steps inside slab 1).
  s.defines = {"REJECT"};
  Hit unskipped = March(s);
  EXPECT_NEAR(unskipped.t, skipped.t, 1e-4);
  EXPECT_LT(skipped.samples * 3, unskipped.samples)
      << skipped.samples << " vs " << unskipped.samples;
  EXPECT_GT(plain.samples, 0);
  // A skip that over-estimates the free distance (2.5x) jumps from z = -1.5
  // to -0.25 and then past the exit: both slabs are lost (the hook is really
  // used; its proof is the includer's).
  s.defines = {"SKIP"};
  s.skip_scale = 2.5f;
  Hit over = March(s);
  EXPECT_EQ(over.outcome, RayOutcome::kExited);
  EXPECT_EQ(over.samples, 3);
}

}  // namespace
}  // namespace render
