#include "render/gl/gpu_mesh.h"

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
}  // namespace

GpuMesh::GpuMesh(const core::TriangleMesh& mesh) {
  mesh.Validate("GpuMesh");
  std::vector<Vertex> vertices(mesh.positions.size());
  for (size_t i = 0; i < vertices.size(); ++i) {
    vertices[i].position = mesh.positions[i];
    vertices[i].normal = mesh.normals.empty() ? glm::vec3(0, 0, 1) : mesh.normals[i];
    vertices[i].uv = mesh.uvs.empty() ? glm::vec2(0) : mesh.uvs[i];
  }
  index_count_ = static_cast<GLsizei>(mesh.indices.size());
  // Zero-size storage is invalid in GL: keep one dummy element for empty meshes.
  const Vertex dummy_vertex{};
  const uint32_t dummy_index = 0;
  vertices_ = Buffer::CreateWithData(
      vertices.empty() ? &dummy_vertex : vertices.data(),
      static_cast<GLsizeiptr>(std::max<size_t>(1, vertices.size()) * sizeof(Vertex)));
  indices_ = Buffer::CreateWithData(
      mesh.indices.empty() ? &dummy_index : mesh.indices.data(),
      static_cast<GLsizeiptr>(std::max<size_t>(1, mesh.indices.size()) * sizeof(uint32_t)));
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
}

GpuMesh::GpuMesh(const core::TriangleMesh& mesh, const std::vector<glm::vec2>& vertex_data)
    : GpuMesh(mesh) {
  if (vertex_data.size() != mesh.positions.size()) {
    core::ThrowInputError("GpuMesh", "{} vertex data values for {} vertices", vertex_data.size(),
                          mesh.positions.size());
  }
  const glm::vec2 dummy(0.0f);
  vertex_data_ = Buffer::CreateWithData(
      vertex_data.empty() ? &dummy : vertex_data.data(),
      static_cast<GLsizeiptr>(std::max<size_t>(1, vertex_data.size()) * sizeof(glm::vec2)));
  glVertexArrayVertexBuffer(vao_.id(), 1, vertex_data_.id(), 0, sizeof(glm::vec2));
  glEnableVertexArrayAttrib(vao_.id(), kVertexDataLocation);
  glVertexArrayAttribFormat(vao_.id(), kVertexDataLocation, 2, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao_.id(), kVertexDataLocation, 1);
}

void GpuMesh::Draw() const {
  if (index_count_ == 0) return;
  glBindVertexArray(vao_.id());
  glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

}  // namespace render
