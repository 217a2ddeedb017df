#version 450 core
// The fast slice path of depth objects and visual hulls
// (ibr/depth_object_fast.cc): every slice in one draw; each vertex carries
// its slice's index (render::SliceBuffer::UploadVolumes, one stack per
// slice), passed flat to the fragment shader, which reads the slice's plane
// by it. Placement by the slicing core.
#include "cores/slicing_core.glsl"

layout(location = 0) in vec3 a_position;  // box coordinates
layout(location = 3) in int a_volume;     // the slice's index (render::kSliceVolumeLocation)

flat out int v_slice;

void main() {
  v_slice = a_volume;
  vec3 p_in_cam;
  gl_Position = SliceVertex(a_position, p_in_cam);
}
