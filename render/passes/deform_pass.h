// Deformation and cut shaders on meshes (Correa, Silver, Chen 2007): the
// mesh outside the deformation box is rasterised as is (stage 1: triangles
// wholly outside one of the box's face planes drawn once; those crossing or
// touching the box drawn as the box's complement, six convex pieces clipped
// exactly by gl_ClipDistance; those wholly inside not at all); inside the box a ray is cast per
// fragment of the box's back faces through the shared ray core (stage 2), sampling the mesh's
// signed distance field (an R32F 3D texture) at the inversely warped point p = p' + M D(M^-1 p')
// (eq. 1-2, D an RGBA 3D texture: xyz inverse displacement in box units, w the cut alpha A), and
// writes gl_FragDepth, so the two stages composite by the depth test wherever they overlap.
//
// The implicit (DeformPassOptions::implicit, one #define): the mesh's signed
// distance field (an R32F 3D texture), or the depth-map cube of sec. 6.1
// (DepthCube: six orthographic depth maps on the faces of a cube around the
// object, an R32F 2D array); only the lookup differs, the warp, cuts, steps
// and normals are one code path.
//
// Sign convention, converted once here: Correa's f is > 0 inside; the ray
// core's field is > 0 in empty space, so RayField = sdf (> 0 outside), the
// paper's f = -sdf. Cuts (sec. 5): hollow = hits of sdf in either direction,
// those where A > 0 rejected (RAY_BOTH_CROSSINGS + RAY_REJECT); solid (eq. 6)
// = the field max(sdf, A) with the cut face's normal grad A; thick shell
// (eq. 7) = max(|sdf + T/2| - T/2, A), or (solid_search) the paper's own
// search of sec. 5.1.2 on the ray core's two-field hook (RAY_SECOND_FIELD).
// Normals (eq. 5): (I + J)^T grad sdf at the warped point, J by central
// differences of the warp. Skips: by the cut alpha (skip_empty, sec. 6.2)
// and by the object's distance field (skip_object).
//
// Outcome bits (frame attachment 3): 1 << RayOutcome for ray-cast pixels,
// kDeformMeshBit for rasterised mesh pixels, kDeformCutFaceBit where the hit
// is on a cut face; bits 6..15 hold the crossings the ray rejected (a surface
// hit inside the cut, a cut boundary outside the body; saturated), bits
// 16..31 the ray's field samples (saturated).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/deformation.h"
#include "core/distance_field.h"
#include "core/enum_names.h"
#include "core/image.h"
#include "core/mesh.h"
#include "render/cores/ray_core.h"
#include "render/gl/gpu_mesh.h"
#include "render/gl/handles.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"

namespace render {

inline constexpr uint32_t kDeformCutFaceBit = 1u << 4;  // the ray hit a cut face (A = 0)
inline constexpr uint32_t kDeformMeshBit = 1u << 5;     // rasterised, undeformed mesh
inline constexpr int kDeformRejectedShift = 6;          // rejected crossings in bits 6..15
inline constexpr uint32_t kDeformRejectedMax = 1023u;   // their saturation
inline constexpr int kDeformSamplesShift = 16;          // samples per ray in bits 16..31

using core::CutMode;

// The implicit the ray stage samples.
enum class DeformImplicit {
  kSdf,        // the mesh's signed distance field (core::DistanceField)
  kDepthCube,  // the depth-map cube of Correa 2007 sec. 6.1 (DepthCube)
};
inline constexpr core::EnumName<DeformImplicit> kDeformImplicitNames[] = {
    {DeformImplicit::kSdf, "sdf"},
    {DeformImplicit::kDepthCube, "depth-cube"},
};
static_assert(core::EnumNamesUnique(kDeformImplicitNames));
// "sdf", "depth-cube" (InputError naming the value otherwise).
DeformImplicit DeformImplicitFromName(const std::string& name);
std::string DeformImplicitName(DeformImplicit implicit);

// The depth-map cube (Correa, Silver, Chen 2007, sec. 6.1), plain CPU data:
// six orthographic depth maps of the object, one per face of a cube around
// it, each looking inwards (ibr::MakeDepthCube renders them with the cube rig
// of `ibr capture`). Face i at an object point p: H_i(u, v) - z_i(p), the
// depth the face saw at p's texel (bilinear) minus p's distance from the
// face, > 0 in front of the surface it saw. The implicit is the largest of
// the six (> 0 empty: in front of some face's surface; the intersection of
// Kautz-Seidel's depth objects, the depth-object ray field of ibr/). The
// paper combines faces as sign * min(|f1|, |f2|); both are <= 0 exactly where
// every face's difference is (the same solid, so the same surface) and differ
// in magnitude only. The max is continuous (a max of bilinear functions), so
// bisection and central-difference normals work on it as on the distance
// field; it is not a distance (an axis distance to the surface seen, >= the
// Euclidean one), which only the threshold step policy reads (as a
// closeness test), and the deform pass's empty-space skip reads the cut alpha
// alone, so it stays a true lower bound with either implicit. It is exact for objects whose every
// surface point is seen by some face (convex ones), up to the maps' texels; concavities no face
// sees are filled. Where a face saw nothing the pass stores `far` (the cube's width: the surface
// "at the far face", so the face only says empty there), except in a one-texel ring around the
// silhouette, which repeats the nearest seen depth (so the bilinear blend with the far face lies
// outside the silhouette and the other faces trim it).
struct DepthCubeFace {
  core::ImageF depth;  // distance from the face to the surface seen; <= 0 = nothing seen
  // Affine: object point -> (u, v) in pixels (centres at +0.5, row v) and z,
  // the distance from the face along its inward axis.
  glm::dmat4 map_from_object{1.0};
};
struct DepthCube {
  std::vector<DepthCubeFace> faces;  // six, square, one size
  double far = 0.0;                  // the cube's width, stored where a face saw nothing
  double texel = 0.0;                // object units per texel (steps, normals)
  // InputError naming `where` unless six square faces of one size, far and
  // texel positive and finite.
  void Check(const std::string& where) const;
  // GPU memory: six R32F maps.
  int64_t Bytes() const;
};

struct DeformPassOptions {
  CutMode cut = CutMode::kNone;
  // Thick shell thickness T (object units), CutMode::kThick only.
  float thickness = 0.05f;
  // Base step of the linear search in distance-field voxels: one voxel
  // resolves what the field can hold (Correa's "constant ds").
  float step_voxels = 1.0f;
  // The ray core's policy and budget (threshold in object units: |sdf| below
  // it takes steps of fine_step_scale; 0.04 is the paper's value for a unit
  // object). max_steps caps the linear search.
  RayStepPolicy step_policy = RayStepPolicy::kFixed;
  float threshold = 0.04f;
  int max_steps = 2048;
  int refine_steps = 10;
  // Empty-space skipping in the cut region by the cut alpha (sec. 6.2):
  // RAY_SKIP with skip = A / Lipschitz(A), a true lower bound of the
  // distance to the cut's boundary.
  bool skip_empty = false;
  // Solid and thick cuts by the paper's two-field search (sec. 5.1.2: a
  // surface hit inside the cut is rejected and the march looks for the cut's
  // boundary inside the body) instead of the CSG field max(body, A). Same
  // surface; the search takes a few more samples per ray (a rejected hit
  // restarts the march on the second field) and a little more time, while
  // the CSG field can miss sharp cuts' slivers thinner than a step
  // (docs/decisions/solid-cut-search.md).
  bool solid_search = false;
  // Empty-space skipping by the object's distance field (sdf implicit only;
  // the depth cube is no distance bound): the march advances by at least
  // (|field| - the lookup's overestimate) / Lipschitz(warp), a true lower
  // bound of the ray length to any crossing.
  bool skip_object = true;
  // The implicit the ray stage samples; the inputs must hold it.
  DeformImplicit implicit = DeformImplicit::kSdf;
  bool draw_mesh = true;  // stage 1; off = the box's ray cast alone
  // Stage 2; off = the mesh outside the box alone (the bench times the mesh
  // stage by itself rather than as a frame minus its ray stage, which
  // carries two frames' noise). At least one stage is drawn.
  bool draw_rays = true;
  // Stage 1 culls back faces where that draws the same pixels (a closed,
  // outward mesh in front of the near plane; DeformPass::Draw); off = both
  // sides everywhere (the tests' and the bench's baseline).
  bool cull_back_faces = true;
  // Seam blending (Correa, Silver, Chen 2007 sec. 3): stage 1's normals turn
  // into the implicit's gradient, the ray stage's normal on the box's faces,
  // across a band of seam_band_voxels distance-field voxels (depth cube:
  // texels) outside the box, so shading does not jump where the stages meet.
  // A few voxels: wide enough to hide the turn, narrow enough that the rest
  // of the mesh keeps its own normals. Off: the two normals meet unblended.
  bool seam_blend = true;
  float seam_band_voxels = 3.0f;
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};
  glm::vec4 cut_color{0.85f, 0.35f, 0.3f, 1.0f};  // cut faces and the inside of hollow shells

  void Check() const;
  bool operator==(const DeformPassOptions&) const = default;
  RayCoreOptions RayCore() const;
  // The shader #defines of the ray-cast stage (ray core's included).
  std::vector<std::string> Defines() const;
  // Those of the mesh stage (SEAM_BLEND and the implicit it reads).
  std::vector<std::string> MeshDefines() const;
};

// What the pass draws, as plain CPU data (world = object space).
struct DeformInputs {
  const core::TriangleMesh* mesh = nullptr;               // the undeformed mesh (stage 1)
  const core::DistanceField* sdf = nullptr;               // over the box grown by max |M D|
  const core::DeformationTexture* deformation = nullptr;  // D and A over the box
  core::Placement placement;                              // object_from_box
  // DeformImplicit::kDepthCube: the object's depth-map cube (sdf unused).
  const DepthCube* depth_cube = nullptr;
};

class DeformPass : public Pass {
 public:
  DeformPass(ProgramCache& programs, const DeformInputs& inputs, const DeformPassOptions& options);
  std::string_view name() const override { return "deform"; }
  void Draw(const RenderTarget& target, const ViewSetup& view) override;
  const DeformPassOptions& options() const { return options_; }
  // Whether the last Draw culled stage 1's back faces (cull_back_faces, a
  // closed outward mesh, wholly in front of the near plane).
  bool last_culled_back_faces() const { return last_culled_back_faces_; }
  // Clusters of the mesh outside the box the last Draw left out whole (all
  // of their triangles facing away, their screen rectangle off the box's
  // footprint).
  size_t last_culled_clusters() const { return last_culled_clusters_; }

 private:
  void UploadDepthCube(const DepthCube& cube);

  ProgramCache& programs_;
  DeformPassOptions options_;
  core::Placement placement_;
  // Stage 1's triangles by where they lie (box coordinates, strict):
  // wholly outside one face plane of the box (drawn once, unclipped), or
  // crossing or touching the box (drawn as the six clipped pieces); those
  // wholly inside are never drawn.
  std::optional<GpuMesh> mesh_outside_;
  std::optional<GpuMesh> mesh_crossing_;
  // options.cull_back_faces and core::IsClosedOutward of the mesh: stage 1
  // may cull back faces (Draw); then mesh_outside_ is clustered.
  bool cull_back_faces_ = false;
  // Draw's cluster lists of mesh_outside_: back faces culled, both sides,
  // facing away but within the box's footprint.
  std::vector<uint32_t> culled_ids_, both_sides_ids_, away_in_footprint_ids_;
  bool last_culled_back_faces_ = false;
  size_t last_culled_clusters_ = 0;
  core::Box3d mesh_bounds_;  // object space, of the mesh's vertices
  Texture sdf_;              // the 3D field, or the depth cube's 2D array
  Texture deformation_;
  Texture deformation_flap_;  // a peel's flap piece (core/deformation.h "Pieces"); empty if none
  // With a flap: each piece's alpha components (DeformationSum::AlphaComponents).
  Texture alpha_components_;
  Texture alpha_components_flap_;
  glm::vec3 sdf_origin_{0.0f};
  float sdf_spacing_ = 1.0f;  // the implicit's grid step (voxel or depth-cube texel)
  glm::ivec3 sdf_size_{0};
  std::vector<glm::mat4> cube_from_object_;  // depth cube: (s, t) texture coordinates, z
  int deformation_resolution_ = 0;
  float alpha_lipschitz_ = 1.0f;  // bound of |grad A| in object units (for the skip)
  // Bounds of |I + M J_D M^-1| per brick of the box, dilated (the object
  // skip; R32F, NEAREST), and the longest skip they hold for.
  Texture warp_lipschitz_;
  float warp_skip_cap_ = 0.0f;
  float sdf_margin_ = 0.0f;  // DistanceField::LookupOverestimate (the object skip)
  VertexArray box_vao_;
  Buffer box_vbo_;
};

}  // namespace render
