// The ray core on its own (shaders/cores/ray_core.glsl through render/cores/ray_core.h),
// against analytic fields: one pixel = one ray along +z through the box
// [-1.5, 1.5]^3, its lateral offset x set by the pixel column.
#include "render/cores/ray_core.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "core/error.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

// The includer side of the contract: an analytic field (sphere or plane),
// optionally a linear warp with its Jacobian, optionally a constant "bend"
// with a domain test. Writes (outcome, t from the ray origin, steps, t_max).
const char* kTestFragment = R"(#version 450 core
uniform int u_width;
uniform float u_x_extent;
uniform int u_field;         // 0: sphere |p| = u_radius; 1: plane z = u_plane_z
uniform float u_radius;
uniform float u_plane_z;
uniform float u_step_div;    // step = t_max / u_step_div
uniform float u_warp_a;      // WARP: T^-1(p) = p + (0, 0, a z)
layout(location = 0) out vec4 o_result;

float RayField(vec3 p) {
#ifdef WARP
  p.z += u_warp_a * p.z;
#endif
  if (u_field == 0) return length(p) - u_radius;
  return u_plane_z - p.z;
}
#ifdef WARP
mat3 RayJacobian(vec3 p) { return mat3(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0 + u_warp_a); }
#endif
#ifdef BENT
#define RAY_BEND
vec3 RayBend(vec3 p) { return vec3(0.0, 0.0, 1.0); }
#define RAY_DOMAIN
bool RayInDomain(vec3 p) { return all(lessThanEqual(abs(p), vec3(1.5))); }
#endif
#include "cores/ray_core.glsl"

void main() {
  int col = int(gl_FragCoord.x);
  float x = u_width > 1 ? mix(-u_x_extent, u_x_extent, float(col) / float(u_width - 1)) : 0.0;
  vec3 o = vec3(x, 0.0, -10.0), d = vec3(0.0, 0.0, 1.0);
  vec2 iv = RayBoxInterval(o, d, vec3(-1.5), vec3(1.5));
  RayMarch r;
  r.origin = o + iv.x * d;
  r.dir = d;
#ifdef BENT
  r.t_max = 1e30;
#else
  r.t_max = iv.y - iv.x;
#endif
  r.step = (iv.y - iv.x) / u_step_div;
  RayResult res = RayMarchRun(r);
  o_result = vec4(float(res.outcome), res.t + iv.x, float(res.steps), iv.y - iv.x);
}
)";

struct RayRow {
  RayOutcome outcome;
  double t;  // from the ray origin (z = -10)
  int steps;
  double t_box;  // path length inside the box
};

struct RaySetup {
  int width = 41;
  float x_extent = 1.4f;
  int field = 0;
  float radius = 1.0f;
  float plane_z = 0.3f;
  float step_div = 64;
  float warp_a = 0;
  bool warp = false;
  bool bent = false;
  RayCoreOptions core;
};

double XOf(const RaySetup& s, int col) {
  return -s.x_extent + 2.0 * s.x_extent * col / (s.width - 1);
}

class RayCoreTest : public test_support::GlTest {
 protected:
  std::vector<RayRow> March(const RaySetup& s) {
    const ShaderSources& embedded = ShaderSources::Embedded();
    const std::string* core = embedded.Find("cores/ray_core.glsl");
    const std::string* vert = embedded.Find("common/fullscreen.vert.glsl");
    EXPECT_TRUE(core && vert);
    ShaderSources sources({{"cores/ray_core.glsl", *core},
                           {"common/fullscreen.vert.glsl", *vert},
                           {"ray_core_test.frag.glsl", kTestFragment}});
    ProgramDesc desc{.vertex = "common/fullscreen.vert.glsl",
                     .fragment = "ray_core_test.frag.glsl"};
    desc.defines = RayCoreDefines(s.core);
    if (s.warp) desc.defines.push_back("WARP");
    if (s.bent) desc.defines.push_back("BENT");
    Program program = BuildProgram(sources, desc);
    RenderTarget target({s.width, 1, {GL_RGBA32F}, false});
    target.Bind();
    const float clear[4] = {0, 0, 0, 0};
    target.Clear(clear);
    glDisable(GL_DEPTH_TEST);
    program.Use();
    SetRayCoreUniforms(program, s.core);
    glUniform1i(program.Uniform("u_width"), s.width);
    glUniform1f(program.Uniform("u_x_extent"), s.x_extent);
    glUniform1i(program.Uniform("u_field"), s.field);
    glUniform1f(program.Uniform("u_radius"), s.radius);
    glUniform1f(program.Uniform("u_plane_z"), s.plane_z);
    glUniform1f(program.Uniform("u_step_div"), s.step_div);
    glUniform1f(program.Uniform("u_warp_a"), s.warp_a);
    VertexArray vao = VertexArray::Create();
    glBindVertexArray(vao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    const core::ImageF image = target.ReadColorF(0);
    std::vector<RayRow> rows;
    for (int col = 0; col < s.width; ++col) {
      rows.push_back({static_cast<RayOutcome>(std::lround(image.at(col, 0, 0))),
                      image.at(col, 0, 1), static_cast<int>(std::lround(image.at(col, 0, 2))),
                      image.at(col, 0, 3)});
    }
    return rows;
  }
};

TEST_F(RayCoreTest, BisectionFindsTheSphereCrossingWithinTheRequestedTolerance) {
  for (int refine : {0, 4, 10}) {
    RaySetup s;
    s.core.max_steps = 64;
    s.core.refine_steps = refine;
    const std::vector<RayRow> rows = March(s);
    const double step = 3.0 / s.step_div;
    // After n bisections the crossing is in a bracket of step / 2^n; the core
    // returns its midpoint. 2e-5 covers float rounding of t ~ 10.
    const double tolerance = step / std::pow(2.0, refine + 1) + 2e-5;
    int hits = 0;
    for (int col = 0; col < s.width; ++col) {
      const double x = XOf(s, col);
      if (std::abs(x) < 0.999) {
        ASSERT_EQ(rows[col].outcome, RayOutcome::kHit) << "x=" << x;
        const double truth = 10.0 - std::sqrt(1.0 - x * x);
        EXPECT_NEAR(rows[col].t, truth, tolerance) << "x=" << x << " refine=" << refine;
        ++hits;
      }
    }
    EXPECT_GT(hits, 20);
  }
}

TEST_F(RayCoreTest, RayThroughEmptySpaceReportsExited) {
  RaySetup s;
  const std::vector<RayRow> rows = March(s);
  int exited = 0;
  for (int col = 0; col < s.width; ++col) {
    const double x = XOf(s, col);
    if (std::abs(x) > 1.001) {
      EXPECT_EQ(rows[col].outcome, RayOutcome::kExited) << "x=" << x;
      // It exits at the box's far face, z = 1.5, after exactly step_div steps.
      EXPECT_NEAR(rows[col].t, 11.5, 1e-4);
      EXPECT_EQ(rows[col].steps, 64);
      ++exited;
    }
  }
  EXPECT_GT(exited, 4);
}

TEST_F(RayCoreTest, TooFewStepsReportsEarlyTermination) {
  RaySetup s;
  s.core.max_steps = 16;  // 16 steps of 3/64 cover 0.75 of the 3-unit box
  const std::vector<RayRow> rows = March(s);
  for (int col = 0; col < s.width; ++col) {
    const double x = XOf(s, col);
    // The sphere is first reached at z = -sqrt(1 - x^2) = t - 10; steps reach
    // t = 8.5 + 0.75 = 9.25 (z = -0.75).
    const double z_hit = std::abs(x) < 1 ? -std::sqrt(1 - x * x) : 99.0;
    if (z_hit < -0.8) {
      EXPECT_EQ(rows[col].outcome, RayOutcome::kHit) << "x=" << x;
    } else if (z_hit > -0.7) {
      EXPECT_EQ(rows[col].outcome, RayOutcome::kEarlyTermination) << "x=" << x;
      EXPECT_EQ(rows[col].steps, 16);
      EXPECT_NEAR(rows[col].t, 9.25, 1e-4);
    }
  }
}

TEST_F(RayCoreTest, OneStepAndManyStepsAreFiniteAndClassifiedCorrectly) {
  for (int steps : {1, 1024}) {
    RaySetup s;
    s.step_div = static_cast<float>(steps);
    s.core.max_steps = steps;
    s.core.refine_steps = 20;
    const std::vector<RayRow> rows = March(s);
    for (int col = 0; col < s.width; ++col) {
      const double x = XOf(s, col);
      ASSERT_TRUE(std::isfinite(rows[col].t));
      if (std::abs(x) < 0.999) {
        // With one step the sample lands on the far face (inside the solid? no:
        // z = 1.5 is outside the sphere), so a single step misses the sphere
        // entirely and must report exited; 1024 steps find it.
        if (steps == 1) {
          EXPECT_EQ(rows[col].outcome, RayOutcome::kExited);
        } else {
          EXPECT_EQ(rows[col].outcome, RayOutcome::kHit);
          EXPECT_NEAR(rows[col].t, 10.0 - std::sqrt(1.0 - x * x), 1e-4);
        }
      } else if (std::abs(x) > 1.001) {
        EXPECT_EQ(rows[col].outcome, RayOutcome::kExited);
      }
    }
  }
}

TEST_F(RayCoreTest, SecantRefinementIsExactOnALinearField) {
  RaySetup s;
  s.field = 1;  // plane z = 0.3: linear along the ray
  s.step_div = 7;
  s.core.refinement = RayRefinement::kSecant;
  const std::vector<RayRow> rows = March(s);
  for (const RayRow& row : rows) {
    ASSERT_EQ(row.outcome, RayOutcome::kHit);
    EXPECT_NEAR(row.t, 10.3, 2e-5);
  }
}

TEST_F(RayCoreTest, BentRayWithDomainMatchesTheStraightRay) {
  // A constant bend is a straight ray traced incrementally: same crossings;
  // leaving the domain (|p| > 1.5) reports exited.
  RaySetup s;
  s.bent = true;
  s.core.refine_steps = 12;
  s.core.max_steps = 80;  // 64 steps reach z = 1.5, still inside; the 65th leaves
  const std::vector<RayRow> rows = March(s);
  for (int col = 0; col < s.width; ++col) {
    const double x = XOf(s, col);
    if (std::abs(x) < 0.999) {
      ASSERT_EQ(rows[col].outcome, RayOutcome::kHit);
      EXPECT_NEAR(rows[col].t, 10.0 - std::sqrt(1.0 - x * x), 1e-4);
    } else if (std::abs(x) > 1.001) {
      EXPECT_EQ(rows[col].outcome, RayOutcome::kExited);
      // The first sample past z = 1.5 is outside the domain.
      EXPECT_GT(rows[col].t, 11.5 - 1e-4);
      EXPECT_LT(rows[col].t, 11.5 + 3.0 / 64 + 1e-4);
    }
  }
}

TEST_F(RayCoreTest, JacobianPolicyShrinksStepsByTheWarpStretch) {
  // T^-1(p) = p + (0, 0, a z) stretches z by 1 + a: eq. 4 gives
  // dt = ds / (1 + a), so crossing the box takes (1 + a) times the samples.
  RaySetup s;
  // Column 0 (x = -1.4) misses the small sphere.
  s.radius = 0.2f;
  s.warp = true;
  s.warp_a = 1.0f;
  s.step_div = 32;
  s.core.max_steps = 200;
  s.core.step_policy = RayStepPolicy::kJacobian;
  const std::vector<RayRow> jacobian = March(s);
  s.core.step_policy = RayStepPolicy::kFixed;
  const std::vector<RayRow> fixed = March(s);
  const RayRow& j = jacobian.front();
  const RayRow& f = fixed.front();
  EXPECT_EQ(f.outcome, RayOutcome::kExited);
  EXPECT_EQ(j.outcome, RayOutcome::kExited);
  EXPECT_EQ(f.steps, 32);
  EXPECT_EQ(j.steps, 64);
}

TEST_F(RayCoreTest, ThresholdPolicyRefinesNearTheSurfaceAndStillHits) {
  RaySetup s;
  s.step_div = 16;
  s.core.step_policy = RayStepPolicy::kThreshold;
  s.core.threshold = 0.5f;
  s.core.fine_step_scale = 0.25f;
  const std::vector<RayRow> adaptive = March(s);
  s.core.step_policy = RayStepPolicy::kFixed;
  const std::vector<RayRow> fixed = March(s);
  const int centre = s.width / 2;  // x = 0: the sphere is reached at t = 9
  ASSERT_EQ(adaptive[centre].outcome, RayOutcome::kHit);
  ASSERT_EQ(fixed[centre].outcome, RayOutcome::kHit);
  EXPECT_NEAR(adaptive[centre].t, 9.0, 3.0 / 16 / 4 / 256 + 2e-5);
  EXPECT_GT(adaptive[centre].steps, fixed[centre].steps);
}

TEST(RayCoreOptionsTest, CheckRejectsBadValuesAndNamesRoundTrip) {
  RayCoreOptions o;
  o.max_steps = 0;
  EXPECT_THROW(o.Check(), core::InputError);
  o = {};
  o.fine_step_scale = 0;
  EXPECT_THROW(o.Check(), core::InputError);
  o = {};
  o.threshold = NAN;
  EXPECT_THROW(o.Check(), core::InputError);
  for (const char* name : {"fixed", "threshold", "jacobian"}) {
    EXPECT_EQ(RayStepPolicyName(RayStepPolicyFromName(name)), name);
  }
  EXPECT_THROW(RayStepPolicyFromName("nope"), core::InputError);
}

}  // namespace
}  // namespace render
