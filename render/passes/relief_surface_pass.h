// Per-pixel displacement of a curved base mesh by ray marching in texture
// space, three methods over ONE ray core (render/cores/ray_core.h):
//  - NCS, normal-based curved silhouettes (Chen-Chang, sec. 3.2, Algorithm 2):
//    at every step the tangent frame at the current uv is looked up in the
//    tangent-space maps (render/passes/tangent_maps.h) and the ray is bent, so a
//    straight object-space ray becomes a curve in texture space; rays that
//    leave the shell are discarded: prism-free silhouettes;
//  - relief mapping [POC05]: linear + binary search with the frame of the
//    entry fragment, a straight texture-space ray, no silhouettes;
//  - parallax occlusion mapping [BT04, Tat06]: linear search with a
//    view-dependent sample count and one intersection with the linear
//    approximation of the height profile, no silhouettes;
//  - curved relief mapping, CRM [OP05] (Oliveira and Policarpo 2005, the
//    baseline of Chen-Chang): relief mapping's straight texture-space ray
//    and entry frame, but the ray's depth is measured from a quadric that
//    approximates the shell near the entry, z = a x^2 + b y^2 (x, y: the
//    ray's tangent-plane offsets along T and B, scene units; a, b fitted per
//    vertex of the base mesh by core::FitVertexQuadrics and interpolated by
//    the rasteriser). At path length t along V the depth below the curved
//    shell is t cos - q t^2, q = a (T.V)^2 + b (B.V)^2: the march ends where
//    it reaches the base (a hit: h >= 0 there) or where it comes back out of
//    the shell (depth < 0); rays that leave are discarded, which carves
//    silhouettes without prisms. The quadric is local to the entry, so
//    grazing rays follow its curvature and can miss a farther part of the
//    surface (Chen-Chang, Fig. 2, sec. 3.2).
//
// Geometry and the texture volume: heights h in [0, 1] displace OUTWARD
// along the normal by h * max_displacement (the convention of
// core::TessellateDisplaced, the ground truth). The rasterised mesh is the
// outer shell, base + max_displacement * N; texture space is (u, v, w) with
// w = height above the base in units of max_displacement, so every ray
// starts at w = 1 and the solid is w <= h(u, v). The paper measures depth
// from the top instead (its z = 1 - w): its "z < 0, discard" is our w > 1,
// "left the shell through the top", and its "z > H" is our w < h.
// A texture-space step for object-space direction V (unit) and path length
// dt (scene units) is dt * (S_t T.V, S_b B.V, N.V / max_displacement), and
// the object-space ray stays straight: the hit is entry + t * V, which gives
// the depth written to the depth buffer and the camera-z output.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/image.h"
#include "core/mesh.h"
#include "render/cores/ray_core.h"
#include "render/gl/gpu_mesh.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/pass.h"
#include "render/passes/tangent_maps.h"

namespace render {

enum class ReliefMethod { kNcs, kRelief, kPom, kCrm };
inline constexpr core::EnumName<ReliefMethod> kReliefMethodNames[] = {
    {ReliefMethod::kNcs, "ncs"},
    {ReliefMethod::kRelief, "relief"},
    {ReliefMethod::kPom, "pom"},
    {ReliefMethod::kCrm, "crm"},
};
static_assert(core::EnumNamesUnique(kReliefMethodNames));
// "ncs", "relief", "pom", "crm" (InputError otherwise).
ReliefMethod ReliefMethodFromName(const std::string& name);
std::string ReliefMethodName(ReliefMethod method);

// What is fixed for a displaced object: its shell and maps.
struct ReliefGeometryOptions {
  float max_displacement = 0.1f;   // scene units for height 1 (as DisplacedMeshOptions)
  TangentMapOptions tangent_maps;  // resolution and periodicity of the parameterisation
  bool height_bilinear =
      true;  // LINEAR (true) or NEAREST height lookups, as the ground truth's `bilinear`
  void Check() const;
};

// Per frame.
struct ReliefSurfaceOptions {
  ReliefMethod method = ReliefMethod::kNcs;
  // Linear-search steps: NCS's num_step (Algorithm 2), relief's and CRM's
  // linear search, POM's maximum sample count. 32 keeps 512^2 frames interactive on llvmpipe.
  int steps = 32;
  // NCS step enlargement c (sec. 5): step = c * l / steps with l the
  // flat-surface path length through the shell; the paper uses 2.5.
  float step_enlargement = 2.5f;
  // Bisection iterations (NCS, relief, CRM); POM uses its secant step instead.
  int refine_steps = 6;
  // POM's minimum sample count at normal incidence (Tatarchuk 2006 varies the
  // count linearly with the view angle between this and `steps`).
  int pom_min_steps = 8;
  // Height map repeats across uv [0, 1] (the paper's Figure 6 tiling).
  float tiling = 1.0f;
  // The flat-surface path length l = max_displacement / max(cos, min_view_cos):
  // at grazing incidence l would be unbounded; 0.02 caps it at 50 shell
  // thicknesses (CRM: its march at 2 l).
  float min_view_cos = 0.02f;
  // Step policy of the ray core (fixed or threshold; the texture-space march
  // has no warp Jacobian, so kJacobian is rejected).
  RayStepPolicy step_policy = RayStepPolicy::kFixed;
  float threshold = 0.04f;  // kThreshold: in units of max_displacement
  // NCS: paint early-terminated fragments red instead of discarding them
  // (the paper's Figure 7); off for measurements.
  bool mark_early_termination = false;
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // albedo without a colour texture
  // A colour texture given to the surface (ReliefSurface::SetColorTexture)
  // repeats this many times across uv [0, 1], independent of `tiling`.
  float color_tiling = 1.0f;
  bool shade = true;  // Lambert head light as render::DrawMesh, with the displaced normal
  glm::mat4 world_from_object{1.0f};
  void Check() const;
  RayCoreOptions RayCore() const;
  // The shader variant (the one place these options become #defines);
  // `color_texture`: the surface has a colour texture (COLOR_TEXTURE).
  std::vector<std::string> Defines(const ReliefGeometryOptions& geometry, bool orthographic,
                                   bool color_texture = false) const;
};

// A displaced object on the GPU: the shell mesh (with CRM's per-vertex
// quadric of the base as attribute kVertexDataLocation), the height texture
// and the tangent-space maps, drawn with per-frame ReliefSurfaceOptions.
class ReliefSurface final : public Pass {
 public:
  // `base` needs normals and uvs with a continuous parameterisation; `height`
  // is a 1-channel map in [0, 1] (core::MakeHeightMap).
  ReliefSurface(ProgramCache& programs, const core::TriangleMesh& base, const core::ImageF& height,
                const ReliefGeometryOptions& options, const ReliefSurfaceOptions& surface = {});

  std::string_view name() const override { return "relief"; }
  // Draws into a frame target; every ray ORs OutcomeBit(its outcome) into the
  // frame's outcome image, also rays whose fragment is discarded or hidden.
  void Draw(const RenderTarget& target, const ViewSetup& view) override;

  // Method, steps, step policy...: per frame, the geometry stays.
  void SetOptions(const ReliefSurfaceOptions& options);
  const ReliefSurfaceOptions& options() const { return options_; }
  // SetOptions + RenderFrame.
  Frame Render(const ViewSetup& view, int width, int height, const ReliefSurfaceOptions& options);

  // The albedo every method shades with: the texture (render::
  // UploadColorTexture; the caller keeps it alive, null = base_color) at the
  // hit's uv * options().color_tiling. A scene without one never compiles
  // the lookup.
  void SetColorTexture(const Texture* color) { color_ = color; }

  const TangentMaps& tangent_maps() const { return maps_; }
  const ReliefGeometryOptions& geometry() const { return geometry_; }

 private:
  // `frames`: ComputeTangentFrames of `base`, shared by the shell's CRM
  // quadrics and the tangent maps.
  ReliefSurface(ProgramCache& programs, const core::TriangleMesh& base, const core::ImageF& height,
                const ReliefGeometryOptions& options, const ReliefSurfaceOptions& surface,
                const TangentFrames& frames);

  ProgramCache* programs_;
  ReliefGeometryOptions geometry_;
  ReliefSurfaceOptions options_;
  GpuMesh shell_;
  Texture height_;
  TangentMaps maps_;
  const Texture* color_ = nullptr;
};

// The outer shell: base + max_displacement * N at every vertex, same uvs and normals.
core::TriangleMesh MakeReliefShell(const core::TriangleMesh& base, float max_displacement);

// CRM's per-vertex (a, b) of `base` (core::FitVertexQuadrics) in the frame
// `frames` = ComputeTangentFrames(base, ...): T and B = handedness * N x T,
// as the tangent maps.
std::vector<glm::vec2> ReliefVertexQuadrics(const core::TriangleMesh& base,
                                            const TangentFrames& frames);

}  // namespace render
