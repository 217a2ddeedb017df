#include "render/gl/fill_rate.h"

#include <cmath>
#include <vector>

#include "core/error.h"
#include "render/gl/render_target.h"

namespace render {

void FillRateOptions::Check() const {
  if (width < 1 || height < 1 || width > 16384 || height > 16384 || layers_per_frame < 1 ||
      layers_per_frame > 4096) {
    core::ThrowInputError("FillRateOptions", "{}x{} x {} layers is out of range", width, height,
                          layers_per_frame);
  }
  timer.Check();
}

FillRate MeasureFillRate(ProgramCache& programs, const FillRateOptions& options) {
  options.Check();
  RenderTarget target({options.width, options.height, {GL_RGBA8}, true});
  // A deterministic 256^2 RGBA texture with alpha > 0 everywhere: the alpha
  // test never discards, but the compiler cannot know it, so the rasteriser
  // cannot treat the pass as opaque and skip overdrawn layers.
  constexpr int kTex = 256;
  std::vector<uint8_t> texels(kTex * kTex * 4);
  for (int i = 0; i < kTex * kTex; ++i) {
    texels[4 * i + 0] = static_cast<uint8_t>(i * 7);
    texels[4 * i + 1] = static_cast<uint8_t>(i * 13);
    texels[4 * i + 2] = static_cast<uint8_t>(i * 29);
    texels[4 * i + 3] = static_cast<uint8_t>(128 + (i % 127));
  }
  Texture texture = Texture::Create2D(GL_RGBA8, kTex, kTex);
  glTextureSubImage2D(texture.id(), 0, 0, 0, kTex, kTex, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
  const GLint filter = options.linear_filter ? GL_LINEAR : GL_NEAREST;
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);

  // The volume floors: a deterministic 64^3 R16 volume, a 256-entry
  // transfer function and a 32^3 RGBA32F map (displacements within +-0.05),
  // all LINEAR.
  using Work = FillRateOptions::Work;
  const bool volume = options.work != Work::kTexture2DAlphaTest;
  const bool displaced = options.work == Work::kDisplacedVolumeBlend;
  constexpr int kVol = 64, kMap = 32;
  Texture volume_texture, map_texture;
  if (volume) {
    std::vector<uint16_t> voxels(kVol * kVol * kVol);
    for (size_t i = 0; i < voxels.size(); ++i) voxels[i] = static_cast<uint16_t>(i * 2654435761u);
    volume_texture = Texture::Create3DWithData(GL_R16, glm::ivec3(kVol), GL_RED, GL_UNSIGNED_SHORT,
                                               voxels.data());
    volume_texture.SetLinearFilter();
  }
  Texture transfer;
  if (volume) {  // 256 RGBA32F entries, low opacities (as the presets')
    std::vector<float> table(4 * 256);
    for (int i = 0; i < 256; ++i) {
      const float x = i / 255.0f;
      table[4 * i + 0] = x, table[4 * i + 1] = 1 - x, table[4 * i + 2] = 0.5f;
      table[4 * i + 3] = 0.05f * x;
    }
    transfer = Texture::Create(GL_TEXTURE_1D);
    glTextureStorage1D(transfer.id(), 1, GL_RGBA32F, 256);
    glTextureSubImage1D(transfer.id(), 0, 0, 256, GL_RGBA, GL_FLOAT, table.data());
    transfer.SetLinearFilter();
  }
  if (displaced) {
    std::vector<float> d(4 * kMap * kMap * kMap);
    for (size_t i = 0; i < d.size(); ++i) d[i] = 0.05f * std::sin(0.37f * static_cast<float>(i));
    map_texture =
        Texture::Create3DWithData(GL_RGBA32F, glm::ivec3(kMap), GL_RGBA, GL_FLOAT, d.data());
    map_texture.SetLinearFilter();
  }

  ProgramDesc desc{
      .vertex = "common/fullscreen.vert.glsl",
      .fragment = volume ? "common/fill_rate_volume.frag.glsl" : "common/fill_rate.frag.glsl"};
  if (displaced) desc.defines.push_back("DISPLACED");
  const Program& program = programs.Get(desc);
  VertexArray vao = VertexArray::Create();
  target.Bind();
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  if (volume) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  } else {
    glDisable(GL_BLEND);
  }
  program.Use();
  glBindVertexArray(vao.id());
  glBindTextureUnit(0, volume ? volume_texture.id() : texture.id());
  if (volume) {
    glBindTextureUnit(1, transfer.id());
    program.Set("u_transfer", 1);
  }
  if (displaced) {
    glBindTextureUnit(2, map_texture.id());
    program.Set("u_map", 2);
  }
  const float clear[4] = {0, 0, 0, 0};
  const GLint u_layer = program.Uniform("u_layer");
  auto frame = [&] {
    target.Clear(clear);
    for (int layer = 0; layer < options.layers_per_frame; ++layer) {
      program.Set(u_layer, volume ? (layer + 0.5f) / static_cast<float>(options.layers_per_frame)
                                  : static_cast<float>(layer));
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
  };
  const core::TimingStats stats = TimeFrames(frame, options.timer);
  glBindVertexArray(0);
  glDisable(GL_BLEND);
  FillRate result;
  result.fragments_per_frame =
      static_cast<double>(options.width) * options.height * options.layers_per_frame;
  result.ms_per_frame = stats.median_ms;
  result.fragments_per_second = result.fragments_per_frame / (stats.median_ms * 1e-3);
  return result;
}

}  // namespace render
