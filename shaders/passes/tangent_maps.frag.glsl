#version 450 core
// Chen-Chang Algorithm 1, lines 5-6: vertex "colours" N + S_binormal into the
// normal map, T + S_tangent into the tangent map (interpolated across t').
in vec3 v_normal;
in vec4 v_tangent;
in float v_s_binormal;

layout(location = 0) out vec4 o_normal_map;
layout(location = 1) out vec4 o_tangent_map;

void main() {
  o_normal_map = vec4(normalize(v_normal), v_s_binormal);
  o_tangent_map = v_tangent;
}
