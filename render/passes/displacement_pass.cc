#include "render/passes/displacement_pass.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>

#include "core/check.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/memory_budget.h"
#include "render/gl/uniform.h"

namespace render {

// ---- displacement textures ----

core::ImageF MakeDisplacementTexels(const core::ImageF& height, float relief) {
  if (height.empty() || height.channels() != 1) {
    core::ThrowInputError("MakeDisplacementTexels",
                          "height map must be a non-empty 1-channel image");
  }
  if (!(relief >= 0) || !std::isfinite(relief)) {
    core::ThrowInputError("MakeDisplacementTexels", "relief {} must be finite and >= 0", relief);
  }
  const int w = height.width(), h = height.height();
  for (float v : height.values()) {
    if (!(v >= 0.0f && v <= 1.0f)) {
      core::ThrowInputError("MakeDisplacementTexels", "height {} outside [0, 1]", v);
    }
  }
  core::CheckMemory(static_cast<std::uint64_t>(w) * h * 4 * sizeof(float), "MakeDisplacementTexels",
                    fmt::format("the {}x{} displacement texels", w, h));
  auto at = [&](int x, int y) { return height.at((x + w) % w, (y + h) % h); };
  const glm::vec3 light = glm::normalize(glm::vec3(-0.45f, -0.55f, 0.7f));
  const glm::vec3 low(0.30f, 0.20f, 0.13f), high(0.95f, 0.86f, 0.62f);
  core::ImageF texels(w, h, 4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float dx = 0.5f * (at(x + 1, y) - at(x - 1, y)) * relief;
      const float dy = 0.5f * (at(x, y + 1) - at(x, y - 1)) * relief;
      const glm::vec3 n = glm::normalize(glm::vec3(-dx, -dy, 1.0f));
      const float light_amount = 0.3f + 0.7f * std::max(0.0f, glm::dot(n, light));
      const float v = at(x, y);
      const glm::vec3 rgb = glm::clamp(light_amount * glm::mix(low, high, v), 0.0f, 1.0f);
      for (int c = 0; c < 3; ++c) texels.at(x, y, c) = rgb[c];
      texels.at(x, y, 3) = v;
    }
  }
  return texels;
}

void DisplacementTextureOptions::Check() const {
  if (internal_format != GL_RGBA8 && internal_format != GL_RGBA32F) {
    core::ThrowInputError("DisplacementTextureOptions",
                          "internal format 0x{:x} is neither RGBA8 nor RGBA32F", internal_format);
  }
}

Texture UploadDisplacementTexture(const core::ImageF& rgba,
                                  const DisplacementTextureOptions& options) {
  options.Check();
  if (rgba.empty() || rgba.channels() != 4) {
    core::ThrowInputError("UploadDisplacementTexture",
                          "texels must be a non-empty 4-channel image");
  }
  // The GL copy (llvmpipe keeps it in system memory) and the RGBA8 staging bytes.
  const std::uint64_t texels = static_cast<std::uint64_t>(rgba.width()) * rgba.height();
  core::CheckMemory(texels * (options.internal_format == GL_RGBA8 ? 8 : 16),
                    "UploadDisplacementTexture",
                    fmt::format("the {}x{} displacement texture", rgba.width(), rgba.height()));
  // Rows go up in GL texture space, but the lookup is by uv with row 0 at
  // v = 0 both here and in the ground truth's SampleHeight*, so the image is
  // uploaded as is (texel (x, y) at uv ((x + 0.5) / w, (y + 0.5) / h)).
  Texture texture = Texture::Create2D(options.internal_format, rgba.width(), rgba.height());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (options.internal_format == GL_RGBA8) {
    std::vector<uint8_t> bytes(rgba.values().size());
    for (size_t i = 0; i < bytes.size(); ++i) {
      bytes[i] =
          static_cast<uint8_t>(std::lround(std::clamp(rgba.values()[i], 0.0f, 1.0f) * 255.0f));
    }
    glTextureSubImage2D(texture.id(), 0, 0, 0, rgba.width(), rgba.height(), GL_RGBA,
                        GL_UNSIGNED_BYTE, bytes.data());
  } else {
    glTextureSubImage2D(texture.id(), 0, 0, 0, rgba.width(), rgba.height(), GL_RGBA, GL_FLOAT,
                        rgba.data());
  }
  const GLint filter = options.linear_filter ? GL_LINEAR : GL_NEAREST;
  glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return texture;
}

Texture UploadColorTexture(const core::Image8& image) {
  if (image.empty() || image.channels() < 1 || image.channels() > 4) {
    core::ThrowInputError("UploadColorTexture", "a colour texture needs 1-4 channels, not {}",
                          image.channels());
  }
  const std::uint64_t texels = static_cast<std::uint64_t>(image.width()) * image.height();
  core::CheckMemory(texels * 8, "UploadColorTexture",  // RGBA8 staging + the GL copy
                    fmt::format("the {}x{} colour texture", image.width(), image.height()));
  std::vector<uint8_t> rgba(texels * 4);
  const int c = image.channels();
  for (std::uint64_t p = 0; p < texels; ++p) {
    const uint8_t* in = image.data() + p * c;
    uint8_t* out = rgba.data() + p * 4;
    // Grey (+ alpha) spreads to RGB; a missing alpha is opaque.
    for (int k = 0; k < 3; ++k) out[k] = in[c >= 3 ? k : 0];
    out[3] = c == 2 ? in[1] : c == 4 ? in[3] : 255;
  }
  Texture texture = Texture::Create2D(GL_RGBA8, image.width(), image.height());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture.id(), 0, 0, 0, image.width(), image.height(), GL_RGBA,
                      GL_UNSIGNED_BYTE, rgba.data());
  for (GLenum p : {GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER})
    glTextureParameteri(texture.id(), p, GL_LINEAR);
  for (GLenum p : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T})
    glTextureParameteri(texture.id(), p, GL_REPEAT);
  return texture;
}

// ---- per-face displacement volumes ----

namespace {

glm::vec3 MeanNormal(const DisplacementVolume& v) {
  // Parallelogram: the fourth corner's normal is n1 + n2 - n0, so the mean of
  // the four corners is (n1 + n2) / 2.
  const glm::vec3 sum = v.triangle ? v.n[0] + v.n[1] + v.n[2] : v.n[1] + v.n[2];
  const float len = glm::length(sum);
  return len > 1e-12f ? sum / len : glm::vec3(0);
}

// A face bounds a volume when it has area and its normals leave the face.
bool BoundsVolume(const DisplacementVolume& v) {
  const glm::vec3 e1 = v.p[1] - v.p[0], e2 = v.p[2] - v.p[0];
  const glm::vec3 cross = glm::cross(e1, e2);
  const float scale = std::max(glm::dot(e1, e1), glm::dot(e2, e2));
  const float area2 = glm::length(cross);
  if (!(scale > 0) || !(area2 > 1e-6f * scale)) return false;
  return glm::dot(MeanNormal(v), cross / area2) > 1e-3f;
}

bool Near(glm::vec3 a, glm::vec3 b, float tolerance) { return glm::length(a - b) <= tolerance; }
bool Near(glm::vec2 a, glm::vec2 b, float tolerance) { return glm::length(a - b) <= tolerance; }

}  // namespace

std::vector<DisplacementVolume> DisplacementVolumesFromMesh(const core::TriangleMesh& base) {
  base.Validate("DisplacementVolumesFromMesh");
  if (base.normals.empty() || base.uvs.empty()) {
    core::ThrowInputError("DisplacementVolumesFromMesh", "the base mesh needs normals and uvs");
  }
  glm::vec3 lo, hi;
  base.Bounds(lo, hi);
  const float tolerance = 1e-5f * std::max(1e-6f, glm::length(hi - lo));
  auto make = [&](uint32_t a, uint32_t b, uint32_t c, bool triangle) {
    DisplacementVolume v;
    const uint32_t ids[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      v.p[k] = base.positions[ids[k]];
      const float len = glm::length(base.normals[ids[k]]);
      v.n[k] = len > 0 ? base.normals[ids[k]] / len : glm::vec3(0);
      v.uv[k] = base.uvs[ids[k]];
    }
    v.triangle = triangle;
    return v;
  };
  std::vector<DisplacementVolume> volumes;
  const auto& ix = base.indices;
  size_t t = 0;
  while (t < base.triangle_count()) {
    // Pair (a, b, d), (a, d, c) sharing the diagonal a-d (core::MakePlane's
    // quads): one parallelogram volume when d = b + c - a in every attribute.
    if (t + 1 < base.triangle_count() && ix[3 * t + 3] == ix[3 * t] &&
        ix[3 * t + 4] == ix[3 * t + 2]) {
      const uint32_t a = ix[3 * t], b = ix[3 * t + 1], d = ix[3 * t + 2], c = ix[3 * t + 5];
      const auto& p = base.positions;
      const auto& n = base.normals;
      const auto& uv = base.uvs;
      if (Near(p[d], p[b] + p[c] - p[a], tolerance) && Near(n[d], n[b] + n[c] - n[a], 1e-5f) &&
          Near(uv[d], uv[b] + uv[c] - uv[a], 1e-6f)) {
        DisplacementVolume v = make(a, b, c, false);
        if (BoundsVolume(v)) volumes.push_back(v);
        t += 2;
        continue;
      }
    }
    DisplacementVolume v = make(ix[3 * t], ix[3 * t + 1], ix[3 * t + 2], true);
    if (BoundsVolume(v)) volumes.push_back(v);
    ++t;
  }
  return volumes;
}

SliceBox DisplacementVolumeBox(const DisplacementVolume& volume, float max_displacement) {
  SliceBox box;
  box.world_from_box = glm::mat4(
      glm::vec4(volume.p[1] - volume.p[0], 0.0f), glm::vec4(volume.p[2] - volume.p[0], 0.0f),
      glm::vec4(max_displacement * MeanNormal(volume), 0.0f), glm::vec4(volume.p[0], 1.0f));
  return box;
}

glm::vec3 DisplacementVolumePoint(const DisplacementVolume& volume, glm::vec3 p_in_box,
                                  float max_displacement) {
  const glm::vec3 base = volume.p[0] + p_in_box.x * (volume.p[1] - volume.p[0]) +
                         p_in_box.y * (volume.p[2] - volume.p[0]);
  glm::vec3 n = volume.n[0] + p_in_box.x * (volume.n[1] - volume.n[0]) +
                p_in_box.y * (volume.n[2] - volume.n[0]);
  const float len = glm::length(n);
  n = len > 1e-12f ? n / len : MeanNormal(volume);
  return base + p_in_box.z * max_displacement * n;
}

// ---- the pass ----

void DisplacementPassOptions::Check() const {
  slicing.Check();
  if (!(max_displacement > 0) || !std::isfinite(max_displacement)) {
    core::ThrowInputError("DisplacementPassOptions", "max_displacement {} must be finite and > 0",
                          max_displacement);
  }
  if (!(tiling > 0) || !(tiling <= 1024)) {
    core::ThrowInputError("DisplacementPassOptions", "tiling {} outside (0, 1024]", tiling);
  }
  if (!(color_tiling > 0) || !(color_tiling <= 1024)) {
    core::ThrowInputError("DisplacementPassOptions", "colour tiling {} outside (0, 1024]",
                          color_tiling);
  }
}

std::vector<std::string> DisplacementPassOptions::Defines(bool orthographic) const {
  std::vector<std::string> defines;
  if (color) {
    defines.push_back("COLOR_TEXTURE");
    if (shade) defines.push_back("SHADED");
    if (orthographic) defines.push_back("ORTHOGRAPHIC");  // the head light's direction
  }
  if (slicing.family == SliceFamily::kSurfaceAligned) defines.push_back("SURFACE_ALIGNED");
  if (slicing.family == SliceFamily::kScreen && slicing.full_size_screen_slices) {
    defines.push_back("FULL_SIZE_SLICES");
  }
  return defines;
}

namespace {

// std430 layout of shaders/displacement.vert.glsl's DisplacementVolume.
struct GpuVolume {
  glm::vec4 p[3];
  glm::vec4 n[3];
  glm::vec4 n_mean;
  glm::vec4 uv01;
  glm::vec4 uv2_triangle;
};
static_assert(sizeof(GpuVolume) == 9 * 16);

// shaders/passes/displacement.{vert,frag}.glsl.
struct DisplacementUniforms {
  explicit DisplacementUniforms(const Program& p)
      : max_displacement(p, "u_max_displacement"),
        tiling(p, "u_tiling"),
        displacement(p, "u_displacement"),
        color_tiling(p, "u_color_tiling"),
        color(p, "u_color") {}
  Uniform<float> max_displacement;
  Uniform<float> tiling;
  Uniform<int> displacement;  // texture unit
  Uniform<float> color_tiling;
  Uniform<int> color;  // texture unit
};

}  // namespace

DisplacementPass::DisplacementPass(ProgramCache& programs, const core::TriangleMesh& base,
                                   const Texture& displacement,
                                   const DisplacementPassOptions& options)
    : programs_(&programs), displacement_(&displacement), options_(options) {
  options_.Check();
  volumes_ = DisplacementVolumesFromMesh(base);
  std::vector<GpuVolume> gpu(std::max<size_t>(1, volumes_.size()));
  for (size_t i = 0; i < volumes_.size(); ++i) {
    const DisplacementVolume& v = volumes_[i];
    boxes_.push_back(DisplacementVolumeBox(v, options_.max_displacement));
    for (int k = 0; k < 3; ++k) {
      gpu[i].p[k] = glm::vec4(v.p[k], 1.0f);
      gpu[i].n[k] = glm::vec4(v.n[k], 0.0f);
    }
    gpu[i].n_mean = glm::vec4(MeanNormal(v), 0.0f);
    gpu[i].uv01 = glm::vec4(v.uv[0], v.uv[1]);
    gpu[i].uv2_triangle = glm::vec4(v.uv[2], v.triangle ? 1.0f : 0.0f, 0.0f);
  }
  volume_data_ =
      Buffer::CreateWithData(gpu.data(), static_cast<GLsizeiptr>(gpu.size() * sizeof(GpuVolume)));
}

void DisplacementPass::SetSlicing(const SlicingOptions& slicing) {
  slicing.Check();
  options_.slicing = slicing;
}

void DisplacementPass::Draw(const RenderTarget& target, const ViewSetup& view) {
  const SlicingOptions& slicing = options_.slicing;
  const bool full_size = slicing.family == SliceFamily::kScreen && slicing.full_size_screen_slices;
  const SliceView slice_view{view.cam_from_world, view.orthographic};
  stacks_.resize(volumes_.size());
  stats_ = {};
  stats_.volumes = static_cast<int>(volumes_.size());
  for (size_t i = 0; i < volumes_.size(); ++i) {
    stacks_[i] = MakeSlices(boxes_[i], slice_view, slicing);
    if (volumes_[i].triangle && !full_size) {
      // Cut the parallelogram box's slices down to the face (box x + y <= 1);
      // full-size slices keep their extra fill and are masked in the shader.
      auto& slices = stacks_[i].slices;
      for (Slice& s : slices)
        s.p_in_box = ClipPolygonToHalfSpace(s.p_in_box, glm::vec3(1, 1, 0), 1.0f);
      slices.erase(std::remove_if(slices.begin(), slices.end(),
                                  [](const Slice& s) { return s.p_in_box.empty(); }),
                   slices.end());
    }
    stats_.slices += static_cast<int>(stacks_[i].slices.size());
  }
  slices_.UploadVolumes(stacks_);
  stats_.triangles = slices_.triangle_count();

  const Program& program = programs_->Get({.vertex = "passes/displacement.vert.glsl",
                                           .fragment = "passes/displacement.frag.glsl",
                                           .defines = options_.Defines(view.orthographic)});
  UseProgram(target, program, view);
  const auto& u = program.Typed<DisplacementUniforms>();
  u.max_displacement.Set(options_.max_displacement);
  u.tiling.Set(options_.tiling);
  u.displacement.Set(0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, volume_data_.id());
  glBindTextureUnit(0, displacement_->id());
  if (options_.color) {
    u.color_tiling.Set(options_.color_tiling);
    u.color.Set(1);
    glBindTextureUnit(1, options_.color->id());
  }
  Query query;
  const bool count = count_fragments_ && epoxy_has_gl_extension("GL_ARB_pipeline_statistics_query");
  if (count) {
    GLuint id = 0;
    glGenQueries(1, &id);  // glCreateQueries rejects this target on Mesa 22
    query = Query(id);
    glBeginQuery(GL_FRAGMENT_SHADER_INVOCATIONS_ARB, query.id());
  }
  slices_.DrawAllBatched();
  if (count) {
    glEndQuery(GL_FRAGMENT_SHADER_INVOCATIONS_ARB);
    GLuint64 invocations = 0;
    glGetQueryObjectui64v(query.id(), GL_QUERY_RESULT, &invocations);
    stats_.fragments = static_cast<double>(invocations);
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
}

// ---- the ground truth ----

// Per vertex: the CPU mesh's position, normal and uv (32 B), GpuMesh's remap
// entry and interleaved copy (36 B), the driver's buffer (32 B) and
// meshoptimizer's cache-optimiser state (about 24 B). Per triangle: three
// indices in the CPU mesh, the optimiser's reordered and remapped copies,
// GpuMesh's copy and the driver's buffer (5 x 12 B) and the optimiser's
// adjacency (about 24 B). An overestimate: some of these are freed before
// the next is made.
constexpr std::uint64_t kTruthBytesPerVertex = 128;
constexpr std::uint64_t kTruthBytesPerTriangle = 84;

std::uint64_t GroundTruthBytes(std::uint64_t faces, int subdivisions) {
  const std::uint64_t s = static_cast<std::uint64_t>(subdivisions);
  return faces * ((s + 1) * (s + 2) / 2 * kTruthBytesPerVertex + s * s * kTruthBytesPerTriangle);
}

std::string GroundTruthPlan::Describe() const {
  std::string line = fmt::format(
      "{} subdivisions per face edge ({} faces, {} triangles, {}), a subdivided edge spans up to "
      "{:.2f} height texels",
      subdivisions, faces, triangles, core::FormatBytes(bytes), texels_per_edge);
  if (limited()) {
    line += fmt::format("; the memory budget ({}) limits it from {}",
                        core::FormatBytes(core::MemoryBudgetBytes()), wanted_subdivisions);
  }
  if (span_texels > static_cast<float>(kMaxGroundTruthSubdivisions)) {
    line += fmt::format("; one texel per edge would need {:.0f} (over the cap of {})",
                        std::ceil(span_texels), kMaxGroundTruthSubdivisions);
  }
  return line;
}

GroundTruthPlan PlanDisplacedGroundTruth(const core::TriangleMesh& base, int texels, float tiling) {
  base.Validate("PlanDisplacedGroundTruth");
  if (base.uvs.empty() || texels < 1 || !(tiling > 0)) {
    core::ThrowInputError("PlanDisplacedGroundTruth",
                          "needs a base mesh with uvs, a height map and tiling > 0");
  }
  float longest_uv_edge = 0;
  for (size_t t = 0; t < base.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const glm::vec2 a = base.uvs[base.indices[3 * t + k]],
                      b = base.uvs[base.indices[3 * t + (k + 1) % 3]];
      longest_uv_edge = std::max(longest_uv_edge, glm::length(b - a));
    }
  }
  GroundTruthPlan plan;
  plan.faces = static_cast<int>(base.triangle_count());
  const double span_texels = static_cast<double>(longest_uv_edge) * tiling * texels;
  plan.wanted_subdivisions = static_cast<int>(
      std::clamp(std::ceil(span_texels), 1.0, static_cast<double>(kMaxGroundTruthSubdivisions)));
  const std::uint64_t faces = base.triangle_count();
  // Also within what one indexed draw addresses: 32-bit indices and a
  // GLsizei index count.
  auto fits = [&](int s) {
    const std::uint64_t triangles = faces * s * s;
    const std::uint64_t vertices = faces * (s + 1) * (s + 2) / 2;
    return 3 * triangles <= 0x7fffffffull && vertices <= 0xffffffffull &&
           core::FitsMemory(GroundTruthBytes(faces, s));
  };
  int s = plan.wanted_subdivisions;
  if (!fits(s)) {
    int lo = 1, hi = s;  // fits(lo) unless even one subdivision does not fit
    while (lo + 1 < hi) {
      const int mid = (lo + hi) / 2;
      (fits(mid) ? lo : hi) = mid;
    }
    s = lo;
  }
  plan.subdivisions = s;
  plan.triangles = faces * s * s;
  plan.vertices = faces * (s + 1) * (s + 2) / 2;
  plan.bytes = GroundTruthBytes(faces, s);
  plan.span_texels = static_cast<float>(span_texels);
  plan.texels_per_edge = static_cast<float>(span_texels / s);
  if (3 * plan.triangles > 0x7fffffffull) {
    core::ThrowInputError("PlanDisplacedGroundTruth",
                          "the tessellated truth of {} faces has more triangles than one draw "
                          "can address ({})",
                          faces, plan.triangles);
  }
  core::CheckMemory(plan.bytes, "PlanDisplacedGroundTruth",
                    fmt::format("the tessellated truth ({} faces at {} subdivision per edge, {} "
                                "triangles)",
                                faces, s, plan.triangles));
  return plan;
}

core::TriangleMesh MakeDisplacedGroundTruth(const core::TriangleMesh& base,
                                            const core::ImageF& height, float max_displacement,
                                            float tiling) {
  if (height.empty()) {
    core::ThrowInputError("MakeDisplacedGroundTruth", "needs a non-empty height map");
  }
  return MakeDisplacedGroundTruth(
      base, height, max_displacement, tiling,
      PlanDisplacedGroundTruth(base, std::max(height.width(), height.height()), tiling), tiling);
}

core::TriangleMesh MakeDisplacedGroundTruth(const core::TriangleMesh& base,
                                            const core::ImageF& height, float max_displacement,
                                            float tiling, const GroundTruthPlan& plan,
                                            float uv_scale) {
  base.Validate("MakeDisplacedGroundTruth");
  if (base.uvs.empty() || height.empty()) {
    core::ThrowInputError("MakeDisplacedGroundTruth",
                          "needs a base mesh with uvs and a non-empty height map");
  }
  core::DisplacedMeshOptions options;
  options.max_displacement = max_displacement;
  options.tiling = tiling;
  options.subdivisions = plan.subdivisions;
  options.bilinear = true;
  core::TriangleMesh mesh = core::TessellateDisplaced(base, height, options);
  for (glm::vec2& uv : mesh.uvs) uv *= uv_scale;
  return mesh;
}

}  // namespace render
