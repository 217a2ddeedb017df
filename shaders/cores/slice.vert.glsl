#version 450 core
// Vertex stage shared by all slicing passes (displacement, depth objects,
// visual hulls, volumes): places slice polygons given in box coordinates.
#include "cores/slicing_core.glsl"

layout(location = 0) in vec3 a_position;  // box coordinates

out vec3 v_p_in_box;
out vec3 v_p_in_cam;

void main() {
  v_p_in_box = a_position;
  gl_Position = SliceVertex(a_position, v_p_in_cam);
}
