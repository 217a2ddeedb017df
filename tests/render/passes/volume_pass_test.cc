// The volume pass against double-precision CPU references at the same sample
// positions (orthographic camera): llvmpipe's 3D filter, DVR images, iso first
// hits, normals on analytic fields, the Fig. 4 ablation, hard cases.
#include "render/passes/volume_pass.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "core/projection.h"
#include "core/volume_io.h"
#include "render/cores/slicing.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

using test_support::GlTest;

// ---- helpers ----

core::Volume SmoothRandomVolume(const glm::ivec3& dims, core::ScalarType type, uint32_t seed) {
  core::Volume v = core::Volume::Zeros(dims, type);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double max = type == core::ScalarType::kUint8    ? 255
                     : type == core::ScalarType::kUint16 ? 65535
                                                         : 1;
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) v.SetValue(x, y, z, u(rng) * max);
  return v;
}

// A ball: normalised density 0.5 + k (R - |t - c|) in texture units,
// clamped to [0, 1] (iso 0.5 = the sphere of radius R).
core::Volume BallVolume(int n, double radius, double k) {
  core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kFloat32);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::dvec3 t((x + 0.5) / n, (y + 0.5) / n, (z + 0.5) / n);
        v.SetValue(x, y, z, std::clamp(0.5 + k * (radius - glm::length(t - 0.5)), 0.0, 1.0));
      }
  return v;
}

// The volume's texture box scaled to its extent and centred at the origin.
glm::mat4 CentredWorldFromVolume(const core::Volume& v) {
  const glm::vec3 e(v.Extent());
  return glm::scale(glm::translate(glm::mat4(1.0f), -0.5f * e), e);
}

struct OrthoCamera {
  ViewSetup view;
  double scale;  // pixels per world unit
  int size;
};

// Orthographic camera looking at the origin from (azimuth, elevation), the
// whole of a sphere of radius `radius` in view.
OrthoCamera Ortho(double azimuth_deg, double elevation_deg, double radius, int size) {
  const double el = glm::radians(elevation_deg), az = glm::radians(azimuth_deg);
  const glm::vec3 horizontal(static_cast<float>(std::cos(az)), static_cast<float>(std::sin(az)), 0);
  const glm::vec3 to_eye = static_cast<float>(std::cos(el)) * horizontal +
                           glm::vec3(0, 0, static_cast<float>(std::sin(el)));
  const glm::vec3 up = -static_cast<float>(std::sin(el)) * horizontal +
                       glm::vec3(0, 0, static_cast<float>(std::cos(el)));
  OrthoCamera c;
  c.size = size;
  c.scale = size / (2.2 * radius);
  c.view.cam_from_world =
      core::CamFromWorldLookAt(static_cast<float>(3 * radius) * to_eye, {0, 0, 0}, up);
  c.view.clip_from_cam = core::ClipFromCamOrthographic(c.scale, c.scale, size / 2.0, size / 2.0,
                                                       size, size, 0.1 * radius, 6 * radius);
  c.view.orthographic = true;
  return c;
}

// Camera-space point at the centre of pixel (col, row) at depth z.
glm::dvec3 PixelInCam(const OrthoCamera& c, int col, int row, double z) {
  return {(col + 0.5 - c.size / 2.0) / c.scale, (row + 0.5 - c.size / 2.0) / c.scale, z};
}

// The frame with a float colour attachment: the truth comparisons see the
// blending without 8-bit rounding at every slice.
RenderTargetOptions FloatFrameOptions(int size) {
  RenderTargetOptions o = FrameTargetOptions(size, size);
  o.color_formats[kFrameColor] = GL_RGBA32F;
  return o;
}

struct Scene {
  core::Volume volume;
  core::TransferFunction transfer;
  std::vector<VolumeMapInput> maps;
  VolumePassOptions options;
};

struct Rendered {
  core::ImageF color;     // RGBA float, image rows
  core::ImageF camera_z;  // 0 where empty
};

Rendered Render(GlTest& t, ProgramCache& programs, const Scene& s, const OrthoCamera& cam,
                VolumePass** keep = nullptr) {
  static std::unique_ptr<VolumePass> pass;
  pass = std::make_unique<VolumePass>(programs, s.volume, s.transfer, s.maps,
                                      CentredWorldFromVolume(s.volume), s.options);
  RenderTarget target(FloatFrameOptions(cam.size));
  BeginFrame(target);
  pass->Draw(target, cam.view);
  if (keep) *keep = pass.get();
  (void)t;
  return {target.ReadColorF(0), target.ReadChannelsF(1, 1)};
}

// What the GPU sees of each map: stored at the pass's bits, dequantised.
std::vector<core::DisplacementMap> StoredMaps(const Scene& s) {
  std::vector<core::DisplacementMap> out;
  for (const auto& m : s.maps)
    out.push_back(core::DequantizeDisplacementMap(
        core::StoreDisplacementMap(m.map, s.options.displacement_bits)));
  return out;
}

std::vector<core::PlacedMap> Placed(const Scene& s,
                                    const std::vector<core::DisplacementMap>& stored) {
  std::vector<core::PlacedMap> placed;
  for (size_t i = 0; i < stored.size(); ++i) placed.push_back({&stored[i], s.maps[i].placement});
  return placed;
}

double Density(const core::Volume& v, const glm::dvec3& p) {
  if (p.x < 0 || p.y < 0 || p.z < 0 || p.x > 1 || p.y > 1 || p.z > 1) return 0;
  return core::SampleTrilinear(v, p);
}

// ---- the DVR reference: the pass's slices, in double ----
struct Reference {
  core::Image<double> color;  // RGBA premultiplied
  core::Image8 ambiguous;  // 1 where a sample lies within 1e-4 of a proxy face (rasterisation ties)
};

Reference DvrReference(const Scene& s, const VolumePass& pass, const OrthoCamera& cam) {
  const glm::dmat4 world_from_box(pass.world_from_proxy());
  const glm::dmat4 cam_from_box = glm::dmat4(cam.view.cam_from_world) * world_from_box;
  const glm::dmat4 box_from_cam = glm::inverse(cam_from_box);
  const SliceStack stack =
      MakeSlices(SliceBox{pass.world_from_proxy()}, SliceView{cam.view.cam_from_world, true},
                 pass.DvrSlicing(cam.view));
  const core::Box3 proxy = pass.proxy_box();
  const auto stored = StoredMaps(s);
  const auto placed = Placed(s, stored);
  const std::vector<glm::vec4> table = s.transfer.Table(256);
  const double exponent = static_cast<float>(stack.spacing_world / pass.voxel_world());
  Reference r{core::Image<double>(cam.size, cam.size, 4, 0.0),
              core::Image8(cam.size, cam.size, 1, 0)};
  for (const Slice& slice : stack.slices) {
    const double z = (cam_from_box * glm::dvec4(glm::dvec3(slice.p_in_box[0]), 1.0)).z;
    for (int row = 0; row < cam.size; ++row)
      for (int col = 0; col < cam.size; ++col) {
        const glm::dvec3 b =
            glm::dvec3(box_from_cam * glm::dvec4(PixelInCam(cam, col, row, z), 1.0));
        const double margin = std::min({b.x, b.y, b.z, 1 - b.x, 1 - b.y, 1 - b.z});
        if (std::abs(margin) < 1e-4) r.ambiguous.at(col, row) = 1;
        if (margin < 0) continue;
        const glm::dvec3 pp = proxy.lo + b * (proxy.hi - proxy.lo);
        const core::DisplacedSample d = core::Displace(placed, pp);
        if (d.alpha < 0.5) continue;
        const double sv = Density(s.volume, d.p);
        const double u = std::clamp(sv, 0.0, 1.0) * 255;
        const int i0 = static_cast<int>(std::floor(u)), i1 = std::min(i0 + 1, 255);
        const glm::dvec4 tf = glm::mix(glm::dvec4(table[i0]), glm::dvec4(table[i1]), u - i0);
        const double a = (1 - std::pow(std::max(1 - tf.a, 0.0), exponent)) * d.alpha;
        if (!(a > 0)) continue;
        for (int c = 0; c < 3; ++c)
          r.color.at(col, row, c) = tf[c] * a + (1 - a) * r.color.at(col, row, c);
        r.color.at(col, row, 3) = a + (1 - a) * r.color.at(col, row, 3);
      }
  }
  return r;
}

VolumeMapInput PlacedEffect(core::Effect e, const glm::ivec3& dims,
                            const glm::dmat4& placement = glm::dmat4(1.0)) {
  core::EffectOptions o;
  o.effect = e;
  return {core::SampleEffect(o, dims), placement};
}

// ---- 1. llvmpipe's 3D linear filter against the CPU trilinear filter ----

TEST_F(GlTest, VolumeFilteringErrorOfLlvmpipeIsMeasured) {
  // A probe program: one sample of u_volume per pixel at the position stored
  // in u_positions; the test's own shader, next to the embedded ones.
  std::map<std::string, std::string> files;
  for (const auto& name : ShaderSources::Embedded().Names())
    files[name] = *ShaderSources::Embedded().Find(name);
  files["probe.frag.glsl"] =
      "#version 450 core\nin vec2 v_uv;\nuniform sampler3D u_volume;\nuniform sampler2D "
      "u_positions;\n"
      "layout(location = 0) out vec4 o;\nvoid main() { o = vec4(texture(u_volume, "
      "texelFetch(u_positions, "
      "ivec2(gl_FragCoord.xy), 0).xyz).r); }\n";
  const ShaderSources sources(files);
  ProgramCache cache(sources);
  const Program& program =
      cache.Get({.vertex = "common/fullscreen.vert.glsl", .fragment = "probe.frag.glsl"});
  constexpr int kSize = 256;
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::vec4> positions(kSize * kSize);
  for (auto& p : positions) p = {u(rng), u(rng), u(rng), 0};
  Texture pos = Texture::Create2D(GL_RGBA32F, kSize, kSize);
  glTextureSubImage2D(pos.id(), 0, 0, 0, kSize, kSize, GL_RGBA, GL_FLOAT, positions.data());
  GLuint vao_id = 0;
  glCreateVertexArrays(1, &vao_id);
  const VertexArray vao(vao_id);  // core profile: a draw needs a vertex array
  // Probes `volume` through the texture bound to unit 0; max and mean error.
  auto probe = [&](const core::Volume& v, const std::string& label, double bound) {
    RenderTarget target(RenderTargetOptions{
        .width = kSize, .height = kSize, .color_formats = {GL_RGBA32F}, .depth_stencil = false});
    target.Bind();
    program.Use();
    glUniform1i(program.Uniform("u_volume"), 0);
    glUniform1i(program.Uniform("u_positions"), 1);
    glBindTextureUnit(1, pos.id());
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(vao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    const core::ImageF got = target.ReadColorF(0);
    double worst = 0, sum = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const glm::vec4 p =
            positions[static_cast<size_t>(kSize - 1 - y) * kSize + x];  // image rows are flipped
        const double e = std::abs(got.at(x, y, 0) - core::SampleTrilinear(v, glm::dvec3(p)));
        worst = std::max(worst, e);
        sum += e;
      }
    std::printf(
        "llvmpipe 3D linear filter vs CPU trilinear (%s): max %.3g, mean %.3g (of the [0,1] "
        "range)\n",
        label.c_str(), worst, sum / (kSize * kSize));
    RecordProperty("filter_error_max_" + label, std::to_string(worst));
    EXPECT_LE(worst, bound) << label;
  };
  for (core::ScalarType type :
       {core::ScalarType::kUint8, core::ScalarType::kUint16, core::ScalarType::kFloat32}) {
    const core::Volume v = SmoothRandomVolume({17, 9, 13}, type, 3);
    // The pass's upload (uint8 widened to R16): float-exact filtering.
    VolumePass pass(programs(), v, core::TransferPreset("ramp"), {}, glm::mat4(1.0f), {});
    pass.BindVolumeTexture(0);
    probe(v, fmt::format("pass-{}", core::ScalarTypeName(type)), 1e-5);
    if (type == core::ScalarType::kUint8) {
      // A plain R8 texture: llvmpipe's 8-bit path interpolates with 8-bit
      // weights; measured 6.2e-3 max (1.6/255). Bound: 2/255.
      Texture r8 = Texture::Create3D(GL_R8, v.dims.x, v.dims.y, v.dims.z);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTextureSubImage3D(r8.id(), 0, 0, 0, 0, v.dims.x, v.dims.y, v.dims.z, GL_RED,
                          GL_UNSIGNED_BYTE, v.bytes.data());
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      glTextureParameteri(r8.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(r8.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glBindTextureUnit(0, r8.id());
      probe(v, "R8", 2.0 / 255);
    }
  }
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace render
