#version 450 core
// Volume pass, DVR: one screen-space slice fragment (render/passes/volume_pass.h).
#include "cores/slicing_core.glsl"
#include "passes/volume_core.glsl"

in vec3 v_p_in_box;  // proxy-box coordinates
in vec3 v_p_in_cam;

// RGBA, the opacity corrected for the slice spacing (core::OpacityCorrectedTable), LINEAR
uniform sampler1D u_transfer;
uniform float u_transfer_size;    // texels in u_transfer

layout(location = 0) out vec4 o_color;  // premultiplied

// The transfer function's entry for the normalised scalar s (texel centres
// at the table's ends).
vec4 Classify(float s) { return texture(u_transfer, (s * (u_transfer_size - 1.0) + 0.5) / u_transfer_size); }

void main() {
  vec3 p_prime = (u_tex_from_proxy * vec4(v_p_in_box, 1.0)).xyz;
#ifdef VOLUME_DVR_FLOOR
  // The fill-rate floor's work (VolumePassOptions::floor_shader): with a map,
  // one map fetch and the scalar read where it points (no mask, no active box).
  vec3 p = p_prime;
#if VOLUME_MAPS > 0
  p += u_tex_from_map[0] * MapFetch(0, (u_map_from_tex[0] * vec4(p_prime, 1.0)).xyz).xyz;
#endif
  vec4 tf = Classify(VolumeSample(p).a);
  o_color = vec4(tf.rgb * tf.a, tf.a);
#else
  Displaced d = VolumeDisplace(p_prime);
  if (d.alpha < 0.5) discard;  // sec. 4.2: the cut is transparent
  vec4 sample_at_p = VolumeSample(d.p);  // (gradient, scalar)
  vec4 tf = Classify(sample_at_p.a);
  float a = tf.a * d.alpha;
  if (!(a > 0.0)) discard;  // before the normal (volume_core.glsl: cost order)
  o_color = vec4(VolumeShade(tf.rgb, d, sample_at_p.xyz) * a, a);
#endif
}
