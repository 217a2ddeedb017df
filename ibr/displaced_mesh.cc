#include "ibr/displaced_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "capture/synthetic.h"
#include "core/error.h"
#include "core/image_io.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/relief_surface_pass.h"

namespace ibr {
namespace {

struct MethodEntry {
  DisplacementMethod method;
  const char* name;
};
constexpr MethodEntry kMethods[] = {
    {DisplacementMethod::kSlicesSurface, "slices-surface"},
    {DisplacementMethod::kSlicesOrthogonal, "slices-orthogonal"},
    {DisplacementMethod::kSlicesScreen, "slices-screen"},
    {DisplacementMethod::kNcs, "ncs"},
    {DisplacementMethod::kRelief, "relief"},
    {DisplacementMethod::kPom, "pom"},
    {DisplacementMethod::kCrm, "crm"},
    {DisplacementMethod::kTessellated, "tessellated"},
};

bool IsSlicing(DisplacementMethod m) {
  return m == DisplacementMethod::kSlicesSurface || m == DisplacementMethod::kSlicesOrthogonal ||
         m == DisplacementMethod::kSlicesScreen;
}

}  // namespace

DisplacementMethod DisplacementMethodFromName(const std::string& name) {
  for (const MethodEntry& m : kMethods) {
    if (name == m.name) return m.method;
  }
  std::string names;
  for (const std::string& n : DisplacementMethodNames()) names += (names.empty() ? "" : ", ") + n;
  core::ThrowInputError("DisplacementMethodFromName", "unknown method '{}' ({})", name, names);
}

std::string DisplacementMethodName(DisplacementMethod method) {
  for (const MethodEntry& m : kMethods) {
    if (method == m.method) return m.name;
  }
  return "?";
}

std::vector<std::string> DisplacementMethodNames() {
  std::vector<std::string> names;
  for (const MethodEntry& m : kMethods) names.emplace_back(m.name);
  return names;
}

void DisplacedMeshOptions::Check() const {
  if (!(max_displacement > 0 && max_displacement <= 10)) {
    core::ThrowInputError("DisplacedMeshOptions", "max_displacement {} outside (0, 10]",
                          max_displacement);
  }
  if (!(tiling > 0 && tiling <= 1024))
    core::ThrowInputError("DisplacedMeshOptions", "tiling {} outside (0, 1024]", tiling);
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

core::ImageF DisplacementTexels(const DisplacedMeshData& data) {
  core::ImageF texels = render::MakeDisplacementTexels(data.height);
  if (data.color.empty()) return texels;
  const core::Image8& c = data.color;
  const int w = texels.width(), h = texels.height();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // Bilinear at the texel centre, clamped (pixel centres at +0.5).
      const float u = (x + 0.5f) / w * c.width() - 0.5f, v = (y + 0.5f) / h * c.height() - 0.5f;
      const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, c.width() - 1);
      const int y0 = std::clamp(static_cast<int>(std::floor(v)), 0, c.height() - 1);
      const int x1 = std::min(x0 + 1, c.width() - 1), y1 = std::min(y0 + 1, c.height() - 1);
      const float fx = std::clamp(u - std::floor(u), 0.0f, 1.0f),
                  fy = std::clamp(v - std::floor(v), 0.0f, 1.0f);
      for (int k = 0; k < 3; ++k) {
        const int ck = std::min(k, c.channels() - 1);
        const float top = (1 - fx) * c.at(x0, y0, ck) + fx * c.at(x1, y0, ck);
        const float bottom = (1 - fx) * c.at(x0, y1, ck) + fx * c.at(x1, y1, ck);
        texels.at(x, y, k) = ((1 - fy) * top + fy * bottom) / 255.0f;
      }
    }
  }
  return texels;
}

struct DisplacedMeshRenderer::Impl {
  // What the pass draws from (declared before the pass, destroyed after it).
  std::optional<render::Texture> texture;  // RGBA: colour + height (slicing, tessellated)
  std::optional<render::GpuMesh> tessellated;
  size_t tessellated_triangles = 0;
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
  if (m == DisplacementMethod::kNcs || m == DisplacementMethod::kRelief ||
      m == DisplacementMethod::kPom || m == DisplacementMethod::kCrm) {
    if (!data.color.empty()) {
      core::ThrowInputError("DisplacedMeshRenderer",
                            "method {} shades with the base colour: a colour texture is "
                            "not built in this version (use a slicing method or tessellated)",
                            DisplacementMethodName(m));
    }
    render::ReliefGeometryOptions geometry;
    geometry.max_displacement = options_.max_displacement;
    render::DetectPeriodicAxes(data.base, geometry.tangent_maps.wrap_u,
                               geometry.tangent_maps.wrap_v);
    render::ReliefSurfaceOptions o;
    o.method = render::ReliefMethodFromName(DisplacementMethodName(m));
    o.tiling = options_.tiling;
    o.steps = options_.steps;
    s.pass = std::make_unique<render::ReliefSurface>(programs, data.base, data.height, geometry, o);
    return;
  }
  s.texture.emplace(render::UploadDisplacementTexture(DisplacementTexels(data)));
  if (IsSlicing(m)) {
    render::DisplacementPassOptions o;
    o.slicing.family =
        m == DisplacementMethod::kSlicesSurface      ? render::SliceFamily::kSurfaceAligned
        : m == DisplacementMethod::kSlicesOrthogonal ? render::SliceFamily::kOrthogonal
                                                     : render::SliceFamily::kScreen;
    o.slicing.count = options_.slices;
    o.max_displacement = options_.max_displacement;
    o.tiling = options_.tiling;
    auto slices = std::make_unique<render::DisplacementPass>(programs, data.base, *s.texture, o);
    s.slices = slices.get();
    s.pass = std::move(slices);
    return;
  }
  const core::TriangleMesh mesh = render::MakeDisplacedGroundTruth(
      data.base, data.height, options_.max_displacement, options_.tiling);
  s.tessellated_triangles = mesh.triangle_count();
  s.tessellated.emplace(mesh);
  render::MeshPassOptions o;
  o.texture = &*s.texture;
  o.shade = false;  // the texture's colour, as the slicing passes show it
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
  if (s.tessellated) return fmt::format("{} triangles", s.tessellated_triangles);
  return fmt::format("{} steps", options_.steps);
}

}  // namespace ibr
