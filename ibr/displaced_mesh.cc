#include "ibr/displaced_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

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
  capture::SceneMesh scene = capture::LoadSceneMesh(path);
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

void DisplacementOrbit::Check() const {
  constexpr const char* kWhere = "DisplacementOrbit";
  if (!(elevation_deg >= -90 && elevation_deg <= 90) || !std::isfinite(azimuth_deg)) {
    core::ThrowInputError(kWhere, "elevation {} outside [-90, 90] or azimuth {} not finite",
                          elevation_deg, azimuth_deg);
  }
  if (!(distance >= 0) || !std::isfinite(distance)) {
    core::ThrowInputError(kWhere, "distance {} must be finite and >= 0 (0 = framed)", distance);
  }
  if (!(fov_deg > 0 && fov_deg < 180))
    core::ThrowInputError(kWhere, "field of view {} degrees outside (0, 180)", fov_deg);
  if (!(glm::length(up) > 0.5f)) core::ThrowInputError(kWhere, "the up axis must be a unit axis");
}

glm::vec3 UpAxisFromName(const std::string& name, std::string_view where) {
  const bool negative = name.size() == 2 && name[0] == '-';
  const std::string axis = negative ? name.substr(1) : name;
  glm::vec3 up(0);
  if (axis == "x") up.x = 1;
  if (axis == "y") up.y = 1;
  if (axis == "z") up.z = 1;
  if (axis.size() != 1 || up == glm::vec3(0)) {
    core::ThrowInputError(where, "up axis '{}' is none of x, y, z, -x, -y, -z", name);
  }
  return negative ? -up : up;
}

render::ViewSetup DisplacementOrbitView(const core::TriangleMesh& base, float max_displacement,
                                        const DisplacementOrbit& orbit, int size_px) {
  orbit.Check();
  if (size_px < 1)
    core::ThrowInputError("DisplacementOrbitView", "size {} px must be >= 1", size_px);
  glm::vec3 lo, hi;
  base.Bounds(lo, hi);
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = 0.5f * glm::length(hi - lo) + max_displacement;
  const double half_fov = 0.5 * orbit.fov_deg * std::numbers::pi / 180.0;
  const double distance = orbit.distance > 0 ? orbit.distance : radius / std::sin(half_fov);
  // A right-handed frame around `up`: h1 the next axis after up's, h2 = up x h1
  // (up z: h1 x, h2 y, the orbit every earlier version used).
  const glm::vec3 up = glm::normalize(orbit.up);
  const int axis = std::abs(up.x) > 0.5f ? 0 : std::abs(up.y) > 0.5f ? 1 : 2;
  glm::vec3 h1(0);
  h1[(axis + 1) % 3] = 1;
  const glm::vec3 h2 = glm::cross(up, h1);
  const double el = orbit.elevation_deg * std::numbers::pi / 180.0,
               az = orbit.azimuth_deg * std::numbers::pi / 180.0;
  const glm::vec3 horizontal =
      static_cast<float>(std::cos(az)) * h1 + static_cast<float>(std::sin(az)) * h2;
  const glm::vec3 to_eye =
      static_cast<float>(std::cos(el)) * horizontal + static_cast<float>(std::sin(el)) * up;
  // The camera's up: perpendicular to the view, towards `up` (away from the eye at a top view).
  const glm::vec3 cam_up =
      -static_cast<float>(std::sin(el)) * horizontal + static_cast<float>(std::cos(el)) * up;
  render::ViewSetup view;
  view.cam_from_world =
      core::CamFromWorldLookAt(centre + static_cast<float>(distance) * to_eye, centre, cam_up);
  const double f = size_px / (2.0 * std::tan(half_fov));
  // Near at most 1.5 radii in front of the centre, never at or behind the
  // eye (an eye inside the bounds sees from 1/1000 of its distance on).
  view.clip_from_cam = core::ClipFromCamPerspective(
      f, f, size_px / 2.0, size_px / 2.0, size_px, size_px,
      std::max(1e-3 * distance, distance - 1.5 * radius), distance + 1.5 * radius);
  return view;
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
    render::DetectPeriodicAxes(data.base, geometry.tangent_maps.wrap_u,
                               geometry.tangent_maps.wrap_v);
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
