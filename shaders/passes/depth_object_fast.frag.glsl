#version 450 core
// The fast slice path of depth objects and visual hulls (ibr/depth_object_fast.cc):
// the map loop of Kautz-Seidel 2001, sec. 4.1 step 2(a) in one fragment
// instead of one stencil pass per map. A slice point is kept iff every
// active map accepts it (robust, ROBUST_COUNT: at least u_required do), with
// the exact path's test (MapAccepts) on the same point (recomputed from the
// pixel centre and the slice's plane) and the same texels; the depth test
// (LESS) keeps the front slice of each pixel. Writes what the exact path's
// accumulation holds for a finished pixel: sum of w_i * colour_i over the
// accepting maps (in the same order) with sum w_i, and (camera z, 1).
//   FAST_MAP_COUNT  the active maps (a constant, so the loop unrolls and the
//                   block is read with static indices)
#include "passes/depth_object_core.glsl"

#ifndef FAST_MAP_COUNT
#error "FAST_MAP_COUNT missing: ibr/depth_object_fast.cc defines it"
#endif

// Slice planes in view camera space, dot(xyz, p) = w, front to back.
layout(std430, binding = 3) readonly buffer DepthObjectFastPlanes {
  vec4 u_planes[];
};
// The active maps in the exact path's loop order.
layout(std140, binding = 3) uniform DepthObjectFastMaps {
  MapRecord u_loop_maps[FAST_MAP_COUNT > 0 ? FAST_MAP_COUNT : 1];
};

flat in int v_slice;

layout(location = 0) out vec4 o_color;  // sum w c, sum w (the exact path's accumulation)
layout(location = 1) out vec2 o_depth;  // view camera z of the slice point, 1 = covered

void main() {
  vec3 p = ViewPointOnPlane(FragmentUv(), u_planes[v_slice]);
  precise vec4 sum = vec4(0.0);
#ifdef ROBUST_COUNT
  int accepted = 0;
#endif
  for (int j = 0; j < FAST_MAP_COUNT; ++j) {
    ivec3 texel;
    if (MapAccepts(u_loop_maps[j], p, texel)) {
#ifdef ROBUST_COUNT
      ++accepted;
#endif
      float w = u_loop_maps[j].extra.x;
      if (texel.x >= 0 && w > 0.0) {
        precise vec4 c = MapColor(texel) * w;
        sum = sum + c;
      }
    } else {
#ifndef ROBUST_COUNT
      discard;  // intersection: the first map that carves decides
#endif
    }
  }
#ifdef ROBUST_COUNT
  if (accepted < u_required) discard;
#endif
  o_color = sum;
  o_depth = vec2(p.z, 1.0);
}
