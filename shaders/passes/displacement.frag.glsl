#version 450 core
// Displacement mapping by slicing (Kautz-Seidel 2001, sec. 3.2-3.3): the
// displacement texture's alpha minus the ramp value h_alpha, then the strict
// alpha test, for every slicing family. Writes colour and camera z.
#include "cores/slicing_core.glsl"

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
  o_color = vec4(texel.rgb, 1.0);
  o_depth = v_p_in_cam.z;
  o_normal = vec4(0.0);
}
