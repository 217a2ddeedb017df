// The GPU side of the slicing core: a SliceStack's polygons as triangle fans
// in one vertex buffer (attribute 0 = box coordinates), drawable one slice at
// a time (the depth-object loop draws each slice once per map) or all at once.
// Vertex shaders include shaders/slicing_core.glsl to place them.
#pragma once

#include <vector>

#include "render/handles.h"
#include "render/slicing.h"

namespace render {

class SliceBuffer {
 public:
  SliceBuffer();
  // Replaces the contents (slices are view-dependent: once per frame).
  void Upload(const SliceStack& stack);
  int size() const { return static_cast<int>(ranges_.size()); }
  // Total triangles uploaded (fill-rate accounting).
  int triangle_count() const { return triangles_; }
  // Binds the vertex array for DrawSlice calls; Unbind() after.
  void Bind() const;
  void Unbind() const;
  // Draws slice i (Bind() first).
  void DrawSlice(int i) const;
  // Binds, draws every slice in order, unbinds.
  void DrawAll() const;

 private:
  struct Range {
    GLint first;
    GLsizei count;
  };
  Buffer vertices_;
  VertexArray vao_;
  size_t capacity_bytes_ = 0;
  std::vector<Range> ranges_;
  int triangles_ = 0;
};

}  // namespace render
