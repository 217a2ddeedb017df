#include "render/passes/volume_pass.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/check.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "render/gl/gl_state.h"
#include "render/gl/uniform.h"

namespace render {
namespace {

// The scalar and its gradient in one RGBA32F texture (rgb: the gradient per
// unit texture coordinate, core::GradientAtVoxel; a: the normalised scalar),
// so a shaded sample is one trilinear fetch, not two (on llvmpipe a fetch's
// fixed cost outweighs its texel width), and two bytes a voxel less. The
// price: the unshaded ablation Fig. 4 (a) reads the wider texel for its
// scalar alone (docs/decisions/volume-scalar-gradient-texture.md). Float
// filtering: within ~1e-6 of a double trilinear filter
// (tests/render/passes/volume_pass_test.cc), where llvmpipe filters 8-bit
// textures with 8-bit weights, far coarser.
Texture UploadSamples(const core::Volume& v) {
  // The RGBA32F texels here and the driver's copy of them (llvmpipe keeps
  // textures in system memory).
  core::CheckMemory(
      v.voxel_count() * 2 * sizeof(glm::vec4), "VolumePass",
      fmt::format("the {} x {} x {} volume's sample texture", v.dims.x, v.dims.y, v.dims.z));
  std::vector<glm::vec4> g(v.voxel_count());
  for (int z = 0; z < v.dims.z; ++z)
    for (int y = 0; y < v.dims.y; ++y)
      for (int x = 0; x < v.dims.x; ++x)
        g[v.Index(x, y, z)] = glm::vec4(glm::vec3(core::GradientAtVoxel(v, x, y, z)),
                                        static_cast<float>(v.Normalized(x, y, z)));
  Texture t = Texture::Create3DWithData(GL_RGBA32F, v.dims, GL_RGBA, GL_FLOAT, g.data());
  t.SetLinearFilter();
  return t;
}

// Bytes a channel of a map's texture takes: the stored bits, or 4 when
// uploaded dequantised (as_float).
int MapTextureChannelBytes(int bits, bool as_float) { return as_float ? 4 : bits / 8; }

Texture UploadMap(const core::StoredDisplacementMap& s, bool as_float) {
  Texture t;
  if (as_float && s.bits != 32) {
    const core::DisplacementMap d = core::DequantizeDisplacementMap(s);
    t = Texture::Create3DWithData(GL_RGBA32F, s.dims, GL_RGBA, GL_FLOAT, d.texels.data());
  } else if (s.bits == 32) {
    t = Texture::Create3DWithData(GL_RGBA32F, s.dims, GL_RGBA, GL_FLOAT, s.floats.data());
  } else if (s.bits == 16) {
    t = Texture::Create3DWithData(GL_RGBA16, s.dims, GL_RGBA, GL_UNSIGNED_SHORT, s.unorm.data());
  } else {
    const std::vector<uint8_t> bytes(s.unorm.begin(), s.unorm.end());
    t = Texture::Create3DWithData(GL_RGBA8, s.dims, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
    // MIRRORED_REPEAT reads as CLAMP_TO_EDGE wherever the shader fetches
    // (inside the map's cube, and half a texel beyond it for the central
    // differences), and keeps llvmpipe off its 8-bit filter path, which
    // interpolates with 8-bit weights (far off the dequantised picture at a
    // sharp cut): with it, RGBA8 filters as exactly as RGBA16 and RGBA32F
    // (docs/decisions/volume-map-precision.md).
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
      glTextureParameteri(t.id(), wrap, GL_MIRRORED_REPEAT);
  }
  t.SetLinearFilter();
  return t;
}

// The table the fragments read, opacities corrected for `exponent` (slice
// spacing / voxel), so no fragment computes a pow (a measurable share of a
// plain unshaded fragment's work: docs/decisions/volume-fragment-cost.md).
// Created once; the
// spacing changes with the view, and then only the 4 KiB of texels are
// rewritten in place (WriteTransfer), no new texture object.
void WriteTransfer(const Texture& texture, const std::vector<glm::vec4>& table, float exponent) {
  const std::vector<glm::vec4> corrected = core::OpacityCorrectedTable(table, exponent);
  glTextureSubImage1D(texture.id(), 0, 0, static_cast<GLsizei>(corrected.size()), GL_RGBA, GL_FLOAT,
                      corrected.data());
}

// The table as is: corrected for an exponent of 1, which leaves it unchanged
// (the first draw rewrites it for its spacing).
Texture UploadTransfer(const std::vector<glm::vec4>& table) {
  Texture t = Texture::Create1DWithData(GL_RGBA32F, static_cast<int>(table.size()), GL_RGBA,
                                        GL_FLOAT, table.data());
  t.SetLinearFilter();
  return t;
}

// J_D's columns and grad alpha of the map as the GPU sees it (dequantised),
// three RGBA32F textures: rgb = dD/du_k, a = dalpha/du_k. RGBA32F rather
// than RGBA16F: llvmpipe filters float texels without a conversion, so the
// wider texel is the cheaper fetch there, at twice the memory (12 MiB for a
// 64^3 map; docs/decisions/volume-map-precision.md).
std::vector<Texture> UploadMapDerivatives(const core::StoredDisplacementMap& s) {
  const core::MapDerivatives d = core::ComputeMapDerivatives(core::DequantizeDisplacementMap(s));
  std::vector<Texture> out;
  std::vector<glm::vec4> column(d.jacobian.size());
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < column.size(); ++i)
      column[i] = glm::vec4(d.jacobian[i][k], d.alpha_gradient[i][k]);
    Texture t = Texture::Create3DWithData(GL_RGBA32F, s.dims, GL_RGBA, GL_FLOAT, column.data());
    t.SetLinearFilter();
    out.push_back(std::move(t));
  }
  return out;
}

// Map i's uniforms in shaders/passes/volume_core.glsl (element i of each
// array; the derivatives are elements 3 i + k).
struct VolumeMapUniforms {
  VolumeMapUniforms() = default;
  VolumeMapUniforms(const Program& p, size_t i)
      : map(p, fmt::format("u_maps[{}]", i)),
        map_from_tex(p, fmt::format("u_map_from_tex[{}]", i)),
        tex_from_map(p, fmt::format("u_tex_from_map[{}]", i)),
        map_from_tex_linear(p, fmt::format("u_map_from_tex_linear[{}]", i)),
        scale(p, fmt::format("u_map_scale[{}]", i)),
        texel(p, fmt::format("u_map_texel[{}]", i)),
        active_lo(p, fmt::format("u_map_active_lo[{}]", i)),
        active_hi(p, fmt::format("u_map_active_hi[{}]", i)) {
    for (size_t k = 0; k < 3; ++k)
      derivatives[k] = Uniform<int>(p, fmt::format("u_map_derivatives[{}]", 3 * i + k));
  }
  Uniform<int> map;  // texture unit
  Uniform<glm::mat4> map_from_tex;
  Uniform<glm::mat3> tex_from_map;
  Uniform<glm::mat3> map_from_tex_linear;
  Uniform<float> scale;
  Uniform<glm::vec3> texel;
  Uniform<glm::vec3> active_lo;
  Uniform<glm::vec3> active_hi;
  std::array<Uniform<int>, 3> derivatives;  // texture units
};

// shaders/cores/slicing_core.glsl, passes/volume_core.glsl, volume_dvr.frag.glsl
// and volume_iso.frag.glsl: one struct for the DVR and iso programs (each
// lacks the other's uniforms, which stay inactive handles).
struct VolumeUniforms {
  explicit VolumeUniforms(const Program& p)
      : world_from_box(p, "u_world_from_box"),
        cam_from_world(p, "u_cam_from_world"),
        clip_from_cam(p, "u_clip_from_cam"),
        tex_from_proxy(p, "u_tex_from_proxy"),
        normal_world_from_tex(p, "u_normal_world_from_tex"),
        light_dir_world(p, "u_light_dir_world"),
        ambient(p, "u_ambient"),
        samples(p, "u_samples"),
        transfer(p, "u_transfer"),
        transfer_size(p, "u_transfer_size"),
        iso(p, "u_iso"),
        orthographic(p, "u_orthographic"),
        eye_in_box(p, "u_eye_in_box"),
        view_dir_in_box(p, "u_view_dir_in_box"),
        box_from_world_linear(p, "u_box_from_world_linear"),
        cam_from_box(p, "u_cam_from_box"),
        step_world(p, "u_step_world") {
    for (size_t i = 0; i < maps.size(); ++i) maps[i] = VolumeMapUniforms(p, i);
  }
  Uniform<glm::mat4> world_from_box;
  Uniform<glm::mat4> cam_from_world;
  Uniform<glm::mat4> clip_from_cam;
  Uniform<glm::mat4> tex_from_proxy;
  Uniform<glm::mat3> normal_world_from_tex;
  Uniform<glm::vec3> light_dir_world;
  Uniform<float> ambient;
  Uniform<int> samples;   // texture unit
  Uniform<int> transfer;  // texture unit
  std::array<VolumeMapUniforms, kMaxVolumeMaps> maps;
  // DVR
  Uniform<float> transfer_size;
  // Iso-surface
  Uniform<float> iso;
  Uniform<int> orthographic;  // GLSL bool
  Uniform<glm::vec3> eye_in_box;
  Uniform<glm::vec3> view_dir_in_box;
  Uniform<glm::mat4> box_from_world_linear;
  Uniform<glm::mat4> cam_from_box;
  Uniform<float> step_world;
};

// Texture units: 0 samples (gradient and scalar), 1 transfer function,
// 2 + i map i, 2 + kMaxVolumeMaps + 3 i + k derivative k of map i.
constexpr int kFirstMapUnit = 2;
constexpr int kFirstDerivativeUnit = kFirstMapUnit + kMaxVolumeMaps;

constexpr int kTransferSize = 256;

// VolumePass::support_box: every map's active box (map space) through its
// placement M (volume texture space) into proxy-box coordinates, bounded.
core::Box3 SupportBox(const std::vector<VolumeMapInput>& maps,
                      const std::vector<core::Box3>& active, const core::Box3& proxy_box) {
  core::Box3 support{glm::dvec3(1e300), glm::dvec3(-1e300)};
  for (size_t i = 0; i < maps.size(); ++i) {
    const core::Box3& b = active[i];
    if (b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z) continue;  // never read
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 u(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z);
      const glm::dvec3 tex(maps[i].placement * glm::dvec4(u, 1.0));
      const glm::dvec3 in_proxy = (tex - proxy_box.lo) / (proxy_box.hi - proxy_box.lo);
      support.lo = glm::min(support.lo, in_proxy);
      support.hi = glm::max(support.hi, in_proxy);
    }
  }
  return support;
}

}  // namespace

VolumeLighting VolumeLightingFromName(std::string_view name) {
  return core::EnumFromName(kVolumeLightingNames, name, "VolumeLightingFromName", "lighting");
}

std::string_view VolumeLightingName(VolumeLighting lighting) {
  return core::EnumToName(kVolumeLightingNames, lighting);
}

VolumeJacobian VolumeJacobianFromName(std::string_view name) {
  return core::EnumFromName(kVolumeJacobianNames, name, "VolumeJacobianFromName", "Jacobian");
}

std::string_view VolumeJacobianName(VolumeJacobian jacobian) {
  return core::EnumToName(kVolumeJacobianNames, jacobian);
}

void CheckVolumeFits(const glm::ivec3& dims, const std::vector<glm::ivec3>& map_dims,
                     int max_3d_texture_size) {
  const auto fits = [&](const glm::ivec3& d) {
    return d.x >= 1 && d.y >= 1 && d.z >= 1 && d.x <= max_3d_texture_size &&
           d.y <= max_3d_texture_size && d.z <= max_3d_texture_size;
  };
  if (!fits(dims)) {
    core::ThrowInputError("VolumePass",
                          "a volume of {} x {} x {} voxels; this GL implementation's 3D textures "
                          "are at most {} a side (GL_MAX_3D_TEXTURE_SIZE)",
                          dims.x, dims.y, dims.z, max_3d_texture_size);
  }
  const int64_t bytes = int64_t{16} * dims.x * dims.y * dims.z;
  if (bytes > kMaxVolumeTextureBytes) {
    core::ThrowInputError("VolumePass",
                          "a volume of {} x {} x {} voxels needs a {} GiB sample texture (16 bytes "
                          "a voxel), more than the {} GiB allowed",
                          dims.x, dims.y, dims.z, bytes >> 30, kMaxVolumeTextureBytes >> 30);
  }
  for (const glm::ivec3& d : map_dims) {
    if (!fits(d)) {
      core::ThrowInputError("VolumePass",
                            "a displacement map of {} x {} x {} texels; this GL implementation's "
                            "3D textures are at most {} a side (GL_MAX_3D_TEXTURE_SIZE)",
                            d.x, d.y, d.z, max_3d_texture_size);
    }
  }
}

int Max3dTextureSize() {
  GLint size = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &size);
  return size;
}

void VolumePassOptions::Check() const {
  if (!std::isfinite(iso_value) || iso_value < 0 || iso_value > 1) {
    core::ThrowInputError("VolumePassOptions", "iso value {} not in [0, 1]", iso_value);
  }
  if (!std::isfinite(sampling_distance_voxels) || sampling_distance_voxels < 0.05 ||
      sampling_distance_voxels > 64) {
    core::ThrowInputError("VolumePassOptions", "sampling distance {} voxels not in [0.05, 64]",
                          sampling_distance_voxels);
  }
  if (displacement_bits != 8 && displacement_bits != 16 && displacement_bits != 32) {
    core::ThrowInputError("VolumePassOptions", "displacement bits {} (8, 16 or 32)",
                          displacement_bits);
  }
  if (!std::isfinite(ambient) || ambient < 0 || ambient > 1) {
    core::ThrowInputError("VolumePassOptions", "ambient {} not in [0, 1]", ambient);
  }
  if (!(glm::length(light_dir_world) > 0) || !std::isfinite(glm::length(light_dir_world))) {
    core::ThrowInputError("VolumePassOptions", "light direction must be finite and non-zero");
  }
  if (brick_texels < 0 || brick_texels > 1024) {
    core::ThrowInputError("VolumePassOptions", "brick size {} texels not in [0, 1024]",
                          brick_texels);
  }
  if (floor_shader && mode != VolumeMode::kDvr) {
    core::ThrowInputError("VolumePassOptions", "the floor shader is a DVR shader");
  }
  ray.Check();
}

std::vector<std::string> VolumePassOptions::Defines(int map_count) const {
  std::vector<std::string> d = {fmt::format("VOLUME_MAPS {}", map_count)};
  if (displacement_bits == 32 || float_map_textures) d.push_back("VOLUME_MAPS_FLOAT");
  switch (lighting) {
    case VolumeLighting::kNone:
      d.push_back("VOLUME_LIGHT_NONE");
      break;
    case VolumeLighting::kGradient:
      d.push_back("VOLUME_LIGHT_GRADIENT");
      break;
    case VolumeLighting::kTransformed:
      d.push_back("VOLUME_LIGHT_TRANSFORMED");
      break;
    case VolumeLighting::kBlended:
      d.push_back("VOLUME_LIGHT_BLENDED");
      break;
  }
  if (UsesJacobianTextures()) d.push_back("VOLUME_JACOBIAN_PRECOMPUTED");
  if (floor_shader) d.push_back("VOLUME_DVR_FLOOR");
  if (mode == VolumeMode::kIso) {
    for (const std::string& r : RayCoreDefines(ray)) d.push_back(r);
  }
  return d;
}

core::Box3 VolumeProxyBox(const std::vector<VolumeMapInput>& maps) {
  std::vector<core::PlacedMap> placed;
  for (const auto& m : maps) placed.push_back({&m.map, m.placement, {}});
  return core::ProxyBox({glm::dvec3(0.0), glm::dvec3(1.0)}, placed);
}

glm::mat4 TexFromProxy(const core::Box3& proxy_box) {
  const glm::vec3 lo(proxy_box.lo), hi(proxy_box.hi);
  return glm::scale(glm::translate(glm::mat4(1.0f), lo), hi - lo);
}

VolumePass::VolumePass(ProgramCache& programs, const core::Volume& volume,
                       const core::TransferFunction& transfer, std::vector<VolumeMapInput> maps,
                       const glm::mat4& world_from_volume, const VolumePassOptions& options)
    : programs_(&programs),
      options_(options),
      dims_(volume.dims),
      world_from_volume_(world_from_volume),
      maps_(std::move(maps)) {
  options_.Check();
  transfer.Check("VolumePass");
  if (volume.bytes.size() != volume.voxel_count() * core::BytesPerScalar(volume.type) ||
      volume.bytes.empty()) {
    core::ThrowInputError("VolumePass", "volume data size does not match its dimensions");
  }
  CheckMaps(maps_);
  // World length of one voxel along the smallest-spacing axis.
  const glm::mat3 lin(world_from_volume_);
  voxel_world_ = 1e30;
  for (int a = 0; a < 3; ++a)
    voxel_world_ = std::min(voxel_world_, static_cast<double>(glm::length(lin[a])) / dims_[a]);

  if (options_.floor_shader && maps_.size() > 1) {
    core::ThrowInputError("VolumePass", "the floor shader reads at most one displacement map");
  }
  proxy_box_ = VolumeProxyBox(maps_);
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_texture_units_);

  sample_texture_ = UploadSamples(volume);
  transfer_table_ = transfer.Table(kTransferSize);
  transfer_texture_ = UploadTransfer(transfer_table_);  // transfer_exponent_ = 1
  SetOptions(options_);

  // The unit cube's 12 triangles (iso mode; orientation does not matter, the
  // shader keeps the exit faces).
  std::vector<glm::vec3> cube;
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  auto corner = [](int c) { return glm::vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1); };
  for (const auto& f : faces) {
    for (int k : {0, 1, 2, 0, 2, 3}) cube.push_back(corner(f[k]));
  }
  GLuint id = 0;
  glCreateBuffers(1, &id);
  box_vertices_ = Buffer(id);
  glNamedBufferStorage(box_vertices_.id(), static_cast<GLsizeiptr>(cube.size() * sizeof(glm::vec3)),
                       cube.data(), 0);
  glCreateVertexArrays(1, &id);
  box_vao_ = VertexArray(id);
  glVertexArrayVertexBuffer(box_vao_.id(), 0, box_vertices_.id(), 0, sizeof(glm::vec3));
  glEnableVertexArrayAttrib(box_vao_.id(), 0);
  glVertexArrayAttribFormat(box_vao_.id(), 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(box_vao_.id(), 0, 0);
}

void VolumePass::CheckMaps(const std::vector<VolumeMapInput>& maps) const {
  if (maps.size() > static_cast<size_t>(kMaxVolumeMaps)) {
    core::ThrowInputError("VolumePass", "{} displacement maps, at most {} compose in one pass",
                          maps.size(), kMaxVolumeMaps);
  }
  std::vector<glm::ivec3> map_dims;
  for (const auto& m : maps) map_dims.push_back(m.map.dims);
  CheckVolumeFits(dims_, map_dims, Max3dTextureSize());
  for (const auto& m : maps) {
    if (std::abs(glm::determinant(glm::dmat3(m.placement))) < 1e-12) {
      core::ThrowInputError("VolumePass", "a displacement map placement is singular");
    }
    for (const auto& t : m.map.texels) {
      if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z) ||
          !std::isfinite(t.w)) {
        core::ThrowInputError("VolumePass", "a displacement map holds NaN or Inf");
      }
    }
  }
}

void VolumePass::SetMaps(std::vector<VolumeMapInput> maps) {
  CheckMaps(maps);
  if (options_.floor_shader && maps.size() > 1) {
    core::ThrowInputError("VolumePass", "the floor shader reads at most one displacement map");
  }
  std::swap(maps_, maps);
  const int needed = TextureUnitsNeeded(options_);
  if (needed > max_texture_units_) {
    std::swap(maps_, maps);  // unchanged
    core::ThrowInputError("VolumePass",
                          "{} displacement maps need {} texture units, GL_MAX_TEXTURE_IMAGE_UNITS "
                          "is {}",
                          maps.size(), needed, max_texture_units_);
  }
  proxy_box_ = VolumeProxyBox(maps_);
  maps_changed_ = true;
  SetOptions(options_);
}

void VolumePass::SetTransferFunction(const core::TransferFunction& transfer) {
  transfer.Check("VolumePass::SetTransferFunction");
  if (transfer.units != core::TransferUnits::kNormalized) {
    core::ThrowInputError("VolumePass::SetTransferFunction",
                          "the function is in data units (core::NormalizedTransfer first)");
  }
  transfer_table_ = transfer.Table(kTransferSize);
  WriteTransfer(transfer_texture_, transfer_table_, transfer_exponent_);
}

int VolumePass::TextureUnitsNeeded(const VolumePassOptions& options) const {
  const int maps = static_cast<int>(maps_.size());
  if (maps == 0) return kFirstMapUnit;
  if (options.UsesJacobianTextures()) return kFirstDerivativeUnit + 3 * maps;
  return kFirstMapUnit + maps;
}

void VolumePass::SetOptions(const VolumePassOptions& options) {
  options.Check();
  // A portability guard: the units are laid out for kMaxVolumeMaps maps, and
  // four maps with per-texel Jacobians reach unit 17.
  if (TextureUnitsNeeded(options) > max_texture_units_) {
    core::ThrowInputError("VolumePass",
                          "{} displacement maps with lighting '{}' and Jacobian '{}' need {} "
                          "texture units, GL_MAX_TEXTURE_IMAGE_UNITS is {}",
                          maps_.size(), VolumeLightingName(options.lighting),
                          VolumeJacobianName(options.jacobian), TextureUnitsNeeded(options),
                          max_texture_units_);
  }
  const bool restore = maps_changed_ || stored_.size() != maps_.size() ||
                       options.displacement_bits != options_.displacement_bits ||
                       options.float_map_textures != options_.float_map_textures;
  const bool resplit = restore || options.brick_texels != options_.brick_texels ||
                       options.support_skip != options_.support_skip;
  options_ = options;
  if (restore) {
    stored_.clear();
    active_.clear();
    map_textures_.clear();
    derivative_textures_.clear();
    for (const auto& m : maps_) {
      stored_.push_back(core::StoreDisplacementMap(m.map, options_.displacement_bits));
      active_.push_back(core::ActiveBox(stored_.back()));
      map_textures_.push_back(UploadMap(stored_.back(), options_.float_map_textures));
    }
    support_ = SupportBox(maps_, active_, proxy_box_);
    maps_changed_ = false;
  }
  if (resplit) {
    // How DrawDvr splits its slices, labelled by core::MapBrickKind: one
    // map's bricks (map space), or the support box (proxy-box coordinates:
    // inside displaced, outside the identity); none without support_skip.
    splitter_.reset();
    if (options_.support_skip && !maps_.empty()) {
      constexpr double kOnPlane = 1e-6;  // tree units: no sliver parts
      const int identity = static_cast<int>(core::MapBrickKind::kIdentity);
      if (maps_.size() == 1 && options_.brick_texels > 0) {
        const core::MapBricks b = core::ClassifyMapBricks(stored_[0], options_.brick_texels);
        std::array<std::vector<double>, 3> edges;
        for (int a = 0; a < 3; ++a) {
          for (int i = 0; i <= b.grid[a]; ++i) edges[a].push_back(b.Edge(a, i));
        }
        std::vector<uint8_t> labels(b.kinds.size());
        for (size_t i = 0; i < labels.size(); ++i) labels[i] = static_cast<uint8_t>(b.kinds[i]);
        const glm::dmat4 map_from_box =
            glm::inverse(maps_[0].placement) * glm::dmat4(TexFromProxy(proxy_box_));
        splitter_.emplace(BoxTreeOfGrid(b.grid, labels, edges, identity), map_from_box, kOnPlane);
      } else if (support_.lo.x <= support_.hi.x) {
        splitter_.emplace(BoxTreeOfBox(support_.lo, support_.hi,
                                       static_cast<int>(core::MapBrickKind::kDisplaced), identity),
                          glm::dmat4(1.0), kOnPlane);
      } else {  // no map moves anything
        splitter_.emplace(BoxTree{{BoxTree::Node{.label = identity}}}, glm::dmat4(1.0), kOnPlane);
      }
    }
  }
  // The derivative textures only when these options read them, built the
  // first time they do (and again after the maps were re-stored).
  if (options_.UsesJacobianTextures() && derivative_textures_.size() != 3 * maps_.size()) {
    derivative_textures_.clear();
    for (const auto& s : stored_) {
      for (Texture& t : UploadMapDerivatives(s)) derivative_textures_.push_back(std::move(t));
    }
  }
}

int64_t VolumePass::map_texture_bytes() const {
  int64_t bytes = 0;
  for (const core::StoredDisplacementMap& s : stored_) {
    const int64_t texels = int64_t{s.dims.x} * s.dims.y * s.dims.z;
    bytes += texels * 4 * MapTextureChannelBytes(s.bits, options_.float_map_textures);
  }
  return bytes;
}

int64_t VolumePass::derivative_texture_bytes() const {
  int64_t bytes = 0;
  for (size_t i = 0; i < derivative_textures_.size(); ++i) {
    const glm::ivec3 d = stored_[i / 3].dims;
    bytes += int64_t{d.x} * d.y * d.z * static_cast<int64_t>(sizeof(glm::vec4));
  }
  return bytes;
}

glm::mat4 VolumePass::world_from_proxy() const {
  return world_from_volume_ * TexFromProxy(proxy_box_);
}

void VolumePass::SetCommonUniforms(const Program& program, const ViewSetup& view) const {
  const auto& u = program.Typed<VolumeUniforms>();
  u.world_from_box.Set(world_from_proxy());
  u.cam_from_world.Set(view.cam_from_world);
  u.clip_from_cam.Set(view.clip_from_cam);
  u.tex_from_proxy.Set(TexFromProxy(proxy_box_));
  u.normal_world_from_tex.Set(glm::transpose(glm::inverse(glm::mat3(world_from_volume_))));
  u.light_dir_world.Set(glm::normalize(options_.light_dir_world));
  u.ambient.Set(options_.ambient);
  u.samples.Set(0);
  u.transfer.Set(1);
  glBindTextureUnit(0, sample_texture_.id());
  glBindTextureUnit(1, transfer_texture_.id());
  for (size_t i = 0; i < maps_.size(); ++i) {
    const VolumeMapUniforms& m = u.maps[i];
    const glm::mat3 a(glm::mat4(maps_[i].placement));
    const int unit = kFirstMapUnit + static_cast<int>(i);
    m.map.Set(unit);
    m.map_from_tex.Set(glm::mat4(glm::inverse(maps_[i].placement)));
    m.tex_from_map.Set(a);
    m.map_from_tex_linear.Set(glm::inverse(a));
    m.scale.Set(stored_[i].scale);
    m.texel.Set(1.0f / glm::vec3(maps_[i].map.dims));
    m.active_lo.Set(glm::vec3(active_[i].lo));
    m.active_hi.Set(glm::vec3(active_[i].hi));
    glBindTextureUnit(static_cast<GLuint>(unit), map_textures_[i].id());
    if (options_.UsesJacobianTextures()) {
      for (size_t k = 0; k < 3; ++k) {
        const auto derivative_unit = static_cast<int>(kFirstDerivativeUnit + 3 * i + k);
        m.derivatives[k].Set(derivative_unit);
        glBindTextureUnit(static_cast<GLuint>(derivative_unit),
                          derivative_textures_[3 * i + k].id());
      }
    }
  }
}

void VolumePass::Draw(const RenderTarget& target, const ViewSetup& view) {
  if (options_.mode == VolumeMode::kDvr) {
    DrawDvr(target, view);
  } else {
    DrawIso(target, view);
  }
}

SlicingOptions VolumePass::DvrSlicing(const ViewSetup& view) const {
  // Screen slices at the sampling distance: count from the proxy's depth range.
  const glm::mat4 world_from_box = world_from_proxy();
  float z_min = 1e30f, z_max = -1e30f;
  for (int c = 0; c < 8; ++c) {
    const glm::vec4 p =
        view.cam_from_world * world_from_box * glm::vec4(c & 1, (c >> 1) & 1, (c >> 2) & 1, 1);
    z_min = std::min(z_min, p.z);
    z_max = std::max(z_max, p.z);
  }
  const double spacing = options_.sampling_distance_voxels * voxel_world_;
  SlicingOptions slicing;
  slicing.family = SliceFamily::kScreen;
  slicing.order = SliceOrder::kBackToFront;
  slicing.count = std::clamp(static_cast<int>(std::ceil((z_max - z_min) / spacing)), 1, 1 << 16);
  return slicing;
}

namespace {

// Projected area (pixels) of a polygon in box coordinates.
double ProjectedArea(const std::vector<glm::vec3>& polygon, const glm::mat4& clip_from_box,
                     int width, int height) {
  std::vector<glm::dvec2> px;
  for (const glm::vec3& v : polygon) {
    const glm::vec4 c = clip_from_box * glm::vec4(v, 1.0f);
    px.push_back({(c.x / c.w * 0.5 + 0.5) * width, (c.y / c.w * 0.5 + 0.5) * height});
  }
  double twice_area = 0;
  for (size_t i = 0; i < px.size(); ++i) {
    const glm::dvec2& a = px[i];
    const glm::dvec2& b = px[(i + 1) % px.size()];
    twice_area += a.x * b.y - b.x * a.y;
  }
  return 0.5 * std::abs(twice_area);
}

// Consecutive slice parts drawn by one program.
struct PartRun {
  bool displaced;
  int first, count;
};

}  // namespace

void VolumePass::DrawDvr(const RenderTarget& target, const ViewSetup& view) {
  const SliceStack stack =
      MakeSlices(SliceBox{world_from_proxy()}, SliceView{view.cam_from_world, view.orthographic},
                 DvrSlicing(view));
  stats_ = {};
  stats_.slices = static_cast<int>(stack.slices.size());
  stats_.slice_spacing_world = stack.spacing_world;
  // Rasterised area of the slices (pixels): the fragments the slices cost.
  const glm::mat4 clip_from_box = view.clip_from_cam * view.cam_from_world * world_from_proxy();
  for (const Slice& slice : stack.slices) {
    stats_.proxy_area_px +=
        ProjectedArea(slice.p_in_box, clip_from_box, target.width(), target.height());
  }

  // The slices split by splitter_ (support_skip), or whole and all
  // displaced. Within a slice the parts are disjoint, so their order is free:
  // the parts of the last run's program come first in the next slice, which
  // halves the program changes.
  std::vector<PartRun> runs;
  const bool split = splitter_.has_value();
  if (split) {
    SliceStack parts;
    for (const Slice& slice : stack.slices) {
      std::vector<SlicePart> pieces = splitter_->Split(slice.p_in_box);
      const bool last_displaced = !runs.empty() && runs.back().displaced;
      std::stable_partition(pieces.begin(), pieces.end(), [&](const SlicePart& p) {
        return (p.label == static_cast<int>(core::MapBrickKind::kDisplaced)) == last_displaced;
      });
      for (SlicePart& piece : pieces) {
        const auto kind = static_cast<core::MapBrickKind>(piece.label);
        const double area =
            ProjectedArea(piece.p_in_box, clip_from_box, target.width(), target.height());
        if (kind == core::MapBrickKind::kCut) {  // transparent throughout: not drawn
          stats_.cut_area_px += area;
          continue;
        }
        const bool displaced = kind == core::MapBrickKind::kDisplaced;
        if (displaced) stats_.displaced_area_px += area;
        if (runs.empty() || runs.back().displaced != displaced) {
          runs.push_back({displaced, static_cast<int>(parts.slices.size()), 0});
        }
        ++runs.back().count;
        parts.slices.push_back(Slice{std::move(piece.p_in_box), slice.offset_in_box});
      }
    }
    stats_.parts = static_cast<int>(parts.slices.size());
    slices_.Upload(parts);
  } else {
    slices_.Upload(stack);
    runs.push_back({true, 0, static_cast<int>(stack.slices.size())});
    stats_.parts = static_cast<int>(stack.slices.size());
    stats_.displaced_area_px = maps_.empty() ? 0 : stats_.proxy_area_px;
  }

  // The displaced program and, when slices are split, the one without maps
  // (the same options otherwise: VOLUME_MAPS 0 is the identity displacement).
  ProgramDesc desc{.vertex = "cores/slice.vert.glsl", .fragment = "passes/volume_dvr.frag.glsl"};
  desc.defines = options_.Defines(static_cast<int>(maps_.size()));
  const Program& displaced_program = programs_->Get(desc);
  desc.defines = options_.Defines(0);
  const Program* plain_program = split ? &programs_->Get(desc) : nullptr;
  // The opacity correction is in the table (rewritten, 4 KiB, when the
  // spacing changes with the view).
  const auto exponent = static_cast<float>(stack.spacing_world / voxel_world_);
  if (exponent != transfer_exponent_) {
    transfer_exponent_ = exponent;
    WriteTransfer(transfer_texture_, transfer_table_, transfer_exponent_);
  }
  target.Bind();
  for (const Program* program : {&displaced_program, plain_program}) {
    if (!program) continue;
    SetCommonUniforms(*program, view);
    program->Typed<VolumeUniforms>().transfer_size.Set(static_cast<float>(kTransferSize));
  }

  // Translucent slices: depth-tested against what is in the frame, no depth
  // writes, premultiplied back-to-front blending into the colour attachment
  // only (camera z and normal masked; the outcome attachment is masked by
  // BeginFrame).
  GlState state;
  state.depth_write = false;
  state.blend = BlendState{GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA};
  const ScopedGlState scoped(state);
  for (GLuint i : {kFrameCameraZ, kFrameNormal})
    glColorMaski(i, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  // One draw per run of parts (the whole stack when nothing is split): GL
  // blends a draw's primitives in the order they are given, so back to front
  // holds; per-slice draws cost llvmpipe a fixed setup each (ibr bench
  // volume, profile rows).
  slices_.Bind();
  for (const PartRun& run : runs) {
    (run.displaced ? displaced_program : *plain_program).Use();
    if (options_.draw_per_slice) {
      for (int i = run.first; i < run.first + run.count; ++i) slices_.DrawSlice(i);
      stats_.draw_calls += run.count;
    } else {
      slices_.DrawSlices(run.first, run.count);
      ++stats_.draw_calls;
    }
  }
  slices_.Unbind();
  for (GLuint i : {kFrameCameraZ, kFrameNormal})
    glColorMaski(i, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void VolumePass::DrawIso(const RenderTarget& target, const ViewSetup& view) {
  const glm::mat4 world_from_box = world_from_proxy();
  const glm::mat4 box_from_world = glm::inverse(world_from_box);
  ProgramDesc desc{.vertex = "cores/slice.vert.glsl", .fragment = "passes/volume_iso.frag.glsl"};
  desc.defines = options_.Defines(static_cast<int>(maps_.size()));
  const Program& program = programs_->Get(desc);
  target.Bind();
  program.Use();
  SetCommonUniforms(program, view);
  SetRayCoreUniforms(program, options_.ray);
  const auto& u = program.Typed<VolumeUniforms>();
  u.iso.Set(static_cast<float>(options_.iso_value));
  u.orthographic.Set(view.orthographic ? 1 : 0);
  const glm::mat4 world_from_cam = glm::inverse(view.cam_from_world);
  const glm::vec3 eye_world(world_from_cam[3]);
  const glm::vec3 forward_world = glm::normalize(glm::vec3(world_from_cam[2]));
  u.eye_in_box.Set(glm::vec3(box_from_world * glm::vec4(eye_world, 1.0f)));
  u.view_dir_in_box.Set(glm::vec3(box_from_world * glm::vec4(forward_world, 0.0f)));
  glm::mat4 linear = box_from_world;
  linear[3] = glm::vec4(0, 0, 0, 1);
  u.box_from_world_linear.Set(linear);
  u.cam_from_box.Set(view.cam_from_world * world_from_box);
  u.step_world.Set(static_cast<float>(options_.sampling_distance_voxels * voxel_world_));
  const ScopedGlState scoped(GlState{});  // depth test LESS with writes (gl_FragDepth)
  BindOutcomeImage(target);               // every ray ORs its outcome, discarded ones too
  glBindVertexArray(box_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 36);
  glBindVertexArray(0);
}

}  // namespace render
