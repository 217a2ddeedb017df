#version 450 core
// The one-pass ray variant of depth objects and visual hulls (issue 5, item
// 7): each pixel marches its view ray through the box on the shared ray core
// (shaders/cores/ray_core.glsl: linear search, then bisection), testing all maps
// per sample with the same MapLookup / depth codes as the slice passes, and
// writes the same accumulation layout as they do (colour = sum of w c at the
// hit, camera z), so the same resolve pass textures it.
#include "passes/depth_object_core.glsl"

uniform mat4 u_box_from_cam;   // view camera -> box [0,1]^3
uniform float u_ray_step;      // camera z per linear-search step (the screen slice spacing)

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec2 o_depth;

float RayField(vec3 p) { return ObjectField(p); }

#ifdef EMPTY_SPACE_SKIPPING
// Empty-space skipping (ibr/empty_space.h): per voxel of the box, the
// chessboard distance in voxels to the nearest voxel the maps do not prove
// empty (0 = maybe occupied). From a sample in a voxel at distance D the
// cube of voxels within D - 1 is free; the skip is the ray's path to that
// cube's exit, rounded down to whole steps so that every sample the march
// still takes is one the fine march takes too (same first surface).
#define RAY_SKIP
uniform usampler3D u_skip_grid;  // R8UI
uniform int u_skip_resolution;   // voxels per box axis
vec3 g_ray_dir_in_grid;          // the current ray's direction, grid units per t

float RaySkip(vec3 p, float field) {
  vec3 g = (u_box_from_cam * vec4(p, 1.0)).xyz * float(u_skip_resolution);
  ivec3 c = clamp(ivec3(floor(g)), ivec3(0), ivec3(u_skip_resolution - 1));
  uint dist = texelFetch(u_skip_grid, c, 0).r;
  if (dist == 0u) return 0.0;
  vec3 lo = vec3(c) - float(dist - 1u), hi = vec3(c) + float(dist);
  float t_exit = 1e30;
  for (int k = 0; k < 3; ++k) {
    float dk = g_ray_dir_in_grid[k];
    if (dk > 0.0) t_exit = min(t_exit, (hi[k] - g[k]) / dk);
    if (dk < 0.0) t_exit = min(t_exit, (lo[k] - g[k]) / dk);
  }
  return floor(max(t_exit, 0.0) / u_ray_step) * u_ray_step;
}
#endif

#include "cores/ray_core.glsl"

void main() {
  vec2 uv = FragmentUv();
  vec3 o, d;
#ifdef VIEW_ORTHOGRAPHIC
  o = vec3(uv.x * u_view_ray.x + u_view_ray.z, uv.y * u_view_ray.y + u_view_ray.w, 0.0);
  d = vec3(0.0, 0.0, 1.0);
#else
  o = vec3(0.0);
  d = vec3(uv.x * u_view_ray.x + u_view_ray.z, uv.y * u_view_ray.y + u_view_ray.w, 1.0);
#endif
  // t is camera z along these rays (d.z = 1).
  vec3 o_box = (u_box_from_cam * vec4(o, 1.0)).xyz;
  vec3 d_box = mat3(u_box_from_cam) * d;
  vec2 span = RayBoxInterval(o_box, d_box, vec3(0.0), vec3(1.0));
#ifndef VIEW_ORTHOGRAPHIC
  // Only in front of the eye. With the eye inside the box the march starts
  // half a step in front of it, where the first screen slice lies: a ray
  // starting inside the object would otherwise hit at the eye, camera z 0,
  // which the frame reads as empty (found by ibr verify --hard).
  if (span.x <= 0.0) span.x = 0.5 * u_ray_step;
#endif
  o_color = vec4(0.0);
  o_depth = vec2(0.0);
  if (!(span.x < span.y)) return;
#ifdef EMPTY_SPACE_SKIPPING
  g_ray_dir_in_grid = d_box * float(u_skip_resolution);
#endif
  // From the box entry to its exit (RayMarch: origin, dir, t_max, step).
  RayResult res = RayMarchRun(RayMarch(o + span.x * d, d, span.y - span.x, u_ray_step));
  if (res.outcome != RAY_OUTCOME_HIT) return;
  vec3 p = res.p;
  // View-dependent colour at the hit (sec. 4.2 weights), as the map loop blends it.
  vec4 acc = vec4(0.0);
  for (int i = 0; i < u_map_count; ++i) {
    if (!(u_maps[i].extra.x > 0.0)) continue;
    vec3 q;
    ivec3 texel;
    if (MapLookup(u_maps[i], p, q, texel)) acc += MapColor(texel) * u_maps[i].extra.x;
  }
  o_color = acc;
  o_depth = vec2(p.z, 1.0);
}
