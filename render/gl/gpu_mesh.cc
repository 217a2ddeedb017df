#include "render/gl/gpu_mesh.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "core/check.h"
#include "core/error.h"

namespace render {

namespace {
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};

// One GL buffer holding `values` (one dummy element when empty: zero-size
// storage is invalid in GL).
template <typename T>
Buffer BufferOf(const std::vector<T>& values) {
  const T dummy{};
  return Buffer::CreateWithData(
      values.empty() ? &dummy : values.data(),
      static_cast<GLsizeiptr>(std::max<size_t>(1, values.size()) * sizeof(T)));
}
}  // namespace

VertexOrder VertexCacheOrder(const std::vector<uint32_t>& indices, size_t vertex_count) {
  VertexOrder order;
  std::vector<uint32_t> reordered(indices.size());
  meshopt_optimizeVertexCache(reordered.data(), indices.data(), indices.size(), vertex_count);
  order.new_from_old.resize(vertex_count);
  order.vertex_count = meshopt_optimizeVertexFetchRemap(order.new_from_old.data(), reordered.data(),
                                                        reordered.size(), vertex_count);
  order.indices.resize(reordered.size());
  meshopt_remapIndexBuffer(order.indices.data(), reordered.data(), reordered.size(),
                           order.new_from_old.data());
  return order;
}

namespace {
// dot(c - e, a) >= cutoff |c - e| + r: every point p of the sphere (centre
// c, radius r) sees every normal n of the cone (axis a) with
// dot(p - e, n) > 0, i.e. facing away from e; with a margin for rounding.
bool ConeFacesAway(const MeshCluster& c, const glm::dvec3& axis, const glm::dvec3& eye) {
  const glm::dvec3 to_center = glm::dvec3(c.center) - eye;
  const double d = glm::length(to_center);
  return c.cone_cutoff < 1.0f &&
         glm::dot(to_center, axis) >= c.cone_cutoff * d + c.radius + 1e-5 * (d + c.radius);
}
bool ConeFacesAwayAlong(const MeshCluster& c, const glm::dvec3& axis, const glm::dvec3& direction) {
  return c.cone_cutoff < 1.0f && glm::dot(glm::normalize(direction), axis) >= c.cone_cutoff + 1e-5;
}
}  // namespace

bool MeshCluster::FacesAwayFrom(const glm::dvec3& eye) const {
  return ConeFacesAway(*this, glm::dvec3(cone_axis), eye);
}
bool MeshCluster::FacesAwayAlong(const glm::dvec3& direction) const {
  return ConeFacesAwayAlong(*this, glm::dvec3(cone_axis), direction);
}
bool MeshCluster::FacesTowards(const glm::dvec3& eye) const {
  return ConeFacesAway(*this, -glm::dvec3(cone_axis), eye);
}
bool MeshCluster::FacesTowardsAlong(const glm::dvec3& direction) const {
  return ConeFacesAwayAlong(*this, -glm::dvec3(cone_axis), direction);
}

ClusterOrder ClustersOf(const std::vector<uint32_t>& indices,
                        const std::vector<glm::vec3>& positions) {
  ClusterOrder out;
  if (indices.empty()) return out;
  constexpr size_t kMaxVertices = 64, kMaxTriangles = 124;
  const float kConeWeight = 0.25f;  // favour clusters whose normals agree
  std::vector<meshopt_Meshlet> meshlets(
      meshopt_buildMeshletsBound(indices.size(), kMaxVertices, kMaxTriangles));
  std::vector<unsigned int> meshlet_vertices(meshlets.size() * kMaxVertices);
  std::vector<unsigned char> meshlet_triangles(meshlets.size() * kMaxTriangles * 3);
  meshlets.resize(meshopt_buildMeshlets(meshlets.data(), meshlet_vertices.data(),
                                        meshlet_triangles.data(), indices.data(), indices.size(),
                                        &positions[0].x, positions.size(), sizeof(glm::vec3),
                                        kMaxVertices, kMaxTriangles, kConeWeight));
  out.indices.reserve(indices.size());
  for (const meshopt_Meshlet& m : meshlets) {
    MeshCluster c;
    c.first_index = static_cast<GLsizei>(out.indices.size());
    c.lo = glm::vec3(std::numeric_limits<float>::infinity());
    c.hi = -c.lo;
    for (size_t k = 0; k < 3 * size_t{m.triangle_count}; ++k) {
      const uint32_t v =
          meshlet_vertices[m.vertex_offset + meshlet_triangles[m.triangle_offset + k]];
      out.indices.push_back(v);
      c.lo = glm::min(c.lo, positions[v]);
      c.hi = glm::max(c.hi, positions[v]);
    }
    c.index_count = static_cast<GLsizei>(out.indices.size()) - c.first_index;
    const meshopt_Bounds b = meshopt_computeClusterBounds(
        out.indices.data() + c.first_index, static_cast<size_t>(c.index_count), &positions[0].x,
        positions.size(), sizeof(glm::vec3));
    c.center = glm::vec3(b.center[0], b.center[1], b.center[2]);
    c.radius = b.radius;
    c.cone_axis = glm::vec3(b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]);
    c.cone_cutoff = b.cone_cutoff;
    out.clusters.push_back(c);
  }
  IBR_CHECK(out.indices.size() == indices.size());
  return out;
}

GpuMesh::GpuMesh(const core::TriangleMesh& mesh) : GpuMesh(mesh, nullptr, false) {}

GpuMesh GpuMesh::Clustered(const core::TriangleMesh& mesh) { return GpuMesh(mesh, nullptr, true); }

GpuMesh::GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>& vertex_data)
    : GpuMesh(mesh, &vertex_data, false) {}

GpuMesh::GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>* vertex_data,
                 bool clustered) {
  mesh.Validate("GpuMesh");
  if (vertex_data && vertex_data->size() != mesh.positions.size()) {
    core::ThrowInputError("GpuMesh", "{} vertex data values for {} vertices", vertex_data->size(),
                          mesh.positions.size());
  }
  const VertexOrder order = VertexCacheOrder(mesh.indices, mesh.positions.size());
  std::vector<Vertex> vertices(order.vertex_count);
  std::vector<glm::vec2> data(vertex_data ? order.vertex_count : 0);
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const uint32_t j = order.new_from_old[i];
    if (j == VertexOrder::kUnused) continue;
    vertices[j].position = mesh.positions[i];
    vertices[j].normal = mesh.normals.empty() ? glm::vec3(0, 0, 1) : mesh.normals[i];
    vertices[j].uv = mesh.uvs.empty() ? glm::vec2(0) : mesh.uvs[i];
    if (vertex_data) data[j] = (*vertex_data)[i];
  }
  std::vector<uint32_t> indices = order.indices;
  if (clustered) {
    std::vector<glm::vec3> positions(vertices.size());
    for (size_t v = 0; v < vertices.size(); ++v) positions[v] = vertices[v].position;
    ClusterOrder clusters = ClustersOf(order.indices, positions);
    indices = std::move(clusters.indices);
    clusters_ = std::move(clusters.clusters);
  }
  index_count_ = static_cast<GLsizei>(indices.size());
  vertices_ = BufferOf(vertices);
  indices_ = BufferOf(indices);
  vao_ = VertexArray::Create();
  glVertexArrayVertexBuffer(vao_.id(), 0, vertices_.id(), 0, sizeof(Vertex));
  glVertexArrayElementBuffer(vao_.id(), indices_.id());
  const GLuint locations[] = {kPositionLocation, kNormalLocation, kUvLocation};
  const GLint sizes[] = {3, 3, 2};
  const GLuint offsets[] = {offsetof(Vertex, position), offsetof(Vertex, normal),
                            offsetof(Vertex, uv)};
  for (int k = 0; k < 3; ++k) {
    glEnableVertexArrayAttrib(vao_.id(), locations[k]);
    glVertexArrayAttribFormat(vao_.id(), locations[k], sizes[k], GL_FLOAT, GL_FALSE, offsets[k]);
    glVertexArrayAttribBinding(vao_.id(), locations[k], 0);
  }
  if (vertex_data) {
    vertex_data_ = BufferOf(data);
    glVertexArrayVertexBuffer(vao_.id(), 1, vertex_data_.id(), 0, sizeof(glm::vec2));
    glEnableVertexArrayAttrib(vao_.id(), kVertexDataLocation);
    glVertexArrayAttribFormat(vao_.id(), kVertexDataLocation, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao_.id(), kVertexDataLocation, 1);
  }
}

void GpuMesh::DrawClusters(const std::vector<uint32_t>& ids) const {
  std::vector<GLsizei>& counts = run_counts_;
  std::vector<const void*>& offsets = run_offsets_;
  counts.clear();
  offsets.clear();
  for (size_t i = 0; i < ids.size(); ++i) {
    const MeshCluster& c = clusters_.at(ids[i]);
    if (i > 0 && ids[i] == ids[i - 1] + 1) {
      counts.back() += c.index_count;  // extends the run
      continue;
    }
    counts.push_back(c.index_count);
    offsets.push_back(
        reinterpret_cast<const void*>(static_cast<size_t>(c.first_index) * sizeof(uint32_t)));
  }
  if (counts.empty()) return;
  glBindVertexArray(vao_.id());
  glMultiDrawElements(GL_TRIANGLES, counts.data(), GL_UNSIGNED_INT, offsets.data(),
                      static_cast<GLsizei>(counts.size()));
  glBindVertexArray(0);
}

void GpuMesh::Draw() const {
  if (index_count_ == 0) return;
  glBindVertexArray(vao_.id());
  glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

}  // namespace render
