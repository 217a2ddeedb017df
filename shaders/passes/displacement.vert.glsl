#version 450 core
// Displacement mapping by slicing (Kautz-Seidel 2001, sec. 3): places the
// slices of per-face displacement volumes. A slice vertex arrives in its
// volume's box coordinates: (x, y) on the base face, z = height as a fraction
// of u_max_displacement, i.e. the alpha-ramp value h_alpha (sec. 3.2). The
// volume is the face extruded along the normalised interpolated vertex
// normals (sec. 3, Figure 2), so the map is evaluated here, per vertex.
// Variants: SURFACE_ALIGNED (h_alpha constant per slice, passed flat so it is
// exact), FULL_SIZE_SLICES (pass the triangle flag for the fragment mask),
// COLOR_TEXTURE (the colour texture's uv and what the fragment shader needs
// for the displaced surface's normal: the interpolated base normal and the
// face's surface gradients of u and v).
#include "cores/slicing_core.glsl"

layout(location = 0) in vec3 a_position;  // box coordinates
layout(location = 3) in int a_volume;     // index into u_volumes

// render/passes/displacement_pass.cc's GpuVolume (std430).
struct DisplacementVolume {
  vec4 p[3];          // base corners (world); box (0,0), (1,0), (0,1)
  vec4 n[3];          // unit vertex normals
  vec4 n_mean;        // fallback where interpolated normals cancel
  vec4 uv01;          // uv of corners 0 and 1
  vec4 uv2_triangle;  // uv of corner 2; z = 1 for a triangle (box x + y <= 1)
};
layout(std430, binding = 0) readonly buffer DisplacementVolumes {
  DisplacementVolume volumes[];
} u_volumes;

uniform float u_max_displacement;  // scene units for height 1
uniform float u_tiling;            // texture repeats across uv [0, 1]

out vec3 v_p_in_box;
out vec3 v_p_in_cam;
out vec2 v_uv;  // already multiplied by u_tiling
#ifdef SURFACE_ALIGNED
flat out float v_h_alpha;
#endif
#ifdef FULL_SIZE_SLICES
flat out int v_triangle;
#endif
#ifdef COLOR_TEXTURE
uniform float u_color_tiling;  // colour texture repeats across uv [0, 1]
out vec2 v_color_uv;
out vec3 v_normal_world;      // unit base normal, interpolated
flat out vec3 v_grad_u;       // surface gradient of u on the face: du per world unit
flat out vec3 v_grad_v;
#endif

void main() {
  DisplacementVolume vol = u_volumes.volumes[a_volume];
  vec3 b = a_position;
  vec3 base = vol.p[0].xyz + b.x * (vol.p[1].xyz - vol.p[0].xyz) + b.y * (vol.p[2].xyz - vol.p[0].xyz);
  vec3 n = vol.n[0].xyz + b.x * (vol.n[1].xyz - vol.n[0].xyz) + b.y * (vol.n[2].xyz - vol.n[0].xyz);
  float len = length(n);
  n = len > 1e-12 ? n / len : vol.n_mean.xyz;
  vec3 p_in_world = base + b.z * u_max_displacement * n;
  vec2 uv = vol.uv01.xy + b.x * (vol.uv01.zw - vol.uv01.xy) + b.y * (vol.uv2_triangle.xy - vol.uv01.xy);
  v_uv = uv * u_tiling;
  v_p_in_box = b;
#ifdef SURFACE_ALIGNED
  v_h_alpha = b.z;
#endif
#ifdef FULL_SIZE_SLICES
  v_triangle = vol.uv2_triangle.z > 0.5 ? 1 : 0;
#endif
#ifdef COLOR_TEXTURE
  v_color_uv = uv * u_color_tiling;
  v_normal_world = n;
  // grad u = a e1 + b e2 in the face plane with (grad u . e1, grad u . e2) =
  // (du1, du2): the 2x2 Gram system of the edges (likewise v).
  vec3 e1 = vol.p[1].xyz - vol.p[0].xyz, e2 = vol.p[2].xyz - vol.p[0].xyz;
  vec2 w1 = vol.uv01.zw - vol.uv01.xy, w2 = vol.uv2_triangle.xy - vol.uv01.xy;
  float g11 = dot(e1, e1), g12 = dot(e1, e2), g22 = dot(e2, e2);
  float det = g11 * g22 - g12 * g12;
  mat2 inv = det > 0.0 ? mat2(g22, -g12, -g12, g11) / det : mat2(0.0);
  vec2 au = inv * vec2(w1.x, w2.x), av = inv * vec2(w1.y, w2.y);
  v_grad_u = au.x * e1 + au.y * e2;
  v_grad_v = av.x * e1 + av.y * e2;
#endif
  gl_Position = SliceVertexWorld(p_in_world, v_p_in_cam);
}
