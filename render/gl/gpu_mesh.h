// A TriangleMesh on the GPU: interleaved position / normal / uv buffer, index
// buffer and vertex array. Attribute locations are fixed project-wide:
// 0 = a_position, 1 = a_normal, 2 = a_uv; optionally 3 = a pass's own
// per-vertex vec2 (the relief pass: curved relief mapping's quadric).
//
// The buffers hold the mesh in VertexCacheOrder: the same triangles (each
// with its own winding) and the same vertices, reordered for the vertex
// cache. Nothing may rely on gl_VertexID or gl_PrimitiveID being the mesh's.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "core/mesh.h"
#include "render/gl/handles.h"

namespace render {

inline constexpr GLuint kPositionLocation = 0;
inline constexpr GLuint kNormalLocation = 1;
inline constexpr GLuint kUvLocation = 2;
inline constexpr GLuint kVertexDataLocation = 3;

// Triangles reordered for the post-transform vertex cache
// (meshopt_optimizeVertexCache), vertices renumbered in order of first use
// (meshopt_optimizeVertexFetchRemap) so that nearby triangles read nearby
// indices. Through a 16-entry FIFO cache model the Stanford bunny's file
// order shades 2.08 vertices a triangle, this order 0.68; on llvmpipe its
// 512 px render took 24.9 -> 20.1 ms a frame.
struct VertexOrder {
  std::vector<uint32_t> indices;       // the triangles, in new vertex numbers
  std::vector<uint32_t> new_from_old;  // per input vertex; kUnused if no triangle uses it
  size_t vertex_count = 0;             // vertices some triangle uses
  static constexpr uint32_t kUnused = ~0u;
};
VertexOrder VertexCacheOrder(const std::vector<uint32_t>& indices, size_t vertex_count);

class GpuMesh {
 public:
  explicit GpuMesh(const core::TriangleMesh& mesh);
  // Also `vertex_data` (one per vertex) at kVertexDataLocation.
  GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>& vertex_data);
  // Issues the indexed draw; binds and unbinds the vertex array.
  void Draw() const;
  GLsizei index_count() const { return index_count_; }

 private:
  GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>* vertex_data);

  Buffer vertices_;
  Buffer indices_;
  Buffer vertex_data_;  // empty without the extra attribute
  VertexArray vao_;
  GLsizei index_count_ = 0;
};

}  // namespace render
