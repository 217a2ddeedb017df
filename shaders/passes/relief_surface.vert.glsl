#version 450 core
// The outer shell of a displaced surface (render/passes/relief_surface_pass.h):
// base + max_displacement * N, rasterised; the fragment shader marches inward.
#include "common/mesh_attributes.glsl"

uniform mat4 u_cam_from_object;
uniform mat4 u_clip_from_cam;

out vec3 v_p_in_object;
out vec2 v_uv;

void main() {
  v_p_in_object = a_position;
  v_uv = a_uv;
  gl_Position = u_clip_from_cam * (u_cam_from_object * vec4(a_position, 1.0));
}
