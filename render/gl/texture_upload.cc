#include "render/gl/texture_upload.h"

#include "core/check.h"

namespace render {

namespace {

GLint WrapMode(TextureWrap wrap) {
  return wrap == TextureWrap::kRepeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
}

}  // namespace

Texture UploadRgba8Texture(const core::Image8& rgba, TextureWrap wrap_s, TextureWrap wrap_t) {
  IBR_CHECK_EQ(rgba.channels(), 4);
  Texture texture = Texture::Create2D(GL_RGBA8, rgba.width(), rgba.height());
  glTextureSubImage2D(texture.id(), 0, 0, 0, rgba.width(), rgba.height(), GL_RGBA, GL_UNSIGNED_BYTE,
                      rgba.data());
  texture.SetLinearFilter();
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, WrapMode(wrap_s));
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, WrapMode(wrap_t));
  return texture;
}

void SampleLinearClamped(const Texture& texture) {
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

}  // namespace render
