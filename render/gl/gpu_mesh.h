// A TriangleMesh on the GPU: interleaved position / normal / uv buffer, index
// buffer and vertex array. Attribute locations are fixed project-wide:
// 0 = a_position, 1 = a_normal, 2 = a_uv; optionally 3 = a pass's own
// per-vertex vec2 (the relief pass: curved relief mapping's quadric).
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "core/mesh.h"
#include "render/gl/handles.h"

namespace render {

inline constexpr GLuint kPositionLocation = 0;
inline constexpr GLuint kNormalLocation = 1;
inline constexpr GLuint kUvLocation = 2;
inline constexpr GLuint kVertexDataLocation = 3;

class GpuMesh {
 public:
  explicit GpuMesh(const core::TriangleMesh& mesh);
  // Also `vertex_data` (one per vertex) at kVertexDataLocation.
  GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>& vertex_data);
  // Issues the indexed draw; binds and unbinds the vertex array.
  void Draw() const;
  GLsizei index_count() const { return index_count_; }

 private:
  Buffer vertices_;
  Buffer indices_;
  Buffer vertex_data_;  // empty without the extra attribute
  VertexArray vao_;
  GLsizei index_count_ = 0;
};

}  // namespace render
