#include "render/passes/mesh_pass.h"

#include <cmath>

#include "core/error.h"
#include "render/gl/uniform.h"

namespace render {

namespace {

// shaders/passes/mesh.{vert,frag}.glsl.
struct MeshUniforms {
  explicit MeshUniforms(const Program& p)
      : world_from_object(p, "u_world_from_object"), base_color(p, "u_base_color") {}
  Uniform<glm::mat4> world_from_object;
  Uniform<glm::vec4> base_color;
};

}  // namespace

void MeshPassOptions::Check() const {
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(base_color[i]))
      core::ThrowInputError("MeshPassOptions", "base colour is not finite");
    for (int j = 0; j < 4; ++j) {
      if (!std::isfinite(world_from_object[i][j])) {
        core::ThrowInputError("MeshPassOptions", "world_from_object is not finite");
      }
    }
  }
}

std::vector<std::string> MeshPassOptions::Defines(bool orthographic) const {
  std::vector<std::string> defines;
  if (texture) defines.push_back("TEXTURED");
  if (shade) defines.push_back("SHADED");
  if (orthographic) defines.push_back("ORTHOGRAPHIC");
  return defines;
}

MeshPass::MeshPass(ProgramCache& programs, const GpuMesh& mesh, const MeshPassOptions& options)
    : programs_(&programs), mesh_(&mesh), options_(options) {
  options_.Check();
}

void MeshPass::Draw(const RenderTarget& target, const ViewSetup& view) {
  const Program& program = programs_->Get({.vertex = "passes/mesh.vert.glsl",
                                           .fragment = "passes/mesh.frag.glsl",
                                           .defines = options_.Defines(view.orthographic)});
  UseProgram(target, program, view);
  const auto& u = program.Typed<MeshUniforms>();
  u.world_from_object.Set(options_.world_from_object);
  u.base_color.Set(options_.base_color);
  if (options_.texture) glBindTextureUnit(0, options_.texture->id());
  mesh_->Draw();
}

Frame RenderMesh(ProgramCache& programs, const GpuMesh& mesh, const ViewSetup& view, int width,
                 int height, const MeshPassOptions& options) {
  MeshPass pass(programs, mesh, options);
  return RenderFrame(pass, view, width, height);
}

}  // namespace render
