#include "render/slice_buffer.h"

#include <algorithm>

#include "core/check.h"
#include "render/gpu_mesh.h"

namespace render {

SliceBuffer::SliceBuffer() : vertices_(Buffer::Create()), vao_(VertexArray::Create()) {
  glEnableVertexArrayAttrib(vao_.id(), kPositionLocation);
  glVertexArrayAttribFormat(vao_.id(), kPositionLocation, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao_.id(), kPositionLocation, 0);
}

void SliceBuffer::Upload(const SliceStack& stack) {
  std::vector<glm::vec3> vertices;
  ranges_.clear();
  triangles_ = 0;
  for (const Slice& slice : stack.slices) {
    IBR_CHECK_GE(slice.p_in_box.size(), 3u);
    const GLint first = static_cast<GLint>(vertices.size());
    // Fan around vertex 0 (the polygons are convex).
    for (size_t i = 1; i + 1 < slice.p_in_box.size(); ++i) {
      vertices.push_back(slice.p_in_box[0]);
      vertices.push_back(slice.p_in_box[i]);
      vertices.push_back(slice.p_in_box[i + 1]);
    }
    ranges_.push_back({first, static_cast<GLsizei>(vertices.size()) - first});
    triangles_ += static_cast<int>(slice.p_in_box.size()) - 2;
  }
  const size_t bytes = std::max<size_t>(1, vertices.size()) * sizeof(glm::vec3);
  if (bytes > capacity_bytes_) {
    // Mutable storage: slices change every frame.
    glNamedBufferData(vertices_.id(), static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_DRAW);
    capacity_bytes_ = bytes;
  }
  if (!vertices.empty()) {
    glNamedBufferSubData(vertices_.id(), 0, static_cast<GLsizeiptr>(vertices.size() * sizeof(glm::vec3)),
                         vertices.data());
  }
  glVertexArrayVertexBuffer(vao_.id(), 0, vertices_.id(), 0, sizeof(glm::vec3));
}

void SliceBuffer::Bind() const { glBindVertexArray(vao_.id()); }
void SliceBuffer::Unbind() const { glBindVertexArray(0); }

void SliceBuffer::DrawSlice(int i) const {
  const Range& r = ranges_.at(static_cast<size_t>(i));
  glDrawArrays(GL_TRIANGLES, r.first, r.count);
}

void SliceBuffer::DrawAll() const {
  Bind();
  for (int i = 0; i < size(); ++i) DrawSlice(i);
  Unbind();
}

}  // namespace render
