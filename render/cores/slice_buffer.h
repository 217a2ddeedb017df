// The GPU side of the slicing core: a SliceStack's polygons as triangle fans
// in one vertex buffer (attribute 0 = box coordinates), drawable one slice at
// a time (the depth-object loop draws each slice once per map) or all at once.
// Vertex shaders include shaders/cores/slicing_core.glsl to place them.
#pragma once

#include <vector>

#include "render/cores/slicing.h"
#include "render/gl/handles.h"

namespace render {

// Vertex attribute (int) naming the volume a slice vertex belongs to, for
// slices of many volumes in one buffer (UploadVolumes): a_volume.
inline constexpr GLuint kSliceVolumeLocation = 3;

class SliceBuffer {
 public:
  SliceBuffer();
  // Replaces the contents (slices are view-dependent: once per frame).
  void Upload(const SliceStack& stack);
  // Slices of many volumes (e.g. the per-face displacement volumes of a mesh,
  // Kautz-Seidel 2001 sec. 3) in one buffer, stack after stack; each vertex
  // carries a_volume = its stack's index. After Upload() a_volume reads 0.
  void UploadVolumes(const std::vector<SliceStack>& stacks);
  int size() const { return static_cast<int>(ranges_.size()); }
  // Total triangles uploaded (fill-rate accounting).
  int triangle_count() const { return triangles_; }
  // Binds the vertex array for DrawSlice calls; Unbind() after.
  void Bind() const;
  void Unbind() const;
  // Draws slice i (Bind() first).
  void DrawSlice(int i) const;
  // Draws slices first .. first + count - 1 (consecutive in the buffer) in one
  // call (Bind() first).
  void DrawSlices(int first, int count) const;
  // Binds, draws every slice in order, unbinds.
  void DrawAll() const;
  // Same pixels as DrawAll() (slices are consecutive in the buffer, in
  // order), in one draw call: thousands of small per-face slices would
  // otherwise be dominated by per-call overhead.
  void DrawAllBatched() const;
  int vertex_count() const { return vertex_count_; }

 private:
  struct Range {
    GLint first;
    GLsizei count;
  };
  void UploadImpl(const std::vector<const SliceStack*>& stacks, bool with_volumes);

  Buffer vertices_;
  Buffer volumes_;
  VertexArray vao_;
  size_t capacity_bytes_ = 0;
  size_t volume_capacity_bytes_ = 0;
  int vertex_count_ = 0;
  std::vector<Range> ranges_;
  int triangles_ = 0;
};

}  // namespace render
