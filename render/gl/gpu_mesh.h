// A TriangleMesh on the GPU: interleaved position / normal / uv buffer, index
// buffer and vertex array. Attribute locations are fixed project-wide:
// 0 = a_position, 1 = a_normal, 2 = a_uv; optionally 3 = a pass's own
// per-vertex vec2 (the relief pass: curved relief mapping's quadric).
//
// The buffers hold the mesh in VertexCacheOrder: the same triangles (each
// with its own winding) and the same vertices, reordered for the vertex
// cache (GpuMesh::Clustered: then regrouped by ClustersOf). Nothing may rely
// on gl_VertexID or gl_PrimitiveID being the mesh's.
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
// indices. A mesh file's own order often reuses few cached vertices, so
// each triangle re-shades most of its corners; this order lets
// neighbouring triangles share them, and llvmpipe's vertex stage and a GPU's
// post-transform cache both profit (docs/decisions/vertex-cache-order.md).
struct VertexOrder {
  std::vector<uint32_t> indices;       // the triangles, in new vertex numbers
  std::vector<uint32_t> new_from_old;  // per input vertex; kUnused if no triangle uses it
  size_t vertex_count = 0;             // vertices some triangle uses
  static constexpr uint32_t kUnused = ~0u;
};
VertexOrder VertexCacheOrder(const std::vector<uint32_t>& indices, size_t vertex_count);

// A run of a clustered GpuMesh's index buffer (GpuMesh::Clustered):
// meshoptimizer's meshlets (at most 64 vertices and 124 triangles each) of
// the cache-ordered triangles, with their bounds in the mesh's frame.
struct MeshCluster {
  GLsizei first_index = 0, index_count = 0;
  glm::vec3 lo{0.0f}, hi{0.0f};  // box of its vertices
  glm::vec3 center{0.0f};        // bounding sphere
  float radius = 0.0f;
  // Every triangle's normal (counter-clockwise winding) is within
  // acos(cone_cutoff) of cone_axis; cutoff 1 when no cone bounds them.
  glm::vec3 cone_axis{0.0f};
  float cone_cutoff = 1.0f;
  // Whether every triangle faces away from an eye at `eye` (perspective),
  // or from rays along `direction` (orthographic): meshoptimizer's sphere
  // form of the cone test, with a margin for float rounding (conservative:
  // false when in doubt).
  bool FacesAwayFrom(const glm::dvec3& eye) const;
  bool FacesAwayAlong(const glm::dvec3& direction) const;
  // Whether every triangle faces the eye (the same test, axis reversed).
  bool FacesTowards(const glm::dvec3& eye) const;
  bool FacesTowardsAlong(const glm::dvec3& direction) const;
};

// The triangles (`indices`, vertex-cache ordered) regrouped into clusters,
// each a contiguous run of the returned indices; every triangle kept once
// with its winding.
struct ClusterOrder {
  std::vector<uint32_t> indices;
  std::vector<MeshCluster> clusters;
};
ClusterOrder ClustersOf(const std::vector<uint32_t>& indices,
                        const std::vector<glm::vec3>& positions);

class GpuMesh {
 public:
  explicit GpuMesh(const core::TriangleMesh& mesh);
  // With clusters(): the index buffer holds the clusters one after another.
  static GpuMesh Clustered(const core::TriangleMesh& mesh);
  // Also `vertex_data` (one per vertex) at kVertexDataLocation.
  GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>& vertex_data);
  // Issues the indexed draw; binds and unbinds the vertex array.
  void Draw() const;
  GLsizei index_count() const { return index_count_; }
  // Empty unless Clustered.
  const std::vector<MeshCluster>& clusters() const { return clusters_; }
  // Draws the clusters with these indices (ascending; consecutive ones as
  // one run of a multi-draw).
  void DrawClusters(const std::vector<uint32_t>& ids) const;

 private:
  GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>* vertex_data,
          bool clustered);

  Buffer vertices_;
  Buffer indices_;
  Buffer vertex_data_;  // empty without the extra attribute
  VertexArray vao_;
  GLsizei index_count_ = 0;
  std::vector<MeshCluster> clusters_;
  // DrawClusters' multi-draw runs (kept: no allocation a draw once grown).
  mutable std::vector<GLsizei> run_counts_;
  mutable std::vector<const void*> run_offsets_;
};

}  // namespace render
