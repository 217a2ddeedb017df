// Displacement mapping by slicing with the alpha test (Kautz-Seidel 2001,
// sec. 3): every face of a base mesh gets a displacement volume (the face
// extruded along its interpolated vertex normals by `max_displacement`), the
// slicing core cuts it into slices (surface-aligned, orthogonal or
// screen-space), and each slice fragment is kept iff the displacement texture's
// height minus the fragment's ramp value h_alpha is > 0 (sec. 3.2, the same
// test for every family, so a height of 0 is never drawn).
//
// Displacement texture: ONE RGBA texture, RGB = colour, A = height in [0, 1]
// (1 = max_displacement scene units), the paper's RGB-alpha layout (sec. 3.1).
// RGBA8 is the paper's format; RGBA32F keeps heights exact (tests of the
// strict inequality). Looked up at uv * tiling with REPEAT wrapping.
//
// Outputs: a frame (render/passes/pass.h) like the mesh pass's, so a frame
// compares pixel by pixel with the tessellated ground truth
// (MakeDisplacedGroundTruth + RenderMesh); normals are 0 (not computed).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/mesh.h"
#include "render/cores/slice_buffer.h"
#include "render/cores/slicing.h"
#include "render/gl/handles.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/pass.h"

namespace render {

// ---- displacement textures ----

// RGBA float texels from a height map (1 channel, values in [0, 1]): A = the
// height; RGB = an albedo ramp by height lit by a fixed light over the
// height map's own slopes (`relief` = height units per texel width that give
// the shading its contrast), so the colour reads without mesh normals.
core::ImageF MakeDisplacementTexels(const core::ImageF& height, float relief = 24.0f);

struct DisplacementTextureOptions {
  GLenum internal_format = GL_RGBA8;  // GL_RGBA8 (paper) or GL_RGBA32F (exact heights)
  bool linear_filter = true;          // LINEAR matches the ground truth's bilinear heights
  void Check() const;
};

// Uploads RGBA texels (4-channel float image, values in [0, 1]), REPEAT wrap.
// The upload's bytes are checked against the memory budget first.
Texture UploadDisplacementTexture(const core::ImageF& rgba,
                                  const DisplacementTextureOptions& options = {});

// A user's colour texture (1-4 channels: grey, grey + alpha, RGB, RGBA) as
// RGBA8, bilinear, REPEAT wrap, rows uploaded as stored (row 0 at v = 0, the
// image convention of the loaders' uvs). Checked against the memory budget.
Texture UploadColorTexture(const core::Image8& image);

// ---- per-face displacement volumes ----

// One face's displacement volume. Box coordinates (x, y, z): the base point
// is p[0] + x (p[1] - p[0]) + y (p[2] - p[0]) (likewise normals and uvs), and
// z in [0, 1] is the height as a fraction of max_displacement, measured along
// the normalised interpolated normal (sec. 3, Figure 2). A parallelogram
// covers the whole box [0, 1]^2; a triangle only x + y <= 1.
struct DisplacementVolume {
  glm::vec3 p[3];   // object = world space
  glm::vec3 n[3];   // unit vertex normals
  glm::vec2 uv[3];  // texture coordinates before tiling
  bool triangle = true;
};

// The base mesh's faces as displacement volumes: consecutive triangle pairs
// that form a parallelogram in position, normal and uv (MakePlane's quads)
// become one parallelogram volume, every other triangle its own; faces of
// zero area (or whose normals lie in the face) are dropped, since they bound
// no volume. Needs normals and uvs (InputError otherwise).
std::vector<DisplacementVolume> DisplacementVolumesFromMesh(const core::TriangleMesh& base);

// The affine box the slicing core slices for `volume` (exact for planar faces
// with one normal; for curved faces the box extrudes along the mean normal and
// the shader maps slice vertices through the interpolated normals).
SliceBox DisplacementVolumeBox(const DisplacementVolume& volume, float max_displacement);

// The volume's point at box coordinates p (the shader's map, on the CPU).
glm::vec3 DisplacementVolumePoint(const DisplacementVolume& volume, glm::vec3 p_in_box,
                                  float max_displacement);

// ---- the pass ----

struct DisplacementPassOptions {
  // Family, slice count PER VOLUME along its slicing axis (screen: along
  // camera z over the volume's depth range), order, full-size screen slices.
  SlicingOptions slicing;
  float max_displacement = 0.1f;  // scene units for height 1.0; > 0
  float tiling = 1.0f;            // the texture repeats `tiling` times across uv [0, 1]
  // Optional colour texture (UploadColorTexture; the caller keeps it alive):
  // looked up at the mesh's uv * color_tiling, NOT at the height map's
  // tiling, and lit by the head light with the displaced surface's normal.
  // Null: the displacement texture's RGB, unlit (its slope colouring is lit
  // already).
  const Texture* color = nullptr;
  float color_tiling = 1.0f;  // colour texture repeats across uv [0, 1]
  bool shade = true;          // light the colour texture (off: its plain colour)
  void Check() const;
  // The shader variant these options need (the one place options become #defines).
  std::vector<std::string> Defines(bool orthographic = false) const;
};

// Counts of the last Draw(), for fill-rate accounting.
struct DisplacementDrawStats {
  int volumes = 0;
  int slices = 0;
  int triangles = 0;
  double fragments = -1;  // fragment-shader invocations (pipeline statistics), -1 if unavailable
};

class DisplacementPass final : public Pass {
 public:
  // Builds the volumes of `base` and uploads them; needs a current context.
  // `displacement` (UploadDisplacementTexture) must outlive the pass.
  DisplacementPass(ProgramCache& programs, const core::TriangleMesh& base,
                   const Texture& displacement, const DisplacementPassOptions& options);

  std::string_view name() const override { return "displacement"; }
  // Slices for this view (CPU), upload, draw into a frame target.
  void Draw(const RenderTarget& target, const ViewSetup& view) override;

  const DisplacementPassOptions& options() const { return options_; }
  // Changes family/count/order; volumes stay.
  void SetSlicing(const SlicingOptions& slicing);
  const std::vector<DisplacementVolume>& volumes() const { return volumes_; }
  // Count fragment-shader invocations in Draw() (a query per frame; off by default).
  void CountFragments(bool on) { count_fragments_ = on; }
  const DisplacementDrawStats& last_stats() const { return stats_; }

 private:
  ProgramCache* programs_;
  const Texture* displacement_;
  DisplacementPassOptions options_;
  std::vector<DisplacementVolume> volumes_;
  std::vector<SliceBox> boxes_;
  std::vector<SliceStack> stacks_;
  Buffer volume_data_;
  SliceBuffer slices_;
  bool count_fragments_ = false;
  DisplacementDrawStats stats_;
};

// ---- the ground truth (seed 002's "ground truth model") ----

// How finely the ground truth is tessellated, decided before anything is
// allocated. Every face gets the same number of subdivisions per edge (so
// neighbouring faces sample their shared edge at the same points: no
// cracks). The rule asks for about one height texel per subdivided edge on
// the face with the longest uv edge, at most kMaxGroundTruthSubdivisions;
// when the whole tessellation (the CPU mesh plus its GPU upload) would not fit
// the memory budget, the count is lowered until it does, and a triangle
// then spans `texels_per_edge` > 1 height texels (coarser truth).
inline constexpr int kMaxGroundTruthSubdivisions = 512;
struct GroundTruthPlan {
  int faces = 0;
  int wanted_subdivisions = 1;  // the rule's count per edge
  int subdivisions = 1;         // the count that fits (<= wanted)
  std::uint64_t vertices = 0;   // of the tessellated mesh
  std::uint64_t triangles = 0;
  std::uint64_t bytes = 0;    // CPU mesh + GPU upload, estimated
  float span_texels = 0;      // height texels along the longest uv edge of a face
  float texels_per_edge = 0;  // ... and along its subdivided edges (span / subdivisions)
  bool limited() const { return subdivisions < wanted_subdivisions; }
  std::string Describe() const;  // one line for the user
};
// Bytes the tessellated truth of `faces` faces at `subdivisions` per edge
// needs: the CPU mesh (core::TessellateDisplaced), GpuMesh's reordered copy
// and the driver's buffers (llvmpipe keeps them in system memory).
std::uint64_t GroundTruthBytes(std::uint64_t faces, int subdivisions);
// The plan for `base` with a `texels`-wide height map repeated `tiling`
// times, under core::MemoryBudgetBytes(). InputError (core::CheckMemory's
// line) when even one subdivision per edge does not fit.
GroundTruthPlan PlanDisplacedGroundTruth(const core::TriangleMesh& base, int texels, float tiling);

// `base` tessellated by `plan` (default: PlanDisplacedGroundTruth) and
// displaced along interpolated normals by bilinear heights; uvs are
// multiplied by `uv_scale` (default: `tiling`, so render::DrawMesh with the
// displacement texture (TEXTURED, shade off) shows the same colours as the
// pass; a colour texture at the mesh's own uvs wants its own tiling).
core::TriangleMesh MakeDisplacedGroundTruth(const core::TriangleMesh& base,
                                            const core::ImageF& height, float max_displacement,
                                            float tiling);
core::TriangleMesh MakeDisplacedGroundTruth(const core::TriangleMesh& base,
                                            const core::ImageF& height, float max_displacement,
                                            float tiling, const GroundTruthPlan& plan,
                                            float uv_scale);

}  // namespace render
