#include "render/gl/gpu_mesh.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cstddef>
#include <vector>

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

GpuMesh::GpuMesh(const core::TriangleMesh& mesh) : GpuMesh(mesh, nullptr) {}

GpuMesh::GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>& vertex_data)
    : GpuMesh(mesh, &vertex_data) {}

GpuMesh::GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>* vertex_data) {
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
  index_count_ = static_cast<GLsizei>(order.indices.size());
  vertices_ = BufferOf(vertices);
  indices_ = BufferOf(order.indices);
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

void GpuMesh::Draw() const {
  if (index_count_ == 0) return;
  glBindVertexArray(vao_.id());
  glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

}  // namespace render
