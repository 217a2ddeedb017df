#include "render/passes/relief_surface_pass.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <vector>

#include "core/error.h"
#include "core/memory_budget.h"
#include "core/surface_quadric.h"
#include "render/gl/uniform.h"

namespace render {

ReliefMethod ReliefMethodFromName(const std::string& name) {
  return core::EnumFromName(kReliefMethodNames, name, "ReliefMethodFromName", "method");
}

std::string ReliefMethodName(ReliefMethod method) {
  return std::string(core::EnumToName(kReliefMethodNames, method));
}

void ReliefGeometryOptions::Check() const {
  if (!std::isfinite(max_displacement) || !(max_displacement > 0)) {
    core::ThrowInputError("ReliefGeometryOptions", "max_displacement {} must be finite and > 0",
                          max_displacement);
  }
  tangent_maps.Check();
}

void ReliefSurfaceOptions::Check() const {
  if (steps < 1 || steps > 65536)
    core::ThrowInputError("ReliefSurfaceOptions", "steps {} outside 1..65536", steps);
  if (!std::isfinite(step_enlargement) || step_enlargement < 0.01f || step_enlargement > 1000) {
    core::ThrowInputError("ReliefSurfaceOptions", "step enlargement c = {} outside [0.01, 1000]",
                          step_enlargement);
  }
  // pom_min_steps above `steps` is used as min(pom_min_steps, steps), so
  // `--steps 1` needs no second option.
  if (pom_min_steps < 1)
    core::ThrowInputError("ReliefSurfaceOptions", "pom_min_steps {} < 1", pom_min_steps);
  if (!std::isfinite(tiling) || tiling <= 0 || tiling > 1024) {
    core::ThrowInputError("ReliefSurfaceOptions", "tiling {} outside (0, 1024]", tiling);
  }
  if (!std::isfinite(color_tiling) || color_tiling <= 0 || color_tiling > 1024) {
    core::ThrowInputError("ReliefSurfaceOptions", "colour tiling {} outside (0, 1024]",
                          color_tiling);
  }
  if (!(min_view_cos > 0 && min_view_cos <= 1)) {
    core::ThrowInputError("ReliefSurfaceOptions", "min_view_cos {} outside (0, 1]", min_view_cos);
  }
  if (step_policy == RayStepPolicy::kJacobian) {
    core::ThrowInputError("ReliefSurfaceOptions",
                          "the Jacobian step policy needs a warp; use fixed or threshold");
  }
  RayCore().Check();
}

RayCoreOptions ReliefSurfaceOptions::RayCore() const {
  RayCoreOptions core;
  core.max_steps = steps;
  core.refine_steps = refine_steps;
  core.step_policy = step_policy;
  core.threshold = threshold;
  core.refinement =
      method == ReliefMethod::kPom ? RayRefinement::kSecant : RayRefinement::kBisection;
  if (step_policy == RayStepPolicy::kThreshold) {
    // Finer steps need more of them to cross the same shell.
    core.max_steps = steps * 4;
    core.fine_step_scale = 0.25f;
  }
  return core;
}

core::TriangleMesh MakeReliefShell(const core::TriangleMesh& base, float max_displacement) {
  base.Validate("MakeReliefShell");
  if (base.normals.empty() || base.uvs.empty()) {
    core::ThrowInputError("MakeReliefShell", "the base mesh needs normals and uvs");
  }
  core::TriangleMesh shell = base;
  for (size_t i = 0; i < shell.positions.size(); ++i) {
    shell.positions[i] += max_displacement * glm::normalize(base.normals[i]);
  }
  return shell;
}

std::vector<glm::vec2> ReliefVertexQuadrics(const core::TriangleMesh& base,
                                            const TangentFrames& frames) {
  std::vector<glm::vec3> bitangents(base.positions.size());
  for (size_t k = 0; k < bitangents.size(); ++k) {
    bitangents[k] =
        frames.handedness[k] * glm::cross(glm::normalize(base.normals[k]), frames.tangents[k]);
  }
  return core::FitVertexQuadrics(base, frames.tangents, bitangents);
}

namespace {
Texture UploadHeight(const core::ImageF& height, bool bilinear) {
  if (height.empty() || height.channels() != 1) {
    core::ThrowInputError("ReliefSurface", "height map must be a non-empty 1-channel image");
  }
  for (float v : height.values()) {
    if (!(v >= 0.0f && v <= 1.0f))
      core::ThrowInputError("ReliefSurface", "height {} outside [0, 1]", v);
  }
  core::CheckMemory(static_cast<std::uint64_t>(height.width()) * height.height() * sizeof(float),
                    "ReliefSurface",
                    fmt::format("the {}x{} height texture", height.width(), height.height()));
  Texture tex = Texture::Create2D(GL_R32F, height.width(), height.height());
  // Row y of the image is v = (y + 0.5) / n (core::MakeHeightMap), which is
  // GL's texel row y: upload unflipped.
  glTextureSubImage2D(tex.id(), 0, 0, 0, height.width(), height.height(), GL_RED, GL_FLOAT,
                      height.data());
  const GLint filter = bilinear ? GL_LINEAR : GL_NEAREST;
  glTextureParameteri(tex.id(), GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(tex.id(), GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return tex;
}

// shaders/passes/relief_surface.{vert,frag}.glsl.
struct ReliefUniforms {
  explicit ReliefUniforms(const Program& p)
      : cam_from_object(p, "u_cam_from_object"),
        clip_from_cam(p, "u_clip_from_cam"),
        world_normal_from_object(p, "u_world_normal_from_object"),
        eye_in_object(p, "u_eye_in_object"),
        view_dir_in_object(p, "u_view_dir_in_object"),
        max_displacement(p, "u_max_displacement"),
        tiling(p, "u_tiling"),
        step_enlargement(p, "u_step_enlargement"),
        min_view_cos(p, "u_min_view_cos"),
        steps(p, "u_steps"),
        pom_min_steps(p, "u_pom_min_steps"),
        base_color(p, "u_base_color"),
        height(p, "u_height"),
        normal_map(p, "u_normal_map"),
        tangent_map(p, "u_tangent_map"),
        color(p, "u_color"),
        color_tiling(p, "u_color_tiling") {}
  Uniform<glm::mat4> cam_from_object;
  Uniform<glm::mat4> clip_from_cam;
  Uniform<glm::mat3> world_normal_from_object;
  Uniform<glm::vec3> eye_in_object;
  Uniform<glm::vec3> view_dir_in_object;
  Uniform<float> max_displacement;
  Uniform<float> tiling;
  Uniform<float> step_enlargement;
  Uniform<float> min_view_cos;
  Uniform<int> steps;
  Uniform<int> pom_min_steps;
  Uniform<glm::vec4> base_color;
  Uniform<int> height;  // texture units from here on
  Uniform<int> normal_map;
  Uniform<int> tangent_map;
  Uniform<int> color;
  Uniform<float> color_tiling;
};

}  // namespace

ReliefSurface::ReliefSurface(ProgramCache& programs, const core::TriangleMesh& base,
                             const core::ImageF& height, const ReliefGeometryOptions& options,
                             const ReliefSurfaceOptions& surface)
    : ReliefSurface(programs, base, height, options, surface,
                    ComputeTangentFrames(
                        base, (options.Check(), surface.Check(), options.tangent_maps.max_scale))) {
}

ReliefSurface::ReliefSurface(ProgramCache& programs, const core::TriangleMesh& base,
                             const core::ImageF& height, const ReliefGeometryOptions& options,
                             const ReliefSurfaceOptions& surface, const TangentFrames& frames)
    : programs_(&programs),
      geometry_(options),
      options_(surface),
      shell_(MakeReliefShell(base, options.max_displacement), ReliefVertexQuadrics(base, frames)),
      height_(UploadHeight(height, options.height_bilinear)),
      maps_(RenderTangentMaps(programs, base, options.tangent_maps, frames)) {}

std::vector<std::string> ReliefSurfaceOptions::Defines(const ReliefGeometryOptions& geometry,
                                                       bool orthographic,
                                                       bool color_texture) const {
  std::vector<std::string> defines = RayCoreDefines(RayCore());
  switch (method) {
    case ReliefMethod::kNcs:
      defines.push_back("METHOD_NCS");
      break;
    case ReliefMethod::kRelief:
      defines.push_back("METHOD_RELIEF");
      break;
    case ReliefMethod::kPom:
      defines.push_back("METHOD_POM");
      break;
    case ReliefMethod::kCrm:
      defines.push_back("METHOD_CRM");
      break;
  }
  if (orthographic) defines.push_back("ORTHOGRAPHIC");
  if (shade) defines.push_back("SHADED");
  if (color_texture) defines.push_back("COLOR_TEXTURE");
  if (geometry.tangent_maps.wrap_u) defines.push_back("WRAP_U");
  if (geometry.tangent_maps.wrap_v) defines.push_back("WRAP_V");
  if (geometry.tangent_maps.pole_u0) defines.push_back("POLE_U0");
  if (geometry.tangent_maps.pole_u1) defines.push_back("POLE_U1");
  if (geometry.tangent_maps.pole_v0) defines.push_back("POLE_V0");
  if (geometry.tangent_maps.pole_v1) defines.push_back("POLE_V1");
  if (mark_early_termination && method == ReliefMethod::kNcs)
    defines.push_back("MARK_EARLY_TERMINATION");
  return defines;
}

void ReliefSurface::SetOptions(const ReliefSurfaceOptions& options) {
  options.Check();
  options_ = options;
}

Frame ReliefSurface::Render(const ViewSetup& view, int width, int height,
                            const ReliefSurfaceOptions& options) {
  SetOptions(options);
  return RenderFrame(*this, view, width, height);
}

void ReliefSurface::Draw(const RenderTarget& target, const ViewSetup& view) {
  const ReliefSurfaceOptions& options = options_;
  const RayCoreOptions core = options.RayCore();
  const Program& program =
      programs_->Get({.vertex = "passes/relief_surface.vert.glsl",
                      .fragment = "passes/relief_surface.frag.glsl",
                      .defines = options.Defines(geometry_, view.orthographic, color_ != nullptr)});

  const glm::mat4 cam_from_object = view.cam_from_world * options.world_from_object;
  const glm::mat4 object_from_cam = glm::inverse(cam_from_object);
  const glm::vec3 eye_in_object = glm::vec3(object_from_cam * glm::vec4(0, 0, 0, 1));
  const glm::vec3 view_dir_in_object =
      glm::normalize(glm::mat3(object_from_cam) * glm::vec3(0, 0, 1));
  const glm::mat3 world_normal_from_object =
      glm::transpose(glm::inverse(glm::mat3(options.world_from_object)));

  target.Bind();
  program.Use();
  SetRayCoreUniforms(program, core);
  const auto& u = program.Typed<ReliefUniforms>();
  u.cam_from_object.Set(cam_from_object);
  u.clip_from_cam.Set(view.clip_from_cam);
  u.world_normal_from_object.Set(world_normal_from_object);
  u.eye_in_object.Set(eye_in_object);
  u.view_dir_in_object.Set(view_dir_in_object);
  u.max_displacement.Set(geometry_.max_displacement);
  u.tiling.Set(options.tiling);
  u.step_enlargement.Set(options.step_enlargement);
  u.min_view_cos.Set(options.min_view_cos);
  u.steps.Set(options.steps);
  u.pom_min_steps.Set(std::min(options.pom_min_steps, options.steps));
  u.base_color.Set(options.base_color);
  u.height.Set(0);
  u.normal_map.Set(1);
  u.tangent_map.Set(2);
  glBindTextureUnit(0, height_.id());
  glBindTextureUnit(1, maps_.normal_map.id());
  glBindTextureUnit(2, maps_.tangent_map.id());
  if (color_) {
    u.color.Set(3);
    u.color_tiling.Set(options.color_tiling);
    glBindTextureUnit(3, color_->id());
  }
  BindOutcomeImage(target);  // every ray ORs its outcome, discarded ones too
  shell_.Draw();
}

}  // namespace render
