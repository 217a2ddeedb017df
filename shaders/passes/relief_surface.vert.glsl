#version 450 core
// The outer shell of a displaced surface (render/passes/relief_surface_pass.h):
// base + max_displacement * N, rasterised; the fragment shader marches inward.
#include "common/mesh_attributes.glsl"

uniform mat4 u_cam_from_object;
uniform mat4 u_clip_from_cam;

out vec3 v_p_in_object;
out vec2 v_uv;
#ifdef METHOD_CRM
// Curved relief mapping's quadric (a, b) of the base at the vertex
// (render::ReliefVertexQuadrics, location render::kVertexDataLocation),
// interpolated across the triangle as in [OP05].
layout(location = 3) in vec2 a_quadric;
out vec2 v_quadric;
#endif

void main() {
  v_p_in_object = a_position;
  v_uv = a_uv;
#ifdef METHOD_CRM
  v_quadric = a_quadric;
#endif
  gl_Position = u_clip_from_cam * (u_cam_from_object * vec4(a_position, 1.0));
}
