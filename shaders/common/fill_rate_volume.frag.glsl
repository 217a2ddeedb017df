#version 450 core
// Fill-rate floors of direct volume rendering (render/gl/fill_rate.h,
// FillRateOptions::Work): one trilinear lookup of a 3D scalar texture per
// fragment, classified by a 1D transfer function (RGBA32F, LINEAR) and written
// premultiplied for ONE, ONE_MINUS_SRC_ALPHA blending: the least a DVR slice
// fragment does. With DISPLACED, first one trilinear lookup of an RGBA32F
// displacement map, the scalar then read at the displaced point: the least a
// displaced DVR fragment does (render/passes/volume_pass.h adds the opacity
// correction, the cut mask and lighting on top).
in vec2 v_uv;
uniform sampler3D u_volume;
uniform sampler1D u_transfer;
#ifdef DISPLACED
uniform sampler3D u_map;
#endif
uniform float u_layer;  // depth of this layer in the volume, and a shift so layers read different texels
out vec4 o_color;

void main() {
  vec3 p = vec3(v_uv + vec2(u_layer * 0.013, u_layer * 0.007), u_layer);
#ifdef DISPLACED
  p += texture(u_map, p).xyz;
#endif
  vec4 tf = texture(u_transfer, texture(u_volume, p).r);
  o_color = vec4(tf.rgb * tf.a, tf.a);
}
