// Rasterises a mesh as seen by a camera: shaded colour (RGBA8), camera-space
// depth (R32F camera z, 0 where empty), and world-space normals.
// The plain reference renderer: synthetic capture, ground truth for the
// displacement passes, and the demo scene.
#pragma once

#include <glm/glm.hpp>

#include "core/image.h"
#include "render/gl/gpu_mesh.h"
#include "render/gl/render_target.h"
#include "render/passes/pass.h"
#include "render/gl/shader_program.h"

namespace render {


struct MeshPassOptions {
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // RGBA, used when there is no texture
  const Texture* texture = nullptr;  // RGBA8 2D texture looked up by uv (TEXTURED variant)
  bool shade = true;                 // Lambert with a head light; off = flat base/texture colour
  glm::mat4 world_from_object{1.0f};
};

// Frame outputs read back to the CPU.
struct MeshFrame {
  core::Image8 color;   // RGBA8, alpha 255 where covered
  core::ImageF depth;   // 1 channel camera z, 0 where empty
  core::ImageF normal;  // 3 channels world-space unit normal, 0 where empty
};

// A render target with attachments RGBA8 colour, R32F depth, RGBA16F normal.
RenderTargetOptions MeshTargetOptions(int width, int height);

// Draws into `target` (made with MeshTargetOptions) after clearing it.
void DrawMesh(ProgramCache& programs, const RenderTarget& target, const GpuMesh& mesh,
              const ViewSetup& view, const MeshPassOptions& options = {});

// DrawMesh + readback.
MeshFrame RenderMesh(ProgramCache& programs, const GpuMesh& mesh, const ViewSetup& view,
                     int width, int height, const MeshPassOptions& options = {});

}  // namespace render
