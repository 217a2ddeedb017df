#include "render/cores/slice_buffer.h"

#include <algorithm>

#include "core/check.h"
#include "render/gl/gpu_mesh.h"

namespace render {

SliceBuffer::SliceBuffer() : vertices_(Buffer::Create()), vao_(VertexArray::Create()) {
  glEnableVertexArrayAttrib(vao_.id(), kPositionLocation);
  glVertexArrayAttribFormat(vao_.id(), kPositionLocation, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao_.id(), kPositionLocation, 0);
}

void SliceBuffer::Upload(const SliceStack& stack) { UploadImpl({&stack}, false); }

void SliceBuffer::UploadVolumes(const std::vector<SliceStack>& stacks) {
  std::vector<const SliceStack*> pointers;
  pointers.reserve(stacks.size());
  for (const SliceStack& s : stacks) pointers.push_back(&s);
  UploadImpl(pointers, true);
}

void SliceBuffer::UploadImpl(const std::vector<const SliceStack*>& stacks, bool with_volumes) {
  std::vector<glm::vec3> vertices;
  std::vector<GLint> volume_of_vertex;
  ranges_.clear();
  triangles_ = 0;
  for (size_t v = 0; v < stacks.size(); ++v) {
    for (const Slice& slice : stacks[v]->slices) {
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
    if (with_volumes) volume_of_vertex.resize(vertices.size(), static_cast<GLint>(v));
  }
  vertex_count_ = static_cast<int>(vertices.size());
  const size_t bytes = std::max<size_t>(1, vertices.size()) * sizeof(glm::vec3);
  if (bytes > capacity_bytes_) {
    // Mutable storage: slices change every frame.
    glNamedBufferData(vertices_.id(), static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_DRAW);
    capacity_bytes_ = bytes;
  }
  if (!vertices.empty()) {
    glNamedBufferSubData(vertices_.id(), 0,
                         static_cast<GLsizeiptr>(vertices.size() * sizeof(glm::vec3)),
                         vertices.data());
  }
  glVertexArrayVertexBuffer(vao_.id(), 0, vertices_.id(), 0, sizeof(glm::vec3));
  if (!with_volumes) {
    glDisableVertexArrayAttrib(vao_.id(), kSliceVolumeLocation);
    return;
  }
  if (!volumes_) volumes_ = Buffer::Create();
  const size_t volume_bytes = std::max<size_t>(1, volume_of_vertex.size()) * sizeof(GLint);
  if (volume_bytes > volume_capacity_bytes_) {
    glNamedBufferData(volumes_.id(), static_cast<GLsizeiptr>(volume_bytes), nullptr,
                      GL_STREAM_DRAW);
    volume_capacity_bytes_ = volume_bytes;
  }
  if (!volume_of_vertex.empty()) {
    glNamedBufferSubData(volumes_.id(), 0,
                         static_cast<GLsizeiptr>(volume_of_vertex.size() * sizeof(GLint)),
                         volume_of_vertex.data());
  }
  glVertexArrayVertexBuffer(vao_.id(), 1, volumes_.id(), 0, sizeof(GLint));
  glEnableVertexArrayAttrib(vao_.id(), kSliceVolumeLocation);
  glVertexArrayAttribIFormat(vao_.id(), kSliceVolumeLocation, 1, GL_INT, 0);
  glVertexArrayAttribBinding(vao_.id(), kSliceVolumeLocation, 1);
}

void SliceBuffer::Bind() const { glBindVertexArray(vao_.id()); }
void SliceBuffer::Unbind() const { glBindVertexArray(0); }

void SliceBuffer::DrawSlice(int i) const {
  const Range& r = ranges_.at(static_cast<size_t>(i));
  glDrawArrays(GL_TRIANGLES, r.first, r.count);
}

void SliceBuffer::DrawSlices(int first, int count) const {
  if (count <= 0) return;
  const Range& a = ranges_.at(static_cast<size_t>(first));
  const Range& b = ranges_.at(static_cast<size_t>(first + count - 1));
  glDrawArrays(GL_TRIANGLES, a.first, b.first + b.count - a.first);
}

void SliceBuffer::DrawAllBatched() const {
  if (vertex_count_ == 0) return;
  Bind();
  glDrawArrays(GL_TRIANGLES, 0, vertex_count_);
  Unbind();
}

void SliceBuffer::DrawAll() const {
  Bind();
  for (int i = 0; i < size(); ++i) DrawSlice(i);
  Unbind();
}

}  // namespace render
