// Shared by the volume pass's DVR and iso fragment stages
// (render/passes/volume_pass.h): discontinuous displacement (Correa, Silver,
// Chen 2006), the volume lookup and the normal of sec. 4.3.
//
// Defines (VolumePassOptions::Defines): VOLUME_MAPS n (0..4);
// VOLUME_MAPS_FLOAT (RGBA32F maps) else UNORM maps with scale and bias;
// exactly one of VOLUME_LIGHT_NONE / _GRADIENT / _TRANSFORMED / _BLENDED.
// Frames: p' and p in volume texture space [0,1]^3; a map's own unit cube u.

uniform sampler3D u_volume;    // normalised scalar, LINEAR, CLAMP_TO_EDGE
uniform sampler3D u_gradient;  // rgb: gradient of the scalar per unit texture coordinate
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
  mat3 jac;        // d p / d p' (I + J_D chained; identity without normals)
  float cut_alpha; // the smallest single mask met (for eq. 7)
  vec3 cut_grad;   // its gradient in p' space
};

bool InUnitCube(vec3 u) { return all(greaterThanEqual(u, vec3(0.0))) && all(lessThanEqual(u, vec3(1.0))); }

// p = G_0(G_1(... G_{n-1}(p'))) with G_i(v) = v + A_i D_i(M_i^-1 v): the last
// map acts first (eq. 9); outside its cube a map is the identity.
Displaced VolumeDisplace(vec3 p_prime, bool with_normals) {
  Displaced d;
  d.p = p_prime;
  d.alpha = 1.0;
  d.jac = mat3(1.0);
  d.cut_alpha = 1.0;
  d.cut_grad = vec3(0.0);
#if VOLUME_MAPS > 0
  for (int i = VOLUME_MAPS - 1; i >= 0; --i) {
    vec3 u = (u_map_from_tex[i] * vec4(d.p, 1.0)).xyz;
    if (!InUnitCube(u)) continue;
    vec4 m = MapFetch(i, u);
    if (with_normals) {
      // J_D and the mask's gradient by central differences at half a texel.
      mat3 jd;
      vec3 ga;
      for (int k = 0; k < 3; ++k) {
        vec3 e = vec3(0.0);
        e[k] = 0.5 * u_map_texel[i][k];
        vec4 hi = MapFetch(i, u + e), lo = MapFetch(i, u - e);
        jd[k] = (hi.xyz - lo.xyz) / (2.0 * e[k]);
        ga[k] = (hi.w - lo.w) / (2.0 * e[k]);
      }
      if (m.w < d.cut_alpha) {
        d.cut_alpha = m.w;
        // d alpha / d p' = J_before^T A^-T grad_u alpha.
        d.cut_grad = transpose(d.jac) * (transpose(u_map_from_tex_linear[i]) * ga);
      }
      d.jac = (mat3(1.0) + u_tex_from_map[i] * jd * u_map_from_tex_linear[i]) * d.jac;
    }
    d.p += u_tex_from_map[i] * m.xyz;
    d.alpha *= m.w;
  }
#endif
  return d;
}

// The normalised scalar at p; 0 outside the volume's box.
float VolumeDensity(vec3 p) {
  if (!InUnitCube(p)) return 0.0;
  return texture(u_volume, p).r;
}

vec3 SafeNormalize(vec3 v) {
  float l = length(v);
  return l > 1e-20 ? v / l : vec3(0.0);
}

// Outward unit normal (world) at p for the displaced sample d; zero where
// the field is flat. Sec. 4.3, Fig. 4 (b)-(d) by define.
vec3 VolumeNormal(Displaced d) {
  vec3 g = InUnitCube(d.p) ? texture(u_gradient, d.p).xyz : vec3(0.0);
#if defined(VOLUME_LIGHT_TRANSFORMED) || defined(VOLUME_LIGHT_BLENDED)
  g = transpose(d.jac) * g;  // eq. 6: n' = (I + J_D)^T n
#endif
#if defined(VOLUME_LIGHT_BLENDED)
  // Eq. 7: w (I + J_D)^T n + (1 - w) grad alpha, w = 0 on the cut's 0.5
  // contour of the smoothed mask, 1 where the mask is 1.
  float w = clamp(2.0 * (d.cut_alpha - 0.5), 0.0, 1.0);
  g = w * SafeNormalize(u_normal_world_from_tex * g) + (1.0 - w) * SafeNormalize(u_normal_world_from_tex * d.cut_grad);
  return -SafeNormalize(g);
#else
  // Gradients point into denser material: the outward normal is against it.
  return -SafeNormalize(u_normal_world_from_tex * g);
#endif
}

vec3 VolumeShade(vec3 rgb, Displaced d) {
#if defined(VOLUME_LIGHT_NONE)
  return rgb;
#else
  float diffuse = max(dot(VolumeNormal(d), u_light_dir_world), 0.0);
  return rgb * (u_ambient + (1.0 - u_ambient) * diffuse);
#endif
}
