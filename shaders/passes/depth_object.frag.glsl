#version 450 core
// The slice passes of the depth-object / visual-hull stencil algorithm
// (Kautz-Seidel 2001, sec. 4.1, steps 2(a)-(f)). Drawn with slice.vert.glsl
// (the slicing core) once per slice and map (the map test) and once per slice to
// clear what did not reach the required count (u_clear_pass); the stencil
// function and operation are set by ibr/depth_object.cc.
#include "passes/depth_object_core.glsl"

uniform vec4 u_slice_plane;  // this slice in view camera space: dot(xyz, p) = w

// The map of this pass: its row of the table bound as its own range, so the
// shader reads it with a static index (fast on llvmpipe).
layout(std140, binding = 1) uniform DepthObjectCurrentMap {
  MapRecord u_map;
};

layout(location = 0) out vec4 o_color;  // weighted colour + weight, blended additively (sec. 4.2)
layout(location = 1) out vec2 o_depth;  // (view camera z of the slice point, 1 = covered); not blended

// 1 for steps (d)-(e): draw the slice with the background (zero: the colour
// accumulation restarts from nothing for pixels that are not finished). One
// program for both kinds of pass: switching programs per slice costs more on
// llvmpipe than the passes themselves.
uniform int u_clear_pass;

void main() {
  if (u_clear_pass != 0) {
    o_color = vec4(0.0);
    o_depth = vec2(0.0);
    return;
  }
  vec3 p = ViewPointOnPlane(FragmentUv(), u_slice_plane);
  ivec3 texel;
  // Step (a)ii: the alpha test -- a fragment that fails map u_map's test is
  // discarded, so the stencil is not incremented.
  if (!MapAccepts(u_map, p, texel)) discard;
  // View-dependent texturing by blending during the map loop (sec. 4.2):
  // this map's colour times its weight; weights of the others are added by
  // their own passes. Outside the map's image, or at weight 0, no colour.
  precise vec4 o = vec4(0.0);
  if (texel.x >= 0 && u_map.extra.x > 0.0) o = MapColor(texel) * u_map.extra.x;
  o_color = o;
  o_depth = vec2(p.z, 1.0);
}
