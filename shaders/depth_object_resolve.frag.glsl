#version 450 core
// Texturing and background after the stencil slice passes (ibr/depth_object.cc):
// a full-screen pass (fullscreen.vert.glsl) reading the accumulated colour
// and the first-surface depth.
//   TEXTURING_VDT         the paper's view-dependent texturing (sec. 4.2), already
//                         blended during the map loop: colour = sum(w c) / sum(w)
//   TEXTURING_VISIBILITY  per pixel, only maps that saw this point (their depth
//                         matches within u_visibility_tolerance) contribute,
//                         weighted by the ULR penalty of ibr/view_weights.h on the
//                         per-pixel ray angles; where no map saw it, fall back to VDT
//   TEXTURING_NONE        grey, Lambert-shaded with normals from depth differences
#include "depth_object_core.glsl"

uniform sampler2D u_accum_color;  // RGBA32F: sum of w c, sum of w
uniform sampler2D u_accum_depth;  // RG32F: view camera z of the first surface, covered flag
uniform vec4 u_background;        // RGBA where nothing is drawn
uniform float u_visibility_tolerance;  // scene units along each map's z

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec2 o_depth;  // camera z (0 where empty), covered

vec3 VdtColor(ivec2 px) {
  vec4 acc = texelFetch(u_accum_color, px, 0);
  // Robust intersection can finish a pixel where no weighted map passed.
  return acc.a > 0.0 ? acc.rgb / acc.a : vec3(0.5);
}

#ifdef TEXTURING_VISIBILITY
vec3 VisibilityColor(ivec2 px, vec3 p) {
  const float kPi = 3.14159265358979;
  vec3 view_ray;
#ifdef VIEW_ORTHOGRAPHIC
  view_ray = vec3(0.0, 0.0, 1.0);
#else
  view_ray = normalize(p);
#endif
  // The four smallest angles among maps that saw p, kept sorted.
  float best_theta[4] = float[4](kPi, kPi, kPi, kPi);
  vec3 best_color[4] = vec3[4](vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));
  int seen = 0;
  for (int i = 0; i < u_map_count; ++i) {
    vec3 q;
    ivec3 texel;
    if (!MapLookup(i, p, q, texel)) continue;
    if (texelFetch(u_mask_maps, texel, 0).r <= 127u) continue;
    float d = texelFetch(u_depth_maps, texel, 0).r;
    if (!(d > 0.0) || abs(q.z - d) > u_visibility_tolerance) continue;
    vec3 map_ray = u_maps[i].centre_in_view.w > 0.5 ? u_maps[i].axis_in_view.xyz
                                                    : normalize(p - u_maps[i].centre_in_view.xyz);
    float theta = acos(clamp(dot(map_ray, view_ray), -1.0, 1.0));
    vec3 c = MapColor(texel).rgb;
    ++seen;
    for (int k = 0; k < 4; ++k) {
      if (theta < best_theta[k]) {
        for (int m = 3; m > k; --m) {
          best_theta[m] = best_theta[m - 1];
          best_color[m] = best_color[m - 1];
        }
        best_theta[k] = theta;
        best_color[k] = c;
        break;
      }
    }
  }
  if (seen == 0) return VdtColor(px);  // graceful fallback: nobody saw this point
  if (best_theta[0] <= 1e-6) return best_color[0];
  int k = min(seen, 3);
  float theta_k = seen > 3 ? best_theta[3] : kPi;
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  for (int j = 0; j < k; ++j) {
    float w = max(0.0, 1.0 - best_theta[j] / theta_k) / best_theta[j];
    sum += w * best_color[j];
    wsum += w;
  }
  return wsum > 0.0 ? sum / wsum : best_color[0];
}
#endif

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec2 zc = texelFetch(u_accum_depth, px, 0).rg;
  vec3 p = ViewPointAtDepth(FragmentUv(), zc.x);
#ifdef TEXTURING_NONE
  // Derivatives before any branch (uniform control flow).
  vec3 n = cross(dFdx(p), dFdy(p));
#endif
  if (zc.y < 0.5) {
    o_color = u_background;
    o_depth = vec2(0.0);
    return;
  }
  vec3 rgb;
#if defined(TEXTURING_VISIBILITY)
  rgb = VisibilityColor(px, p);
#elif defined(TEXTURING_NONE)
  float len = length(n);
  float lambert = len > 0.0 ? abs(n.z) / len : 1.0;
  rgb = vec3(0.15 + 0.75 * lambert);
#else
  rgb = VdtColor(px);
#endif
  o_color = vec4(rgb, 1.0);
  o_depth = vec2(zc.x, 1.0);
}
