#version 450 core
// Chen-Chang Algorithm 1, line 4: each base triangle t is drawn as t' with
// vertices (u, v, 0), i.e. in UV space, so the maps are indexed by uv.
#include "common/mesh_attributes.glsl"  // a_uv: drawn in uv space, uv is the position
layout(location = 3) in vec4 a_tangent;     // xyz = T, w = handedness * S_tangent
layout(location = 4) in float a_s_binormal;

out vec3 v_normal;
out vec4 v_tangent;
out float v_s_binormal;

void main() {
  v_normal = a_normal;
  v_tangent = a_tangent;
  v_s_binormal = a_s_binormal;
  gl_Position = vec4(a_uv * 2.0 - 1.0, 0.0, 1.0);
}
