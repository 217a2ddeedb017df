#include "render/gl/handles.h"

#include <gtest/gtest.h>

#include <type_traits>

#include "tests/support/gl_test.h"

namespace render {
namespace {

static_assert(!std::is_copy_constructible_v<Buffer> && !std::is_copy_assignable_v<Buffer>);
static_assert(std::is_nothrow_move_constructible_v<Buffer> &&
              std::is_nothrow_move_assignable_v<Buffer>);
static_assert(std::is_nothrow_move_constructible_v<Texture> &&
              std::is_nothrow_move_assignable_v<Texture>);
static_assert(std::is_nothrow_move_constructible_v<Framebuffer>);
static_assert(std::is_nothrow_move_constructible_v<Renderbuffer>);
static_assert(std::is_nothrow_move_constructible_v<VertexArray>);
static_assert(std::is_nothrow_move_constructible_v<Program>);
static_assert(std::is_nothrow_move_constructible_v<Query>);
static_assert(!std::is_copy_constructible_v<Texture>);

class HandlesTest : public test_support::GlTest {};

TEST_F(HandlesTest, DestructorFreesTheName) {
  GLuint buffer_id = 0, texture_id = 0, fbo_id = 0, vao_id = 0, rbo_id = 0, query_id = 0;
  {
    Buffer buffer = Buffer::Create();
    Texture texture = Texture::Create2D(GL_RGBA8, 4, 4);
    Framebuffer fbo = Framebuffer::Create();
    VertexArray vao = VertexArray::Create();
    Renderbuffer rbo = Renderbuffer::Create(GL_DEPTH24_STENCIL8, 4, 4);
    Query query = Query::Create(GL_SAMPLES_PASSED);
    buffer_id = buffer.id();
    texture_id = texture.id();
    fbo_id = fbo.id();
    vao_id = vao.id();
    rbo_id = rbo.id();
    query_id = query.id();
    EXPECT_TRUE(glIsBuffer(buffer_id));
    EXPECT_TRUE(glIsTexture(texture_id));
    EXPECT_TRUE(glIsFramebuffer(fbo_id));
    EXPECT_TRUE(glIsVertexArray(vao_id));
    EXPECT_TRUE(glIsRenderbuffer(rbo_id));
    EXPECT_TRUE(glIsQuery(query_id));
  }
  EXPECT_FALSE(glIsBuffer(buffer_id));
  EXPECT_FALSE(glIsTexture(texture_id));
  EXPECT_FALSE(glIsFramebuffer(fbo_id));
  EXPECT_FALSE(glIsVertexArray(vao_id));
  EXPECT_FALSE(glIsRenderbuffer(rbo_id));
  EXPECT_FALSE(glIsQuery(query_id));
}

TEST_F(HandlesTest, MoveTransfersOwnershipAndZeroesTheSource) {
  Texture a = Texture::Create3D(GL_R8, 4, 4, 4);
  const GLuint id = a.id();
  EXPECT_EQ(a.target(), static_cast<GLenum>(GL_TEXTURE_3D));
  Texture b = std::move(a);
  EXPECT_EQ(a.id(), 0u);  // NOLINT(bugprone-use-after-move): the point of the test
  EXPECT_EQ(b.id(), id);
  EXPECT_EQ(b.target(), static_cast<GLenum>(GL_TEXTURE_3D));
  Texture c = Texture::Create2D(GL_R8, 2, 2);
  const GLuint c_old = c.id();
  c = std::move(b);  // frees c's old texture
  EXPECT_EQ(c.id(), id);
  EXPECT_FALSE(glIsTexture(c_old));
  EXPECT_TRUE(glIsTexture(id));
  Buffer empty;  // id 0: destructor must not call glDelete*
  EXPECT_FALSE(static_cast<bool>(empty));
}

}  // namespace
}  // namespace render
