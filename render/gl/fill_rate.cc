#include "render/gl/fill_rate.h"

#include <cmath>
#include <vector>

#include "core/error.h"
#include "render/gl/gl_state.h"
#include "render/gl/render_target.h"
#include "render/gl/uniform.h"

namespace render {

namespace {

// shaders/common/fill_rate*.frag.glsl.
struct FillRateUniforms {
  explicit FillRateUniforms(const Program& p)
      : layer(p, "u_layer"), transfer(p, "u_transfer"), map(p, "u_map") {}
  Uniform<float> layer;   // the floor's layer (volume: its texture coordinate)
  Uniform<int> transfer;  // texture unit of the transfer function
  Uniform<int> map;       // texture unit of the displacement map
};

}  // namespace

void FillRateOptions::Check() const {
  if (width < 1 || height < 1 || width > 16384 || height > 16384 || layers_per_frame < 1 ||
      layers_per_frame > 4096) {
    core::ThrowInputError("FillRateOptions", "{}x{} x {} layers is out of range", width, height,
                          layers_per_frame);
  }
  timer.Check();
}

namespace {

// The calibration's texture: a deterministic 256^2 RGBA texture with alpha > 0
// everywhere: the alpha test never discards, but the compiler cannot know it,
// so the rasteriser cannot treat the pass as opaque and skip overdrawn layers.
Texture CalibrationTexture(bool linear_filter) {
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
  const GLint filter = linear_filter ? GL_LINEAR : GL_NEAREST;
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return texture;
}

// The volume floors' textures, all LINEAR: a deterministic 64^3 R16 volume,
// a 256-entry RGBA32F transfer function of low opacities (as the presets'),
// and a 32^3 RGBA32F map of displacements within +-0.05.
Texture FloorVolume() {
  constexpr int kVol = 64;
  std::vector<uint16_t> voxels(kVol * kVol * kVol);
  for (size_t i = 0; i < voxels.size(); ++i) voxels[i] = static_cast<uint16_t>(i * 2654435761u);
  Texture t =
      Texture::Create3DWithData(GL_R16, glm::ivec3(kVol), GL_RED, GL_UNSIGNED_SHORT, voxels.data());
  t.SetLinearFilter();
  return t;
}

Texture FloorTransfer() {
  constexpr int kEntries = 256;
  std::vector<glm::vec4> table(kEntries);
  for (int i = 0; i < kEntries; ++i) {
    const float x = static_cast<float>(i) / (kEntries - 1);
    table[i] = {x, 1 - x, 0.5f, 0.05f * x};
  }
  Texture t = Texture::Create1DWithData(GL_RGBA32F, kEntries, GL_RGBA, GL_FLOAT, table.data());
  t.SetLinearFilter();
  return t;
}

Texture FloorMap() {
  constexpr int kMap = 32;
  std::vector<float> d(4 * kMap * kMap * kMap);
  for (size_t i = 0; i < d.size(); ++i) d[i] = 0.05f * std::sin(0.37f * static_cast<float>(i));
  Texture t = Texture::Create3DWithData(GL_RGBA32F, glm::ivec3(kMap), GL_RGBA, GL_FLOAT, d.data());
  t.SetLinearFilter();
  return t;
}

}  // namespace

FillRate MeasureFillRate(ProgramCache& programs, const FillRateOptions& options) {
  options.Check();
  RenderTarget target({options.width, options.height, {GL_RGBA8}, true});
  using Work = FillRateOptions::Work;
  const bool volume = options.work != Work::kTexture2DAlphaTest;
  const bool displaced = options.work == Work::kDisplacedVolumeBlend;
  // Only the textures this work reads, on units 0 (2D texture or volume),
  // 1 (transfer function) and 2 (map).
  std::vector<Texture> textures;
  if (volume) {
    textures.push_back(FloorVolume());
    textures.push_back(FloorTransfer());
    if (displaced) textures.push_back(FloorMap());
  } else {
    textures.push_back(CalibrationTexture(options.linear_filter));
  }

  ProgramDesc desc{
      .vertex = "common/fullscreen.vert.glsl",
      .fragment = volume ? "common/fill_rate_volume.frag.glsl" : "common/fill_rate.frag.glsl"};
  if (displaced) desc.defines.push_back("DISPLACED");
  const Program& program = programs.Get(desc);
  VertexArray vao = VertexArray::Create();
  target.Bind();
  // No depth or stencil test; the floors blend premultiplied, as DVR slices.
  GlState state;
  state.depth_test = false;
  state.depth_write = false;
  if (volume)
    state.blend = BlendState{GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA};
  const ScopedGlState scoped(state);
  program.Use();
  glBindVertexArray(vao.id());
  for (size_t unit = 0; unit < textures.size(); ++unit) {
    glBindTextureUnit(static_cast<GLuint>(unit), textures[unit].id());
  }
  const auto& u = program.Typed<FillRateUniforms>();
  if (volume) u.transfer.Set(1);
  if (displaced) u.map.Set(2);
  const float clear[4] = {0, 0, 0, 0};
  auto frame = [&] {
    target.Clear(clear);
    for (int layer = 0; layer < options.layers_per_frame; ++layer) {
      u.layer.Set(volume ? (layer + 0.5f) / static_cast<float>(options.layers_per_frame)
                         : static_cast<float>(layer));
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
  };
  const core::TimingStats stats = TimeFrames(frame, options.timer);
  glBindVertexArray(0);
  FillRate result;
  result.fragments_per_frame =
      static_cast<double>(options.width) * options.height * options.layers_per_frame;
  result.ms_per_frame = stats.median_ms;
  result.fragments_per_second = result.fragments_per_frame / (stats.median_ms * 1e-3);
  return result;
}

}  // namespace render
