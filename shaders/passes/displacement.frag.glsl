#version 450 core
// Displacement mapping by slicing (Kautz-Seidel 2001, sec. 3.2-3.3): the
// displacement texture's alpha minus the ramp value h_alpha, then the strict
// alpha test, for every slicing family. Writes colour and camera z.
// Variant COLOR_TEXTURE: the colour comes from u_color at the mesh's own uvs
// (times u_color_tiling, independent of the height map's tiling) and is lit
// by the head light with the displaced surface's normal, N - md grad h
// (first order in the face's plane), also written to the normal output;
// SHADED (with COLOR_TEXTURE) lights it, else the plain texture colour.
#include "cores/slicing_core.glsl"
#include "common/shading.glsl"

in vec3 v_p_in_box;
in vec3 v_p_in_cam;
in vec2 v_uv;
#ifdef SURFACE_ALIGNED
flat in float v_h_alpha;
#endif
#ifdef FULL_SIZE_SLICES
flat in int v_triangle;
#endif

uniform sampler2D u_displacement;  // RGB colour, A height / max displacement
#ifdef COLOR_TEXTURE
in vec2 v_color_uv;
in vec3 v_normal_world;
flat in vec3 v_grad_u;
flat in vec3 v_grad_v;
uniform sampler2D u_color;         // RGBA8, REPEAT
uniform float u_tiling;            // height map repeats across uv [0, 1]
uniform float u_max_displacement;  // scene units for height 1
#endif

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;  // camera z
layout(location = 2) out vec4 o_normal;  // unknown here: 0 (render/passes/pass.h)

void main() {
#ifdef FULL_SIZE_SLICES
  // Outside the volume the paper's texture border has alpha 0 (sec. 3.3).
  if (!InsideUnitBox(v_p_in_box) || (v_triangle == 1 && v_p_in_box.x + v_p_in_box.y > 1.0)) discard;
#endif
#ifdef SURFACE_ALIGNED
  float h_alpha = v_h_alpha;
#else
  float h_alpha = v_p_in_box.z;
#endif
  vec4 texel = texture(u_displacement, v_uv);
  if (!SliceAlphaTest(texel.a, h_alpha)) discard;
#ifdef COLOR_TEXTURE
  // Central differences one texel apart in the tiled uv; dh/du of the base
  // uv is u_tiling times dh/ds of the tiled one.
  vec2 texel_st = 1.0 / vec2(textureSize(u_displacement, 0));
  float h_s = (texture(u_displacement, v_uv + vec2(texel_st.x, 0.0)).a -
               texture(u_displacement, v_uv - vec2(texel_st.x, 0.0)).a) / (2.0 * texel_st.x);
  float h_t = (texture(u_displacement, v_uv + vec2(0.0, texel_st.y)).a -
               texture(u_displacement, v_uv - vec2(0.0, texel_st.y)).a) / (2.0 * texel_st.y);
  vec3 grad_h = u_tiling * (h_s * v_grad_u + h_t * v_grad_v);  // per world unit
  vec3 n_world = normalize(normalize(v_normal_world) - u_max_displacement * grad_h);
  vec3 albedo = texture(u_color, v_color_uv).rgb;
#ifdef SHADED
  albedo = HeadLight(albedo, normalize(mat3(u_cam_from_world) * n_world), v_p_in_cam);
#endif
  o_color = vec4(albedo, 1.0);
  o_normal = vec4(n_world, 0.0);
#else
  o_color = vec4(texel.rgb, 1.0);
  o_normal = vec4(0.0);
#endif
  o_depth = v_p_in_cam.z;
}
