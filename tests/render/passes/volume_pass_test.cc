// The volume pass against double-precision CPU references at the same sample
// positions (orthographic camera): llvmpipe's 3D filter, DVR images (against
// verify/volume_reference.h, the reference the report's gallery shares), iso
// first hits, normals on analytic fields, the Fig. 4 ablation, hard cases.
#include "render/passes/volume_pass.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/projection.h"
#include "core/volume_io.h"
#include "tests/support/gl_test.h"
#include "verify/volume_reference.h"

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

using K = core::DeformationKind;

// The maps these tests were written for (Correa 2006's figures) in the one
// vocabulary (core::kDeformationTable): a peel of 160 degrees of the layer
// 0.4 <= z <= 0.5, x >= 0.5 (T = 0.1, its box moved down by 0.4 so the hinge
// is at z = 0.5); slices of period 0.25 and gap 0.06; a seam opening to 0.2
// from z = 0.3; a pull of amplitude 1 and sigma 0.15; a wave of amplitude
// 0.05 and wavelength 0.5.
VolumeMapInput PlacedEffect(K kind, const glm::ivec3& dims,
                            const glm::dmat4& placement = glm::dmat4(1.0)) {
  core::Deformation d = core::Deformation::Default(kind);
  d.parent_from_box = placement;
  if (kind == K::kPeel) {
    d.amount = 160 * M_PI / 180, d.width = 0.1;
    d.parent_from_box = placement * glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -0.4));
  }
  if (kind == K::kSeam) d.amount = 0.2, d.width = 0.7;
  if (kind == K::kPull) d.amount = 1.0, d.width = 0.15;
  return {core::SampleDeformationMap(d, dims), core::VolumeMapPlacement(d)};
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
      "u_positions;\nuniform int u_channel;\n"
      "layout(location = 0) out vec4 o;\nvoid main() { o = vec4(texture(u_volume, "
      "texelFetch(u_positions, "
      "ivec2(gl_FragCoord.xy), 0).xyz)[u_channel]); }\n";
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
  // Probes `volume` through `channel` of the texture bound to unit 0; max
  // and mean error.
  auto probe = [&](const core::Volume& v, int channel, const std::string& label, double bound) {
    RenderTarget target(RenderTargetOptions{
        .width = kSize, .height = kSize, .color_formats = {GL_RGBA32F}, .depth_stencil = false});
    target.Bind();
    program.Use();
    glUniform1i(program.Uniform("u_volume"), 0);
    glUniform1i(program.Uniform("u_positions"), 1);
    glUniform1i(program.Uniform("u_channel"), channel);
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
    // The pass's upload (the scalar normalised in the alpha of an RGBA32F
    // texture): float-exact filtering.
    VolumePass pass(programs(), v, core::TransferPreset("ramp"), {}, glm::mat4(1.0f), {});
    pass.BindSampleTexture(0);
    probe(v, 3, fmt::format("pass-{}", core::ScalarTypeName(type)), 1e-5);
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
      probe(v, 0, "R8", 2.0 / 255);
    }
  }
  EXPECT_NO_GL_ERROR();
}

// ---- 2. DVR against the double CPU reference ----

struct Agreement {
  double max = 0, mean = 0;  // per channel, in units of 1/255
  int64_t compared = 0;
};

Agreement Compare(const core::ImageF& gpu, const ibr::DvrReferenceImage& ref) {
  Agreement a;
  double sum = 0;
  for (int y = 0; y < gpu.height(); ++y)
    for (int x = 0; x < gpu.width(); ++x) {
      if (ref.ambiguous.at(x, y)) continue;
      if (gpu.at(x, y, 3) == 0 && ref.color.at(x, y, 3) == 0)
        continue;  // empty in both: not a comparison
      for (int c = 0; c < 4; ++c) {
        const double e = std::abs(gpu.at(x, y, c) - ref.color.at(x, y, c)) * 255;
        a.max = std::max(a.max, e);
        sum += e;
        ++a.compared;
      }
    }
  a.mean = a.compared ? sum / a.compared : 0;
  return a;
}

TEST_F(GlTest, VolumeDvrAgreesWithTheDoubleReference) {
  const auto dat = test_support::SharedData("volumes/neghip_64x64x64_uint8.dat");
  if (dat.empty()) GTEST_SKIP() << "../shared/data is absent";
  struct Case {
    const char* label;
    Scene scene;
  };
  std::vector<Case> cases;
  {
    Scene s{core::ReadVolume(dat), core::TransferPreset("neghip"), {}, {}};
    s.options.lighting = VolumeLighting::kNone;
    cases.push_back({"neghip plain", s});
    // The bench's floor profile (no discard, no lighting): the same picture.
    s.options.floor_shader = true;
    cases.push_back({"neghip plain floor shader", s});
    // The displaced floor (one map fetch, the scalar where it points; no
    // mask, no identity outside the map's active box): with a constant shift
    // whose cube holds the whole proxy box, the displaced picture.
    {
      VolumeMapInput shift;
      shift.map.dims = {4, 4, 4};
      shift.map.texels.assign(64, glm::vec4(0.04f, -0.03f, 0.02f, 1.0f));
      shift.placement =
          glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(-0.25)), glm::dvec3(1.5));
      Scene f = s;
      f.maps = {shift};
      f.options.support_skip = false;
      f.options.displacement_bits = 32;
      cases.push_back({"neghip displaced floor shader, constant shift", f});
    }
    s.options.floor_shader = false;
    s.maps.push_back(PlacedEffect(K::kPeel, {32, 32, 32}));
    cases.push_back({"neghip peel 16-bit", s});
    // The dequantised RGBA32F texture instead of the RGBA16 one (scale and
    // bias in the shader): the same values, so the same bounds.
    s.options.float_map_textures = true;
    cases.push_back({"neghip peel 16-bit RGBA32F texture", s});
    s.options.float_map_textures = false;
    s.options.displacement_bits = 8;
    cases.push_back({"neghip peel 8-bit RGBA8 texture", s});
    s.options.displacement_bits = 32;
    s.maps.push_back(
        PlacedEffect(K::kWave, {32, 8, 8},
                     glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(0.1, 0.1, 0.0)),
                                glm::dvec3(0.8, 0.8, 0.6))));
    cases.push_back({"neghip peel+wave placed 32-bit", s});
  }
  {
    Scene s{SmoothRandomVolume({20, 12, 7}, core::ScalarType::kUint16, 4),
            core::TransferPreset("ramp"),
            {},
            {}};
    s.volume.spacing = {1.0, 1.5, 3.0};  // non-cubic voxels
    s.options.lighting = VolumeLighting::kNone;
    s.options.sampling_distance_voxels = 0.7;
    s.maps.push_back(PlacedEffect(K::kSlices, {32, 4, 4}));
    cases.push_back({"random uint16 anisotropic slices", s});
  }
  for (const Case& c : cases) {
    VolumePass* pass = nullptr;
    const double radius = 0.5 * glm::length(c.scene.volume.Extent());
    const OrthoCamera cam = Ortho(30, 25, 1.6 * radius, 96);
    const Rendered got = Render(*this, programs(), c.scene, cam, &pass);
    const ibr::DvrReferenceImage ref = ibr::DvrReference(
        c.scene.volume, c.scene.transfer, c.scene.maps, *pass, cam.view, cam.size, cam.size);
    const Agreement a = Compare(got.color, ref);
    double coverage = 0;
    for (int y = 0; y < 96; ++y)
      for (int x = 0; x < 96; ++x) coverage += got.color.at(x, y, 3) > 0.02;
    std::printf(
        "DVR vs double reference (%s): max %.3f/255, mean %.4f/255 over %lld channel values of "
        "non-empty pixels, %.0f covered px\n",
        c.label, a.max, a.mean, static_cast<long long>(a.compared), coverage);
    EXPECT_GT(coverage, 300) << c.label;
    EXPECT_LE(a.max, 2.0) << c.label;
    EXPECT_LE(a.mean, 0.2) << c.label;
    {
      core::Image8 img(96, 96, 4);
      for (size_t i = 0; i < img.values().size(); ++i)
        img.values()[i] =
            static_cast<uint8_t>(std::clamp(got.color.values()[i] * 255.0f, 0.0f, 255.0f));
      test_support::WriteDebugImage(std::string("dvr-") + c.label + ".png", img);
    }
  }
  EXPECT_NO_GL_ERROR();
}

// 8- and 16-bit maps kept 8/16-bit on the GPU (RGBA8 / RGBA16 UNORM, scale
// and bias in the shader) hold the same numbers as their dequantised RGBA32F
// upload: the same picture, over effects with sharp cuts (peel, slices,
// seam) and a smooth one (pull), lit by eq. 6+7, from three views.
TEST_F(GlTest, VolumeUnormMapTexturesDrawTheDequantisedPicture) {
  const auto dat = test_support::SharedData("volumes/neghip_64x64x64_uint8.dat");
  if (dat.empty()) GTEST_SKIP() << "../shared/data is absent";
  const core::Volume volume = core::ReadVolume(dat);
  const double radius = 0.5 * glm::length(volume.Extent());
  for (const int bits : {8, 16}) {
    double worst = 0, sum = 0;
    int64_t values = 0, off = 0;
    for (const K effect : {K::kPeel, K::kSlices, K::kSeam, K::kPull}) {
      Scene s{volume, core::TransferPreset("neghip"), {PlacedEffect(effect, {32, 32, 32})}, {}};
      s.options.displacement_bits = bits;
      for (const double azimuth : {30.0, 150.0, 260.0}) {
        const OrthoCamera cam = Ortho(azimuth, 25, 1.6 * radius, 96);
        s.options.float_map_textures = true;
        const core::ImageF dequantised = Render(*this, programs(), s, cam).color;
        s.options.float_map_textures = false;
        const core::ImageF unorm = Render(*this, programs(), s, cam).color;
        for (size_t i = 0; i < unorm.values().size(); ++i) {
          const double e = std::abs(unorm.values()[i] - dequantised.values()[i]) * 255;
          worst = std::max(worst, e);
          sum += e;
          off += e > 0.5;
          ++values;
        }
      }
    }
    std::printf(
        "%d-bit map as RGBA%d UNORM vs dequantised RGBA32F: max %.4f/255, mean %.6f/255, %lld of "
        "%lld channel values more than 0.5/255 apart\n",
        bits, bits, worst, sum / static_cast<double>(values), static_cast<long long>(off),
        static_cast<long long>(values));
    // The same numbers: only float rounding of (2 t - 1) scale in the shader
    // against the CPU's may differ (measured 0.0021/255 at 8 bits, 0.0013 at
    // 16). Bound 0.02/255; an RGBA8 texture filtered with llvmpipe's 8-bit
    // weights (CLAMP_TO_EDGE) was 73/255 off at the cuts.
    EXPECT_LE(worst, 0.02) << bits;
  }
  EXPECT_NO_GL_ERROR();
}

// The opacity correction lives in the transfer table the pass uploads for
// its slice spacing: one pass redrawn at other sampling distances (and so
// other spacings) agrees with the reference at each, and a coarser spacing
// changes the picture only within the sampling error. A stale table (the
// re-upload switched off, measured once): 119/255 off the reference at 4
// voxels, summed alpha 0.60 of the 1-voxel picture's; 64/255 and 1.21 at 0.5.
TEST_F(GlTest, VolumeDvrOpacityFollowsTheSliceSpacing) {
  const auto dat = test_support::SharedData("volumes/neghip_64x64x64_uint8.dat");
  if (dat.empty()) GTEST_SKIP() << "../shared/data is absent";
  Scene s{core::ReadVolume(dat), core::TransferPreset("neghip"), {}, {}};
  s.options.lighting = VolumeLighting::kNone;
  s.maps.push_back(PlacedEffect(K::kPeel, {32, 32, 32}));
  const double radius = 0.5 * glm::length(s.volume.Extent());
  const OrthoCamera cam = Ortho(30, 25, 1.6 * radius, 96);
  VolumePass* pass = nullptr;
  const core::ImageF first = Render(*this, programs(), s, cam, &pass).color;
  for (const double sampling : {4.0, 0.5, 1.0}) {
    VolumePassOptions o = pass->options();
    o.sampling_distance_voxels = sampling;
    pass->SetOptions(o);
    RenderTarget target(FloatFrameOptions(cam.size));
    BeginFrame(target);
    pass->Draw(target, cam.view);
    const core::ImageF got = target.ReadColorF(0);
    const ibr::DvrReferenceImage ref =
        ibr::DvrReference(s.volume, s.transfer, s.maps, *pass, cam.view, cam.size, cam.size);
    const Agreement a = Compare(got, ref);
    // Total opacity against the 1-voxel picture drawn first: the correction
    // keeps it within the sampling error; without it, 4 voxels would lose
    // most of it (each slice standing for 4 voxels at the opacity of one).
    double alpha_first = 0, alpha_now = 0;
    for (int y = 0; y < cam.size; ++y)
      for (int x = 0; x < cam.size; ++x) {
        alpha_first += first.at(x, y, 3);
        alpha_now += got.at(x, y, 3);
      }
    std::printf(
        "DVR at sampling %.1f voxel after redraws: vs reference max %.3f/255, mean %.4f/255; "
        "summed alpha %.3f of the 1-voxel picture's\n",
        sampling, a.max, a.mean, alpha_now / alpha_first);
    EXPECT_LE(a.max, 2.0) << sampling;
    EXPECT_LE(a.mean, 0.2) << sampling;
    EXPECT_NEAR(alpha_now / alpha_first, 1.0, 0.15) << sampling;
  }
  EXPECT_NO_GL_ERROR();
}

// ---- 2b. the support skip: slices split at the maps' support box ----

// A map cube turned 30 degrees about z in the volume: its support is no
// axis-aligned box there.
glm::dmat4 RotatedPlacement() {
  return glm::scale(glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 0.1, 0.2)),
                                glm::radians(30.0), glm::dvec3(0, 0, 1)),
                    glm::dvec3(0.5, 0.5, 0.7));
}

// The pass's support box (proxy-box coordinates) against a brute-force scan
// of 32-bit maps (where the stored identity is exactly (0, 0, 0, 1)): every
// texel whose D, alpha, J_D or grad alpha (core::ComputeMapDerivatives, what
// the pass uploads) is not the identity's, with the trilinear footprint of
// that texel, placed; and every p' of a grid over the proxy box that
// core::Displace (maps read everywhere) moves, masks or shears. The box is
// also tight: within half a texel of the scanned footprints.
TEST_F(GlTest, VolumeSupportBoxHoldsEveryPointTheMapsMove) {
  const core::Volume volume = BallVolume(12, 0.3, 2.0);
  const glm::dmat4 placed = glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(0.2, 0.3, 0.1)),
                                       glm::dvec3(0.5, 0.4, 0.6));
  const glm::dmat4 rotated = RotatedPlacement();
  struct Case {
    const char* label;
    std::vector<VolumeMapInput> maps;
  };
  const std::vector<Case> cases = {
      {"peel", {PlacedEffect(K::kPeel, {32, 32, 32})}},
      {"pull placed", {PlacedEffect(K::kPull, {16, 16, 16}, placed)}},
      {"seam rotated", {PlacedEffect(K::kSeam, {16, 16, 16}, rotated)}},
      {"slices", {PlacedEffect(K::kSlices, {32, 4, 4})}},
      {"peel + pull rotated",
       {PlacedEffect(K::kPeel, {16, 16, 16}), PlacedEffect(K::kPull, {16, 16, 16}, rotated)}},
  };
  for (const Case& c : cases) {
    VolumePassOptions options;
    options.displacement_bits = 32;
    const VolumePass pass(programs(), volume, core::TransferPreset("ramp"), c.maps,
                          CentredWorldFromVolume(volume), options);
    const core::Box3 support = pass.support_box();
    const core::Box3 proxy = pass.proxy_box();
    const auto to_proxy = [&](const glm::dvec3& tex) {
      return (tex - proxy.lo) / (proxy.hi - proxy.lo);
    };
    const auto in_support = [&](const glm::dvec3& q) {
      return glm::all(glm::greaterThanEqual(q, support.lo - 1e-9)) &&
             glm::all(glm::lessThanEqual(q, support.hi + 1e-9));
    };
    // Texel scan.
    core::Box3 scanned{glm::dvec3(1e300), glm::dvec3(-1e300)};
    int64_t moving = 0;
    for (const VolumeMapInput& m : c.maps) {
      const core::DisplacementMap stored =
          core::DequantizeDisplacementMap(core::StoreDisplacementMap(m.map, 32));
      const core::MapDerivatives d = core::ComputeMapDerivatives(stored);
      const glm::ivec3 n = stored.dims;
      for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
          for (int x = 0; x < n.x; ++x) {
            const size_t i = (static_cast<size_t>(z) * n.y + y) * n.x + x;
            if (stored.texels[i] == glm::vec4(0, 0, 0, 1) && d.jacobian[i] == glm::mat3(0.0f) &&
                d.alpha_gradient[i] == glm::vec3(0.0f)) {
              continue;
            }
            ++moving;
            // Filtered samples read texel i within one texel of its centre.
            const glm::dvec3 cell(x, y, z);
            for (const double grow : {0.0, 0.5}) {
              const glm::dvec3 lo = glm::max((cell - 0.5 - grow) / glm::dvec3(n), 0.0);
              const glm::dvec3 hi = glm::min((cell + 1.5 + grow) / glm::dvec3(n), 1.0);
              for (int k = 0; k < 8; ++k) {
                const glm::dvec3 u(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
                const glm::dvec3 q = to_proxy(glm::dvec3(m.placement * glm::dvec4(u, 1.0)));
                if (grow == 0) {
                  ASSERT_TRUE(in_support(q)) << c.label << ": texel " << x << " " << y << " " << z;
                } else {
                  scanned.lo = glm::min(scanned.lo, q);
                  scanned.hi = glm::max(scanned.hi, q);
                }
              }
            }
          }
    }
    ASSERT_GT(moving, 0) << c.label;
    EXPECT_TRUE(glm::all(glm::greaterThanEqual(support.lo, scanned.lo - 1e-9)) &&
                glm::all(glm::lessThanEqual(support.hi, scanned.hi + 1e-9)))
        << c.label << ": the support box is looser than half a texel";
    // Point scan through the CPU displacement with the maps read everywhere.
    const std::vector<core::DisplacementMap> stored = ibr::VolumeStoredMaps(c.maps, 32);
    std::vector<core::PlacedMap> everywhere;
    for (size_t i = 0; i < c.maps.size(); ++i)
      everywhere.push_back({&stored[i], c.maps[i].placement, {}});
    constexpr int kGrid = 40;
    int64_t moved = 0, outside = 0;
    for (int z = 0; z < kGrid; ++z)
      for (int y = 0; y < kGrid; ++y)
        for (int x = 0; x < kGrid; ++x) {
          const glm::dvec3 q = (glm::dvec3(x, y, z) + 0.5) / static_cast<double>(kGrid);
          const glm::dvec3 p_prime = proxy.lo + q * (proxy.hi - proxy.lo);
          const core::DisplacedSample d = core::Displace(everywhere, p_prime, true);
          // (The double trilinear weights of a mask of ones sum to 1 - 1e-16.)
          const bool identity =
              d.p == p_prime && std::abs(d.alpha - 1.0) < 1e-12 && d.jacobian == glm::dmat3(1.0);
          moved += !identity;
          outside += !in_support(q);
          if (!identity) {
            EXPECT_TRUE(in_support(q)) << c.label << ": p' " << p_prime.x << " " << p_prime.y << " "
                                       << p_prime.z << " moves outside the support";
          }
        }
    std::printf(
        "support box (%s): [%.3f %.3f %.3f]-[%.3f %.3f %.3f] of the proxy box; %lld texels "
        "not the identity, %lld of %d grid points moved, %lld outside the box\n",
        c.label, support.lo.x, support.lo.y, support.lo.z, support.hi.x, support.hi.y, support.hi.z,
        static_cast<long long>(moving), static_cast<long long>(moved), kGrid * kGrid * kGrid,
        static_cast<long long>(outside));
    EXPECT_GT(moved, 0) << c.label;
  }
  EXPECT_NO_GL_ERROR();
}

// Pixels with a slice sample within 1e-4 of a proxy face (proxy box units,
// as ibr::DvrReference marks them) or of a face of a map's cube (map units):
// the field jumps there (to nothing, or from the map's displacement to the
// identity outside its cube), so whether a sample just on it is drawn, or by
// which side's part, is a tie: a split slice and the whole one may differ
// there by one sample.
core::Image8 SplitTies(const VolumePass& pass, const OrthoCamera& cam,
                       const std::vector<VolumeMapInput>& maps) {
  const glm::dmat4 cam_from_box(cam.view.cam_from_world * pass.world_from_proxy());
  const glm::dmat4 box_from_cam = glm::inverse(cam_from_box);
  const SliceStack stack = MakeSlices(SliceBox{pass.world_from_proxy()},
                                      SliceView{cam.view.cam_from_world, cam.view.orthographic},
                                      pass.DvrSlicing(cam.view));
  core::Image8 ties(cam.size, cam.size, 1, 0);
  for (int row = 0; row < cam.size; ++row)
    for (int col = 0; col < cam.size; ++col) {
      const ibr::CamLine line = ibr::PixelLineInCam(cam.view, cam.size, cam.size, col, row);
      for (const Slice& slice : stack.slices) {
        const double z = (cam_from_box * glm::dvec4(glm::dvec3(slice.p_in_box[0]), 1.0)).z;
        const glm::dvec3 b = glm::dvec3(box_from_cam * glm::dvec4(line.AtZ(z), 1.0));
        const double margin = std::min({b.x, b.y, b.z, 1 - b.x, 1 - b.y, 1 - b.z});
        if (std::abs(margin) < 1e-4) ties.at(col, row) = 1;
        const glm::dvec3 tex =
            pass.proxy_box().lo + b * (pass.proxy_box().hi - pass.proxy_box().lo);
        for (const VolumeMapInput& m : maps) {
          const glm::dvec3 u = glm::dvec3(glm::inverse(m.placement) * glm::dvec4(tex, 1.0));
          const double mm = std::min({u.x, u.y, u.z, 1 - u.x, 1 - u.y, 1 - u.z});
          if (std::abs(mm) < 1e-4) ties.at(col, row) = 1;
        }
      }
    }
  return ties;
}

// The split slices (support_skip, the default) draw what the unsplit ones
// draw: on every pixel the reference does not call a tie, within the DVR
// reference bounds, and without the one-sample jumps a crack or an overlap
// between the parts of a slice would leave (> 0.5/255); both with the map's
// bricks (the default; identity bricks drawn without maps, cut-away ones not
// drawn) and with the support box alone. Lit and unlit, 8/16/32-bit maps,
// placed, rotated and composed maps, a view along a box axis (slices
// parallel to the support box's faces), voxels full to the proxy's faces, a
// seam wide enough to cut whole bricks away.
TEST_F(GlTest, VolumeSupportSkipDrawsWhatTheUnsplitSlicesDraw) {
  const auto dat = test_support::SharedData("volumes/neghip_64x64x64_uint8.dat");
  if (dat.empty()) GTEST_SKIP() << "../shared/data is absent";
  const glm::dmat4 rotated = RotatedPlacement();
  struct Case {
    const char* label;
    Scene scene;
    double azimuth, elevation;
  };
  std::vector<Case> cases;
  const core::Volume neghip = core::ReadVolume(dat);
  {
    Scene s{neghip, core::TransferPreset("neghip"), {}, {}};
    s.options.lighting = VolumeLighting::kNone;
    s.maps.push_back(PlacedEffect(K::kPeel, {32, 32, 32}));
    cases.push_back({"peel 16-bit", s, 30, 25});
    s.options.lighting = VolumeLighting::kBlended;
    s.options.displacement_bits = 8;
    cases.push_back({"peel 8-bit blended", s, 30, 25});
    cases.push_back({"peel 8-bit blended axis view", s, 0, 0});
    s.options.displacement_bits = 32;
    s.options.lighting = VolumeLighting::kTransformed;
    s.maps.push_back(PlacedEffect(K::kPull, {16, 16, 16}, rotated));
    cases.push_back({"peel + pull rotated 32-bit transformed", s, -50, 40});
  }
  {
    Scene s{SmoothRandomVolume({20, 12, 7}, core::ScalarType::kUint16, 4),
            core::TransferPreset("ramp"),
            {},
            {}};
    s.volume.spacing = {1.0, 1.5, 3.0};
    s.options.lighting = VolumeLighting::kNone;
    s.options.sampling_distance_voxels = 0.7;
    s.maps.push_back(PlacedEffect(K::kSeam, {16, 16, 16}));
    cases.push_back({"random uint16 anisotropic seam", s, 120, -20});
  }
  {
    // A seam opening wide enough at 64^3 for whole bricks to be cut away,
    // lit by eq. 6 + 7 and unlit, and rotated (bricks split in map space).
    Scene s{neghip, core::TransferPreset("neghip"), {}, {}};
    s.maps.push_back(PlacedEffect(K::kSeam, {64, 64, 64}));
    cases.push_back({"seam 64^3 blended", s, 70, 30});
    s.options.displacement_bits = 32;
    cases.push_back({"seam 64^3 blended 32-bit", s, 70, 30});
    s.options.displacement_bits = 16;
    s.options.lighting = VolumeLighting::kNone;
    cases.push_back({"seam 64^3 unlit", s, 70, 30});
    s.maps = {PlacedEffect(K::kSeam, {64, 64, 64}, rotated)};
    cases.push_back({"seam 64^3 rotated unlit", s, 70, 30});
  }
  for (Case& c : cases) {
    const double radius = 0.5 * glm::length(c.scene.volume.Extent());
    const OrthoCamera cam = Ortho(c.azimuth, c.elevation, 1.6 * radius, 96);
    VolumePass* pass = nullptr;
    c.scene.options.support_skip = false;
    const Rendered whole = Render(*this, programs(), c.scene, cam, &pass);
    const VolumeDrawStats whole_stats = pass->last_stats();
    // The reference marks the ties (samples on a proxy face) for both.
    const ibr::DvrReferenceImage ref = ibr::DvrReference(
        c.scene.volume, c.scene.transfer, c.scene.maps, *pass, cam.view, cam.size, cam.size);
    // Samples on a proxy face or a map cube's face: ties between the split
    // and the whole slices (SplitTies; a 3-texel brick split put a part edge
    // 1.4e-4 px from a pixel centre on the rotated seam's cube face x = 1).
    const core::Image8 ties = SplitTies(*pass, cam, c.scene.maps);
    // Bricks (the default, one map only) and the support box alone.
    double brick_displaced_area = 0, box_displaced_area = 0, brick_cut_area = 0;
    for (const int brick_texels : {VolumePassOptions{}.brick_texels, 0}) {
      c.scene.options.support_skip = true;
      c.scene.options.brick_texels = brick_texels;
      const Rendered split = Render(*this, programs(), c.scene, cam, &pass);
      const VolumeDrawStats split_stats = pass->last_stats();
      double max = 0, sum = 0, coverage = 0;
      int64_t compared = 0, jumps = 0;
      for (int y = 0; y < cam.size; ++y)
        for (int x = 0; x < cam.size; ++x) {
          coverage += whole.color.at(x, y, 3) > 0.02;
          if (ties.at(x, y)) continue;
          double pixel = 0;
          for (int ch = 0; ch < 4; ++ch) {
            const double e = std::abs(split.color.at(x, y, ch) - whole.color.at(x, y, ch)) * 255;
            pixel = std::max(pixel, e);
            sum += e;
            ++compared;
          }
          max = std::max(max, pixel);
          jumps += pixel > 0.5;
        }
      const double mean = compared ? sum / compared : 0;
      std::printf(
          "support skip (%s, bricks %d): split vs unsplit max %.4f/255, mean %.6f/255, %lld px > "
          "0.5/255; displaced area %.0f, cut away %.0f of %.0f px, %d parts, %d draw calls\n",
          c.label, brick_texels, max, mean, static_cast<long long>(jumps),
          split_stats.displaced_area_px, split_stats.cut_area_px, split_stats.proxy_area_px,
          split_stats.parts, split_stats.draw_calls);
      const std::string label = fmt::format("{}, bricks {}", c.label, brick_texels);
      EXPECT_GT(coverage, 300) << label;
      EXPECT_LE(max, 2.0) << label;
      EXPECT_LE(mean, 0.2) << label;
      EXPECT_EQ(jumps, 0) << label;
      EXPECT_DOUBLE_EQ(split_stats.proxy_area_px, whole_stats.proxy_area_px);
      EXPECT_GT(split_stats.displaced_area_px, 0) << label;
      EXPECT_LT(split_stats.displaced_area_px, 0.99 * whole_stats.displaced_area_px) << label;
      (brick_texels ? brick_displaced_area : box_displaced_area) = split_stats.displaced_area_px;
      if (brick_texels) brick_cut_area = split_stats.cut_area_px;
      if (brick_texels == 0 || c.scene.maps.size() > 1) {
        EXPECT_EQ(split_stats.cut_area_px, 0) << label;
      }
      if (c.scene.options.lighting == VolumeLighting::kNone) {
        const Agreement a = Compare(split.color, ref);
        EXPECT_LE(a.max, 2.0) << label;
        EXPECT_LE(a.mean, 0.2) << label;
      }
    }
    // One map: the bricks (within the box) leave no more to the displaced
    // shader than the box, much less for the peel at 16 and 32 bits (8 bits:
    // cut bricks only; the seam moves nearly all of its box); several maps:
    // the box alone.
    if (c.scene.maps.size() == 1) {
      EXPECT_LE(brick_displaced_area, box_displaced_area * (1 + 1e-9)) << c.label;
      if (c.scene.options.displacement_bits != 8 && std::string(c.label).starts_with("peel")) {
        EXPECT_LT(brick_displaced_area, 0.95 * box_displaced_area) << c.label;
      }
    } else {
      EXPECT_DOUBLE_EQ(brick_displaced_area, box_displaced_area) << c.label;
    }
    // The seam at 64^3 opens wider than a brick and its margins.
    if (std::string(c.label).starts_with("seam 64")) {
      EXPECT_GT(brick_cut_area, 100) << c.label;
    }
  }
  EXPECT_NO_GL_ERROR();
}

// The brick split over a sweep of random views (unlit, where a missing or
// doubled slice sample shows most): no pixel of the split render more than
// 0.5/255 off the unsplit one (1/255 for a 16-bit map) but the ties of
// SplitTies. A crack or an overlap between a slice's parts (a T-junction, a
// fan folding over after the rasteriser snaps its vertices) would leave such
// a jump on some pixel of some view. (Without the map-face ties, a rotated
// seam, displaced up to its cube's faces, showed 4-6 such pixels, up to
// 2.2/255, with the box split as with bricks.)
TEST_F(GlTest, VolumeBrickSplitHasNoJumpsOverAViewSweep) {
  const auto dat = test_support::SharedData("volumes/neghip_64x64x64_uint8.dat");
  if (dat.empty()) GTEST_SKIP() << "../shared/data is absent";
  const core::Volume neghip = core::ReadVolume(dat);
  struct SweepScene {
    const char* label;
    Scene scene;
    double jump;  // 1/255: a difference above it counts as a jump
  };
  std::vector<SweepScene> scenes;
  {
    Scene s{neghip, core::TransferPreset("neghip"), {}, {}};
    s.options.lighting = VolumeLighting::kNone;
    s.options.displacement_bits = 32;
    s.maps.push_back(PlacedEffect(K::kPeel, {64, 64, 64}));
    scenes.push_back({"peel 64^3 32-bit", s, 0.5});
    s.maps = {PlacedEffect(K::kSeam, {64, 64, 64})};
    scenes.push_back({"seam 64^3 32-bit", s, 0.5});
    // 16 bits: the identity bricks drawn without maps, where the unsplit
    // shader shifts by the stored zero (1.5e-5 of the scale): 0.52/255 seen.
    s.options.displacement_bits = 16;
    s.maps = {PlacedEffect(K::kPeel, {64, 64, 64})};
    scenes.push_back({"peel 64^3 16-bit", s, 1.0});
    // Rotated: the bricks split the slices at tilted planes in the volume.
    s.maps = {PlacedEffect(K::kSeam, {64, 64, 64}, RotatedPlacement())};
    scenes.push_back({"seam 64^3 rotated", s, 1.0});
  }
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> azimuth(-180, 180), elevation(-80, 80);
  int views = 0;
  int64_t jumps = 0;
  double worst = 0;
  for (auto& [label, scene, jump] : scenes) {
    const double radius = 0.5 * glm::length(scene.volume.Extent());
    for (int v = 0; v < 24; ++v, ++views) {
      const OrthoCamera cam = Ortho(azimuth(rng), elevation(rng), 1.6 * radius, 96);
      scene.options.support_skip = false;
      const Rendered whole = Render(*this, programs(), scene, cam);
      VolumePass* pass = nullptr;
      scene.options.support_skip = true;
      const Rendered split = Render(*this, programs(), scene, cam, &pass);
      const core::Image8 ties = SplitTies(*pass, cam, scene.maps);
      int64_t view_jumps = 0;
      for (int y = 0; y < cam.size; ++y)
        for (int x = 0; x < cam.size; ++x) {
          if (ties.at(x, y)) continue;
          double pixel = 0;
          for (int ch = 0; ch < 4; ++ch) {
            const double e = std::abs(split.color.at(x, y, ch) - whole.color.at(x, y, ch));
            pixel = std::max(pixel, 255 * e);
          }
          worst = std::max(worst, pixel);
          view_jumps += pixel > jump;
        }
      EXPECT_EQ(view_jumps, 0) << label << ", view " << v;
      jumps += view_jumps;
    }
  }
  std::printf("brick split over %d random views: %lld jumps, worst %.4f/255 (ties excluded)\n",
              views, static_cast<long long>(jumps), worst);
  EXPECT_NO_GL_ERROR();
}

// ---- 3. iso first hits against the double CPU march ----

struct IsoReference {
  core::Image8 hit;                 // 1 where the CPU ray hits
  core::ImageF camera_z;            // camera z of the hit
  std::vector<glm::dvec3> p_prime;  // hit point, volume texture space (row-major pixels)
};

double IsoField(const Scene& s, const std::vector<core::PlacedMap>& placed, const glm::dvec3& pp) {
  const core::DisplacedSample d = core::Displace(placed, pp);
  if (d.alpha < 0.5) return 1.0;
  return s.options.iso_value - ibr::VolumeDensity(s.volume, d.p);
}

// The GPU's march in double: samples from the proxy entry at the same world
// step (the last one on the exit), the first sample with field <= 0, then
// bisection to 1e-10 of a step.
IsoReference IsoMarch(const Scene& s, const VolumePass& pass, const OrthoCamera& cam) {
  const glm::dmat4 world_from_box(pass.world_from_proxy());
  const glm::dmat4 cam_from_box = glm::dmat4(cam.view.cam_from_world) * world_from_box;
  const glm::dmat4 box_from_cam = glm::inverse(cam_from_box);
  const core::Box3 proxy = pass.proxy_box();
  const auto stored = ibr::VolumeStoredMaps(s.maps, s.options.displacement_bits);
  const auto placed = ibr::VolumePlacedMaps(s.maps, s.options.displacement_bits, stored);
  const double step = s.options.sampling_distance_voxels * pass.voxel_world();
  IsoReference r{core::Image8(cam.size, cam.size, 1, 0), core::ImageF(cam.size, cam.size, 1, 0.0f),
                 std::vector<glm::dvec3>(static_cast<size_t>(cam.size) * cam.size)};
  const glm::dvec3 dir =
      glm::dvec3(box_from_cam * glm::dvec4(0, 0, 1, 0));  // one world (= camera) unit
  for (int row = 0; row < cam.size; ++row)
    for (int col = 0; col < cam.size; ++col) {
      const glm::dvec3 o = glm::dvec3(
          box_from_cam *
          glm::dvec4(ibr::PixelLineInCam(cam.view, cam.size, cam.size, col, row).AtZ(0.0), 1.0));
      double t0 = -1e30, t1 = 1e30;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(dir[k]) < 1e-12) {
          if (o[k] < 0 || o[k] > 1) t0 = 1, t1 = -1;
          continue;
        }
        const double a = -o[k] / dir[k], b = (1 - o[k]) / dir[k];
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
      }
      if (!(t0 < t1)) continue;
      auto field = [&](double t) {
        return IsoField(s, placed, proxy.lo + (o + t * dir) * (proxy.hi - proxy.lo));
      };
      double t = t0, f = field(t);
      bool hit = f <= 0;
      double ta = t0, tb = t0;
      while (!hit && t < t1) {
        double next = t + step;
        if (next >= t1 - 1e-4 * step) next = t1;
        const double fn = field(next);
        if (fn <= 0) {
          hit = true;
          ta = t;
          tb = next;
          break;
        }
        t = next;
      }
      if (!hit) continue;
      for (int k = 0; k < 60 && tb - ta > 1e-10 * step; ++k) {
        const double tm = 0.5 * (ta + tb);
        (field(tm) <= 0 ? tb : ta) = tm;
      }
      const double th = 0.5 * (ta + tb);
      const glm::dvec3 b = o + th * dir;
      r.hit.at(col, row) = 1;
      r.camera_z.at(col, row) = static_cast<float>((cam_from_box * glm::dvec4(b, 1.0)).z);
      r.p_prime[static_cast<size_t>(row) * cam.size + col] = proxy.lo + b * (proxy.hi - proxy.lo);
    }
  return r;
}

// The iso pass ORs every ray's outcome into the frame; a hit sets this bit.
bool GpuHit(const Frame& frame, int x, int y) {
  return (frame.outcome.at(x, y) & OutcomeBit(RayOutcome::kHit)) != 0;
}

struct IsoRun {
  Frame frame;
  IsoReference ref;
  double voxel_world = 0;
};

IsoRun RunIso(GlTest& t, ProgramCache& programs, const Scene& s, const OrthoCamera& cam) {
  VolumePass pass(programs, s.volume, s.transfer, s.maps, CentredWorldFromVolume(s.volume),
                  s.options);
  RenderTarget target(FrameTargetOptions(cam.size, cam.size));
  BeginFrame(target);
  pass.Draw(target, cam.view);
  (void)t;
  return {ReadFrame(target), IsoMarch(s, pass, cam), pass.voxel_world()};
}

Scene BallScene(int n) {
  Scene s{BallVolume(n, 0.3, 2.0), core::TransferPreset("ramp"), {}, {}};
  s.options.mode = VolumeMode::kIso;
  s.options.iso_value = 0.5;
  s.options.displacement_bits = 32;
  return s;
}

TEST_F(GlTest, VolumeIsoFirstHitsAgreeWithTheDoubleMarch) {
  std::vector<std::pair<std::string, Scene>> cases;
  cases.push_back({"ball", BallScene(40)});
  Scene waved = BallScene(40);
  core::Deformation wave = core::Deformation::Default(K::kWave);
  wave.amount = 0.08;
  waved.maps.push_back(
      {core::SampleDeformationMap(wave, {48, 8, 8}), core::VolumeMapPlacement(wave)});
  cases.push_back({"ball + wave", waved});
  Scene peeled = waved;
  // The peel's map spans 1.5 boxes in z (core::BoxFromMap): 40 texels per
  // box unit, as before its map grew.
  peeled.maps.push_back(PlacedEffect(K::kPeel, {40, 40, 60}));
  cases.push_back({"ball + wave o peel", peeled});
  for (const auto& [label, s] : cases) {
    const OrthoCamera cam = Ortho(35, 30, 0.45 * s.volume.dims.x, 96);
    const IsoRun run = RunIso(*this, programs(), s, cam);
    int64_t agree = 0, hits = 0, total = 0;
    double worst_dz = 0;
    std::vector<double> dz;
    for (int y = 0; y < cam.size; ++y)
      for (int x = 0; x < cam.size; ++x) {
        const bool gpu = GpuHit(run.frame, x, y);
        const bool cpu = run.ref.hit.at(x, y) != 0;
        ++total;
        agree += gpu == cpu;
        if (gpu && cpu) {
          ++hits;
          const double e =
              std::abs(run.frame.depth.at(x, y) - run.ref.camera_z.at(x, y)) / run.voxel_world;
          dz.push_back(e);
          worst_dz = std::max(worst_dz, e);
        }
      }
    std::sort(dz.begin(), dz.end());
    const double p999 = dz.empty() ? 0 : dz[static_cast<size_t>(0.999 * (dz.size() - 1))];
    std::printf(
        "iso vs double march (%s): hit/miss agree on %.4f%% of %lld px (%lld hits), depth error "
        "max %.2g, "
        "p99.9 %.2g voxel\n",
        label.c_str(), 100.0 * agree / total, static_cast<long long>(total),
        static_cast<long long>(hits), worst_dz, p999);
    EXPECT_GT(hits, 1500) << label;
    EXPECT_GE(static_cast<double>(agree) / total, 0.999) << label;
    EXPECT_LE(p999, 1e-3) << label;
  }
  EXPECT_NO_GL_ERROR();
}

// Correa 2006 sec. 4: material the maps move out of the volume's box is
// drawn (the proxy grows to the maps' boxes, core::VolumeMapBox). A sphere of
// radius 0.45 exploded into slices (period 0.25, gap 0.06: object slabs of
// 0.19, slab k shifted by 0.06 k along +x): its last slab, object x in
// [0.76, 0.95], lands at [1.0, 1.19], outside the box's x = 1 face. Seen from
// above, the GPU's hits reach x = 1.19 (texture units) and agree with the
// double march.
TEST_F(GlTest, VolumeIsoDrawsMaterialMovedOutOfTheVolumesBox) {
  Scene s{BallVolume(48, 0.45, 2.0), core::TransferPreset("ramp"), {}, {}};
  s.options.mode = VolumeMode::kIso;
  s.options.iso_value = 0.5;
  s.options.displacement_bits = 32;
  const core::Deformation slices = core::Deformation::Default(K::kSlices);
  s.maps.push_back({core::SampleDeformationMap(slices, core::VolumeMapDims(slices, 64)),
                    core::VolumeMapPlacement(slices)});
  const OrthoCamera cam = Ortho(0, 90, 0.75 * s.volume.dims.x, 160);
  const IsoRun run = RunIso(*this, programs(), s, cam);
  const glm::dmat4 world_from_cam = glm::inverse(glm::dmat4(cam.view.cam_from_world));
  const double extent_x = s.volume.Extent().x;
  double max_x = -1;
  int64_t outside = 0, agree = 0;
  for (int y = 0; y < cam.size; ++y)
    for (int x = 0; x < cam.size; ++x) {
      agree += GpuHit(run.frame, x, y) == (run.ref.hit.at(x, y) != 0);
      if (!GpuHit(run.frame, x, y)) continue;
      const glm::dvec3 p_cam =
          ibr::PixelLineInCam(cam.view, cam.size, cam.size, x, y).AtZ(run.frame.depth.at(x, y));
      const double tex_x = (world_from_cam * glm::dvec4(p_cam, 1.0)).x / extent_x + 0.5;
      max_x = std::max(max_x, tex_x);
      outside += tex_x > 1.0;
    }
  const double pixel_tex = 1.0 / (cam.scale * extent_x);
  std::printf(
      "slices from above: hits reach x = %.4f (texture units; analytic 1.19), %lld hit "
      "pixels beyond the volume's box, hit/miss agree on %.4f%%\n",
      max_x, static_cast<long long>(outside), 100.0 * agree / (cam.size * cam.size));
  EXPECT_NEAR(max_x, 0.95 + 4 * slices.amount, 2 * pixel_tex);
  EXPECT_GT(outside, 100);
  EXPECT_GE(static_cast<double>(agree) / (cam.size * cam.size), 0.999);
  EXPECT_NO_GL_ERROR();
}

// ---- 4. normals on an analytic field, away from cuts ----

// World normal of the displaced field at p' by central differences of the
// whole CPU pipeline (maps as stored, trilinear volume): the truth the
// precomputed gradient + (I + J_D)^T of eq. 6 approximates.
glm::dvec3 FieldNormalWorld(const Scene& s, const std::vector<core::PlacedMap>& placed,
                            const glm::dvec3& pp) {
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    // Half a voxel each side: the scale of the precomputed central
    // differences; a smaller step sees the trilinear field's per-cell kinks.
    const double h = 0.5 / s.volume.dims[a];
    glm::dvec3 lo = pp, hi = pp;
    lo[a] -= h;
    hi[a] += h;
    g[a] = (ibr::VolumeDensity(s.volume, core::Displace(placed, hi).p) -
            ibr::VolumeDensity(s.volume, core::Displace(placed, lo).p)) /
           (2 * h);
  }
  const glm::dmat3 normal_world_from_tex =
      glm::transpose(glm::inverse(glm::dmat3(CentredWorldFromVolume(s.volume))));
  return -glm::normalize(normal_world_from_tex * g);
}

std::vector<double> NormalErrorsDeg(const Scene& s, const IsoRun& run, int size) {
  const auto stored = ibr::VolumeStoredMaps(s.maps, s.options.displacement_bits);
  const auto placed = ibr::VolumePlacedMaps(s.maps, s.options.displacement_bits, stored);
  std::vector<double> err;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      if (!run.ref.hit.at(x, y) || !GpuHit(run.frame, x, y)) continue;
      const glm::dvec3 pp = run.ref.p_prime[static_cast<size_t>(y) * size + x];
      if (core::Displace(placed, pp).alpha < 0.999) continue;  // away from cuts
      const glm::dvec3 truth = FieldNormalWorld(s, placed, pp);
      const glm::dvec3 got(run.frame.normal.at(x, y, 0), run.frame.normal.at(x, y, 1),
                           run.frame.normal.at(x, y, 2));
      if (!(glm::length(got) > 0.5)) {
        err.push_back(180);
        continue;
      }
      err.push_back(
          glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(got), truth), -1.0, 1.0))));
    }
  std::sort(err.begin(), err.end());
  return err;
}

TEST_F(GlTest, VolumeIsoNormalsMatchTheDisplacedFieldsGradient) {
  core::Deformation wave = core::Deformation::Default(K::kWave);
  wave.amount = 0.06;
  // The layer 0.2 <= z <= 0.5 turned by 160 degrees (T = 0.3: its box moved
  // down by 0.2 puts the hinge at z = 0.5).
  core::Deformation peel = core::Deformation::Default(K::kPeel);
  peel.amount = 160 * M_PI / 180, peel.width = 0.3;
  struct Case {
    std::string label;
    Scene scene;
  };
  std::vector<Case> cases;
  cases.push_back({"ball", BallScene(48)});
  Scene w = BallScene(48);
  w.options.lighting = VolumeLighting::kTransformed;
  w.maps.push_back({core::SampleDeformationMap(wave, {64, 8, 8}), core::VolumeMapPlacement(wave)});
  cases.push_back({"ball + wave", w});
  Scene p = BallScene(48);
  p.options.lighting = VolumeLighting::kTransformed;
  // The peel's 160 degree flip, placed (eq. 10): eq. 6 must rotate the
  // normals of the flipped part by the same angle.
  peel.parent_from_box = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, 0.1 - 0.2));
  p.maps.push_back(
      {core::SampleDeformationMap(peel, {48, 48, 48}), core::VolumeMapPlacement(peel)});
  cases.push_back({"ball + placed peel", p});
  // The same two with J_D by central differences per sample.
  for (size_t i : {size_t{1}, size_t{2}}) {
    Case fd = cases[i];
    fd.label += " (J_D differences)";
    fd.scene.options.jacobian = VolumeJacobian::kFiniteDifferences;
    cases.push_back(fd);
  }
  for (const Case& c : cases) {
    const OrthoCamera cam = Ortho(200, 35, 0.45 * c.scene.volume.dims.x, 96);
    const IsoRun run = RunIso(*this, programs(), c.scene, cam);
    const std::vector<double> err = NormalErrorsDeg(c.scene, run, cam.size);
    ASSERT_GT(err.size(), 800u) << c.label;
    const double median = err[err.size() / 2],
                 p95 = err[static_cast<size_t>(0.95 * (err.size() - 1))];
    std::printf(
        "iso normals vs FD gradient of the displaced field (%s): median %.3f deg, p95 %.3f deg "
        "over %zu px\n",
        c.label.c_str(), median, p95, err.size());
    EXPECT_LE(median, 1.0) << c.label;
    EXPECT_LE(p95, 3.0) << c.label;
  }
  // The test can fail: the flipped part keeps its old normals without eq. 6.
  Scene uncorrected = cases[2].scene;
  uncorrected.options.lighting = VolumeLighting::kGradient;
  const OrthoCamera cam = Ortho(200, 35, 0.45 * uncorrected.volume.dims.x, 96);
  const std::vector<double> err =
      NormalErrorsDeg(uncorrected, RunIso(*this, programs(), uncorrected, cam), cam.size);
  const double p95 = err[static_cast<size_t>(0.95 * (err.size() - 1))];
  std::printf(
      "iso normals without eq. 6 (ball + placed peel, precomputed gradient only): p95 %.1f deg\n",
      p95);
  EXPECT_GT(p95, 30.0);
  EXPECT_NO_GL_ERROR();
}

// ---- 5. Fig. 4 as numbers ----

// A plate (normalised density 1 inside x, y in [0.15, 0.85], z in [0.38, 0.5],
// 2-voxel ramps at its faces), its right half peeled 160 degrees over its
// left half: the flipped plate's underside now faces the light above, and the
// cut leaves a rim facing +x at x = 0.5.
Scene PlateScene(VolumeLighting lighting, VolumeJacobian jacobian) {
  const int n = 48;
  core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kFloat32);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::dvec3 t((x + 0.5) / n, (y + 0.5) / n, (z + 0.5) / n);
        const double d =
            std::min({t.x - 0.15, 0.85 - t.x, t.y - 0.15, 0.85 - t.y, t.z - 0.38, 0.5 - t.z});
        v.SetValue(x, y, z, std::clamp(0.5 + d * n / 2, 0.0, 1.0));
      }
  Scene s{v, core::TransferPreset("ramp"), {}, {}};
  s.options.mode = VolumeMode::kIso;
  s.options.lighting = lighting;
  s.options.jacobian = jacobian;
  s.options.displacement_bits = 32;
  s.options.light_dir_world = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
  // The layer 0.32 <= z <= 0.52, x >= 0.5, turned by 160 degrees (T = 0.2:
  // its box moved down by 0.28 puts the hinge at z = 0.52).
  core::Deformation peel = core::Deformation::Default(K::kPeel);
  peel.amount = 160 * M_PI / 180, peel.width = 0.2;
  peel.parent_from_box = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -0.28));
  s.maps.push_back({core::SampleDeformationMap(peel, {48, 48, 48}, /*smooth_alpha_passes=*/2),
                    core::VolumeMapPlacement(peel)});
  return s;
}

struct Fig4Numbers {
  int64_t underside = 0, underside_lit = 0;  // flipped plate's old bottom face: N.L > 0
  int64_t rim = 0, rim_dark = 0;             // cut face at x = 0.5: N.L <= 0
};

Fig4Numbers MeasureFig4(GlTest& t, ProgramCache& programs, VolumeLighting lighting,
                        VolumeJacobian jacobian) {
  const Scene s = PlateScene(lighting, jacobian);
  const auto stored = ibr::VolumeStoredMaps(s.maps, s.options.displacement_bits);
  const auto placed = ibr::VolumePlacedMaps(s.maps, s.options.displacement_bits, stored);
  const glm::dvec3 light(s.options.light_dir_world);
  Fig4Numbers r;
  const double voxel = 1.0 / s.volume.dims.x;
  // From above for the underside; from +x, low, for the rim.
  for (const auto& [azimuth, elevation] : {std::pair{-90.0, 70.0}, std::pair{0.0, 15.0}}) {
    const OrthoCamera cam = Ortho(azimuth, elevation, 0.45 * s.volume.dims.x, 128);
    const IsoRun run = RunIso(t, programs, s, cam);
    for (int y = 0; y < cam.size; ++y)
      for (int x = 0; x < cam.size; ++x) {
        if (!run.ref.hit.at(x, y) || !GpuHit(run.frame, x, y)) continue;
        const glm::dvec3 pp = run.ref.p_prime[static_cast<size_t>(y) * cam.size + x];
        const core::DisplacedSample d = core::Displace(placed, pp);
        const glm::dvec3 n(run.frame.normal.at(x, y, 0), run.frame.normal.at(x, y, 1),
                           run.frame.normal.at(x, y, 2));
        const bool lit = glm::dot(n, light) > 0;
        const bool moved = glm::length(d.p - pp) > 0.02;
        if (elevation > 45 && moved && d.p.z < 0.44) {
          ++r.underside;
          r.underside_lit += lit;
        }
        if (elevation < 45 && !moved && std::abs(pp.x - 0.5) < 2 * voxel && pp.z > 0.39 &&
            pp.z < 0.49 && pp.y > 0.2 && pp.y < 0.8) {
          ++r.rim;
          r.rim_dark += !lit;
        }
      }
  }
  return r;
}

TEST_F(GlTest, VolumeFig4LightingAblationAsNumbers) {
  // Both ways of finding J_D and grad alpha (per sample or per texel) must
  // give the paper's figure.
  for (const auto& [l, j] :
       {std::pair{VolumeLighting::kGradient, VolumeJacobian::kPrecomputed},
        std::pair{VolumeLighting::kTransformed, VolumeJacobian::kPrecomputed},
        std::pair{VolumeLighting::kBlended, VolumeJacobian::kPrecomputed},
        std::pair{VolumeLighting::kTransformed, VolumeJacobian::kFiniteDifferences},
        std::pair{VolumeLighting::kBlended, VolumeJacobian::kFiniteDifferences}}) {
    const Fig4Numbers f = MeasureFig4(*this, programs(), l, j);
    const double lit = f.underside ? static_cast<double>(f.underside_lit) / f.underside : 0;
    const double dark = f.rim ? static_cast<double>(f.rim_dark) / f.rim : 0;
    std::printf(
        "Fig. 4 (%s, J_D %s): peeled underside N.L > 0 on %.1f%% of %lld px; dark rim %.1f%% of "
        "%lld px\n",
        VolumeLightingName(l).data(), VolumeJacobianName(j).data(), 100 * lit,
        static_cast<long long>(f.underside), 100 * dark, static_cast<long long>(f.rim));
    ASSERT_GT(f.underside, 300) << VolumeLightingName(l);
    ASSERT_GT(f.rim, 100) << VolumeLightingName(l);
    switch (l) {
      case VolumeLighting::kGradient:  // (b): the old normals face away from the light
        EXPECT_LT(lit, 0.1);
        break;
      case VolumeLighting::kTransformed:  // (c): underside lit, rim dark
        EXPECT_GE(lit, 0.95);
        EXPECT_GT(dark, 0.5);
        break;
      case VolumeLighting::kBlended:  // (d): both right
        EXPECT_GE(lit, 0.95);
        EXPECT_LE(dark, 0.05);
        break;
      case VolumeLighting::kNone:
        break;
    }
  }
  EXPECT_NO_GL_ERROR();
}

// Precomputed J_D with no lighting or the plain gradient reads no derivative
// textures: none are built, defined or bound. Switching the lighting to one
// that reads them builds them once, and the pass then draws what a pass built
// with that lighting draws.
TEST_F(GlTest, VolumeJacobianTexturesOnlyWhereTheLightingReadsThem) {
  const Scene gradient = PlateScene(VolumeLighting::kGradient, VolumeJacobian::kPrecomputed);
  const Scene blended = PlateScene(VolumeLighting::kBlended, VolumeJacobian::kPrecomputed);
  const auto defines_precomputed = [](const VolumePassOptions& o) {
    const std::vector<std::string> d = o.Defines(1);
    return std::find(d.begin(), d.end(), "VOLUME_JACOBIAN_PRECOMPUTED") != d.end();
  };
  EXPECT_FALSE(gradient.options.UsesJacobianTextures());
  EXPECT_FALSE(defines_precomputed(gradient.options));
  EXPECT_TRUE(blended.options.UsesJacobianTextures());
  EXPECT_TRUE(defines_precomputed(blended.options));
  const auto make = [&](const Scene& s) {
    return std::make_unique<VolumePass>(programs(), s.volume, s.transfer, s.maps,
                                        CentredWorldFromVolume(s.volume), s.options);
  };
  int64_t before = Texture::created_count();
  const auto built_blended = make(blended);
  const int64_t blended_textures = Texture::created_count() - before;
  before = Texture::created_count();
  const auto pass = make(gradient);
  const int64_t gradient_textures = Texture::created_count() - before;
  EXPECT_EQ(blended_textures - gradient_textures, 3) << "three derivative textures a map";

  const OrthoCamera cam = Ortho(-90, 70, 0.45 * gradient.volume.dims.x, 64);
  RenderFrame(*pass, cam.view, cam.size, cam.size);  // draws without them
  before = Texture::created_count();
  pass->SetOptions(blended.options);
  EXPECT_EQ(Texture::created_count() - before, 3);
  pass->SetOptions(gradient.options);
  pass->SetOptions(blended.options);
  EXPECT_EQ(Texture::created_count() - before, 3) << "built once";
  const Frame switched = RenderFrame(*pass, cam.view, cam.size, cam.size);
  const Frame built = RenderFrame(*built_blended, cam.view, cam.size, cam.size);
  EXPECT_GT(built.CountOutcome(OutcomeBit(RayOutcome::kHit)), 0);
  EXPECT_EQ(switched.color, built.color);
  EXPECT_EQ(switched.normal, built.normal);
  EXPECT_NO_GL_ERROR();
}

// ---- 6. hard cases: finite output over random configurations ----

TEST_F(GlTest, VolumeHardCaseSweepGivesOnlyFinitePixels) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto uniform = [&](double a, double b) { return a + (b - a) * u01(rng); };
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  constexpr int kConfigs = 200, kSize = 24;
  int64_t bad_pixels = 0, drawn_pixels = 0;
  for (int config = 0; config < kConfigs; ++config) {
    // A volume, possibly one voxel thick, with non-cubic spacing.
    glm::ivec3 dims(1 + pick(10), 1 + pick(10), 1 + pick(10));
    if (pick(4) == 0) dims[pick(3)] = 1;
    const auto type = static_cast<core::ScalarType>(pick(3));
    Scene s{SmoothRandomVolume(dims, type, static_cast<uint32_t>(config)), {}, {}, {}};
    s.volume.spacing = {uniform(0.2, 5), uniform(0.2, 5), uniform(0.2, 5)};
    const auto presets = core::TransferPresetNames();
    s.transfer =
        core::TransferPreset(presets[static_cast<size_t>(pick(static_cast<int>(presets.size())))]);
    // Maps: procedural effects with random parameters, or raw maps pointing
    // far out of the volume with masks of exactly 0, 0.5 and 1.
    const int map_count = pick(kMaxVolumeMaps + 1);
    for (int m = 0; m < map_count; ++m) {
      VolumeMapInput in;
      if (pick(2) == 0) {
        const K kinds[] = {K::kPeel, K::kSlices, K::kSeam, K::kPull, K::kWave};
        core::Deformation e = core::Deformation::Default(kinds[pick(5)]);
        if (e.kind == K::kPeel) e.amount = uniform(0, M_PI), e.width = uniform(0.01, 0.5);
        if (e.kind == K::kSlices) e.width = uniform(0.05, 1), e.amount = uniform(0, 0.99) * e.width;
        if (e.kind == K::kSeam) e.amount = uniform(0.01, 0.5), e.width = uniform(0.05, 1);
        if (e.kind == K::kPull) e.amount = 1, e.width = uniform(0.01, 1);
        if (e.kind == K::kWave) e.amount = uniform(-0.5, 0.5);
        in.map = core::SampleDeformationMap(e, {1 + pick(8), 1 + pick(8), 1 + pick(8)}, pick(3));
      } else {
        in.map.dims = {1 + pick(5), 1 + pick(5), 1 + pick(5)};
        const float alphas[] = {0.0f, 0.5f, 1.0f, static_cast<float>(u01(rng))};
        for (int i = 0; i < in.map.dims.x * in.map.dims.y * in.map.dims.z; ++i) {
          in.map.texels.push_back({static_cast<float>(uniform(-3, 3)),
                                   static_cast<float>(uniform(-3, 3)),
                                   static_cast<float>(uniform(-3, 3)), alphas[pick(4)]});
        }
      }
      const glm::dvec3 axis =
          glm::normalize(glm::dvec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) + 1e-3);
      in.placement = glm::scale(
          glm::rotate(glm::translate(glm::dmat4(1.0),
                                     glm::dvec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1))),
                      uniform(0, 6.3), axis),
          glm::dvec3(uniform(0.2, 2), uniform(0.2, 2), uniform(0.2, 2)));
      s.maps.push_back(std::move(in));
    }
    s.options.mode = pick(2) ? VolumeMode::kDvr : VolumeMode::kIso;
    s.options.iso_value = pick(5) == 0 ? 0.0 : u01(rng);
    s.options.sampling_distance_voxels = uniform(0.3, 3);
    s.options.displacement_bits = std::array{8, 16, 32}[static_cast<size_t>(pick(3))];
    s.options.lighting = static_cast<VolumeLighting>(pick(4));
    s.options.ray.max_steps = 512;
    const double radius = 0.5 * glm::length(s.volume.Extent());
    OrthoCamera cam = Ortho(uniform(0, 360), uniform(-89, 89), 2 * radius, kSize);
    if (pick(2) == 0) {
      // Perspective, sometimes from inside the proxy box.
      const double dist = uniform(0.3, 4) * radius;
      const glm::vec3 eye =
          static_cast<float>(dist) *
          glm::normalize(glm::vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) + 1e-3f);
      cam.view.cam_from_world =
          core::CamFromWorldLookAt(eye, {0, 0, 0}, glm::vec3(0, 0, 1) + 0.01f * eye);
      cam.view.clip_from_cam = core::ClipFromCamPerspective(
          kSize, kSize, kSize / 2.0, kSize / 2.0, kSize, kSize, 0.01 * radius, 20 * radius);
      cam.view.orthographic = false;
    }
    VolumePass pass(programs(), s.volume, s.transfer, s.maps, CentredWorldFromVolume(s.volume),
                    s.options);
    RenderTarget target(FloatFrameOptions(kSize));
    BeginFrame(target);
    pass.Draw(target, cam.view);
    const core::ImageF color = target.ReadColorF(kFrameColor);
    const core::ImageF z = target.ReadChannelsF(kFrameCameraZ, 1);
    const core::ImageF n = target.ReadChannelsF(kFrameNormal, 3);
    for (float v : color.values()) bad_pixels += !std::isfinite(v) || v < -1e-6f || v > 1 + 1e-4f;
    for (float v : z.values()) bad_pixels += !std::isfinite(v);
    for (float v : n.values()) bad_pixels += !std::isfinite(v) || std::abs(v) > 1.01f;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) drawn_pixels += color.at(x, y, 3) > 0;
  }
  std::printf(
      "hard-case sweep: %d configurations, %lld pixels drawn, %lld non-finite or out-of-range "
      "values\n",
      kConfigs, static_cast<long long>(drawn_pixels), static_cast<long long>(bad_pixels));
  EXPECT_EQ(bad_pixels, 0);
  EXPECT_GT(drawn_pixels, 1000);  // the sweep draws something
  EXPECT_NO_GL_ERROR();
}

TEST_F(GlTest, VolumePassRefusesBadInput) {
  const core::Volume v = BallVolume(4, 0.3, 2.0);
  VolumePassOptions o;
  o.sampling_distance_voxels = std::nan("");
  EXPECT_THROW(VolumePass(programs(), v, core::TransferPreset("ramp"), {}, glm::mat4(1.0f), o),
               core::InputError);
  VolumeMapInput nan_map;
  nan_map.map.dims = {1, 1, 1};
  nan_map.map.texels = {{std::nanf(""), 0, 0, 1}};
  EXPECT_THROW(
      VolumePass(programs(), v, core::TransferPreset("ramp"), {nan_map}, glm::mat4(1.0f), {}),
      core::InputError);
  // The floor shader reads at most one map (the displaced floor), no iso mode.
  VolumePassOptions floor_options;
  floor_options.floor_shader = true;
  VolumeMapInput identity;
  identity.map.dims = {1, 1, 1};
  identity.map.texels = {{0, 0, 0, 1}};
  EXPECT_THROW(VolumePass(programs(), v, core::TransferPreset("ramp"), {identity, identity},
                          glm::mat4(1.0f), floor_options),
               core::InputError);
  floor_options.mode = VolumeMode::kIso;
  EXPECT_THROW(floor_options.Check(), core::InputError);
  core::TransferFunction tf = core::TransferPreset("ramp");
  tf.points[1].rgba.a = std::nan("");
  EXPECT_THROW(VolumePass(programs(), v, tf, {}, glm::mat4(1.0f), {}), core::InputError);
  std::istringstream nan_json(R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, NaN]]})");
  EXPECT_THROW(core::ReadTransferFunction(nan_json, "tf.json"), core::InputError);
  std::istringstream nan_string(R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, "nan"]]})");
  EXPECT_THROW(core::ReadTransferFunction(nan_string, "tf.json"), core::InputError);
  std::istringstream ok(R"({"points": [[0, 0, 0, 0, 0], [0.5, 1, 0, 0, 0.2], [1, 1, 1, 1, 1]]})");
  EXPECT_EQ(core::ReadTransferFunction(ok, "tf.json").points.size(), 3u);
}

// A volume or map the GL cannot hold as a 3D texture is refused with the
// limit named, before anything is allocated (a side beyond
// GL_MAX_3D_TEXTURE_SIZE used to draw nothing without a word), and a sample
// texture beyond kMaxVolumeTextureBytes likewise (checked on dimensions
// alone: no such volume is made here).
TEST_F(GlTest, VolumeBeyondTheGlsTextureLimitsIsRefused) {
  const int limit = Max3dTextureSize();
  ASSERT_GE(limit, 256);  // GL 4.5 guarantees 2048
  const auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { CheckVolumeFits({limit, 2, 2}, {{limit, 1, 1}}, limit); }), "no error");
  EXPECT_NE(message([&] {
              CheckVolumeFits({limit + 1, 2, 2}, {}, limit);
            }).find("GL_MAX_3D_TEXTURE_SIZE"),
            std::string::npos);
  EXPECT_NE(message([&] {
              CheckVolumeFits({4, 4, 4}, {{2, limit + 1, 2}}, limit);
            }).find("displacement map"),
            std::string::npos);
  // 800^3 voxels: 7.6 GiB of texture, allowed; 1024^3: 16 GiB, refused.
  EXPECT_EQ(message([] { CheckVolumeFits({800, 800, 800}, {}, 4096); }), "no error");
  EXPECT_NE(message([] {
              CheckVolumeFits({1024, 1024, 1024}, {}, 4096);
            }).find("16 GiB"),
            std::string::npos);
  EXPECT_NE(message([] {
              CheckVolumeFits({0, 4, 4}, {}, 4096);
            }).find("0 x 4 x 4"),
            std::string::npos);
  // The pass itself, on a volume one voxel wider than the limit.
  const core::Volume wide = core::Volume::Zeros({limit + 1, 2, 2}, core::ScalarType::kUint8);
  EXPECT_NE(message([&] {
              VolumePass(programs(), wide, core::TransferPreset("ramp"), {}, glm::mat4(1.0f), {});
            }).find("GL_MAX_3D_TEXTURE_SIZE"),
            std::string::npos);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace render
