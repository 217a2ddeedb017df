#version 450 core
// Inverse displacement mapping on a curved base mesh, all methods through the
// ray core (render/passes/relief_surface_pass.h explains the texture volume:
// (u, v, w), w = height above the base in units of u_max_displacement, the
// solid is w <= h(u, v), rays start on the outer shell at w = 1).
// Variants: METHOD_NCS (Chen-Chang Algorithm 2) | METHOD_RELIEF [POC05] |
// METHOD_POM [Tat06] | METHOD_CRM (curved relief mapping [OP05]);
// ORTHOGRAPHIC; SHADED; WRAP_U / WRAP_V (periodic parameterisation);
// POLE_U0 / POLE_U1 / POLE_V0 / POLE_V1 (a chart edge that is a pole,
// render::DetectChart); MARK_EARLY_TERMINATION (NCS: red instead of discard,
// the paper's Figure 7); COLOR_TEXTURE (albedo from u_color at the hit's uv
// times u_color_tiling: the mesh's own uvs, not the height map's tiling);
// plus render::RayCoreDefines().
#include "common/shading.glsl"

in vec3 v_p_in_object;
in vec2 v_uv;

uniform mat4 u_cam_from_object;
uniform mat4 u_clip_from_cam;
uniform mat3 u_world_normal_from_object;
uniform vec3 u_eye_in_object;
uniform vec3 u_view_dir_in_object;  // ORTHOGRAPHIC
uniform float u_max_displacement;   // scene units for w = 1
uniform float u_tiling;             // height map repeats per uv unit
uniform float u_step_enlargement;   // NCS c (sec. 5)
uniform float u_min_view_cos;       // caps the flat path length l
uniform int u_steps;                // NCS num_step / relief linear steps / POM max samples
uniform int u_pom_min_steps;
uniform vec4 u_base_color;
#ifdef COLOR_TEXTURE
uniform sampler2D u_color;          // RGBA8, REPEAT
uniform float u_color_tiling;       // colour texture repeats per uv unit
#endif
uniform sampler2D u_height;         // R32F, REPEAT
uniform sampler2D u_normal_map;     // xyz = N, w = S_binormal (Algorithm 1)
uniform sampler2D u_tangent_map;    // xyz = T, w = handedness * S_tangent
layout(r32ui) uniform coherent uimage2D u_outcome_flags;

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;  // camera z
layout(location = 2) out vec4 o_normal;  // world-space unit normal

struct TangentFrame {
  vec3 t, b, n;
  float s_t, s_b;  // texture units per scene unit along t, b
};

// SetData of Algorithm 2, line 3: the frame at any uv from the maps.
TangentFrame LookupFrame(vec2 uv) {
  vec4 nm = texture(u_normal_map, uv);
  vec4 tm = texture(u_tangent_map, uv);
  TangentFrame f;
  float n_len = length(nm.xyz);
  f.n = n_len > 1e-12 ? nm.xyz / n_len : vec3(0.0, 0.0, 1.0);
  vec3 t = tm.xyz - dot(tm.xyz, f.n) * f.n;  // bilinear blends are re-orthogonalised
  float t_len = length(t);
  if (t_len > 1e-12) {
    f.t = t / t_len;
  } else {
    // Degenerate frame (pole): any unit vector orthogonal to n.
    vec3 a = abs(f.n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    f.t = normalize(cross(f.n, a));
  }
  f.b = (tm.w < 0.0 ? -1.0 : 1.0) * cross(f.n, f.t);
  f.s_t = abs(tm.w);
  f.s_b = nm.w;
  return f;
}

// [S] [TBN] V of Algorithm 2, line 4: texture-space change per scene unit of
// object-space path along V.
vec3 TextureDirection(TangentFrame f, vec3 v_in_object) {
  return vec3(f.s_t * dot(f.t, v_in_object), f.s_b * dot(f.b, v_in_object),
              dot(f.n, v_in_object) / u_max_displacement);
}

// Over a pole. The march goes on in unfolded coordinates, continuous
// across a pole: past the pole v = 0 lies v < 0, which is the chart point
// (u + 1/2, -v) (likewise v = 1, and the u edges across a periodic v).
// ChartPoint folds an unfolded point back onto the chart; `flip` is the
// fold's Jacobian (+-1 per axis), which turns a velocity in chart
// coordinates into one in unfolded coordinates.
vec2 ChartPoint(vec2 uv, out vec2 flip) {
  flip = vec2(1.0);
  // Two folds reach any point a ray of one shell crossing can: over one
  // pole and, on a short chart, over the other.
  for (int k = 0; k < 2; ++k) {
#ifdef POLE_V0
    if (uv.y < 0.0) {
      uv = vec2(uv.x + 0.5, -uv.y);
      flip.y = -flip.y;
    }
#endif
#ifdef POLE_V1
    if (uv.y > 1.0) {
      uv = vec2(uv.x + 0.5, 2.0 - uv.y);
      flip.y = -flip.y;
    }
#endif
#ifdef POLE_U0
    if (uv.x < 0.0) {
      uv = vec2(-uv.x, uv.y + 0.5);
      flip.x = -flip.x;
    }
#endif
#ifdef POLE_U1
    if (uv.x > 1.0) {
      uv = vec2(2.0 - uv.x, uv.y + 0.5);
      flip.x = -flip.x;
    }
#endif
  }
  return uv;
}
vec2 ChartPoint(vec2 uv) {
  vec2 flip;
  return ChartPoint(uv, flip);
}

float HeightAt(vec2 uv) { return texture(u_height, uv * u_tiling).r; }

#ifdef METHOD_CRM
in vec2 v_quadric;     // (a, b): depth below the tangent plane = a x^2 + b y^2, scene units
float g_crm_q;         // a (T.V)^2 + b (B.V)^2: quadric depth per squared path length
float g_crm_t_per_dw;  // path length per unit drop of the straight ray's w: md / cos
// The straight march's w drops linearly from the tangent plane; the curved
// shell lies q t^2 below that plane at path length t, so the ray's height
// above the base, measured from the quadric, is w + q t^2 / md [OP05].
float CurvedW(vec3 p) {
  float t = (1.0 - p.z) * g_crm_t_per_dw;
  return p.z + g_crm_q * t * t / u_max_displacement;
}
#endif

// The ray core's field: > 0 above the height field. The 1e-5 (of a shell
// thickness) counts a sample landing exactly on the surface -- e.g. on the
// base of a zero height map after exactly l -- as inside.
float RayField(vec3 p) {
#ifdef METHOD_CRM
  return CurvedW(p) - HeightAt(ChartPoint(p.xy)) - 1e-5;
#else
  return p.z - HeightAt(ChartPoint(p.xy)) - 1e-5;
#endif
}

#ifdef METHOD_NCS
vec3 g_view_in_object;  // the straight object-space ray (unit)
#define RAY_BEND
// Algorithm 2, lines 3-4: look up the frame at the current uv, bend.
vec3 RayBend(vec3 p) {
  vec2 flip;
  vec2 uv = ChartPoint(p.xy, flip);
  vec3 d = TextureDirection(LookupFrame(uv), g_view_in_object);
  return vec3(flip * d.xy, d.z);
}
#define RAY_DOMAIN
// Left the texture volume: through the top of the shell (the paper's z < 0)
// or through a chart border (neither periodic nor a pole).
bool RayInDomain(vec3 p) {
  bool inside = p.z <= 1.0;
  vec2 uv = ChartPoint(p.xy);
#ifndef WRAP_U
  inside = inside && uv.x >= 0.0 && uv.x <= 1.0;
#endif
#ifndef WRAP_V
  inside = inside && uv.y >= 0.0 && uv.y <= 1.0;
#endif
  return inside;
}
#endif

#include "cores/ray_core.glsl"

void main() {
#ifdef ORTHOGRAPHIC
  vec3 v = u_view_dir_in_object;
#else
  vec3 v = normalize(v_p_in_object - u_eye_in_object);
#endif
  TangentFrame f0 = LookupFrame(v_uv);
  float cos_in = -dot(f0.n, v);
  // Flat-surface path length through the shell (sec. 5: "l"), capped at grazing.
  float l = u_max_displacement / max(cos_in, u_min_view_cos);
  RayMarch r;
  r.origin = vec3(v_uv, 1.0);
  r.dir = TextureDirection(f0, v);
#ifdef METHOD_NCS
  g_view_in_object = v;
  r.t_max = 1e30;  // NCS ends by hit, leaving the domain, or running out of steps
  r.step = u_step_enlargement * l / float(u_steps);  // c * delta, Algorithm 2 line 4
#else
  if (cos_in <= 0.0) {
    // Back-facing or tangent to the shell: a straight ray in the fragment's
    // tangent space never enters the volume.
    imageAtomicOr(u_outcome_flags, ivec2(gl_FragCoord.xy), 1u << RAY_OUTCOME_EXITED);
    discard;
  }
  r.t_max = l;
#ifdef METHOD_CRM
  // Depth below the quadric at path length t: d(t) = t cos - q t^2. The
  // march ends at the first root of d = md (the base: w = 0 <= h, a hit)
  // or, where the quadric bends away faster (no such root, q > 0), where
  // the ray comes back out of the shell, d = 0 at t = cos / q: a silhouette.
  float v_t = dot(f0.t, v), v_b = dot(f0.b, v);  // tangent-plane components of V
  g_crm_q = v_quadric.x * v_t * v_t + v_quadric.y * v_b * v_b;
  g_crm_t_per_dw = u_max_displacement / cos_in;
  float disc = cos_in * cos_in - 4.0 * g_crm_q * u_max_displacement;
  float t_end = disc >= 0.0 ? 2.0 * u_max_displacement / (cos_in + sqrt(disc)) : cos_in / g_crm_q;
  // Capped at 2 l (100 shell thicknesses at the default min_view_cos): a
  // near-flat quadric at grazing incidence would march without bound.
  r.t_max = min(t_end, 2.0 * l);
#endif
#ifdef METHOD_POM
  // Tatarchuk 2006: sample count from the view angle.
  float n = floor(mix(float(u_steps), float(u_pom_min_steps), clamp(cos_in, 0.0, 1.0)) + 0.5);
  r.step = l / max(n, 1.0);
#else
  r.step = r.t_max / float(u_steps);  // relief: l; CRM: the quadric path, up to 2 l
#endif
#endif
  RayResult res = RayMarchRun(r);
  imageAtomicOr(u_outcome_flags, ivec2(gl_FragCoord.xy), 1u << res.outcome);

  vec3 color_override = vec3(-1.0);
#ifdef METHOD_CRM
  if (res.outcome != RAY_OUTCOME_HIT) discard;  // came out of the quadric: silhouette
#endif
#ifdef METHOD_NCS
  if (res.outcome == RAY_OUTCOME_EARLY_TERMINATION) {
#ifdef MARK_EARLY_TERMINATION
    color_override = vec3(1.0, 0.0, 0.0);
#else
    discard;  // sec. 3.2: no intersection within num_step steps
#endif
  } else if (res.outcome != RAY_OUTCOME_HIT) {
    discard;  // left the texture volume: a carved silhouette pixel
  }
#endif
  // Relief and POM shade wherever the march stopped (they never carve).
  // CRM's hit lies on the straight object-space ray like theirs: the
  // quadric only decides where along it the surface is.

  vec3 p_in_object = v_p_in_object + res.t * v;  // the object-space ray is straight
  vec4 p_in_cam = u_cam_from_object * vec4(p_in_object, 1.0);
  vec4 clip = u_clip_from_cam * p_in_cam;
  gl_FragDepth = clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);

  // Normal of the displaced surface P + md h N at the hit (central
  // differences one texel apart): N - md (S_t h_u T + S_b h_v B).
  res.p.xy = ChartPoint(res.p.xy);
  TangentFrame f = LookupFrame(res.p.xy);
  vec2 texel = 1.0 / (vec2(textureSize(u_height, 0)) * u_tiling);
  float h_u = (HeightAt(res.p.xy + vec2(texel.x, 0.0)) - HeightAt(res.p.xy - vec2(texel.x, 0.0))) / (2.0 * texel.x);
  float h_v = (HeightAt(res.p.xy + vec2(0.0, texel.y)) - HeightAt(res.p.xy - vec2(0.0, texel.y))) / (2.0 * texel.y);
  vec3 n_object = normalize(f.n - u_max_displacement * (f.s_t * h_u * f.t + f.s_b * h_v * f.b));
  vec3 n_world = normalize(u_world_normal_from_object * n_object);

#ifdef COLOR_TEXTURE
  vec3 color = texture(u_color, res.p.xy * u_color_tiling).rgb;
#else
  vec3 color = u_base_color.rgb;
#endif
#ifdef SHADED
  color = HeadLight(color, normalize(mat3(u_cam_from_object) * n_object), p_in_cam.xyz);
#endif
  if (color_override.r >= 0.0) color = color_override;
  o_color = vec4(color, 1.0);
  o_depth = p_in_cam.z;
  o_normal = vec4(n_world, 0.0);
}
