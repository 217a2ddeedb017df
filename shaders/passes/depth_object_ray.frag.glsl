#version 450 core
// The one-pass ray variant of depth objects and visual hulls (issue 5, item
// 7): each pixel marches its view ray through the box on the shared ray core
// (shaders/ray_core.glsl: linear search, then bisection), testing all maps
// per sample with the same MapLookup / depth codes as the slice passes, and
// writes the same accumulation layout as they do (colour = sum of w c at the
// hit, camera z), so the same resolve pass textures it.
#include "passes/depth_object_core.glsl"

uniform mat4 u_box_from_cam;   // view camera -> box [0,1]^3
uniform int u_required;        // maps that must accept a point (N - k)
uniform float u_field_scale;   // scene units: the field value of "carved" (outside a mask, ...)
uniform float u_ray_step;      // camera z per linear-search step (the screen slice spacing)

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec2 o_depth;

// Map m's signed field at p: <= 0 where m accepts p (the same decision as
// MapAccepts), > 0 where it carves; for valid depth the signed depth
// difference d - z (scene units), so the field is continuous at surfaces.
float MapField(MapRecord m, vec3 p) {
  const float kFree = -1e30;
  vec3 q;
  ivec3 texel;
  if (!MapLookup(m, p, q, texel)) {
#ifdef OUTSIDE_PASSES
    return kFree;
#else
    return u_field_scale;
#endif
  }
  float d = texelFetch(u_depth_maps, texel, 0).r;
  if (d < 0.0) return u_field_scale;  // outside the silhouette
#ifdef VISUAL_HULL
  return -u_field_scale;
#else
  if (d > 0.0) return d - q.z;
#ifdef INVALID_DEPTH_PASSES
  return kFree;
#else
  return u_field_scale;
#endif
#endif
}

// "Inside all maps" (Kautz-Seidel's intersection): the largest map field;
// robust (ROBUST_COUNT): enough maps accept, as a step field.
float RayField(vec3 p) {
#ifdef ROBUST_COUNT
  int accepted = 0;
  for (int i = 0; i < u_map_count; ++i) {
    if (u_maps[i].extra.y > 0.5 && MapField(u_maps[i], p) <= 0.0) ++accepted;
  }
  return accepted >= u_required ? -1.0 : 1.0;
#else
  float f = -1e30;
  for (int i = 0; i < u_map_count; ++i) {
    if (u_maps[i].extra.y > 0.5) f = max(f, MapField(u_maps[i], p));
  }
  return f;
#endif
}

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
  span.x = max(span.x, 0.0);  // only in front of the eye
#endif
  o_color = vec4(0.0);
  o_depth = vec2(0.0);
  if (!(span.x < span.y)) return;
  RayMarch r;
  r.origin = o + span.x * d;
  r.dir = d;
  r.t_max = span.y - span.x;
  r.step = u_ray_step;
  RayResult res = RayMarchRun(r);
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
