#include "render/gl/context.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "render/gl/gl.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

class ContextTest : public test_support::GlTest {};

TEST_F(ContextTest, MadeWithNoDisplay) {
  // ctest removes DISPLAY/WAYLAND_DISPLAY for this suite: the context below
  // came from EGL alone.
  EXPECT_EQ(std::getenv("DISPLAY"), nullptr);
  EXPECT_EQ(std::getenv("WAYLAND_DISPLAY"), nullptr);
  const GlInfo& info = test_support::SharedContext()->info();
  EXPECT_GE(info.major * 10 + info.minor, 33);
  EXPECT_NE(info.platform, "window");
  EXPECT_FALSE(info.renderer.empty());
  GLint profile = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
  std::printf("context: %s | %s | EGL %s\n", info.version.c_str(), info.renderer.c_str(),
              info.platform.c_str());
}

TEST_F(ContextTest, HasStencilCapableDefaultConfigAndFeaturesWeUse) {
  GLint max_3d = 0, max_draw_buffers = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max_3d);
  glGetIntegerv(GL_MAX_DRAW_BUFFERS, &max_draw_buffers);
  EXPECT_GE(max_3d, 256);
  EXPECT_GE(max_draw_buffers, 4);
}

}  // namespace
}  // namespace render
