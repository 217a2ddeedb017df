// Rasterises a mesh as seen by a camera into a frame (render/passes/pass.h):
// shaded colour, camera z, world-space normals, outcome 0. The plain reference
// renderer: synthetic capture, ground truth for the displacement passes, and
// the opaque objects of a scene.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/image.h"
#include "render/gl/gpu_mesh.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"

namespace render {

struct MeshPassOptions {
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // RGBA, used when there is no texture
  const Texture* texture = nullptr;  // RGBA8 2D texture looked up by uv (TEXTURED variant)
  bool shade = true;                 // Lambert with a head light; off = flat base/texture colour
  glm::mat4 world_from_object{1.0f};
  void Check() const;
  // The shader variant these options need (the one place options become #defines).
  std::vector<std::string> Defines(bool orthographic) const;
};

// Draws a GpuMesh the caller keeps alive for the pass's lifetime.
class MeshPass final : public Pass {
 public:
  MeshPass(ProgramCache& programs, const GpuMesh& mesh, const MeshPassOptions& options = {});
  std::string_view name() const override { return "mesh"; }
  void Draw(const RenderTarget& target, const ViewSetup& view) override;
  const MeshPassOptions& options() const { return options_; }

 private:
  ProgramCache* programs_;
  const GpuMesh* mesh_;
  MeshPassOptions options_;
};

// One frame of one mesh: BeginFrame on a fresh frame target, MeshPass::Draw,
// ReadFrame.
Frame RenderMesh(ProgramCache& programs, const GpuMesh& mesh, const ViewSetup& view, int width,
                 int height, const MeshPassOptions& options = {});

}  // namespace render
