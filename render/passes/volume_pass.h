// Direct volume rendering with discontinuous displacement maps (Correa,
// Silver, Chen 2006), and an isosurface mode.
//
// DVR (sec. 4.2): the proxy box (the volume's box grown by the placed maps,
// core::ProxyBox) is cut into screen-space slices by the slicing core
// (MakeSlices, screen family, back to front); each fragment p' is displaced
// through every map in one pass (eq. 9, 10), the cut mask discards alpha < 0.5
// and modulates the rest, the volume is sampled at p = p' + D(p'), classified
// by the 1D transfer function, its table's opacities corrected for the slice
// spacing (1 - (1 - a)^(spacing / voxel), core::OpacityCorrectedTable,
// re-uploaded when the spacing changes) and composited premultiplied
// (ONE, ONE_MINUS_SRC_ALPHA). The slices are depth-tested (LESS) against the
// frame's depth buffer and write no depth, so opaque objects drawn before
// hide what lies behind them.
//
// Iso (first hit at an iso value): the proxy box's back faces start one ray
// per pixel through the shared ray core (shaders/cores/ray_core.glsl supplies the
// march; this pass supplies RayField = iso - density(displaced p'), > 0
// empty); hits write colour, camera z, outcome flags and gl_FragDepth.
//
// Normals (sec. 4.3; the Fig. 4 ablation as VolumeLighting): the precomputed
// gradient volume, transformed by (I + J_D)^T (eq. 6, J_D by central
// differences of the map texture at half a texel, chained over maps), blended
// towards the cut mask's gradient near cuts (eq. 7, w from the smoothed mask).
//
// Frames: volume texture space t in [0,1]^3 (the volume's texture
// coordinates), world = world_from_volume * t. Maps are placed in t (eq. 10).
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"
#include "core/transfer_function.h"
#include "core/volume.h"
#include "core/volume_displacement.h"
#include "render/cores/ray_core.h"
#include "render/cores/slice_buffer.h"
#include "render/cores/slicing.h"
#include "render/gl/handles.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"

namespace render {

enum class VolumeMode { kDvr, kIso };

// Fig. 4 of the paper: (a) no lighting, (b) the precomputed gradient as is,
// (c) transformed by (I + J_D)^T (eq. 6), (d) (c) blended with the cut
// mask's gradient at discontinuities (eq. 7).
enum class VolumeLighting { kNone, kGradient, kTransformed, kBlended };
inline constexpr core::EnumName<VolumeLighting> kVolumeLightingNames[] = {
    {VolumeLighting::kNone, "none"},
    {VolumeLighting::kGradient, "gradient"},
    {VolumeLighting::kTransformed, "transformed"},
    {VolumeLighting::kBlended, "blended"},
};
static_assert(core::EnumNamesUnique(kVolumeLightingNames));
VolumeLighting VolumeLightingFromName(std::string_view name);  // none|gradient|transformed|blended
std::string_view VolumeLightingName(VolumeLighting lighting);

// How J_D (eq. 6) and the mask's gradient (eq. 7) are found per sample:
// precomputed per map texel (sec. 4.3.1; three RGBA32F textures a map, three
// filtered fetches a sample) or central differences of the map at half a
// texel (six fetches a sample, no extra memory).
enum class VolumeJacobian { kPrecomputed, kFiniteDifferences };
inline constexpr core::EnumName<VolumeJacobian> kVolumeJacobianNames[] = {
    {VolumeJacobian::kPrecomputed, "precomputed"},
    {VolumeJacobian::kFiniteDifferences, "differences"},
};
static_assert(core::EnumNamesUnique(kVolumeJacobianNames));
VolumeJacobian VolumeJacobianFromName(std::string_view name);  // precomputed|differences
std::string_view VolumeJacobianName(VolumeJacobian jacobian);

// Most maps one pass composes (eq. 9); a shader variant per count.
inline constexpr int kMaxVolumeMaps = 4;

// Most bytes of a volume's sample texture (RGBA32F, 16 a voxel, staged on the
// host before the upload): 8 GiB, 512 M voxels (800^3).
inline constexpr int64_t kMaxVolumeTextureBytes = int64_t{8} << 30;
// InputError("VolumePass: ...") unless a volume of `dims` and maps of
// `map_dims` fit: every side within `max_3d_texture_size` (the context's
// GL_MAX_3D_TEXTURE_SIZE, 2048 on llvmpipe, where a larger texture is not
// created and DVR drew nothing without a word) and the sample texture within
// kMaxVolumeTextureBytes. VolumePass checks it before allocating anything;
// callers that read files check it first to name the file.
void CheckVolumeFits(const glm::ivec3& dims, const std::vector<glm::ivec3>& map_dims,
                     int max_3d_texture_size);
// GL_MAX_3D_TEXTURE_SIZE of the current context.
int Max3dTextureSize();

struct VolumePassOptions {
  VolumeMode mode = VolumeMode::kDvr;
  // Iso mode: the iso value on the normalised scalar (what the texture
  // returns, [0, 1]).
  double iso_value = 0.5;
  // Slice spacing (DVR) or ray step (iso) in voxels of the smallest spacing
  // axis; 1 = Table 1's d = 1.0.
  double sampling_distance_voxels = 1.0;
  // How the maps are stored on the GPU: 8 or 16 bits (scale and bias, sec. 4
  // and 8) or 32-bit float.
  int displacement_bits = 16;
  // Off (default): 8/16-bit maps stay 8/16-bit on the GPU, RGBA8 / RGBA16
  // UNORM textures with the scale and bias applied in the shader (Correa
  // 2006 sec. 8, Table 2: a quarter / half of RGBA32F's memory). The same
  // picture as the dequantised upload within float rounding
  // (tests/render/passes/volume_pass_test.cc). On: dequantised once on the
  // CPU and uploaded as RGBA32F (the bench's baseline;
  // docs/decisions/volume-map-precision.md).
  bool float_map_textures = false;
  VolumeLighting lighting = VolumeLighting::kBlended;
  // Precomputed by default: the cheaper per sample (ibr bench volume).
  VolumeJacobian jacobian = VolumeJacobian::kPrecomputed;
  // DVR: one draw call per slice instead of one for the whole stack (the
  // same pixels, GL keeps primitive order for blending). For the bench's
  // profile of the per-draw overhead only.
  bool draw_per_slice = false;
  // DVR: each slice fragment does only what the fill-rate floor's does
  // (render/gl/fill_rate.h, Work::kVolumeBlend): one lookup of the scalar,
  // the transfer function, premultiplied output; no lighting and no discard
  // (a transparent fragment blends zero). Without maps the picture is plain
  // unshaded DVR's. With one map (Work::kDisplacedVolumeBlend's work): one
  // map fetch, the scalar read where it points, no mask and no identity
  // outside the map's active box, so not the displaced picture: the least a
  // displaced fragment does, on the frame's own slices. For the bench only
  // (ibr bench volume's floor rows), against the same work on full-screen
  // layers and against the eq. 6+7 frame.
  bool floor_shader = false;
  // DVR with maps: each slice is split on the CPU by the maps' support box
  // (VolumePass::support_box: outside it every map is the identity) into the
  // part inside, drawn by the displaced shader, and up to six parts outside,
  // drawn by the shader without maps (same transfer function, opacity
  // correction and lighting; the parts of a slice are disjoint and drawn
  // before the next slice, so the blending is unchanged). Off: every slice
  // fragment runs the displaced shader, which skips the fetches outside each
  // map's active box by a branch (the baseline of ibr bench volume).
  bool support_skip = true;
  // With support_skip and exactly one map: the part inside the support box
  // is split further by the map's bricks of this many texels a side
  // (core::ClassifyMapBricks, merged into boxes by render::BoxTreeOfGrid):
  // bricks where the map is the identity are drawn by the shader without
  // maps too, bricks it cuts away entirely (alpha < 0.5 at every sample) are
  // not drawn, the rest displaced. 0: the support box only. Several maps
  // compose (eq. 9: only the last reads p' itself), so they are split by the
  // support box only. Smaller bricks hug the cut more closely but add parts
  // (draws and T-junction seams), larger ones displace more identity texels;
  // 3 is the size `ibr bench volume`'s brick rows (2, 3, 4, 8) favour
  // (docs/decisions/brick-splitting.md).
  int brick_texels = 3;
  // Direction TOWARDS the light, world frame (normalised on use). Default:
  // from above (+z), as in Fig. 4.
  glm::vec3 light_dir_world{0.0f, 0.0f, 1.0f};
  float ambient = 0.3f;  // fraction of the colour lit without the light
  // Iso mode: linear-search steps beyond the box diagonal / step are capped here.
  RayCoreOptions ray{.max_steps = 4096, .refine_steps = 10};

  void Check() const;  // InputError on bad values
  bool operator==(const VolumePassOptions&) const = default;
  // The per-texel J_D / grad alpha textures (VolumeJacobian::kPrecomputed) are
  // read only by the lightings that transform normals (eq. 6, 7): no lighting
  // or the plain gradient never builds, defines or binds them.
  bool UsesJacobianTextures() const {
    return jacobian == VolumeJacobian::kPrecomputed &&
           (lighting == VolumeLighting::kTransformed || lighting == VolumeLighting::kBlended);
  }
  // The shader #defines these options select (one place).
  std::vector<std::string> Defines(int map_count) const;
};

// A displacement map and where it sits in volume texture space (eq. 10).
struct VolumeMapInput {
  core::DisplacementMap map;
  glm::dmat4 placement{1.0};  // map unit cube -> volume texture space
};

// The proxy geometry of sec. 4.2 for these maps: core::ProxyBox of the
// volume's unit box, volume texture space.
core::Box3 VolumeProxyBox(const std::vector<VolumeMapInput>& maps);
// The proxy box's unit cube -> volume texture space (translate to lo, scale by
// hi - lo; single precision, as the shaders get it). world_from_volume times
// this is VolumePass::world_from_proxy().
glm::mat4 TexFromProxy(const core::Box3& proxy_box);

struct VolumeDrawStats {
  int slices = 0;
  double slice_spacing_world = 0;
  double proxy_area_px = 0;  // sum of the slices' projected areas, pixels (fill estimate)
  // The part of proxy_area_px drawn by the displaced shader (all of it
  // without support_skip).
  double displaced_area_px = 0;
  // The part not drawn: bricks the map cuts away entirely (brick_texels).
  double cut_area_px = 0;
  int parts = 0;  // slice parts drawn
  int draw_calls = 0;
};

class VolumePass : public Pass {
 public:
  // Plain CPU data in; uploads the volume with its gradient (one RGBA32F
  // texture: rgb the gradient, a the normalised scalar), the maps and the
  // transfer function. world_from_volume maps texture space to the world
  // (e.g. scale by the extent, centre at 0). core::InputError when the
  // options need more texture units than the context's
  // GL_MAX_TEXTURE_IMAGE_UNITS (GL 4.5 guarantees 16; four maps with
  // precomputed Jacobians use 18).
  VolumePass(ProgramCache& programs, const core::Volume& volume,
             const core::TransferFunction& transfer, std::vector<VolumeMapInput> maps,
             const glm::mat4& world_from_volume, const VolumePassOptions& options);

  std::string_view name() const override { return "volume"; }
  // The Pass contract: into a frame begun by BeginFrame, depth-tested against
  // it, leaving BeginFrame's state. DVR writes colour only (premultiplied;
  // the translucent slices have no single camera z or normal); iso writes all
  // four attachments.
  void Draw(const RenderTarget& target, const ViewSetup& view) override;
  // DVR blends translucent slices over what is drawn before it.
  bool translucent() const override { return options_.mode == VolumeMode::kDvr; }

  const VolumePassOptions& options() const { return options_; }
  // Same maps and volume; builds the derivative textures the first time the
  // options use them (UsesJacobianTextures). InputError as the constructor's
  // for options needing more texture units than GL_MAX_TEXTURE_IMAGE_UNITS.
  void SetOptions(const VolumePassOptions& options);
  // Same volume, new maps (an effect's parameter changed): re-stores and
  // uploads only what depends on the maps (the volume's texture stays), so
  // the pass draws what one constructed with these maps draws. InputError as
  // the constructor's for invalid maps (the pass is then unchanged).
  void SetMaps(std::vector<VolumeMapInput> maps);
  // Same volume and maps, a new transfer function (normalised units,
  // core::NormalizedTransfer): rewrites the 1D table in place, as a spacing
  // change does (no volume or map upload). InputError from its Check() (the
  // pass is then unchanged).
  void SetTransferFunction(const core::TransferFunction& transfer);
  const core::Box3& proxy_box() const { return proxy_box_; }  // volume texture space
  const VolumeDrawStats& last_stats() const { return stats_; }
  // core::ActiveBox of each map (map space): where its fetch is not skipped.
  const std::vector<core::Box3>& active_boxes() const { return active_; }
  // Where the displaced shader differs from the one without maps, proxy-box
  // coordinates: the bounding box of every map's active box placed in the
  // volume (eq. 10); outside every one of them each map is the identity (the
  // last map acts first, eq. 9, and leaves p' unmoved). Empty (lo > hi) when
  // no map moves anything.
  const core::Box3& support_box() const { return support_; }
  // GPU memory of the maps' (D, alpha) textures as uploaded (texels x the
  // format's bytes: 4 RGBA8, 8 RGBA16, 16 RGBA32F) and of their derivative
  // textures (3 RGBA32F a map; 0 until the options use them): Correa 2006
  // Table 2's "texture memory".
  int64_t map_texture_bytes() const;
  int64_t derivative_texture_bytes() const;
  // World length of one voxel of the smallest-spacing axis.
  double voxel_world() const { return voxel_world_; }
  glm::mat4 world_from_proxy() const;
  // The slicing DVR uses for `view` (screen family, back to front, the count
  // giving the sampling distance): MakeSlices(world_from_proxy(), ...) with
  // it reproduces the slices drawn.
  SlicingOptions DvrSlicing(const ViewSetup& view) const;
  // Binds the volume's 3D texture (rgb: the scalar's gradient, a: the
  // normalised scalar; for probes of the filtering in tests).
  void BindSampleTexture(GLuint unit) const { glBindTextureUnit(unit, sample_texture_.id()); }

 private:
  void DrawDvr(const RenderTarget& target, const ViewSetup& view);
  void DrawIso(const RenderTarget& target, const ViewSetup& view);
  void SetCommonUniforms(const Program& program, const ViewSetup& view) const;

  // Highest texture unit SetCommonUniforms binds for options_, plus one.
  int TextureUnitsNeeded(const VolumePassOptions& options) const;
  // InputError for maps the pass cannot draw (count, size, singular
  // placement, non-finite texels).
  void CheckMaps(const std::vector<VolumeMapInput>& maps) const;

  ProgramCache* programs_;
  int max_texture_units_ = 0;  // GL_MAX_TEXTURE_IMAGE_UNITS of the context
  VolumePassOptions options_;
  glm::ivec3 dims_{0};
  glm::mat4 world_from_volume_{1.0f};
  std::vector<VolumeMapInput> maps_;
  std::vector<core::StoredDisplacementMap> stored_;
  bool maps_changed_ = true;        // stored_ and what follows from it are stale
  std::vector<core::Box3> active_;  // core::ActiveBox of each stored map
  core::Box3 support_;              // support_box()
  // How DrawDvr splits slices (support_skip): one map's bricks (brick_texels)
  // or the support box, labelled by core::MapBrickKind; empty without split.
  std::optional<SliceSplitter> splitter_;
  core::Box3 proxy_box_;
  double voxel_world_ = 1;
  Texture sample_texture_;
  std::vector<glm::vec4> transfer_table_;  // core::TransferFunction::Table, uncorrected
  float transfer_exponent_ = 1;            // the opacity correction transfer_texture_ holds
  Texture transfer_texture_;
  std::vector<Texture> map_textures_;
  // Per map: J_D columns + grad alpha, 3 each; built when first
  // UsesJacobianTextures(), empty before.
  std::vector<Texture> derivative_textures_;
  SliceBuffer slices_;
  Buffer box_vertices_;
  VertexArray box_vao_;
  VolumeDrawStats stats_;
};

}  // namespace render
