// The pass contract (render/passes/pass.h): every pass draws into the one
// frame type, passes drawn into one target composite by depth whatever their
// order, Draw leaves the frame's state as it found it, outcome bits are the
// pass's own; and the GL helpers the passes share (typed uniforms cached at
// link, scoped state).
#include "render/passes/pass.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/heightfield.h"
#include "core/mesh.h"
#include "core/projection.h"
#include "render/gl/gl_state.h"
#include "render/passes/displacement_pass.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/relief_surface_pass.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

constexpr int kSize = 128;

class PassTest : public test_support::GlTest {
 protected:
  static ViewSetup View() {
    ViewSetup view;
    view.cam_from_world = core::CamFromWorldLookAt({0.6f, 1.2f, 3.5f}, {0, 0, 0}, {0, 1, 0});
    view.clip_from_cam =
        core::ClipFromCamPerspective(150, 150, kSize / 2.0, kSize / 2.0, kSize, kSize, 0.1, 20);
    return view;
  }
};

// Every pixel of a composite frame equals the frame of whichever pass is
// nearest there (colour, camera z, normal, exactly), and its outcome bits are
// the OR of every pass's.
void ExpectCompositeOfNearest(const Frame& composite, const std::vector<const Frame*>& singles) {
  int64_t covered = 0, overlapped = 0, bad = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const Frame* nearest = nullptr;
      int count = 0;
      uint32_t outcome = 0;
      for (const Frame* f : singles) outcome |= f->outcome.at(x, y);
      bad += composite.outcome.at(x, y) != outcome;
      for (const Frame* f : singles) {
        if (!f->Covered(x, y)) continue;
        ++count;
        if (!nearest || f->depth.at(x, y) < nearest->depth.at(x, y)) nearest = f;
      }
      if (!nearest) {
        bad += composite.Covered(x, y) || composite.depth.at(x, y) != 0.0f;
        continue;
      }
      ++covered;
      overlapped += count > 1;
      bool same = composite.depth.at(x, y) == nearest->depth.at(x, y);
      for (int c = 0; c < 4; ++c)
        same = same && composite.color.at(x, y, c) == nearest->color.at(x, y, c);
      for (int c = 0; c < 3; ++c)
        same = same && composite.normal.at(x, y, c) == nearest->normal.at(x, y, c);
      bad += !same;
    }
  }
  EXPECT_GT(covered, kSize * kSize / 8);
  EXPECT_GT(overlapped, 200) << "the scene must make the passes overlap";
  EXPECT_EQ(bad, 0) << "pixels that are not the nearest pass's";
}

TEST_F(PassTest, FrameTargetHasTheContractsAttachments) {
  const RenderTarget target(FrameTargetOptions(16, 8));
  BeginFrame(target);
  const Frame f = ReadFrame(target);
  EXPECT_EQ(f.color.channels(), 4);
  EXPECT_EQ(f.depth.channels(), 1);
  EXPECT_EQ(f.normal.channels(), 3);
  EXPECT_EQ(f.outcome.channels(), 1);
  EXPECT_EQ(f.color.width(), 16);
  EXPECT_EQ(f.outcome.height(), 8);
  for (uint32_t v : f.outcome.values()) EXPECT_EQ(v, 0u);
  for (float v : f.depth.values()) EXPECT_EQ(v, 0.0f);
  EXPECT_NO_GL_ERROR();
}

TEST_F(PassTest, BeginFrameClearsTheOutcomeOfAReusedTarget) {
  // BeginFrame masks the outcome attachment; the next BeginFrame on the same
  // target must still clear it (benchmarks reuse one target per frame).
  const RenderTarget target(FrameTargetOptions(16, 8));
  BeginFrame(target);
  const uint32_t stale = 7;
  glClearTexImage(target.color(kFrameOutcome).id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &stale);
  EXPECT_EQ(ReadFrame(target).outcome.at(3, 2), stale);
  BeginFrame(target);
  const Frame cleared = ReadFrame(target);
  for (uint32_t v : cleared.outcome.values()) EXPECT_EQ(v, 0u);
  EXPECT_NO_GL_ERROR();
}

TEST_F(PassTest, MeshDisplacementAndReliefCompositeByDepthInAnyOrder) {
  const ViewSetup view = View();
  // A sphere, a displaced plane cutting through it and a relief (NCS) torus
  // around it: each pair overlaps on screen, the sphere and the plane with
  // both depth orders.
  const GpuMesh sphere(core::MakeSphere(0.7f, 48, 96));
  MeshPassOptions sphere_options;
  sphere_options.base_color = {0.9f, 0.3f, 0.2f, 1.0f};
  MeshPass mesh(programs(), sphere, sphere_options);

  core::HeightMapOptions bumps;
  bumps.size = 64;
  const core::ImageF height = core::MakeHeightMap(bumps);
  const Texture texture = UploadDisplacementTexture(MakeDisplacementTexels(height));
  DisplacementPassOptions disp_options;
  disp_options.slicing.family = SliceFamily::kOrthogonal;
  disp_options.slicing.count = 16;
  disp_options.max_displacement = 0.15f;
  core::TriangleMesh plane = core::MakePlane(1.2f, 2);  // z = 0, facing the camera (+z)
  for (glm::vec3& p : plane.positions) p.z -= 0.3f;     // through the sphere, behind the torus
  DisplacementPass displacement(programs(), plane, texture, disp_options);

  ReliefGeometryOptions geometry;
  geometry.max_displacement = 0.08f;
  geometry.tangent_maps.size = 128;
  DetectPeriodicAxes(core::MakeTorus(1.0f, 0.2f, 48, 24), geometry.tangent_maps.wrap_u,
                     geometry.tangent_maps.wrap_v);
  ReliefSurface relief(programs(), core::MakeTorus(1.0f, 0.2f, 48, 24), height, geometry);

  const Frame a = RenderFrame(mesh, view, kSize, kSize);
  const Frame b = RenderFrame(displacement, view, kSize, kSize);
  const Frame c = RenderFrame(relief, view, kSize, kSize);
  std::vector<Pass*> order = {&mesh, &displacement, &relief};
  std::vector<Frame> composites;
  for (int k = 0; k < 3; ++k) {
    const RenderTarget target(FrameTargetOptions(kSize, kSize));
    BeginFrame(target);
    for (Pass* p : order) p->Draw(target, view);
    composites.push_back(ReadFrame(target));
    std::rotate(order.begin(), order.begin() + 1, order.end());
  }
  test_support::WriteDebugImage("mesh.png", a.color);
  test_support::WriteDebugImage("displacement.png", b.color);
  test_support::WriteDebugImage("relief.png", c.color);
  test_support::WriteDebugImage("composite.png", composites[0].color);
  for (const Frame& composite : composites) ExpectCompositeOfNearest(composite, {&a, &b, &c});
  // The relief pass records its rays' outcomes; the mesh pass none.
  EXPECT_GT(c.CountOutcome(OutcomeBit(RayOutcome::kHit)), 0);
  EXPECT_EQ(a.CountOutcome(~0u), 0);
  EXPECT_NO_GL_ERROR();
}

TEST_F(PassTest, DrawLeavesTheFrameStateAsItFoundIt) {
  const GpuMesh sphere(core::MakeSphere(0.7f, 16, 32));
  MeshPass mesh(programs(), sphere);
  const RenderTarget target(FrameTargetOptions(32, 32));
  BeginFrame(target);
  mesh.Draw(target, View());
  EXPECT_TRUE(glIsEnabled(GL_DEPTH_TEST));
  EXPECT_FALSE(glIsEnabled(GL_STENCIL_TEST));
  EXPECT_FALSE(glIsEnabled(GL_BLEND));
  GLint func = 0;
  glGetIntegerv(GL_DEPTH_FUNC, &func);
  EXPECT_EQ(func, GL_LESS);
  EXPECT_NO_GL_ERROR();
}

TEST_F(PassTest, ScopedGlStateRestoresWhatItFound) {
  const RenderTarget target(FrameTargetOptions(8, 8));  // with a stencil buffer: GL clamps the
  BeginFrame(target);                                   // queried reference to its bits
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
  {
    GlState state;
    state.depth_test = false;
    state.stencil = StencilState{.func = GL_EQUAL, .ref = 3, .depth_pass = GL_INCR};
    state.blend = BlendState{.dst_rgb = GL_ONE, .dst_alpha = GL_ONE};
    ScopedGlState scoped(state);
    EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
    EXPECT_TRUE(glIsEnabled(GL_STENCIL_TEST));
    EXPECT_TRUE(glIsEnabled(GL_BLEND));
    GLint ref = 0;
    glGetIntegerv(GL_STENCIL_REF, &ref);
    EXPECT_EQ(ref, 3);
  }
  EXPECT_TRUE(glIsEnabled(GL_DEPTH_TEST));
  EXPECT_FALSE(glIsEnabled(GL_STENCIL_TEST));
  EXPECT_FALSE(glIsEnabled(GL_BLEND));
  GLint func = 0;
  glGetIntegerv(GL_DEPTH_FUNC, &func);
  EXPECT_EQ(func, GL_LEQUAL);
  glDepthFunc(GL_LESS);
  EXPECT_NO_GL_ERROR();
}

TEST_F(PassTest, UniformLocationsAreCachedAtLinkAndMatchGl) {
  const Program& program = programs().Get({.vertex = "passes/mesh.vert.glsl",
                                           .fragment = "passes/mesh.frag.glsl",
                                           .defines = {"SHADED"}});
  for (const char* name :
       {"u_cam_from_world", "u_clip_from_cam", "u_world_from_object", "u_base_color"}) {
    EXPECT_EQ(program.Uniform(name), glGetUniformLocation(program.id(), name)) << name;
    EXPECT_GE(program.Uniform(name), 0) << name;
  }
  EXPECT_EQ(program.Uniform("u_not_there"), -1);
  const glm::vec4 colour(0.25f, 0.5f, 0.75f, 1.0f);
  program.Set("u_base_color", colour);
  glm::vec4 read(0);
  glGetUniformfv(program.id(), program.Uniform("u_base_color"), &read[0]);
  EXPECT_EQ(read, colour);
  program.Set("u_not_there", 1.0f);  // a uniform the variant lacks is ignored, not an error
  EXPECT_NO_GL_ERROR();
}

// ---- The frame size check (docs/guide/limits.md, "Frame size") -------------

// The error line CheckFrameSize throws, or "" when the size is accepted.
std::string FrameSizeError(int width, int height, const GlSizeLimits& limits) {
  try {
    CheckFrameSize("ibr test", "--size", width, height, limits);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameSize, BytesPerPixelIsTheSumOfTheFrameAttachments) {
  // RGBA8 4 + R32F 4 + RGBA16F 8 + R32UI 4 + D24S8 4.
  EXPECT_EQ(FrameBytesPerPixel(), 24);
  RenderTargetOptions colour_only;
  colour_only.color_formats = {GL_RGBA8};
  colour_only.depth_stencil = false;
  EXPECT_EQ(TargetBytesPerPixel(colour_only), 4);
}

TEST(FrameSize, MemoryBudgetAdmitsExactly8192Squared) {
  // Limits far above the budget, so only the memory estimate decides.
  const GlSizeLimits big{1 << 20, 1 << 20, 1 << 20, 1 << 20};
  EXPECT_EQ(FrameSizeError(8192, 8192, big), "");   // 2^26 px x 24 B = 1536 MiB, the budget
  EXPECT_EQ(FrameSizeError(16384, 4096, big), "");  // the same pixel count, another shape
  EXPECT_EQ(FrameSizeError(8193, 8192, big),
            "ibr test: --size: a 8193x8192 frame needs 1536.2 MiB (24 bytes per pixel), over the "
            "frame budget of 1536 MiB");
  EXPECT_EQ(FrameSizeError(12000, 12000, big),
            "ibr test: --size: a 12000x12000 frame needs 3295.9 MiB (24 bytes per pixel), over the "
            "frame budget of 1536 MiB");
  // No overflow at the largest ints.
  EXPECT_NE(FrameSizeError(INT32_MAX, INT32_MAX, {INT32_MAX, INT32_MAX, INT32_MAX, INT32_MAX}), "");
}

TEST(FrameSize, EverySideWithinTheLeastGlLimit) {
  // The least limit decides, per axis: here the viewport's height.
  const GlSizeLimits gl{4096, 8192, 8192, 2048};
  EXPECT_EQ(FrameSizeError(4096, 2048, gl), "");
  EXPECT_EQ(FrameSizeError(4097, 16, gl),
            "ibr test: --size: a 4097x16 frame is larger than this GL implementation's largest, "
            "4096x2048 (GL_MAX_RENDERBUFFER_SIZE 4096, GL_MAX_TEXTURE_SIZE 8192, "
            "GL_MAX_VIEWPORT_DIMS 8192x2048)");
  EXPECT_NE(FrameSizeError(16, 2049, gl).find("a 16x2049 frame is larger"), std::string::npos);
  EXPECT_EQ(FrameSizeError(0, 16, gl), "ibr test: --size: a 0x16 frame is empty (at least 1x1)");
  EXPECT_NE(FrameSizeError(16, -5, gl), "");
}

TEST_F(PassTest, GlSizeLimitsAreThisImplementationsAndAdmitTheDefaultFrame) {
  const GlSizeLimits gl = QueryGlSizeLimits();
  GLint renderbuffer = 0, texture = 0, viewport[2] = {0, 0};
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &renderbuffer);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &texture);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
  EXPECT_EQ(gl.max_renderbuffer_size, renderbuffer);
  EXPECT_EQ(gl.max_texture_size, texture);
  EXPECT_EQ(gl.max_viewport_width, viewport[0]);
  EXPECT_EQ(gl.max_viewport_height, viewport[1]);
  // The GL 4.5 minimum maxima are 16384 (renderbuffer, texture, viewport).
  EXPECT_GE(gl.MaxWidth(), 16384);
  EXPECT_GE(gl.MaxHeight(), 16384);
  CheckFrameSize("ibr test", "--size", 512, 512);
  EXPECT_THROW(CheckFrameSize("ibr test", "--size", gl.MaxWidth() + 1, 1), core::InputError);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace render
