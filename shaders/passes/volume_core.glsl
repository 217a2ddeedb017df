// Shared by the volume pass's DVR and iso fragment stages
// (render/passes/volume_pass.h): discontinuous displacement (Correa, Silver,
// Chen 2006), the volume lookup and the normal of sec. 4.3.
//
// Defines (VolumePassOptions::Defines): VOLUME_MAPS n (0..4);
// VOLUME_MAPS_FLOAT (RGBA32F maps) else UNORM maps with scale and bias;
// exactly one of VOLUME_LIGHT_NONE / _GRADIENT / _TRANSFORMED / _BLENDED;
// VOLUME_JACOBIAN_PRECOMPUTED (J_D and grad alpha from per-texel textures,
// 3 fetches a map) else central differences of the map (6 fetches a map).
// Frames: p' and p in volume texture space [0,1]^3; a map's own unit cube u.
//
// Cost order (sec. 4.2): VolumeDisplace gives p and the mask only; the
// Jacobian (VolumeNormalFrame) is evaluated after the mask and the transfer
// function have kept the sample, so where a GPU skips a branch no lane takes,
// cut or transparent samples do not pay for the normal. llvmpipe does not:
// a discard or an if only masks lanes, and the code after it runs anyway, so
// there the order saves next to nothing
// (docs/decisions/volume-fragment-cost.md).

// rgb: the scalar's gradient per unit texture coordinate, a: the normalised
// scalar (one fetch for both); LINEAR, CLAMP_TO_EDGE.
uniform sampler3D u_samples;
uniform mat4 u_tex_from_proxy; // proxy-box coordinates -> volume texture coordinates
uniform mat3 u_normal_world_from_tex;  // inverse transpose of world_from_volume's linear part
uniform vec3 u_light_dir_world;        // towards the light, unit
uniform float u_ambient;

#if VOLUME_MAPS > 0
uniform sampler3D u_maps[VOLUME_MAPS];
uniform mat4 u_map_from_tex[VOLUME_MAPS];    // M^-1 (eq. 10)
uniform mat3 u_tex_from_map[VOLUME_MAPS];    // A, the linear part of M
uniform mat3 u_map_from_tex_linear[VOLUME_MAPS];  // A^-1
uniform float u_map_scale[VOLUME_MAPS];      // UNORM maps: D = (2 t - 1) scale
uniform vec3 u_map_texel[VOLUME_MAPS];       // 1 / dims of each map
// core::ActiveBox (map space): outside it a map is the identity, unread.
uniform vec3 u_map_active_lo[VOLUME_MAPS];
uniform vec3 u_map_active_hi[VOLUME_MAPS];
#ifdef VOLUME_JACOBIAN_PRECOMPUTED
// Per map, three RGBA32F textures: rgb = column k of J_D (dD/du_k), a =
// dalpha/du_k (core::ComputeMapDerivatives), map units. Index 3 i + k.
uniform sampler3D u_map_derivatives[3 * VOLUME_MAPS];
#endif
#endif

// (D in map units, alpha) of map i at u.
#if VOLUME_MAPS > 0
vec4 MapFetch(int i, vec3 u) {
  vec4 t = texture(u_maps[i], u);
#ifdef VOLUME_MAPS_FLOAT
  return t;
#else
  return vec4((2.0 * t.xyz - 1.0) * u_map_scale[i], t.w);
#endif
}
#endif

struct Displaced {
  vec3 p;          // where to sample the volume
  float alpha;     // product of the masks (eq. 9)
#if VOLUME_MAPS > 0
  vec3 u[VOLUME_MAPS];      // where each map was read (map space)
  float mask[VOLUME_MAPS];  // each map's mask there; -1 where the map was skipped
#endif
};

bool InUnitCube(vec3 u) { return all(greaterThanEqual(u, vec3(0.0))) && all(lessThanEqual(u, vec3(1.0))); }

// p = G_0(G_1(... G_{n-1}(p'))) with G_i(v) = v + A_i D_i(M_i^-1 v): the last
// map acts first (eq. 9); outside its cube, and outside the part of it that
// moves anything (core::ActiveBox), a map is the identity. The map is read
// everywhere and the identity selected outside that box, without a branch:
// llvmpipe masks lanes rather than branching, so a branch around the fetch
// adds its own cost and saves no fetch (docs/decisions/volume-fragment-cost.md).
// Whole regions outside the box are skipped on the CPU instead
// (VolumePassOptions::support_skip).
Displaced VolumeDisplace(vec3 p_prime) {
  Displaced d;
  d.p = p_prime;
  d.alpha = 1.0;
#if VOLUME_MAPS > 0
  for (int i = VOLUME_MAPS - 1; i >= 0; --i) {
    vec3 u = (u_map_from_tex[i] * vec4(d.p, 1.0)).xyz;
    d.u[i] = u;
    bool moves = all(greaterThanEqual(u, u_map_active_lo[i])) && all(lessThanEqual(u, u_map_active_hi[i]));
    vec4 m = MapFetch(i, u);
    m = moves ? m : vec4(0.0, 0.0, 0.0, 1.0);
    d.mask[i] = moves ? m.w : -1.0;
    d.p += u_tex_from_map[i] * m.xyz;
    d.alpha *= m.w;
  }
#endif
  return d;
}

// What the normal needs from the maps (sec. 4.3), for the gradient g at p.
struct NormalFrame {
  vec3 g;           // (d p / d p')^T g, d p / d p' = prod_i (I + A_i J_D,i A_i^-1) (eq. 6, 10)
  float cut_alpha;  // the smallest single mask met (for eq. 7)
  vec3 cut_grad;    // its gradient in p' space
};

// J_D (columns) and grad alpha of map i at u, map units.
#if VOLUME_MAPS > 0
void MapDerivatives(int i, vec3 u, out mat3 jd, out vec3 ga) {
#ifdef VOLUME_JACOBIAN_PRECOMPUTED
  for (int k = 0; k < 3; ++k) {
    vec4 t = texture(u_map_derivatives[3 * i + k], u);
    jd[k] = t.xyz;
    ga[k] = t.w;
  }
#else
  // Central differences of the filtered map at half a texel.
  for (int k = 0; k < 3; ++k) {
    vec3 e = vec3(0.0);
    e[k] = 0.5 * u_map_texel[i][k];
    vec4 hi = MapFetch(i, u + e), lo = MapFetch(i, u - e);
    jd[k] = (hi.xyz - lo.xyz) / (2.0 * e[k]);
    ga[k] = (hi.w - lo.w) / (2.0 * e[k]);
  }
#endif
}
#endif

#if VOLUME_MAPS > 0
// (I + A J_D A^-1)^T v = v + A^-T J_D^T A^T v for map i, as three
// vector-matrix products (v * M = M^T v): a third of the multiply-adds of
// forming the matrix product and transposing it.
vec3 MapJacobianTransposeTimes(int i, mat3 jd, vec3 v) {
  return v + ((v * u_tex_from_map[i]) * jd) * u_map_from_tex_linear[i];
}
#endif

// d p / d p' is the product J_0 J_1 ... J_{n-1} of the maps' Jacobians (the
// last map acts first, eq. 9), so its transpose applies J_0^T first; the cut's
// gradient d alpha_m / d p' = (J_{m+1} ... J_{n-1})^T A_m^-T grad_u alpha_m
// for the map m of the smallest mask. One map: the vector form above; several:
// the chained matrix (a vector form has to keep every map's J_D in an array
// until J_0^T is applied, and on llvmpipe that array cost more than the
// multiply-adds it saves: docs/decisions/volume-fragment-cost.md).
NormalFrame VolumeNormalFrame(Displaced d, vec3 g) {
  NormalFrame f;
  f.g = g;
  f.cut_alpha = 1.0;
  f.cut_grad = vec3(0.0);
#if VOLUME_MAPS == 1
  if (d.mask[0] >= 0.0) {
    mat3 jd;
    vec3 ga;
    MapDerivatives(0, d.u[0], jd, ga);
    f.cut_alpha = min(d.mask[0], 1.0);
    f.cut_grad = d.mask[0] < 1.0 ? ga * u_map_from_tex_linear[0] : vec3(0.0);
    f.g = MapJacobianTransposeTimes(0, jd, g);
  }
#elif VOLUME_MAPS > 1
  mat3 jac = mat3(1.0);
  for (int i = VOLUME_MAPS - 1; i >= 0; --i) {
    if (d.mask[i] < 0.0) continue;
    mat3 jd;
    vec3 ga;
    MapDerivatives(i, d.u[i], jd, ga);
    if (d.mask[i] < f.cut_alpha) {
      f.cut_alpha = d.mask[i];
      f.cut_grad = transpose(jac) * (ga * u_map_from_tex_linear[i]);
    }
    jac = (mat3(1.0) + u_tex_from_map[i] * jd * u_map_from_tex_linear[i]) * jac;
  }
  f.g = transpose(jac) * g;
#endif
  return f;
}

// (gradient, normalised scalar) at p; 0 outside the volume's box.
vec4 VolumeSample(vec3 p) { return InUnitCube(p) ? texture(u_samples, p) : vec4(0.0); }

// v / |v|, zero where |v| <= 1e-18 (one reciprocal square root: no sqrt
// and divide per call, up to three calls a sample with eq. 7).
vec3 SafeNormalize(vec3 v) {
  float l2 = dot(v, v);
  return l2 > 1e-36 ? v * inversesqrt(l2) : vec3(0.0);
}

// Outward unit normal (world) for the displaced sample d with the gradient g
// read at d.p; zero where the field is flat. Sec. 4.3, Fig. 4 (b)-(d) by define.
vec3 VolumeNormal(Displaced d, vec3 g) {
#if defined(VOLUME_LIGHT_TRANSFORMED) || defined(VOLUME_LIGHT_BLENDED)
  NormalFrame f = VolumeNormalFrame(d, g);
  g = f.g;  // eq. 6: n' = (I + J_D)^T n
#endif
#if defined(VOLUME_LIGHT_BLENDED)
  // Eq. 7: w (I + J_D)^T n + (1 - w) grad alpha, w = 0 on the cut's 0.5
  // contour of the smoothed mask, 1 where the mask is 1.
  float w = clamp(2.0 * (f.cut_alpha - 0.5), 0.0, 1.0);
  g = w * SafeNormalize(u_normal_world_from_tex * g) + (1.0 - w) * SafeNormalize(u_normal_world_from_tex * f.cut_grad);
  return -SafeNormalize(g);
#else
  // Gradients point into denser material: the outward normal is against it.
  return -SafeNormalize(u_normal_world_from_tex * g);
#endif
}

// Diffuse + ambient with the outward normal n (world, unit or zero); the
// colour as is without lighting (Fig. 4 (a)).
vec3 VolumeShadeWithNormal(vec3 rgb, vec3 n) {
#if defined(VOLUME_LIGHT_NONE)
  return rgb;
#else
  float diffuse = max(dot(n, u_light_dir_world), 0.0);
  return rgb * (u_ambient + (1.0 - u_ambient) * diffuse);
#endif
}

// g: the gradient read at d.p (VolumeSample).
vec3 VolumeShade(vec3 rgb, Displaced d, vec3 g) {
  vec3 n = vec3(0.0);
#if !defined(VOLUME_LIGHT_NONE)
  n = VolumeNormal(d, g);  // no lighting needs no normal: not evaluated
#endif
  return VolumeShadeWithNormal(rgb, n);
}
