// Image-based depth objects and visual hulls (Kautz-Seidel 2001, sec. 4-5),
// GPU side: the per-map test "is this point inside what map i allows" -- the
// paper's alpha test after ramp subtraction, generalised from a displacement
// map on a cube face to any registered orthographic or pinhole camera.
// Included by the slice passes, the resolve pass and the ray variant; never
// copied.
//
// Arithmetic contract: every `precise` line here is mirrored operation for
// operation by verify/reference.cc, so the CPU reference reproduces each
// decision bit for bit (IEEE single precision, source order, no fused multiply-add;
// checked on the driver by tests/ibr/shader_arithmetic_test). Texels are
// fetched with integer indices (texelFetch), never filtered.
//
// Variant defines:
//   VISUAL_HULL              test silhouettes only (sec. 5), else depth (sec. 4)
//   OUTSIDE_PASSES           points outside a map's image (or behind a pinhole
//                            map) are not constrained by it; else they are carved
//   INVALID_DEPTH_PASSES     depth 0 inside the silhouette = no constraint; else empty
//   VIEW_ORTHOGRAPHIC        the novel view is orthographic
//   ROBUST_COUNT             ObjectField counts accepting maps (robust intersection)
//   SUBTEXEL_DEPTH           depth interpolated inside the silhouette (ray path only;
//                            the slice passes stay bit-exact with nearest texels)
//
// The map table holds any number of maps up to the GL implementation's
// limits (ibr/depth_object.cc CheckMapLimits): a uniform block of MAX_MAPS
// records (the maps rounded up to 64) where GL_MAX_UNIFORM_BLOCK_SIZE allows,
// else (MAPS_IN_STORAGE_BUFFER) a storage buffer, whose object field loops
// over the frame's maps only (u_active_maps: FrameParams::active). Loops run
// to u_map_count.

struct MapRecord {
  vec4 m0, m1, m2, m3;  // columns of map_cam_from_view_cam (xyz; w unused)
  vec4 proj;            // fx, fy, cx, cy (orthographic: sx, sy in pixels per unit)
  ivec4 info;           // width, height, orthographic (0/1), texture layer
  vec4 extra;           // x: view-dependent weight, y: record j < u_active_count: the j-th
                        // active map's index (the maps that carve this view); zw unused
  vec4 centre_in_view;  // map's centre (orthographic: a point far back along its axis) in view camera space, w = orthographic
  vec4 axis_in_view;    // map's +z axis in view camera space
};

// MAPS_IN_STORAGE_BUFFER: more maps than a uniform block holds; else a
// uniform block of MAX_MAPS records (llvmpipe reads a uniform block far
// faster than a storage buffer in the ray loop:
// docs/decisions/map-table-storage.md).
#ifdef MAPS_IN_STORAGE_BUFFER
layout(std430, binding = 0) readonly buffer DepthObjectMaps {
  MapRecord u_maps[];
};
layout(std430, binding = 1) readonly buffer DepthObjectActiveMaps {
  int u_active_maps[];  // indices into u_maps, in loop order (ascending)
};
#else
#ifndef MAX_MAPS
#error "MAX_MAPS missing: the renderer defines it"
#endif
layout(std140, binding = 0) uniform DepthObjectMaps {
  MapRecord u_maps[MAX_MAPS];
};
#endif
uniform int u_map_count;
uniform int u_active_count;

// The index of the j-th active map (j < u_active_count).
int ActiveMap(int j) {
#ifdef MAPS_IN_STORAGE_BUFFER
  return u_active_maps[j];
#else
  return int(u_maps[j].extra.y);
#endif
}

// R32F, one fetch answers both questions: < 0 = outside the silhouette
// (empty), 0 = invalid depth inside it, > 0 = camera z of the surface seen
// (visual hulls: 1 inside). See ibr::MakeMapTables.
uniform sampler2DArray u_depth_maps;
uniform usampler2DArray u_color_maps;  // RGBA8UI

// The novel view's pixel rays: perspective direction (u ax + bx, v ay + by, 1)
// from the origin; orthographic origin (u ax + bx, v ay + by, 0) along +z.
uniform vec4 u_view_ray;     // ax, ay, bx, by
uniform float u_view_height; // pixels

// The fragment's image coordinates (sparse convention: pixel centres at +0.5),
// exact: gl_FragCoord holds the pixel centre.
vec2 FragmentUv() {
  precise float v = u_view_height - gl_FragCoord.y;
  return vec2(gl_FragCoord.x, v);
}

// The point of plane dot(n, p) = d (view camera space, plane = (n, d)) seen
// through image point uv. The slice polygons only decide WHICH pixels a slice
// covers; the point itself is recomputed here from the pixel centre so the
// CPU reference can reproduce it exactly.
vec3 ViewPointOnPlane(vec2 uv, vec4 plane) {
#ifdef VIEW_ORTHOGRAPHIC
  precise float ox = uv.x * u_view_ray.x + u_view_ray.z;
  precise float oy = uv.y * u_view_ray.y + u_view_ray.w;
  precise float s = plane.w - (plane.x * ox + plane.y * oy);
  precise float z = s / plane.z;
  precise vec3 p = vec3(ox, oy, z);
#else
  precise float dx = uv.x * u_view_ray.x + u_view_ray.z;
  precise float dy = uv.y * u_view_ray.y + u_view_ray.w;
  precise float den = (plane.x * dx + plane.y * dy) + plane.z;
  precise float t = plane.w / den;
  precise vec3 p = vec3(t * dx, t * dy, t);
#endif
  return p;
}

// The point at camera depth z (> 0) on the ray through uv.
vec3 ViewPointAtDepth(vec2 uv, float z) {
#ifdef VIEW_ORTHOGRAPHIC
  precise float ox = uv.x * u_view_ray.x + u_view_ray.z;
  precise float oy = uv.y * u_view_ray.y + u_view_ray.w;
  precise vec3 p = vec3(ox, oy, z);
#else
  precise float dx = uv.x * u_view_ray.x + u_view_ray.z;
  precise float dy = uv.y * u_view_ray.y + u_view_ray.w;
  precise vec3 p = vec3(z * dx, z * dy, z);
#endif
  return p;
}

// Where view-camera point p falls in map m: its map-camera point q and its
// texel (layer in .z). Returns false when p is outside the map's image or
// behind a pinhole map.
bool MapLookupUv(MapRecord m, vec3 p, out vec3 q, out ivec3 texel, out vec2 uv) {
  precise vec3 qq = m.m0.xyz * p.x + m.m1.xyz * p.y + m.m2.xyz * p.z + m.m3.xyz;
  q = qq;
  texel = ivec3(-1);
  uv = vec2(-1.0);
  precise float u;
  precise float v;
  bool in_front;
  if (m.info.z == 1) {
    u = qq.x * m.proj.x + m.proj.z;
    v = qq.y * m.proj.y + m.proj.w;
    in_front = true;
  } else {
    u = (qq.x / qq.z) * m.proj.x + m.proj.z;
    v = (qq.y / qq.z) * m.proj.y + m.proj.w;
    in_front = qq.z > 0.0;
  }
  // Range test in float first (NaN fails), so the integer conversion only
  // ever sees values in [0, size): truncation is then floor.
  if (!(in_front && u >= 0.0 && u < float(m.info.x) && v >= 0.0 &&
        v < float(m.info.y))) {
    return false;
  }
  texel = ivec3(int(u), int(v), m.info.w);
  uv = vec2(u, v);
  return true;
}
bool MapLookup(MapRecord m, vec3 p, out vec3 q, out ivec3 texel) {
  vec2 uv;
  return MapLookupUv(m, p, q, texel, uv);
}

// One texel's width of map m, in scene units, at map camera z q_z
// (orthographic: 1 / sx, the same at every depth).
float MapTexelSize(MapRecord m, float q_z) {
  return m.info.z == 1 ? 1.0 / m.proj.x : q_z / m.proj.x;
}

#ifdef SUBTEXEL_DEPTH
// Sub-texel depth (issue 12, item 2): the depth at image point uv (texel
// centres at +0.5) interpolated bilinearly over the 2x2 texels around it,
// using only texels inside the silhouette with valid depth on the same
// surface as the nearest texel (within u_subtexel_edge texel widths of
// depth, so no ramp is drawn across a depth edge and no background bleeds
// in); the nearest texel's depth d0 where no neighbour qualifies.
uniform float u_subtexel_edge;  // texel widths
float SubtexelDepth(MapRecord m, vec2 uv, float d0, float q_z) {
  vec2 f = uv - 0.5;
  ivec2 i0 = ivec2(floor(f));
  vec2 t = f - vec2(i0);
  float edge = u_subtexel_edge * MapTexelSize(m, q_z);
  float wsum = 0.0, dsum = 0.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 ij = clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), m.info.xy - 1);
    float dk = texelFetch(u_depth_maps, ivec3(ij, m.info.w), 0).r;
    float w = ((k & 1) != 0 ? t.x : 1.0 - t.x) * ((k >> 1) != 0 ? t.y : 1.0 - t.y);
    if (dk > 0.0 && abs(dk - d0) <= edge) {
      wsum += w;
      dsum += w * dk;
    }
  }
  return wsum > 0.0 ? dsum / wsum : d0;
}
#endif

// Kautz-Seidel 2001, sec. 4.1: a point belongs to the object if it passes
// the test of every map; this is map m's test as a signed field at p: <= 0
// where m accepts p, > 0 where it carves. Depth object: the point is at or
// behind the surface map m saw (camera z >= depth; the paper: the
// displacement exceeds the ramp), field = depth - z in scene units, so the
// field is continuous at surfaces (d - z <= 0 exactly when z >= d in IEEE
// arithmetic: the CPU mirror tests z >= d). Visual hull (sec. 5): the point
// projects inside map m's silhouette. `texel` is the texel used (-1 when
// outside the image).
const float kMapFree = -1e30;   // no constraint from this map
const float kMapCarved = 1e30;  // carved by this map
float MapField(MapRecord m, vec3 p, out ivec3 texel) {
  vec3 q;
  vec2 uv;
  if (!MapLookupUv(m, p, q, texel, uv)) {
#ifdef OUTSIDE_PASSES
    return kMapFree;
#else
    return kMapCarved;
#endif
  }
  float d = texelFetch(u_depth_maps, texel, 0).r;
  if (d < 0.0) return kMapCarved;  // outside the silhouette
#ifdef VISUAL_HULL
  return kMapFree;
#else
#ifdef SUBTEXEL_DEPTH
  if (d > 0.0) return SubtexelDepth(m, uv, d, q.z) - q.z;
#else
  if (d > 0.0) return d - q.z;
#endif
#ifdef INVALID_DEPTH_PASSES
  return kMapFree;
#else
  return kMapCarved;
#endif
#endif
}

// The map test of the slice passes (the alpha test of sec. 4.1 step 2(a)ii).
bool MapAccepts(MapRecord m, vec3 p, out ivec3 texel) {
  return MapField(m, p, texel) <= 0.0;
}

// The object as one field over the active maps (ActiveMap), for the ray
// core (ray pass, resolve pass): "inside all maps" is the largest map field
// (Kautz-Seidel's intersection); robust (ROBUST_COUNT): at least u_required
// maps accept, as a step field.
uniform int u_required;  // maps that must accept a point (N - k)
float ObjectField(vec3 p) {
  // Over the active maps' list, not every map with a test of its flag:
  // llvmpipe evaluates a skipped map's lookup anyway, masked (a hull's three
  // inactive cube maps cost as much as its three active ones).
  ivec3 texel;
#ifdef ROBUST_COUNT
  int accepted = 0;
  for (int j = 0; j < u_active_count; ++j) {
    if (MapField(u_maps[ActiveMap(j)], p, texel) <= 0.0) ++accepted;
  }
  return accepted >= u_required ? -1.0 : 1.0;
#else
  float f = kMapFree;
  for (int j = 0; j < u_active_count; ++j) f = max(f, MapField(u_maps[ActiveMap(j)], p, texel));
  return f;
#endif
}

// Map i's colour at a texel, in [0, 1] (u_inv255 = 1/255 as a float uniform,
// so the CPU multiplies by the same value).
uniform float u_inv255;
vec4 MapColor(ivec3 texel) {
  precise vec4 c = vec4(texelFetch(u_color_maps, texel, 0)) * u_inv255;
  return c;
}
