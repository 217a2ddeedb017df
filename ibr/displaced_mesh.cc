#include "ibr/displaced_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

#include "capture/synthetic.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/relief_surface_pass.h"

namespace ibr {
namespace {

bool IsSlicing(DisplacementMethod m) {
  return m == DisplacementMethod::kSlicesSurface || m == DisplacementMethod::kSlicesOrthogonal ||
         m == DisplacementMethod::kSlicesScreen;
}

}  // namespace

DisplacementMethod DisplacementMethodFromName(const std::string& name) {
  return core::EnumFromName(kDisplacementMethodNames, name, "DisplacementMethodFromName", "method");
}

std::string DisplacementMethodName(DisplacementMethod method) {
  return std::string(core::EnumToName(kDisplacementMethodNames, method));
}

std::vector<std::string> DisplacementMethodNames() {
  std::vector<std::string> names;
  for (const auto& m : kDisplacementMethodNames) names.emplace_back(m.name);
  return names;
}

void DisplacedMeshOptions::Check() const {
  if (!(max_displacement > 0 && max_displacement <= 10)) {
    core::ThrowInputError("DisplacedMeshOptions", "max_displacement {} outside (0, 10]",
                          max_displacement);
  }
  if (!(tiling > 0 && tiling <= 1024))
    core::ThrowInputError("DisplacedMeshOptions", "tiling {} outside (0, 1024]", tiling);
  if (!(texture_tiling > 0 && texture_tiling <= 1024)) {
    core::ThrowInputError("DisplacedMeshOptions", "texture tiling {} outside (0, 1024]",
                          texture_tiling);
  }
  if (slices < 1 || slices > 4096)
    core::ThrowInputError("DisplacedMeshOptions", "slices {} outside 1..4096", slices);
  if (steps < 1 || steps > 4096)
    core::ThrowInputError("DisplacedMeshOptions", "steps {} outside 1..4096", steps);
}

core::TriangleMesh DisplacementBaseMesh(const std::string& name) {
  if (name == "torus") return core::MakeTorus(1.0f, 0.4f, 25, 25);
  if (name == "plane") return core::MakePlane(1.0f, 1);
  if (name == "sphere") return core::MakeSphere(1.0f, 16, 32);
  core::ThrowInputError("DisplacementBaseMesh", "unknown base '{}' (torus, plane, sphere)", name);
}

std::vector<std::string> DisplacementBaseMeshNames() { return {"torus", "plane", "sphere"}; }

core::ImageF DisplacementHeightMap(core::HeightPattern pattern, int texels, float floor) {
  if (!(floor >= 0.0f && floor < 1.0f)) {
    core::ThrowInputError("DisplacementHeightMap", "floor {} outside [0, 1)", floor);
  }
  core::HeightMapOptions options;
  options.pattern = pattern;
  options.size = texels;
  options.level = pattern == core::HeightPattern::kConstant ? 0.5f : 1.0f;
  core::ImageF height = core::MakeHeightMap(options);
  for (float& v : height.values()) v = floor + (1.0f - floor) * v;
  return height;
}

core::ImageF ReadHeightMap(const std::filesystem::path& path) {
  // OpenImageIO converts 8/16-bit integer pixels to [0, 1] floats.
  const core::ImageF all = core::ReadImage<float>(path);
  if (all.width() < 2 || all.height() < 2 || all.width() > 16384 || all.height() > 16384) {
    core::ThrowFileError("ReadHeightMap", path, "height map {}x{} outside 2..16384 pixels",
                         all.width(), all.height());
  }
  core::ImageF height(all.width(), all.height(), 1);
  for (size_t p = 0; p < height.pixel_count(); ++p) {
    const float v = all.data()[p * all.channels()];
    if (!(v >= 0.0f && v <= 1.0f)) {
      core::ThrowFileError("ReadHeightMap", path, "height {} at pixel ({}, {}) outside [0, 1]", v,
                           static_cast<int>(p % all.width()), static_cast<int>(p / all.width()));
    }
    height.data()[p] = v;
  }
  return height;
}

core::TriangleMesh ReadDisplacementBase(const std::filesystem::path& path) {
  // The colour comes from --texture alone (the kind's `texture`): the mesh's
  // own material is not looked for, so nothing says "untextured" and then
  // draws a texture.
  capture::SceneMesh scene = capture::LoadSceneMesh(path, {}, capture::MeshTextures::kSkip);
  const core::TriangleMesh& m = scene.mesh;
  // LoadSceneMesh gives (0, 0) where the file has no texture coordinates: a
  // layout where every vertex has the same uv cannot carry a height map.
  bool varied = false;
  for (const glm::vec2& uv : m.uvs) varied = varied || uv != m.uvs.front();
  if (m.uvs.size() != m.positions.size() || m.normals.size() != m.positions.size() || !varied) {
    core::ThrowFileError("ReadDisplacementBase", path,
                         "a displaced mesh needs texture coordinates on every vertex");
  }
  return std::move(scene.mesh);
}

namespace {

// The sphere the orbit frames: the base's bounds grown by the displacement.
std::pair<glm::dvec3, double> DisplacedSphere(const core::TriangleMesh& base,
                                              float max_displacement) {
  glm::vec3 lo, hi;
  base.Bounds(lo, hi);
  return {glm::dvec3(0.5f * (lo + hi)), 0.5 * glm::length(hi - lo) + max_displacement};
}

}  // namespace

ViewCamera DisplacementOrbitCamera(const core::TriangleMesh& base, float max_displacement,
                                   const OrbitCamera& orbit, int size_px) {
  const auto [centre, radius] = DisplacedSphere(base, max_displacement);
  return OrbitCameraView(centre, radius, orbit, size_px);
}

render::ViewSetup DisplacementOrbitView(const core::TriangleMesh& base, float max_displacement,
                                        const OrbitCamera& orbit, int size_px) {
  const auto [centre, radius] = DisplacedSphere(base, max_displacement);
  return OrbitViewSetup(centre, radius, orbit, size_px);
}

struct DisplacedMeshRenderer::Impl {
  // What the pass draws from (declared before the pass, destroyed after it).
  std::optional<render::Texture> texture;  // RGBA: slope colour + height (slicing, tessellated)
  std::optional<render::Texture> color;    // the user's colour texture, if any
  std::optional<render::GpuMesh> tessellated;
  std::optional<render::GroundTruthPlan> plan;
  std::unique_ptr<render::Pass> pass;
  render::DisplacementPass* slices = nullptr;  // `pass` when it slices (for its counts)
  std::optional<render::RenderTarget> target;  // Draw()'s own frame target
};

DisplacedMeshRenderer::DisplacedMeshRenderer(render::ProgramCache& programs,
                                             const DisplacedMeshData& data,
                                             const DisplacedMeshOptions& options)
    : impl_(std::make_unique<Impl>()), options_(options) {
  options_.Check();
  if (data.base.uvs.empty() || data.base.normals.empty()) {
    core::ThrowInputError("DisplacedMeshRenderer",
                          "the base mesh needs normals and texture coordinates");
  }
  if (data.height.channels() != 1 || data.height.empty()) {
    core::ThrowInputError("DisplacedMeshRenderer",
                          "the height map must be a non-empty 1-channel image");
  }
  Impl& s = *impl_;
  const DisplacementMethod m = options_.method;
  // The tessellated truth is planned (and refused or limited by the memory
  // budget) before any texture or mesh is made.
  if (m == DisplacementMethod::kTessellated) {
    s.plan = render::PlanDisplacedGroundTruth(
        data.base, std::max(data.height.width(), data.height.height()), options_.tiling);
  }
  if (!data.color.empty()) s.color.emplace(render::UploadColorTexture(data.color));
  const render::Texture* color = s.color ? &*s.color : nullptr;
  if (m == DisplacementMethod::kNcs || m == DisplacementMethod::kRelief ||
      m == DisplacementMethod::kPom || m == DisplacementMethod::kCrm) {
    render::ReliefGeometryOptions geometry;
    geometry.max_displacement = options_.max_displacement;
    render::DetectChart(data.base, geometry.tangent_maps);
    render::ReliefSurfaceOptions o;
    o.method = render::ReliefMethodFromName(DisplacementMethodName(m));
    o.tiling = options_.tiling;
    o.color_tiling = options_.texture_tiling;
    o.shade = options_.shade || !color;
    o.steps = options_.steps;
    auto relief =
        std::make_unique<render::ReliefSurface>(programs, data.base, data.height, geometry, o);
    relief->SetColorTexture(color);
    s.pass = std::move(relief);
    return;
  }
  s.texture.emplace(render::UploadDisplacementTexture(render::MakeDisplacementTexels(data.height)));
  if (IsSlicing(m)) {
    render::DisplacementPassOptions o;
    o.slicing.family =
        m == DisplacementMethod::kSlicesSurface      ? render::SliceFamily::kSurfaceAligned
        : m == DisplacementMethod::kSlicesOrthogonal ? render::SliceFamily::kOrthogonal
                                                     : render::SliceFamily::kScreen;
    o.slicing.count = options_.slices;
    o.max_displacement = options_.max_displacement;
    o.tiling = options_.tiling;
    o.color = color;
    o.color_tiling = options_.texture_tiling;
    o.shade = options_.shade;
    auto slices = std::make_unique<render::DisplacementPass>(programs, data.base, *s.texture, o);
    s.slices = slices.get();
    s.pass = std::move(slices);
    return;
  }
  // With a colour texture: its colour at the mesh's uvs, lit by the
  // tessellation's own normals; without: the slope colours at the tiled uvs,
  // unlit, as the slicing passes show them.
  s.tessellated.emplace(render::MakeDisplacedGroundTruth(
      data.base, data.height, options_.max_displacement, options_.tiling, *s.plan,
      color ? options_.texture_tiling : options_.tiling));
  render::MeshPassOptions o;
  o.texture = color ? color : &*s.texture;
  o.shade = color != nullptr && options_.shade;
  s.pass = std::make_unique<render::MeshPass>(programs, *s.tessellated, o);
}

DisplacedMeshRenderer::~DisplacedMeshRenderer() = default;

render::Pass& DisplacedMeshRenderer::pass() { return *impl_->pass; }

void DisplacedMeshRenderer::Draw(const render::ViewSetup& view, int width, int height) {
  Impl& s = *impl_;
  if (!s.target || s.target->width() != width || s.target->height() != height) {
    s.target.emplace(render::FrameTargetOptions(width, height));
  }
  render::DrawFrame(*s.target, *s.pass, view);
}

render::Frame DisplacedMeshRenderer::Read() const {
  IBR_CHECK(impl_->target.has_value());
  return render::ReadFrame(*impl_->target);
}

std::string DisplacedMeshRenderer::Detail() const {
  const Impl& s = *impl_;
  if (s.slices) {
    const auto& st = s.slices->last_stats();
    return fmt::format("{} volumes, {} slices, {} triangles", st.volumes, st.slices, st.triangles);
  }
  if (s.plan) return fmt::format("{} triangles", s.plan->triangles);
  return fmt::format("{} steps", options_.steps);
}

const render::GroundTruthPlan* DisplacedMeshRenderer::truth_plan() const {
  return impl_->plan ? &*impl_->plan : nullptr;
}

}  // namespace ibr
