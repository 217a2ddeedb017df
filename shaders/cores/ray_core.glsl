// The ray core, GPU side: ONE marching loop for every pass that casts rays
// (NCS, parallax occlusion mapping, relief mapping, the depth-object ray
// variant, cut/deformation shaders). Passes include it; none copies the loop.
// C++ side: render/cores/ray_core.h (options, #defines, uniforms, outcome codes).
//
// The march (Correa-Silver-Chen 2007, sec. 3.1): samples p_i along the ray,
// linear search for the first sample that is inside the solid, then a
// refinement of the crossing between the last outside and the first inside
// sample (bisection as in relief mapping [POC05]; or one secant step, POM's
// "intersect the linear approximation" [Tat06]).
//
// ---------------------------------------------------------------------------
// CONTRACT. Before `#include "cores/ray_core.glsl"` the includer defines:
//
//   float RayField(vec3 p);                                       (required)
//       The field at march-space point p: > 0 in empty space, <= 0 inside
//       the solid. "Hit" = the first sample with RayField <= 0. Whatever the
//       per-sample transform is (Correa's inverse warp p -> T^-1(p), a height
//       field lookup, "inside all depth maps" = max over maps of the signed
//       depth difference, ...), it lives inside RayField; the core only sees
//       the sign and, for the threshold and secant options, the value.
//
//   #define RAY_BEND and  vec3 RayBend(vec3 p);                   (optional)
//       Per-step bend (Chen-Chang, Algorithm 2 line 4): the march-space
//       direction per unit of path parameter t at p. The ray then advances
//       incrementally, p_{i+1} = p_i + dt * RayBend(p_i): a straight
//       object-space ray traced as a piecewise-linear curve in a curved
//       (texture) space. Without RAY_BEND the ray is straight,
//       p(t) = origin + t * dir.
//
//   #define RAY_DOMAIN and  bool RayInDomain(vec3 p);              (optional)
//       False once a sample has left the marched region (NCS: above the shell
//       or off the texture chart); the march then reports RAY_OUTCOME_EXITED.
//       Straight rays also exit when t reaches RayMarch.t_max (the box exit).
//
//   RAY_STEP_JACOBIAN also requires  mat3 RayJacobian(vec3 p);
//       the Jacobian J_{T^-1}(p) = I + J_D(p) of the inverse warp at p
//       (Correa 2007, eq. 4).
//
//   #define RAY_BOTH_CROSSINGS                                     (optional)
//       A hit is a change of side in either direction (empty -> solid or
//       solid -> empty), so a ray that starts inside the solid is not a hit
//       at its origin and finds where it leaves (thin shells seen from
//       inside: Correa 2007 sec. 5.1.1, hollow cuts). Without it, a hit is
//       empty -> solid only and a ray starting inside hits at its origin.
//       RayResult.entering tells the direction.
//
//   #define RAY_REJECT and  bool RayRejectHit(vec3 p);             (optional)
//       Called at every refined crossing; true rejects it and the march goes
//       on from the sample after it, now on the crossing's far side (Correa
//       2007 sec. 5.1.1: intersections inside the cut region are discarded).
//       RayResult.rejected counts them.
//
//   #define RAY_SKIP and  float RaySkip(vec3 p, float field);      (optional)
//       Empty-space skipping (Correa 2007 sec. 6.2): a distance along the
//       ray, in t units, proven free of any crossing (and of any hit that
//       would not be rejected) from sample p, where the field is `field`
//       (the core passes the value it already has: a distance-like field
//       bounds the skip at no extra lookup); the march advances by
//       max(policy step, skip). Return 0 where nothing is known. A skip
//       that is not a true lower bound loses hits: that is the includer's
//       proof to make.
//
//   #define RAY_SECOND_FIELD                                       (optional)
//       Two-field search (Correa 2007 sec. 5.1.2, solid cuts): the march
//       alternates between field 0 (the solid) and field 1 (the cut: > 0
//       inside it, so "solid" = leaving the cut). A crossing of the current
//       field k that the reject test turns down switches the search to the
//       other field, from the rejected crossing on (a surface hit inside the
//       cut: now look for where the ray leaves the cut inside the solid; a
//       cut-boundary crossing outside the solid: look for the surface
//       again). Then the includer defines, instead of RayField / RaySkip /
//       RayRejectHit,
//         float RayFieldK(vec3 p, int k);
//         bool RayRejectHitK(vec3 p, int k);    (RAY_REJECT is implied)
//         float RaySkipK(vec3 p, float field, int k);   (with RAY_SKIP)
//       and the reject test of field k must be "the other field is > 0
//       (empty) here", so the search resumes on the empty side. A ray that
//       starts inside field 0 where that is rejected starts on field 1.
//       RayResult.field says which field the hit is on.
//
// Defines that render::RayCoreDefines() inserts (never written by hand):
//   RAY_OUTCOME_HIT / RAY_OUTCOME_EXITED / RAY_OUTCOME_EARLY_TERMINATION:
//       the outcome codes, shared with C++ render::RayOutcome;
//   exactly one step policy: RAY_STEP_FIXED | RAY_STEP_THRESHOLD | RAY_STEP_JACOBIAN;
//   exactly one refinement: RAY_REFINE_BISECTION | RAY_REFINE_SECANT.
// Uniforms (render::SetRayCoreUniforms): u_ray_max_steps, u_ray_refine_steps,
// u_ray_threshold, u_ray_fine_step_scale.
//
// Per ray the includer fills a RayMarch {origin, dir, t_max, step} and calls
// RayMarchRun(); the result says hit / exited / ran out of steps (= early
// termination, Chen-Chang sec. 5) with the refined point and path parameter,
// and how many field evaluations the ray cost (samples).
// ---------------------------------------------------------------------------

#if !defined(RAY_OUTCOME_HIT) || !defined(RAY_OUTCOME_EXITED) || !defined(RAY_OUTCOME_EARLY_TERMINATION)
#error "ray_core.glsl: outcome codes missing; build the program with render::RayCoreDefines()"
#endif
#if defined(RAY_STEP_FIXED) + defined(RAY_STEP_THRESHOLD) + defined(RAY_STEP_JACOBIAN) != 1
#error "ray_core.glsl: define exactly one of RAY_STEP_FIXED, RAY_STEP_THRESHOLD, RAY_STEP_JACOBIAN"
#endif
#if defined(RAY_REFINE_BISECTION) + defined(RAY_REFINE_SECANT) != 1
#error "ray_core.glsl: define exactly one of RAY_REFINE_BISECTION, RAY_REFINE_SECANT"
#endif

#ifdef RAY_SECOND_FIELD
#ifndef RAY_REJECT
#define RAY_REJECT
#endif
#define RAY_FIELD_K(p, k) RayFieldK(p, k)
#define RAY_REJECT_K(p, k) RayRejectHitK(p, k)
#define RAY_SKIP_K(p, f, k) RaySkipK(p, f, k)
float RayField(vec3 p) { return RayFieldK(p, 0); }
#else
#define RAY_FIELD_K(p, k) RayField(p)
#define RAY_REJECT_K(p, k) RayRejectHit(p)
#define RAY_SKIP_K(p, f, k) RaySkip(p, f)
#endif

uniform int u_ray_max_steps;          // linear-search samples before early termination
uniform int u_ray_refine_steps;       // bisection iterations after the first inside sample
uniform float u_ray_threshold;        // RAY_STEP_THRESHOLD: |field| below which steps shrink
uniform float u_ray_fine_step_scale;  // RAY_STEP_THRESHOLD: step factor near the surface

struct RayMarch {
  vec3 origin;  // march-space start point (the entry: rasterised surface, box entry, ...)
  vec3 dir;     // march-space direction per unit t (straight rays; ignored with RAY_BEND)
  float t_max;  // path parameter at the exit (straight rays; use 1e30 for "no exit")
  float step;   // base step in t units (fixed policy: the step; others scale it)
};

struct RayResult {
  int outcome;  // RAY_OUTCOME_*
  vec3 p;       // refined crossing (hit), else the last sample
  float t;      // path parameter of p
  int steps;    // linear-search samples taken
  int samples;  // RayField evaluations: origin + linear search + refinement
  bool entering;  // hit: the crossing goes empty -> solid (always, without RAY_BOTH_CROSSINGS)
  int rejected;   // crossings RayRejectHit turned down (0 without RAY_REJECT)
  int field;      // RAY_SECOND_FIELD: the field the hit (or the last sample) is on; else 0
};

// Entry/exit parameters of the straight ray o + t d against the box [lo, hi]:
// (t_near, t_far); t_near > t_far when it misses. Axis-parallel components are
// handled explicitly (no reliance on 1/0 = inf).
vec2 RayBoxInterval(vec3 o, vec3 d, vec3 lo, vec3 hi) {
  float t_near = -1e30, t_far = 1e30;
  for (int k = 0; k < 3; ++k) {
    if (abs(d[k]) < 1e-12) {
      if (o[k] < lo[k] || o[k] > hi[k]) return vec2(1.0, -1.0);
    } else {
      float a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
      t_near = max(t_near, min(a, b));
      t_far = min(t_far, max(a, b));
    }
  }
  return vec2(t_near, t_far);
}

// RayBoxInterval intersected with the parameter range t_range = (t_min,
// t_max): the part of the ray inside the box AND in that range (e.g. t >= 0,
// the segment between the clip planes, a depth interval). Empty (x >= y) when
// either is; a miss stays empty.
vec2 RayBoxIntervalClamped(vec3 o, vec3 d, vec3 lo, vec3 hi, vec2 t_range) {
  vec2 t = RayBoxInterval(o, d, lo, hi);
  return vec2(max(t.x, t_range.x), min(t.y, t_range.y));
}

// Step length at sample p (policy chosen by #define).
float RayStepLength(vec3 p, vec3 dir, float field, float base_step) {
#if defined(RAY_STEP_THRESHOLD)
  // Threshold-adaptive sampling (Hadwiger et al. 2005, as offered by Correa
  // 2007 sec. 3.1.1): finer steps where the field is close to the surface.
  return abs(field) < u_ray_threshold ? base_step * u_ray_fine_step_scale : base_step;
#elif defined(RAY_STEP_JACOBIAN)
  // Jacobian sampling, Correa 2007 eq. 4: dt_i = ds / |J_{T^-1}(p_i) v|, so
  // samples are uniform along the warped curve in undeformed space.
  return base_step / max(length(RayJacobian(p) * dir), 1e-6);
#else
  return base_step;
#endif
}

// The refinement (the one bisection): the crossing on the segment [p, q]
// between two samples on different sides (RayField(p) = fp, RayField(q) = fq,
// one > 0 and the other <= 0; either direction, for RAY_BOTH_CROSSINGS), as a
// fraction of the way from p to q. Also called by passes that find the
// bracketing samples another way (the depth-object slice passes' resolve,
// between the finishing slice and the one before).
// RayRefineCrossingK: the same on field `field` (RAY_SECOND_FIELD).
float RayRefineCrossingK(vec3 p, vec3 q, float fp, float fq, int field) {
#if defined(RAY_REFINE_SECANT)
  float den = fp - fq;
  return clamp(fp / (abs(den) > 1e-30 ? den : 1e-30), 0.0, 1.0);
#else
  bool q_inside = fq <= 0.0;
  float ta = 0.0, tb = 1.0;  // fractions along [p, q]: ta on p's side, tb on q's
  for (int k = 0; k < u_ray_refine_steps; ++k) {
    float tm = 0.5 * (ta + tb);
    float fm = RAY_FIELD_K(mix(p, q, tm), field);
    if ((fm <= 0.0) == q_inside) tb = tm; else ta = tm;
  }
  return 0.5 * (ta + tb);
#endif
}
float RayRefineCrossing(vec3 p, vec3 q, float fp, float fq) {
  return RayRefineCrossingK(p, q, fp, fq, 0);
}

// The march moves on to sample q (path step dt, field fq there); true when
// that ends it: q was the exit's sample, or it left the domain.
bool RayAdvance(inout vec3 p, inout float t, inout float f, inout bool inside, vec3 q, float dt,
                float fq, bool last) {
  p = q;
  t += dt;
  f = fq;
  inside = fq <= 0.0;
#ifdef RAY_DOMAIN
  return last || !RayInDomain(p);
#else
  return last;
#endif
}

RayResult RayMarchRun(RayMarch r) {
  RayResult res;
  res.steps = 0;
  res.samples = 1;
  res.rejected = 0;
  res.entering = true;
  res.t = 0.0;
  res.p = r.origin;
  res.field = 0;
  int field = 0;  // the field searched (RAY_SECOND_FIELD), else 0
  float f = RayField(r.origin);
  bool inside = f <= 0.0;  // side of the last sample (<= 0 is solid)
#if !defined(RAY_BOTH_CROSSINGS)
  if (inside) {
#ifdef RAY_REJECT
    if (!RAY_REJECT_K(r.origin, 0)) {
      res.outcome = RAY_OUTCOME_HIT;  // starts inside: the entry is the crossing
      return res;
    }
    res.rejected = 1;
#ifdef RAY_SECOND_FIELD
    field = 1;  // inside the solid, in the cut: look for the cut's boundary
    f = RAY_FIELD_K(r.origin, 1);
    inside = f <= 0.0;
    res.samples += 1;
#endif
#else
    res.outcome = RAY_OUTCOME_HIT;  // starts inside: the entry is the crossing
    return res;
#endif
  }
#endif
  vec3 p = r.origin;
  float t = 0.0;
  bool exited = false;
  int i = 0;  // linear-search samples taken, over all segments
  // Each round marches to the next crossing (inner loop: one field
  // evaluation per sample and nothing else), then refines and tests it. The
  // refinement and the reject test stay out of the per-sample loop: llvmpipe
  // has no branches (an if masks lanes), so a branch inside the loop costs
  // every iteration whether or not a lane takes it; a GPU skips it only when
  // no lane of the warp does.
  while (i < u_ray_max_steps) {
    bool crossed = false;
    vec3 q = p;
    float fq = f, dt = 0.0;
    bool inside_q = inside, last = false;
    while (i < u_ray_max_steps) {
#ifdef RAY_BEND
      vec3 dir = RayBend(p);
#else
      vec3 dir = r.dir;
#endif
      dt = RayStepLength(p, dir, f, r.step);
      if (!(dt > 0.0) || isinf(dt)) dt = r.step;  // NaN/inf-safe: a bad policy value never stalls
#ifdef RAY_SKIP
      float skip = RAY_SKIP_K(p, f, field);
      if (skip > dt && !isinf(skip)) dt = skip;  // NaN and inf skips are ignored
#endif
      // The sample that would pass the exit lands exactly on it (a relative
      // slack absorbs rounding so n steps of t_max/n do reach the exit).
      last = t + dt >= r.t_max - 1e-4 * dt;
      if (last) dt = r.t_max - t;
#ifdef RAY_BEND
      q = p + dt * dir;
#else
      q = r.origin + (t + dt) * r.dir;
#endif
      fq = RAY_FIELD_K(q, field);
      inside_q = fq <= 0.0;
      ++i;
      res.steps = i;
      res.samples += 1;
#ifdef RAY_BOTH_CROSSINGS
      crossed = inside_q != inside;
#else
      crossed = inside_q && !inside;
#endif
      if (crossed) break;
      exited = RayAdvance(p, t, f, inside, q, dt, fq, last);
      if (exited) break;
    }
    if (!crossed) break;  // exited, or the steps ran out
    // The crossing lies on the segment [p, q] (straight in march space even
    // for bent rays: the piecewise-linear curve of Chen-Chang Fig. 5).
    float s_hit = RayRefineCrossingK(p, q, f, fq, field);
#if !defined(RAY_REFINE_SECANT)
    res.samples += u_ray_refine_steps;
#endif
    vec3 hit = mix(p, q, s_hit);
#ifdef RAY_REJECT
    if (RAY_REJECT_K(hit, field)) {
      res.rejected += 1;
#ifdef RAY_SECOND_FIELD
      // Search the other field from the rejected crossing on (empty there
      // by the reject test's contract); the next step starts at it.
      field = 1 - field;
      p = hit;
      t += s_hit * dt;
      f = RAY_FIELD_K(hit, field);
      inside = f <= 0.0;
      res.samples += 1;
#else
      // Go on from the sample after the crossing, now on its far side.
      exited = RayAdvance(p, t, f, inside, q, dt, fq, last);
      if (exited) break;
#endif
      continue;
    }
#endif
    res.outcome = RAY_OUTCOME_HIT;
    res.entering = inside_q;
    res.p = hit;
    res.t = t + s_hit * dt;
    res.field = field;
    return res;
  }
  if (exited) {
    res.outcome = RAY_OUTCOME_EXITED;
    res.p = p;
    res.t = t;
    return res;
  }
  res.outcome = RAY_OUTCOME_EARLY_TERMINATION;  // still inside the domain: steps ran out
  res.p = p;
  res.t = t;
  res.field = field;
  return res;
}
