#version 450 core
// Fill-rate floor of direct volume rendering (render/gl/fill_rate.h,
// FillRateOptions::volume_fetch): one trilinear lookup of a 3D scalar texture
// per fragment, written premultiplied for ONE, ONE_MINUS_SRC_ALPHA blending:
// the least a DVR slice fragment does (render/passes/volume_pass.h adds the
// transfer function, displacement and lighting on top).
in vec2 v_uv;
uniform sampler3D u_volume;
uniform float u_layer;  // depth of this layer in the volume, and a shift so layers read different texels
out vec4 o_color;

void main() {
  float s = texture(u_volume, vec3(v_uv + vec2(u_layer * 0.013, u_layer * 0.007), u_layer)).r;
  o_color = vec4(0.9, 0.7, 0.5, 1.0) * (0.02 * s);
}
