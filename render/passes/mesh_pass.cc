#include "render/passes/mesh_pass.h"

#include <glm/gtc/type_ptr.hpp>

namespace render {

RenderTargetOptions MeshTargetOptions(int width, int height) {
  return {width, height, {GL_RGBA8, GL_R32F, GL_RGBA16F}, true};
}

void DrawMesh(ProgramCache& programs, const RenderTarget& target, const GpuMesh& mesh,
              const ViewSetup& view, const MeshPassOptions& options) {
  ProgramDesc desc{.vertex = "passes/mesh.vert.glsl", .fragment = "passes/mesh.frag.glsl"};
  if (options.texture) desc.defines.push_back("TEXTURED");
  if (options.shade) desc.defines.push_back("SHADED");
  if (view.orthographic) desc.defines.push_back("ORTHOGRAPHIC");
  const Program& program = programs.Get(desc);

  BeginDepthTestedFrame(target);
  program.Use();
  glUniformMatrix4fv(program.Uniform("u_cam_from_world"), 1, GL_FALSE, glm::value_ptr(view.cam_from_world));
  glUniformMatrix4fv(program.Uniform("u_clip_from_cam"), 1, GL_FALSE, glm::value_ptr(view.clip_from_cam));
  glUniformMatrix4fv(program.Uniform("u_world_from_object"), 1, GL_FALSE,
                     glm::value_ptr(options.world_from_object));
  glUniform4fv(program.Uniform("u_base_color"), 1, glm::value_ptr(options.base_color));
  if (options.texture) glBindTextureUnit(0, options.texture->id());
  mesh.Draw();
  glDisable(GL_DEPTH_TEST);
}

MeshFrame RenderMesh(ProgramCache& programs, const GpuMesh& mesh, const ViewSetup& view, int width,
                     int height, const MeshPassOptions& options) {
  RenderTarget target(MeshTargetOptions(width, height));
  DrawMesh(programs, target, mesh, view, options);
  MeshFrame frame;
  frame.color = target.ReadColor8(0);
  frame.depth = target.ReadChannelsF(1, 1);
  frame.normal = target.ReadChannelsF(2, 3);
  return frame;
}

}  // namespace render
