#version 450 core
// Deform pass fragments (render/passes/deform_pass.h), two variants:
//   MESH_STAGE  the rasterised, undeformed mesh outside the box;
//   RAY_STAGE   the ray cast inside the box (Correa-Silver-Chen 2007) on the
//               shared ray core; writes gl_FragDepth.
// SEAM_BLEND (MESH_STAGE): the mesh's normals blended into the implicit's
// gradient across a band outside the box, so shading does not jump where
// the two stages meet (sec. 3).
// Cut variants (RAY_STAGE): CUT_HOLLOW, CUT_SOLID, CUT_THICK; with CUT_SOLID
// or CUT_THICK, SOLID_SEARCH selects the paper's two-field search (sec.
// 5.1.2) instead of the CSG field max(body, A). SKIP_EMPTY adds empty-space
// skipping by the cut alpha (sec. 6.2); SKIP_OBJECT skipping by the object's
// distance field (sphere tracing's bound through the warp's Lipschitz
// constant). ORTHOGRAPHIC: parallel rays.
// IMPLICIT_DEPTH_CUBE: the object's implicit from the depth-map cube of
// sec. 6.1 instead of the 3D distance field (Implicit(), the only difference).
// DEFORM_FLAP: the deformation has a second piece, a peel's flap
// (core/deformation.h "Pieces"): the field is the union (min) of the rest's
// and the flap's, each warped by its own continuous D; the flap is bounded
// by its mask (u_deformation_flap's alpha) in every cut mode.
//
// Sign convention, converted here once: the paper's f is > 0 inside; the
// ray core's field (RayField) is > 0 in empty space, so RayField works on
// the signed distance sdf = -f (> 0 outside).

uniform mat4 u_cam_from_world;
uniform mat4 u_clip_from_cam;
uniform vec4 u_base_color;

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;    // camera z
layout(location = 2) out vec4 o_normal;    // world-space unit normal
// The frame's outcome bits (render/passes/pass.h; render/passes/deform_pass.h:
// cut face, mesh, rejected crossings, samples), ORed per fragment.
layout(r32ui) uniform coherent uimage2D u_outcome_flags;

#include "common/shading.glsl"

vec3 Shade(vec3 albedo, vec3 n_world, vec3 p_in_cam) {
  return HeadLight(albedo, normalize(mat3(u_cam_from_world) * n_world), p_in_cam);
}

// The object's implicit and the box's frame: the ray stage's, and the mesh
// stage's where it blends its normals into the ray-cast ones (SEAM_BLEND).
#if defined(RAY_STAGE) || defined(SEAM_BLEND)
uniform mat4 u_object_from_box;
uniform mat4 u_box_from_object;
#ifdef IMPLICIT_DEPTH_CUBE
uniform sampler2DArray u_sdf;     // the six faces' depths (R32F, bilinear; the far face where empty)
uniform mat4 u_cube_from_object[6];  // per face: object -> (s, t) texture coordinates, z from the face
#else
uniform sampler3D u_sdf;          // signed distance, > 0 outside, nodes at texel centres
uniform vec3 u_sdf_origin;        // object position of node (0, 0, 0)
uniform vec3 u_sdf_size;          // nodes per axis
#endif
uniform float u_sdf_spacing;      // object units between nodes (depth cube: per texel)

// The object's implicit at an undeformed point (> 0 outside), the one lookup
// that differs between the variants.
#ifdef IMPLICIT_DEPTH_CUBE
// Depth-map cube (sec. 6.1; render::DepthCube): the largest of the six faces'
// signed depth differences (depth seen - distance from the face).
float Implicit(vec3 p) {
  float f = -1e30;
  for (int i = 0; i < 6; ++i) {
    vec3 q = (u_cube_from_object[i] * vec4(p, 1.0)).xyz;
    f = max(f, texture(u_sdf, vec3(q.xy, float(i))).r - q.z);
  }
  return f;
}
#else
float Implicit(vec3 p) { return texture(u_sdf, ((p - u_sdf_origin) / u_sdf_spacing + 0.5) / u_sdf_size).r; }
#endif

vec3 ImplicitGradient(vec3 p) {
#ifdef IMPLICIT_DEPTH_CUBE
  // Two texels each way: the max switches between faces whose bilinear
  // maps facet the surface per texel (a face seeing it at a grazing angle
  // carves it most), so half a texel bands the shading texel by texel
  // (Spot at 256 px); two texels soften the bands, they do not remove them.
  float h = 2.0 * u_sdf_spacing;
#else
  float h = 0.5 * u_sdf_spacing;
#endif
  return vec3(Implicit(p + vec3(h, 0, 0)) - Implicit(p - vec3(h, 0, 0)),
              Implicit(p + vec3(0, h, 0)) - Implicit(p - vec3(0, h, 0)),
              Implicit(p + vec3(0, 0, h)) - Implicit(p - vec3(0, 0, h)));
}
#endif

#ifdef MESH_STAGE
// Early tests: only fragments that pass the depth test (at the time they
// are drawn) OR the mesh bit.
layout(early_fragment_tests) in;
in vec3 v_normal_world;
in vec3 v_p_in_cam;
#ifdef SEAM_BLEND
in vec3 v_p_world;
uniform float u_seam_band;  // object units
#endif
void main() {
  vec3 n = length(v_normal_world) > 0.0 ? normalize(v_normal_world) : vec3(0.0, 0.0, 1.0);
#ifdef SEAM_BLEND
  // Correa, Silver, Chen 2007 sec. 3: where the rasterised mesh meets the
  // ray-cast box the normals jump from the mesh's interpolated ones to the
  // implicit's gradient (the ray stage's, eq. 5 with J = 0 on the box's
  // faces). Within u_seam_band of the box the mesh's normal turns into the
  // gradient, reaching it on the box's face; beyond the band nothing changes.
  vec3 u = (u_box_from_object * vec4(v_p_world, 1.0)).xyz;
  float d = length(mat3(u_object_from_box) * (u - clamp(u, 0.0, 1.0)));
  if (d < u_seam_band) {
    vec3 g = ImplicitGradient(v_p_world);
    if (dot(g, g) > 0.0) n = normalize(mix(normalize(g), n, smoothstep(0.0, u_seam_band, d)));
  }
#endif
  o_color = vec4(Shade(u_base_color.rgb, n, v_p_in_cam), 1.0);
  o_depth = v_p_in_cam.z;
  o_normal = vec4(n, 0.0);
  imageAtomicOr(u_outcome_flags, ivec2(gl_FragCoord.xy), DEFORM_MESH_BIT);
}
#endif

#ifdef RAY_STAGE
in vec3 v_p_world;

uniform mat4 u_world_from_cam;
uniform vec2 u_clip_z;            // camera z of the near and far clip planes (core::ClipRangeZ)
uniform sampler3D u_deformation;  // xyz: D (box units), w: cut alpha A (> 0 cut)
#ifdef DEFORM_FLAP
uniform sampler3D u_deformation_flap;  // the flap piece: xyz its D, w its mask (> 0 no flap)
// Per piece, its alpha as four smooth components (core::DeformationSum::
// AlphaComponents; a lone peel's planes), for exact cut-face normals.
uniform sampler3D u_alpha_components;
uniform sampler3D u_alpha_components_flap;
#endif
uniform float u_deform_resolution;
uniform float u_step;             // base step, object units
uniform float u_thickness;        // CUT_THICK: shell thickness T, object units
uniform float u_alpha_lipschitz;  // bound of |grad A| in object units (SKIP_EMPTY, SKIP_OBJECT)
uniform sampler3D u_warp_lipschitz;  // SKIP_OBJECT: per box brick, a bound of |I + J| over
                                     // the brick and its neighbours (R32F, NEAREST)
uniform float u_warp_skip_cap;       // SKIP_OBJECT: the longest skip those bounds hold for
uniform float u_sdf_margin;       // SKIP_OBJECT: the most a lookup can exceed the true distance
uniform vec4 u_cut_color;


// The texture coordinate of box point u in the deformation's textures (node
// (i, j, k) at u = (i, j, k) / (res - 1) is a texel centre).
vec3 DeformTexCoord(vec3 u) { return (u * (u_deform_resolution - 1.0) + 0.5) / u_deform_resolution; }

// (p' + M D(M^-1 p'), A(p')) of one piece for a deformed-space point p'
// (eq. 2; piece 1: the flap, A its mask); outside the box D = 0 and A = -1
// (the flap's mask: +1, no flap there).
vec4 WarpPiece(vec3 p, int piece) {
  vec3 u = (u_box_from_object * vec4(p, 1.0)).xyz;
  // The box's faces belong to it: a ray's entry point, computed on a face,
  // may round to just outside (1e-5: float rounding of the box transform).
  if (any(lessThan(u, vec3(-1e-5))) || any(greaterThan(u, vec3(1.0 + 1e-5))))
    return vec4(p, piece == 0 ? -1.0 : 1.0);
  vec3 s = DeformTexCoord(u);
#ifdef DEFORM_FLAP
  vec4 e = piece == 0 ? texture(u_deformation, s) : texture(u_deformation_flap, s);
#else
  vec4 e = texture(u_deformation, s);
#endif
  return vec4(p + mat3(u_object_from_box) * e.xyz, e.w);
}
vec4 Warp(vec3 p) { return WarpPiece(p, 0); }

// The object's field before the cut: sdf, or the thick shell of eq. 7
// (solid where -T <= sdf <= 0).
float Body(float sdf) {
#ifdef CUT_THICK
  return abs(sdf + 0.5 * u_thickness) - 0.5 * u_thickness;
#else
  return sdf;
#endif
}

#if (defined(CUT_SOLID) || defined(CUT_THICK)) && defined(SOLID_SEARCH)
#define TWO_FIELDS  // the ray core's RAY_SECOND_FIELD: k = 0 the body, k = 1 the cut
#endif

// One piece's (field, mask): the rest's field per cut mode, the flap's
// bounded by its mask; k (TWO_FIELDS, the rest only): 0 the body alone, 1 the
// cut alpha alone. The mask is the piece's alpha (w) at p.
vec2 PieceFieldAndMask(vec3 p, int piece, int k) {
  vec4 w = WarpPiece(p, piece);
  float body = Body(Implicit(w.xyz));
  if (piece == 1) return vec2(max(body, w.w), w.w);
#ifdef TWO_FIELDS
  return vec2(k == 0 ? body : w.w, w.w);
#elif defined(CUT_SOLID) || defined(CUT_THICK)
  return vec2(max(body, w.w), w.w);  // eq. 6: inside the body and outside the cut
#else
  return vec2(body, w.w);
#endif
}
float PieceFieldK(vec3 p, int piece, int k) { return PieceFieldAndMask(p, piece, k).x; }

// The cut alpha where FieldK was last evaluated (the smaller of the pieces'
// masks), so the cut skip at a sample the march just evaluated costs no
// second warp lookup; CutSkip checks the position before using it.
vec3 g_alpha_p = vec3(1e30);
float g_alpha = 0.0;

float FieldK(vec3 p, int k) {
  vec2 rest = PieceFieldAndMask(p, 0, k);
  g_alpha_p = p;
  g_alpha = rest.y;
#ifdef DEFORM_FLAP
  vec2 flap = PieceFieldAndMask(p, 1, k);
  g_alpha = min(g_alpha, flap.y);
  return min(rest.x, flap.x);  // the union of the pieces
#else
  return rest.x;
#endif
}

// The piece whose field is the smaller at p (where a hit lies on).
int ActivePieceK(vec3 p, int k) {
#ifdef DEFORM_FLAP
  return PieceFieldK(p, 1, k) < PieceFieldK(p, 0, k) ? 1 : 0;
#else
  return 0;
#endif
}
int ActivePiece(vec3 p) { return ActivePieceK(p, 0); }

// J_{T^-1} = I + J_D of one piece by central differences of its warp (half
// a texel of D).
mat3 WarpJacobian(vec3 p, int piece) {
  float h = 0.5 * length(mat3(u_object_from_box)[0]) / (u_deform_resolution - 1.0);
  h = max(h, 1e-5);
  mat3 j;
  for (int a = 0; a < 3; ++a) {
    vec3 e = vec3(0.0);
    e[a] = h;
    j[a] = (WarpPiece(p + e, piece).xyz - WarpPiece(p - e, piece).xyz) / (2.0 * h);
  }
  return j;
}

#ifdef RAY_STEP_JACOBIAN
// The rest's (the flap's D is a rigid turn for a lone peel: I + J is a rotation).
mat3 RayJacobian(vec3 p) { return WarpJacobian(p, 0); }
#endif

#ifdef CUT_HOLLOW
#define RAY_BOTH_CROSSINGS
#define RAY_REJECT
// Sec. 5.1.1: hits of the surface inside the cut are discarded (the rest's;
// the flap is bounded by its mask instead).
bool RayRejectHit(vec3 p) { return ActivePiece(p) == 0 && Warp(p).w > 0.0; }
#endif

#ifdef TWO_FIELDS
#define RAY_SECOND_FIELD
float RayFieldK(vec3 p, int k) { return FieldK(p, k); }
// Sec. 5.1.2. Field 0: a surface hit inside the cut (A > 0) is discarded and
// the search turns to the cut's boundary. Field 1: a boundary crossing
// outside the body is no cut face, and the search turns to the surface
// again. A flap hit is never rejected (its mask bounds it in both fields).
bool RayRejectHitK(vec3 p, int k) {
  if (ActivePieceK(p, k) != 0) return false;
  vec4 w = Warp(p);
  return k == 0 ? w.w > 0.0 : Body(Implicit(w.xyz)) > 0.0;
}
#endif

#if defined(SKIP_EMPTY) || defined(SKIP_OBJECT)
#define RAY_SKIP
// A crossing-free distance from p given the current field's value f there.
// Every field here is a max / min / |.| of the body (a distance through the
// warp: changes by at most L_warp per unit of ray, plus the lookup's margin)
// and the cut alpha (u_alpha_lipschitz), so reaching a sign change takes at
// least min((|f| - margin) / L_warp, |f| / L_A); L_warp is the bound of p's
// brick, valid up to u_warp_skip_cap.
float ObjectSkip(vec3 p, float f) {
  float a = abs(f);
  vec3 u = clamp((u_box_from_object * vec4(p, 1.0)).xyz, 0.0, 1.0);
  float l = texture(u_warp_lipschitz, u).r;
  float skip = min((a - u_sdf_margin) / l, a / u_alpha_lipschitz);
  return clamp(skip, 0.0, u_warp_skip_cap);
}
// Inside the cut (A > 0) nothing is hit within A / Lipschitz(A) (sec. 6.2).
// With a flap, both pieces must be empty there: the smaller of the two (the
// cached alpha is that minimum). The alpha is the march's own evaluation at
// p; where p is not the last point evaluated (a hollow cut's first sample
// after a rejected hit: the refinement evaluated since) the skip is 0, always
// a true bound, rather than a second warp lookup: llvmpipe runs an if's
// both sides for every sample, so a fallback lookup would cost every sample,
// not only the stale ones, a second 3D fetch, more than the skip saves
// (docs/decisions/cut-skip.md).
float CutSkip(vec3 p) {
  float a = p == g_alpha_p ? g_alpha : 0.0;
  return a > 0.0 ? a / u_alpha_lipschitz : 0.0;
}
float SkipK(vec3 p, float f, int k) {
  float skip = 0.0;
#ifdef SKIP_OBJECT
  if (k == 0) skip = ObjectSkip(p, f);
#endif
#ifdef SKIP_EMPTY
  // Inside the cut nothing is hit (field 0 of the search: a surface crossing
  // there would be rejected; field 1: the cut's boundary is A / L_A away).
  skip = max(skip, CutSkip(p));
#endif
  return skip;
}
#ifdef TWO_FIELDS
float RaySkipK(vec3 p, float f, int k) { return SkipK(p, f, k); }
#else
float RaySkip(vec3 p, float f) { return SkipK(p, f, 0); }
#endif
#endif

#ifndef TWO_FIELDS
float RayField(vec3 p) { return FieldK(p, 0); }
#endif

#include "cores/ray_core.glsl"


#ifdef DEFORM_FLAP
// The components at box point u, clamped into the box (each is affine where
// a peel's, so differences of clamped points stay exact).
vec4 AlphaComponents(vec3 u, int piece) {
  vec3 s = DeformTexCoord(clamp(u, 0.0, 1.0));
  return piece == 0 ? texture(u_alpha_components, s) : texture(u_alpha_components_flap, s);
}
// The gradient of the component that sets the alpha at p (A = max(s max(c.w,
// min(c.x, c.y, c.z)), -1)): the face's own plane beside the slab's edges,
// where differences of the interpolated alpha blend two faces' normals. The
// flap ends at the box (its mask is 1 outside, WarpPiece): where the box's
// face is nearer than the mask's planes, that face bounds it.
vec3 AlphaGradient(vec3 p, int piece) {
  vec3 u = (u_box_from_object * vec4(p, 1.0)).xyz;
  vec4 c = AlphaComponents(u, piece);
  float lo = min(min(c.x, c.y), c.z);
  vec3 g = vec3(0.0);
  vec3 inside = min(u, 1.0 - u);
  float box_face = -min(min(inside.x, inside.y), inside.z);
  if (piece == 1 && box_face >= -max(c.w, lo)) {
    int axis = inside.x <= min(inside.y, inside.z) ? 0 : (inside.y <= inside.z ? 1 : 2);
    g[axis] = u[axis] > 0.5 ? 1.0 : -1.0;  // outwards
  } else {
    int which = c.w >= lo ? 3 : (lo == c.x ? 0 : (lo == c.y ? 1 : 2));
    float h = 0.5 / (u_deform_resolution - 1.0);
    for (int a = 0; a < 3; ++a) {
      vec3 e = vec3(0.0);
      e[a] = h;
      vec3 up = clamp(u + e, 0.0, 1.0), um = clamp(u - e, 0.0, 1.0);
      g[a] = (AlphaComponents(up, piece)[which] - AlphaComponents(um, piece)[which]) /
             max(up[a] - um[a], 1e-7);
    }
    g *= piece == 0 ? 1.0 : -1.0;  // the flap's mask is -max(...)
  }
  return transpose(mat3(u_box_from_object)) * g;  // grad_p = M^-T grad_u
}
#else
vec3 AlphaGradient(vec3 p, int piece) {
  float h = 0.5 * length(mat3(u_object_from_box)[0]) / (u_deform_resolution - 1.0);
  return vec3(WarpPiece(p + vec3(h, 0, 0), piece).w - WarpPiece(p - vec3(h, 0, 0), piece).w,
              WarpPiece(p + vec3(0, h, 0), piece).w - WarpPiece(p - vec3(0, h, 0), piece).w,
              WarpPiece(p + vec3(0, 0, h), piece).w - WarpPiece(p - vec3(0, 0, h), piece).w);
}
#endif

void main() {
#ifdef ORTHOGRAPHIC
  vec3 dir = normalize(mat3(u_world_from_cam) * vec3(0.0, 0.0, 1.0));
  vec3 eye = v_p_world - 1e4 * dir;  // far in front: the box entry clamps it
#else
  vec3 eye = (u_world_from_cam * vec4(0.0, 0.0, 0.0, 1.0)).xyz;
  vec3 dir = normalize(v_p_world - eye);
#endif
  // Only the part in front of the eye and between the clip planes is marched,
  // as the rasteriser clips the mesh: a camera inside the solid sees it cut by
  // the near plane (the hit is there), never a hit behind it that no fragment
  // could show. dz > 0: every rasterised fragment lies in front of the camera.
  float z0 = (u_cam_from_world * vec4(eye, 1.0)).z, dz = (mat3(u_cam_from_world) * dir).z;
  vec2 tz = (u_clip_z - z0) / dz;
  // The box interval in box coordinates (affine: the same t).
  vec3 o_box = (u_box_from_object * vec4(eye, 1.0)).xyz;
  vec3 d_box = mat3(u_box_from_object) * dir;
  vec2 iv = RayBoxIntervalClamped(o_box, d_box, vec3(0.0), vec3(1.0), vec2(max(tz.x, 0.0), tz.y));
  if (!(iv.x < iv.y)) discard;
  RayMarch r;
  r.origin = eye + iv.x * dir;
  r.dir = dir;
  r.t_max = iv.y - iv.x;
  r.step = u_step;
  RayResult res = RayMarchRun(r);
  uint samples = (uint(min(res.samples, 65535)) << DEFORM_SAMPLES_SHIFT) |
                 (uint(min(res.rejected, DEFORM_REJECTED_MAX)) << DEFORM_REJECTED_SHIFT);
  if (res.outcome != RAY_OUTCOME_HIT) {
    // Every ray ORs its outcome and samples, those that find nothing too.
    imageAtomicOr(u_outcome_flags, ivec2(gl_FragCoord.xy), (1u << uint(res.outcome)) | samples);
    discard;
  }
  vec3 p = res.p;
  int piece = ActivePieceK(p, res.field);
  vec4 w = WarpPiece(p, piece);
  float sdf = Implicit(w.xyz);
  bool cut_face = piece == 1 && w.w > Body(sdf);  // the flap's mask bounds it in every mode
#if defined(CUT_SOLID) || defined(CUT_THICK)
  cut_face = w.w > Body(sdf);  // eq. 6: the cut's term is the active one
#endif
  vec3 n;
  if (cut_face) {
    n = normalize(AlphaGradient(p, piece));  // out of the solid, into the cut
  } else {
    // Eq. 5: n' = (I + J_D)^T grad f at the warped point.
    vec3 g = ImplicitGradient(w.xyz);
#ifdef CUT_THICK
    if (sdf + 0.5 * u_thickness < 0.0) g = -g;  // the shell's inner surface
#endif
    n = normalize(transpose(WarpJacobian(p, piece)) * g);
  }
  vec4 p_in_cam = u_cam_from_world * vec4(p, 1.0);
  vec4 clip = u_clip_from_cam * p_in_cam;
  gl_FragDepth = clamp(0.5 * (clip.z / clip.w) + 0.5, 0.0, 1.0);
  // Hollow: a hit leaving the solid shows the inside of the shell.
  vec3 albedo = (cut_face || !res.entering) ? u_cut_color.rgb : u_base_color.rgb;
  o_color = vec4(Shade(albedo, n, p_in_cam.xyz), 1.0);
  o_depth = p_in_cam.z;
  o_normal = vec4(n, 0.0);
  imageAtomicOr(u_outcome_flags, ivec2(gl_FragCoord.xy),
                (1u << uint(res.outcome)) | (cut_face ? DEFORM_CUT_FACE_BIT : 0u) | samples);
}
#endif
