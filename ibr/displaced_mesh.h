// A displacement-mapped mesh drawn by one of the methods of `ibr displace`
// (the one method table: the command, the scene renderer, the demo and the
// benches use it): slicing with the alpha test (Kautz-Seidel 2001, sec. 3;
// three slice families), ray marching through the ray core (NCS, Chen-Chang
// sec. 3.2; relief mapping; POM; curved relief mapping, Oliveira-Policarpo
// 2005) and the tessellated ground truth.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"
#include "core/heightfield.h"
#include "core/image.h"
#include "core/mesh.h"
#include "ibr/views.h"
#include "render/gl/shader_program.h"
#include "render/passes/displacement_pass.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/pass.h"

namespace ibr {

enum class DisplacementMethod {
  kSlicesSurface,
  kSlicesOrthogonal,
  kSlicesScreen,
  kNcs,
  kRelief,
  kPom,
  kCrm,
  kTessellated
};
inline constexpr core::EnumName<DisplacementMethod> kDisplacementMethodNames[] = {
    {DisplacementMethod::kSlicesSurface, "slices-surface"},
    {DisplacementMethod::kSlicesOrthogonal, "slices-orthogonal"},
    {DisplacementMethod::kSlicesScreen, "slices-screen"},
    {DisplacementMethod::kNcs, "ncs"},
    {DisplacementMethod::kRelief, "relief"},
    {DisplacementMethod::kPom, "pom"},
    {DisplacementMethod::kCrm, "crm"},
    {DisplacementMethod::kTessellated, "tessellated"},
};
static_assert(core::EnumNamesUnique(kDisplacementMethodNames));
// "slices-surface", "slices-orthogonal", "slices-screen", "ncs", "relief", "pom", "crm",
// "tessellated".
DisplacementMethod DisplacementMethodFromName(
    const std::string& name);  // InputError listing the names
std::string DisplacementMethodName(DisplacementMethod method);
std::vector<std::string> DisplacementMethodNames();

struct DisplacedMeshOptions {
  DisplacementMethod method = DisplacementMethod::kSlicesOrthogonal;
  float max_displacement = 0.15f;  // scene units for height 1 (the torus tube radius is 0.4)
  float tiling = 1.0f;             // height map repeats across uv [0, 1]
  // The colour texture (DisplacedMeshData::color) repeats this many times
  // across uv [0, 1]: 1 keeps it where the mesh's uvs put it, whatever the
  // height map's `tiling`.
  float texture_tiling = 1.0f;
  // Light the colour texture with the displaced normal (head light); off:
  // its plain colour (to compare where the texture lands, unconfounded by
  // each method's normals). Without a colour texture nothing changes.
  bool shade = true;
  int slices = 64;  // slicing methods: slices per face volume
  int steps = 32;   // ray methods: linear-search steps (render::ReliefSurfaceOptions)
  void Check() const;
  // Field by field (tests/ibr/object_kind_registry_test: the CLI and a scene agree).
  bool operator==(const DisplacedMeshOptions&) const = default;
};

// Plain CPU inputs.
struct DisplacedMeshData {
  core::TriangleMesh base;  // normals + uvs, world space
  core::ImageF height;      // 1 channel, [0, 1] (1 = max_displacement)
  // Optional colour texture (1-4 channels, any size) at the mesh's uvs; every
  // method shades it with the head light and the displaced normal. Empty =
  // colour from the height's slopes (slicing, tessellated) or a grey albedo
  // (ray methods).
  core::Image8 color;
};

// Built-in base meshes: "torus" (the paper's 625-polygon donut, R 1, r 0.4),
// "plane" (2 x 2, one quad, z = 0, normal +z), "sphere" (radius 1, 16 x 32).
core::TriangleMesh DisplacementBaseMesh(const std::string& name);
std::vector<std::string> DisplacementBaseMeshNames();
// Height map in [floor, floor + (1 - floor) * pattern]: floor > 0 gives the
// surface a solid base everywhere (a height of 0 is masked out, sec. 3.2).
core::ImageF DisplacementHeightMap(core::HeightPattern pattern, int texels, float floor = 0.0f);
// A user's height map: 8/16-bit PNG (scaled to [0, 1]) or EXR (values must
// lie in [0, 1]); the first channel. InputError naming the file otherwise.
core::ImageF ReadHeightMap(const std::filesystem::path& path);
// A user's mesh (OBJ/PLY through assimp): needs texture coordinates.
core::TriangleMesh ReadDisplacementBase(const std::filesystem::path& path);

// The orbit camera (ibr/views.h, OrbitCameraView) of `ibr displace` around a
// displaced mesh: the bounds of `base` grown by max_displacement framed.
ViewCamera DisplacementOrbitCamera(const core::TriangleMesh& base, float max_displacement,
                                   const OrbitCamera& orbit, int size_px);
// The same orbit as pass inputs (OrbitViewSetup), for the benches and tests
// that draw a method's pass alone.
render::ViewSetup DisplacementOrbitView(const core::TriangleMesh& base, float max_displacement,
                                        const OrbitCamera& orbit, int size_px);

// A displaced mesh on the GPU: uploads once and holds the method's
// render::Pass (render::DisplacementPass, render::ReliefSurface or, for the
// tessellated truth, render::MeshPass), which draws into any frame target
// begun by render::BeginFrame (a scene draws every object's pass into one).
// Needs a current context.
class DisplacedMeshRenderer {
 public:
  DisplacedMeshRenderer(render::ProgramCache& programs, const DisplacedMeshData& data,
                        const DisplacedMeshOptions& options);
  ~DisplacedMeshRenderer();
  DisplacedMeshRenderer(const DisplacedMeshRenderer&) = delete;
  DisplacedMeshRenderer& operator=(const DisplacedMeshRenderer&) = delete;

  // The method's pass (lives as long as the renderer).
  render::Pass& pass();
  // One whole frame into the renderer's own frame target (resized to width x
  // height): render::DrawFrame, what the benches time.
  void Draw(const render::ViewSetup& view, int width, int height);
  // The last Draw read back (render::ReadFrame).
  render::Frame Read() const;
  // One line about the last Draw of the pass (counts).
  std::string Detail() const;
  // The tessellated truth's plan (subdivisions, size, what the budget
  // limited); null for the other methods.
  const render::GroundTruthPlan* truth_plan() const;
  const DisplacedMeshOptions& options() const { return options_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  DisplacedMeshOptions options_;
};

}  // namespace ibr
