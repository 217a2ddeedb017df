#version 450 core
// Variants: TEXTURED (colour from u_texture at v_uv), SHADED (Lambert with a
// light at the camera), ORTHOGRAPHIC (view direction is the camera z axis).
#include "common/shading.glsl"

in vec3 v_normal_world;
in vec3 v_p_in_cam;
in vec2 v_uv;

uniform vec4 u_base_color;
uniform mat4 u_cam_from_world;
#ifdef TEXTURED
uniform sampler2D u_texture;
#endif

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;   // camera z
layout(location = 2) out vec4 o_normal;   // world-space unit normal

void main() {
  vec3 n_world = normalize(v_normal_world);
#ifdef TEXTURED
  vec4 albedo = texture(u_texture, v_uv);
#else
  vec4 albedo = u_base_color;
#endif
  vec3 color = albedo.rgb;
#ifdef SHADED
  color = HeadLight(color, normalize(mat3(u_cam_from_world) * n_world), v_p_in_cam);
#endif
  o_color = vec4(color, 1.0);
  o_depth = v_p_in_cam.z;
  o_normal = vec4(n_world, 0.0);
}
