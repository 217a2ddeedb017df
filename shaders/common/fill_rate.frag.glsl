#version 450 core
// Fill-rate calibration: one texture lookup + an alpha test per fragment, the
// per-fragment work of one displacement slice (Kautz-Seidel 2001, sec. 3).
in vec2 v_uv;
uniform sampler2D u_texture;
uniform float u_layer;  // shifts the lookup so every layer reads different texels
out vec4 o_color;

void main() {
  vec4 texel = texture(u_texture, v_uv * 2.0 + vec2(u_layer * 0.013, u_layer * 0.007));
  if (texel.a <= 0.0) discard;
  o_color = texel;
}
