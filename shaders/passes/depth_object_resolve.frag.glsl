#version 450 core
// Texturing (empty pixels 0) after the stencil slice passes (ibr/depth_object.cc):
// a full-screen pass (fullscreen.vert.glsl) reading the accumulated colour
// and the first-surface depth.
//   TEXTURING_VDT         view-dependent texturing (sec. 4.2 weights, ibr/view_weights.h)
//                         with a visibility test: map i contributes w_i times the
//                         fraction of its 2x2 texel footprint that saw the point
//                         (VdtSeenColor); where none of the weighted maps saw it, any
//                         map that did; where none did, the nearest surface
//   TEXTURING_VDT_PAPER   the paper's view-dependent texturing (sec. 4.2), already
//                         blended during the map loop: colour = sum(w c) / sum(w)
//   TEXTURING_VISIBILITY  per pixel, only maps that saw this point (their
//                         bilinear depth matches within u_visibility_tolerance,
//                         softly) contribute, weighted by cos^8 of the angle
//                         between their ray and the view's; where no map saw it,
//                         the map whose surface is nearest; else VDT
//   TEXTURING_NONE        grey, Lambert-shaded with normals from depth differences
#include "passes/depth_object_core.glsl"

uniform sampler2D u_accum_color;  // RGBA32F: sum of w c, sum of w
uniform sampler2D u_accum_depth;  // RG32F: view camera z of the first surface, covered flag
uniform float u_visibility_tolerance;  // scene units along each map's z
// Refinement of the first surface between the slice that finished the pixel
// and the one before it (all slices of a frame are parallel planes), by the
// ray core's refinement (RayRefineCrossing) on the object's field:
uniform int u_refine;          // 1 = refine, 0 = the slice position itself
uniform vec4 u_plane0;         // the first slice's plane (normal in xyz)
uniform float u_plane_step;    // |w| difference between neighbouring slices (> 0)

float RayField(vec3 p) { return ObjectField(p); }
#include "cores/ray_core.glsl"

// The first-surface point to texture and to report: the crossing between the
// previous slice (outside) and the finishing slice (inside) on the pixel's ray.
vec3 RefineSurface(vec2 uv, vec3 p_inside) {
  // The neighbouring plane on the eye's side: along the ray, w grows with
  // the distance when dot(n, ray) > 0 (perspective: sign(w), the eye has w 0).
  float w = dot(u_plane0.xyz, p_inside);
#ifdef VIEW_ORTHOGRAPHIC
  float toward_eye = u_plane0.z > 0.0 ? -1.0 : 1.0;
#else
  float toward_eye = w > 0.0 ? -1.0 : 1.0;
#endif
  vec3 p_outside = ViewPointOnPlane(uv, vec4(u_plane0.xyz, w + toward_eye * u_plane_step));
  // With the eye within one slice spacing of the finishing slice (the eye in
  // the box) the previous plane meets the ray behind the eye (camera z <= 0):
  // bracket from a point on the same ray just in front of the eye instead,
  // so the refined surface never lies behind it (found by ibr verify --hard).
  if (!(p_outside.z > 0.0)) {
#ifdef VIEW_ORTHOGRAPHIC
    p_outside = vec3(p_inside.xy, 1e-3 * p_inside.z);
#else
    p_outside = 1e-3 * p_inside;
#endif
  }
  float s = RayRefineCrossing(p_outside, p_inside, RayField(p_outside), RayField(p_inside));
  return mix(p_outside, p_inside, s);
}

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec2 o_depth;  // camera z (0 where empty), covered

#ifdef FRAME_OUTPUT
// The pass contract's frame (render/passes/pass.h): attachment 1 is R32F
// (camera z: o_depth.x), 2 the world normal (unknown here: 0); the outcome
// bits are ORed into the frame's outcome image for every covered pixel,
// visible or hidden (gl_FragDepth is written, so every fragment runs); the
// window depth from u_clip_from_cam, depth-tested against the frame; empty
// pixels discarded.
uniform mat4 u_clip_from_cam;
layout(location = 2) out vec4 o_normal;
layout(r32ui, binding = 0) uniform coherent uimage2D u_outcome_image;
float WindowDepth(vec3 p) {
  vec4 clip = u_clip_from_cam * vec4(p, 1.0);
  float ndc = clip.z / clip.w;
  return 0.5 * (gl_DepthRange.diff * ndc + gl_DepthRange.near + gl_DepthRange.far);
}
#endif

// The novel view's ray through view-space point p (unit, towards the scene).
vec3 ViewRay(vec3 p) {
#ifdef VIEW_ORTHOGRAPHIC
  return vec3(0.0, 0.0, 1.0);
#else
  return normalize(p);
#endif
}

vec3 VdtColor(ivec2 px) {
  vec4 acc = texelFetch(u_accum_color, px, 0);
  // Robust intersection can finish a pixel where no weighted map passed.
  return acc.a > 0.0 ? acc.rgb / acc.a : vec3(0.5);
}

// How densely map m sampled the surface at a footprint of depths d[4]
// (bilinear weights t within it, texels of `texel_size` scene units):
// cos^4 of the angle between the map's axis and the surface, tan = the
// bilinear depth surface's slope in depth per texel width. A map that sees
// a surface at a grazing angle (stretched texels; its shading baked at that
// angle) fades out smoothly instead of dropping in and out along its
// terraces as its texels' residuals cross the visibility tolerance (contour
// stripes on Spot's flanks, from the top map). Ranks maps as the resolution
// penalty of unstructured lumigraph rendering (Buehler et al. 2001) does.
// At least 0.01: a map the view looks through keeps its colours at its own
// silhouette (the sphere's limb is grazing to the map that shows it) against
// the other maps' small weights there; a grazing map beside one that saw the
// surface squarely keeps about 1 % of the weight (about one level of colour).
float SamplingDensity(float d[4], vec2 t, float texel_size) {
  vec2 slope = vec2(mix(d[1] - d[0], d[3] - d[2], t.y), mix(d[2] - d[0], d[3] - d[1], t.x));
  float tan2 = dot(slope, slope) / (texel_size * texel_size);
  float cos2 = 1.0 / (1.0 + tan2);
  return max(cos2 * cos2, 0.01);
}

#ifdef TEXTURING_VDT
// The residual between a point at map camera z and the surface a texel of
// depth code d (ibr::MakeMapTables) saw; 1e30 where the texel cannot show it:
// outside the silhouette (d < 0: that colour is the background) and, for
// depth objects, invalid depth (d = 0, a sensor hole: no evidence). Depth
// objects: |z - d|, the texel's surface is the point's. Visual hulls: the
// hull lies in front of the object, so only a point behind the texel's
// surface (z - d > 0, occluded) has a residual; without depth (d = 0) the
// silhouette alone decides.
float TexelResidual(float d, float z) {
  if (d < 0.0) return 1e30;
#ifdef VISUAL_HULL
  return d == 0.0 ? 0.0 : max(z - d, 0.0);
#else
  return d == 0.0 ? 1e30 : abs(z - d);
#endif
}

// Map m at view point p: the fraction of its bilinear 2x2 footprint (texel
// centres at +0.5) whose texels saw p -- softly, 1 within half the
// visibility tolerance, 0 beyond it -- and the colour over those texels
// alone, so neither an occluder in front of p, nor the background beyond a
// silhouette, nor a sensor hole lends p its colour. Also the smallest
// residual of the footprint and that texel's colour (the fallback).
float VdtSeenColor(MapRecord m, vec3 p, out vec3 color, inout float nearest_residual,
                   inout vec3 nearest_color) {
  color = vec3(0.0);
  vec3 q;
  ivec3 texel;
  vec2 uv;
  if (!MapLookupUv(m, p, q, texel, uv)) return 0.0;
  vec2 f = uv - 0.5;
  ivec2 i0 = ivec2(floor(f));
  vec2 t = f - vec2(i0);
  float d[4], b[4];
  ivec3 ij[4];
  float dmin = 1e30, dmax = -1e30, dbil = 0.0;
  for (int k = 0; k < 4; ++k) {
    ij[k] = ivec3(clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), m.info.xy - 1), m.info.w);
    b[k] = ((k & 1) != 0 ? t.x : 1.0 - t.x) * ((k >> 1) != 0 ? t.y : 1.0 - t.y);
    d[k] = texelFetch(u_depth_maps, ij[k], 0).r;
    dmin = min(dmin, d[k]);
    dmax = max(dmax, d[k]);
    dbil += b[k] * d[k];
  }
  // A footprint on one surface (every depth valid, spanning at most 4 texel
  // widths: slopes up to 76 degrees to the map) is compared by its bilinear
  // depth, which follows a slope between the texel centres (each texel's own
  // depth would leave a sawtooth residual of a texel times the slope: contour
  // stripes); across a depth edge each texel by its own.
  float texel_size = MapTexelSize(m, q.z);
  bool one_surface = dmin > 0.0 && dmax - dmin <= 4.0 * texel_size;
  float seen = 0.0;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < 4; ++k) {
    float residual = TexelResidual(one_surface ? dbil : d[k], q.z);
    if (residual < nearest_residual) {
      nearest_residual = residual;
      nearest_color = MapColor(ij[k]).rgb;
    }
    float v =
        b[k] * (1.0 - smoothstep(0.5 * u_visibility_tolerance, u_visibility_tolerance, residual));
    if (v > 0.0) {
      seen += v;
      sum += v * MapColor(ij[k]).rgb;
    }
  }
  if (seen > 0.0) color = sum / seen;
  // Across a depth edge (not one surface) the slope is the edge's: a texel
  // there saw the point only if its own residual says so, at the least
  // density beside a map that saw the surface squarely.
  return seen * SamplingDensity(d, t, texel_size);
}

// sum_i w_i s_i c_i / sum_i w_i s_i over the maps (s_i = VdtSeenColor's
// fraction), w_i = the sec. 4.2 weight (extra.x) + 1e-3 ((1 + cos theta_i) /
// 2)^8, theta_i between map i's ray and the view's: the second term is
// negligible wherever a weighted map saw the point and the answer where none
// did (a concavity only an unweighted map saw), continuously between the two.
// Where no map saw it (no texel within the tolerance), the colour of the
// texel whose surface lies nearest to it along its map's ray; where no map
// has a valid texel there, the paper's blend.
vec3 VisibleVdtColor(ivec2 px, vec3 p) {
  const vec3 view_ray = ViewRay(p);
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  float nearest_residual = 1e30;
  vec3 nearest_color = VdtColor(px);
  for (int i = 0; i < u_map_count; ++i) {
    vec3 map_ray = u_maps[i].centre_in_view.w > 0.5 ? u_maps[i].axis_in_view.xyz
                                                    : normalize(p - u_maps[i].centre_in_view.xyz);
    float h = 0.5 + 0.5 * dot(map_ray, view_ray);
    float h2 = h * h, h4 = h2 * h2;
    float w = max(u_maps[i].extra.x, 0.0) + 1e-3 * h4 * h4;
    vec3 c;
    float s = VdtSeenColor(u_maps[i], p, c, nearest_residual, nearest_color);
    sum += w * s * c;
    wsum += w * s;
  }
  return wsum > 0.0 ? sum / wsum : nearest_color;
}
#endif

#ifdef TEXTURING_VISIBILITY
// Bilinear depth and colour of map m at map-camera point q (texel centres at
// +0.5), for texturing only (the object itself uses nearest texels). A
// nearest-texel depth would make the visibility residual a sawtooth of a
// texel times the surface slope, which shows as contour stripes. Falls back
// to the nearest texel where a neighbour is invalid or outside the mask.
// Also the map's SamplingDensity there (about 0 across a depth edge).
bool MapSampleBilinear(MapRecord m, vec3 q, ivec3 nearest, out float depth, out vec3 color,
                       out float density) {
  vec2 uv = m.info.z == 1 ? q.xy * m.proj.xy + m.proj.zw : (q.xy / q.z) * m.proj.xy + m.proj.zw;
  vec2 f = uv - 0.5;
  ivec2 i0 = ivec2(floor(f));
  vec2 t = f - vec2(i0);
  ivec2 size = m.info.xy;
  float d[4];
  vec3 c[4];
  bool ok = true;
  for (int k = 0; k < 4; ++k) {
    ivec2 ij = clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), size - 1);
    d[k] = texelFetch(u_depth_maps, ivec3(ij, m.info.w), 0).r;
    c[k] = MapColor(ivec3(ij, m.info.w)).rgb;
    ok = ok && d[k] > 0.0;
  }
  density = SamplingDensity(d, t, MapTexelSize(m, q.z));
  if (!ok) {
    depth = texelFetch(u_depth_maps, nearest, 0).r;
    color = MapColor(nearest).rgb;
    return depth > 0.0;
  }
  depth = mix(mix(d[0], d[1], t.x), mix(d[2], d[3], t.x), t.y);
  color = mix(mix(c[0], c[1], t.x), mix(c[2], c[3], t.x), t.y);
  return true;
}

vec3 VisibilityColor(ivec2 px, vec3 p) {
  const vec3 view_ray = ViewRay(p);
  // Soft visibility times a view-dependent falloff: w = v * cos^8(theta),
  // v = 1 - smoothstep(tol/2, tol, residual). Both factors are continuous in
  // the point and the camera, so maps fade in and out instead of switching
  // (hard set changes show as seams where the maps' shading differs).
  float nearest_residual = 1e30;
  vec3 nearest_color = VdtColor(px);
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  for (int i = 0; i < u_map_count; ++i) {
    vec3 q;
    ivec3 texel;
    if (!MapLookup(u_maps[i], p, q, texel)) continue;
    float d, density;
    vec3 c;
    if (!MapSampleBilinear(u_maps[i], q, texel, d, c, density)) continue;
    float residual = abs(q.z - d);
    if (residual < nearest_residual) {
      nearest_residual = residual;
      nearest_color = c;
    }
    float v = 1.0 - smoothstep(0.5 * u_visibility_tolerance, u_visibility_tolerance, residual);
    vec3 map_ray = u_maps[i].centre_in_view.w > 0.5 ? u_maps[i].axis_in_view.xyz
                                                    : normalize(p - u_maps[i].centre_in_view.xyz);
    float cos_theta = max(dot(map_ray, view_ray), 0.0);
    float c2 = cos_theta * cos_theta, c4 = c2 * c2;
    float w = v * c4 * c4 * density;
    sum += w * c;
    wsum += w;
  }
  // Graceful fallback: where no map saw the point, the map whose surface is
  // nearest to it (in its own depth); where none has valid depth there, VDT.
  return wsum > 1e-6 ? sum / wsum : nearest_color;
}
#endif

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec2 zc = texelFetch(u_accum_depth, px, 0).rg;
  vec3 p = ViewPointAtDepth(FragmentUv(), zc.x);
#ifdef TEXTURING_NONE
  // Derivatives before any branch (uniform control flow).
  vec3 n = cross(dFdx(p), dFdy(p));
#endif
  if (zc.y < 0.5) {
#ifdef FRAME_OUTPUT
    discard;
#endif
    o_color = vec4(0.0);  // empty = 0, as in every frame (render/passes/pass.h)
    o_depth = vec2(0.0);
    return;
  }
  if (u_refine != 0) p = RefineSurface(FragmentUv(), p);
  vec3 rgb;
#if defined(TEXTURING_VDT)
  rgb = VisibleVdtColor(px, p);
#elif defined(TEXTURING_VISIBILITY)
  rgb = VisibilityColor(px, p);
#elif defined(TEXTURING_NONE)
  float len = length(n);
  float lambert = len > 0.0 ? abs(n.z) / len : 1.0;
  rgb = vec3(0.15 + 0.75 * lambert);
#else
  rgb = VdtColor(px);
#endif
  o_color = vec4(rgb, 1.0);
  o_depth = vec2(p.z, 1.0);
#ifdef FRAME_OUTPUT
  gl_FragDepth = WindowDepth(p);
  o_normal = vec4(0.0);
  imageAtomicOr(u_outcome_image, ivec2(gl_FragCoord.xy), 1u << RAY_OUTCOME_HIT);
#endif
}
