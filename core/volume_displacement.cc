#include "core/volume_displacement.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include "core/check.h"
#include "core/deformation.h"
#include "core/error.h"
#include "core/summed_volume.h"

namespace core {
namespace {

bool InUnitCube(const glm::dvec3& u) {
  return u.x >= 0 && u.x <= 1 && u.y >= 0 && u.y <= 1 && u.z >= 0 && u.z <= 1;
}

}  // namespace

float DisplacementMap::MaxAbsDisplacement() const {
  float m = 0;
  for (const auto& t : texels) m = std::max({m, std::abs(t.x), std::abs(t.y), std::abs(t.z)});
  return m;
}

glm::dvec4 EvaluateVolumeMap(const Deformation& d, const glm::dvec3& u) {
  const glm::dvec4 e = d.EvaluateInBox(u);
  if (d.kind == DeformationKind::kPeel && d.amount > 0) {
    // Outside the flap (the flap's D moves its points: A = -1 and a pre-image
    // in the slab), above the hinge: no continuous D (see the header).
    const bool flap = e.w <= -1.0 && glm::dvec3(e) != glm::dvec3(0.0);
    if (!flap && (e.w > 0 || u.z > 1.0 - d.width)) return {0, 0, 0, 0};
  }
  return {glm::dvec3(e), e.w > 0 ? 0.0 : 1.0};
}

Box3d VolumeMapBox(const Deformation& d) {
  Box3d box{glm::dvec3(0.0), glm::dvec3(1.0)};
  if (d.kind == DeformationKind::kPeel) {
    box.hi.z = 1.5;  // the turned flap; its own fill and cut rules (EvaluateVolumeMap)
    return box;
  }
  // Every node of a grid over the box, faces included: the forward image of
  // the material where the kind has one (the extremes lie on the faces or
  // the grid's nodes for these piecewise-monotone maps), else the largest
  // inverse displacement per axis and sign (pull and wave move along z only,
  // p' = p - D(p'), by at most max |D| each way).
  constexpr int kGrid = 32;
  Box3d moved = box;
  glm::dvec3 max_d(0.0), min_d(0.0);
  for (int k = 0; k <= kGrid; ++k)
    for (int j = 0; j <= kGrid; ++j)
      for (int i = 0; i <= kGrid; ++i) {
        const glm::dvec3 u(double(i) / kGrid, double(j) / kGrid, double(k) / kGrid);
        if (d.HasForward()) {
          const glm::dvec3 f = d.ForwardInBox(u);
          moved.lo = glm::min(moved.lo, f);
          moved.hi = glm::max(moved.hi, f);
        } else {
          const glm::dvec3 e(d.EvaluateInBox(u));
          max_d = glm::max(max_d, e);
          min_d = glm::min(min_d, e);
        }
      }
  moved.lo -= max_d;  // p' = p - D(p')
  moved.hi -= min_d;
  // A texel of margin where it grew (at 64 texels a box unit): the last
  // texel centre still holds the outermost material.
  for (int a = 0; a < 3; ++a) {
    if (moved.lo[a] < 0) moved.lo[a] = std::max(moved.lo[a] - 1.0 / 64, -kMaxMapGrowth);
    if (moved.hi[a] > 1) moved.hi[a] = std::min(moved.hi[a] + 1.0 / 64, 1.0 + kMaxMapGrowth);
  }
  return moved;
}

glm::dmat4 BoxFromMap(const Deformation& d) {
  const Box3d box = VolumeMapBox(d);
  glm::dmat4 m(1.0);
  for (int a = 0; a < 3; ++a) {
    m[a][a] = box.hi[a] - box.lo[a];
    m[3][a] = box.lo[a];
  }
  return m;
}

glm::dmat4 VolumeMapPlacement(const Deformation& d) { return d.parent_from_box * BoxFromMap(d); }

glm::ivec3 VolumeMapDims(const Deformation& d, int size) {
  // As many texels per box unit as `size` along every axis the map spans
  // (a grown map keeps its density), at most kMaxMapTexels.
  const Box3d box = VolumeMapBox(d);
  glm::ivec3 dims;
  for (int a = 0; a < 3; ++a) {
    const double texels = std::ceil(size * (box.hi[a] - box.lo[a]) - 1e-9);
    dims[a] = std::clamp(static_cast<int>(texels), 1, std::max(size, kMaxMapTexels));
  }
  const int thin = std::min(size, 4);
  switch (d.kind) {
    case DeformationKind::kPeel:
    case DeformationKind::kSlices:
    case DeformationKind::kWave:
    case DeformationKind::kSeam:
    case DeformationKind::kKnife:
    case DeformationKind::kBend:
      dims.y = thin;
      break;
    case DeformationKind::kClip:
      dims.x = dims.y = thin;
      break;
    default:
      break;
  }
  return dims;
}

DisplacementMap SampleDeformationMap(const Deformation& deformation, const glm::ivec3& dims,
                                     int smooth_alpha_passes, int fill_iterations) {
  deformation.Check();
  IBR_CHECK(dims.x > 0 && dims.y > 0 && dims.z > 0);
  DisplacementMap map;
  map.dims = dims;
  map.texels.resize(static_cast<size_t>(dims.x) * dims.y * dims.z);
  std::vector<bool> valid(map.texels.size(), true);
  const bool peel = deformation.kind == DeformationKind::kPeel;
  const glm::dmat4 box_from_map = BoxFromMap(deformation);
  const glm::dmat3 map_from_box = glm::inverse(glm::dmat3(box_from_map));  // D's units
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const glm::dvec3 u((x + 0.5) / dims.x, (y + 0.5) / dims.y, (z + 0.5) / dims.z);
        const glm::dvec4 e =
            EvaluateVolumeMap(deformation, glm::dvec3(box_from_map * glm::dvec4(u, 1.0)));
        map.at(x, y, z) = glm::vec4(glm::vec3(map_from_box * glm::dvec3(e)), float(e.w));
        // Only the peel lacks an analytic pseudo-inverse.
        if (peel && e.w == 0) valid[map.Index(x, y, z)] = false;
      }
  if (peel) FillPseudoInverse(map, valid, fill_iterations);
  // Binomial smoothing of alpha along each axis (clamped at the faces).
  for (int pass = 0; pass < smooth_alpha_passes; ++pass) {
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<float> a(map.texels.size());
      for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
          for (int x = 0; x < dims.x; ++x) {
            glm::ivec3 p(x, y, z), lo = p, hi = p;
            lo[axis] = std::max(p[axis] - 1, 0);
            hi[axis] = std::min(p[axis] + 1, dims[axis] - 1);
            a[map.Index(x, y, z)] = 0.25f * map.at(lo.x, lo.y, lo.z).w + 0.5f * map.at(x, y, z).w +
                                    0.25f * map.at(hi.x, hi.y, hi.z).w;
          }
      for (size_t i = 0; i < a.size(); ++i) map.texels[i].w = a[i];
    }
  }
  return map;
}

void FillPseudoInverse(DisplacementMap& map, const std::vector<bool>& valid, int iterations) {
  IBR_CHECK_EQ(valid.size(), map.texels.size());
  const glm::ivec3 n = map.dims;
  const glm::ivec3 steps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  auto inside = [&](const glm::ivec3& p) {
    return p.x >= 0 && p.y >= 0 && p.z >= 0 && p.x < n.x && p.y < n.y && p.z < n.z;
  };
  // Start: nearest valid value by breadth-first propagation.
  std::vector<bool> known = valid;
  std::deque<glm::ivec3> queue;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x)
        if (known[map.Index(x, y, z)]) queue.push_back({x, y, z});
  if (queue.empty()) return;  // nothing to extend from: keep what is there
  while (!queue.empty()) {
    const glm::ivec3 p = queue.front();
    queue.pop_front();
    for (const auto& s : steps) {
      const glm::ivec3 q = p + s;
      if (!inside(q) || known[map.Index(q.x, q.y, q.z)]) continue;
      known[map.Index(q.x, q.y, q.z)] = true;
      const float w = map.at(q.x, q.y, q.z).w;
      map.at(q.x, q.y, q.z) = glm::vec4(glm::vec3(map.at(p.x, p.y, p.z)), w);
      queue.push_back(q);
    }
  }
  // Successive over-relaxation (in-place Gauss-Seidel, factor 1.9) of the
  // free texels towards the harmonic fill; at the faces only neighbours
  // inside count (zero normal derivative).
  constexpr float kOmega = 1.9f;
  for (int it = 0; it < iterations; ++it) {
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x) {
          const size_t i = map.Index(x, y, z);
          if (valid[i]) continue;
          glm::vec3 sum(0);
          int count = 0;
          for (const auto& s : steps) {
            const glm::ivec3 q = glm::ivec3(x, y, z) + s;
            if (!inside(q)) continue;
            sum += glm::vec3(map.at(q.x, q.y, q.z));
            ++count;
          }
          const glm::vec3 old = glm::vec3(map.texels[i]);
          map.texels[i] =
              glm::vec4(old + kOmega * (sum / static_cast<float>(count) - old), map.texels[i].w);
        }
  }
}

StoredDisplacementMap StoreDisplacementMap(const DisplacementMap& map, int bits) {
  if (bits != 8 && bits != 16 && bits != 32)
    ThrowInputError("StoreDisplacementMap", "bits {} (8, 16 or 32)", bits);
  StoredDisplacementMap s;
  s.dims = map.dims;
  s.bits = bits;
  if (bits == 32) {
    s.floats.reserve(map.texels.size() * 4);
    for (const auto& t : map.texels) s.floats.insert(s.floats.end(), {t.x, t.y, t.z, t.w});
    return s;
  }
  const double max_unorm = bits == 8 ? 255.0 : 65535.0;
  // A map without displacement still needs a non-zero scale.
  s.scale = std::max(map.MaxAbsDisplacement(), 1e-6f);
  auto q = [&](double v01) {
    return static_cast<uint16_t>(std::lround(std::clamp(v01, 0.0, 1.0) * max_unorm));
  };
  s.unorm.reserve(map.texels.size() * 4);
  for (const auto& t : map.texels) {
    for (int c = 0; c < 3; ++c) s.unorm.push_back(q(0.5 * t[c] / s.scale + 0.5));
    s.unorm.push_back(q(t.w));
  }
  return s;
}

DisplacementMap DequantizeDisplacementMap(const StoredDisplacementMap& s) {
  DisplacementMap map;
  map.dims = s.dims;
  const size_t n = static_cast<size_t>(s.dims.x) * s.dims.y * s.dims.z;
  map.texels.resize(n);
  if (s.bits == 32) {
    IBR_CHECK_EQ(s.floats.size(), 4 * n);
    for (size_t i = 0; i < n; ++i)
      map.texels[i] = {s.floats[4 * i], s.floats[4 * i + 1], s.floats[4 * i + 2],
                       s.floats[4 * i + 3]};
    return map;
  }
  IBR_CHECK_EQ(s.unorm.size(), 4 * n);
  const double max_unorm = s.bits == 8 ? 255.0 : 65535.0;
  for (size_t i = 0; i < n; ++i) {
    glm::vec4 t;
    for (int c = 0; c < 3; ++c)
      t[c] = static_cast<float>((2.0 * s.unorm[4 * i + c] / max_unorm - 1.0) * s.scale);
    t.w = static_cast<float>(s.unorm[4 * i + 3] / max_unorm);
    map.texels[i] = t;
  }
  return map;
}

glm::dvec4 SampleMap(const DisplacementMap& map, const glm::dvec3& u) {
  int i0[3], i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const int n = map.dims[a];
    const double t = std::clamp(u[a] * n - 0.5, 0.0, static_cast<double>(n - 1));
    const double fl = std::floor(t);
    i0[a] = static_cast<int>(fl);
    i1[a] = std::min(i0[a] + 1, n - 1);
    f[a] = t - fl;
  }
  glm::dvec4 r(0.0);
  for (int c = 0; c < 8; ++c) {
    const int cx = c & 1, cy = (c >> 1) & 1, cz = (c >> 2) & 1;
    const double w = (cx ? f[0] : 1 - f[0]) * (cy ? f[1] : 1 - f[1]) * (cz ? f[2] : 1 - f[2]);
    if (w == 0) continue;
    r += w * glm::dvec4(map.at(cx ? i1[0] : i0[0], cy ? i1[1] : i0[1], cz ? i1[2] : i0[2]));
  }
  return r;
}

DisplacedSample Displace(const std::vector<PlacedMap>& maps, const glm::dvec3& p_prime,
                         bool with_jacobian) {
  DisplacedSample s;
  s.p = p_prime;
  // Eq. 9: the last map of the list acts first on p'.
  for (auto it = maps.rbegin(); it != maps.rend(); ++it) {
    IBR_CHECK(it->map != nullptr);
    const glm::dmat4& m = it->placement;
    const glm::dmat3 a(m);
    const glm::dmat4 m_inv = glm::inverse(m);
    const glm::dvec3 u = glm::dvec3(m_inv * glm::dvec4(s.p, 1.0));
    // Outside its cube (or its active part) a map is the identity.
    if (!InUnitCube(u) || glm::any(glm::lessThan(u, it->active.lo)) ||
        glm::any(glm::greaterThan(u, it->active.hi)))
      continue;
    const glm::dvec4 d = SampleMap(*it->map, u);
    if (with_jacobian) {
      // J_D in map units by central differences at half a texel.
      glm::dmat3 jd(0.0);
      for (int axis = 0; axis < 3; ++axis) {
        const double h = 0.5 / it->map->dims[axis];
        glm::dvec3 lo = u, hi = u;
        lo[axis] -= h;
        hi[axis] += h;
        jd[axis] =
            (glm::dvec3(SampleMap(*it->map, hi)) - glm::dvec3(SampleMap(*it->map, lo))) / (2 * h);
      }
      // p = p' + A D(M^-1 p'): d p / d p' = I + A J_D A^-1 (eq. 10).
      const glm::dmat3 j = glm::dmat3(1.0) + a * jd * glm::inverse(a);
      s.jacobian = j * s.jacobian;
    }
    s.p += a * glm::dvec3(d);
    s.alpha *= d.w;
  }
  return s;
}

MapDerivatives ComputeMapDerivatives(const DisplacementMap& map) {
  MapDerivatives out;
  out.jacobian.assign(map.texels.size(), glm::mat3(0.0f));
  out.alpha_gradient.assign(map.texels.size(), glm::vec3(0.0f));
  const glm::ivec3 n = map.dims;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const glm::ivec3 p(x, y, z);
        const size_t i = map.Index(x, y, z);
        for (int axis = 0; axis < 3; ++axis) {
          glm::ivec3 lo = p, hi = p;
          lo[axis] = std::max(p[axis] - 1, 0);
          hi[axis] = std::min(p[axis] + 1, n[axis] - 1);
          if (lo[axis] == hi[axis]) continue;
          const float du = static_cast<float>(hi[axis] - lo[axis]) / static_cast<float>(n[axis]);
          const glm::vec4 d = (map.at(hi.x, hi.y, hi.z) - map.at(lo.x, lo.y, lo.z)) / du;
          out.jacobian[i][axis] = glm::vec3(d);
          out.alpha_gradient[i][axis] = d.w;
        }
      }
  return out;
}

Box3 ProxyBox(const Box3& object_box, const std::vector<PlacedMap>& maps) {
  // A displaced p' outside every placed cube has p = p' (in the object box);
  // inside a cube it may show anything. So the union bounds every visible p'.
  Box3 box = object_box;
  for (const auto& pm : maps) {
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 corner(c & 1, (c >> 1) & 1, (c >> 2) & 1);
      const glm::dvec3 q = glm::dvec3(pm.placement * glm::dvec4(corner, 1.0));
      box.lo = glm::min(box.lo, q);
      box.hi = glm::max(box.hi, q);
    }
  }
  return box;
}

namespace {

// Per texel of a stored map: whether it reads as the identity (D = 0 as
// stored, alpha = 1), and whether its mask as the GPU reads it is below
// kCutAlpha (x fastest).
struct TexelFlags {
  std::vector<uint8_t> identity, cut;
};
// Below 0.5 with room for the GPU's filtering weights (llvmpipe's 8-bit
// lerps stay within the two values they blend; the room is for anything
// coarser).
constexpr double kCutAlpha = 0.45;

TexelFlags ClassifyTexels(const StoredDisplacementMap& s) {
  const size_t count = static_cast<size_t>(s.dims.x) * s.dims.y * s.dims.z;
  IBR_CHECK_EQ(s.bits == 32 ? s.floats.size() : s.unorm.size(), 4 * count);
  const double max_unorm = s.bits == 8 ? 255.0 : 65535.0;
  const auto zero_code = static_cast<uint16_t>(std::lround(0.5 * max_unorm));
  const auto one_code = static_cast<uint16_t>(max_unorm);
  TexelFlags flags{std::vector<uint8_t>(count), std::vector<uint8_t>(count)};
  for (size_t t = 0; t < count; ++t) {
    const size_t i = 4 * t;
    bool identity = true;
    for (int c = 0; c < 4; ++c) {
      if (s.bits == 32) {
        identity = identity && s.floats[i + c] == (c == 3 ? 1.0f : 0.0f);
      } else {
        identity = identity && s.unorm[i + c] == (c == 3 ? one_code : zero_code);
      }
    }
    const double alpha = s.bits == 32 ? s.floats[i + 3] : s.unorm[i + 3] / max_unorm;
    flags.identity[t] = identity;
    flags.cut[t] = alpha < kCutAlpha;
  }
  return flags;
}

// ActiveBox in texels [lo, hi): the texels that are not the identity, two
// more each side (one for the trilinear footprint, one for the central
// differences), clipped to the map; lo > hi when there are none.
struct TexelRange {
  glm::ivec3 lo, hi;
};
TexelRange ActiveTexels(const glm::ivec3& n, const TexelFlags& flags) {
  glm::ivec3 first = n, last(-1);
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        if (flags.identity[(static_cast<size_t>(z) * n.y + y) * n.x + x]) continue;
        first = glm::min(first, glm::ivec3(x, y, z));
        last = glm::max(last, glm::ivec3(x, y, z));
      }
  if (last.x < 0) return {n, glm::ivec3(0)};
  return {glm::max(first - 2, glm::ivec3(0)), glm::min(last + 3, n)};
}

}  // namespace

Box3 ActiveBox(const StoredDisplacementMap& s) {
  const TexelRange r = ActiveTexels(s.dims, ClassifyTexels(s));
  if (r.lo.x > r.hi.x) return {glm::dvec3(1.0), glm::dvec3(0.0)};
  // Texel i spans [i, i + 1] / n.
  const glm::dvec3 texel = 1.0 / glm::dvec3(s.dims);
  return {glm::dvec3(r.lo) * texel, glm::dvec3(r.hi) * texel};
}

double MapBricks::Edge(int axis, int b) const {
  return static_cast<double>(std::min(lo[axis] + b * brick_texels, hi[axis])) / dims[axis];
}

MapBricks ClassifyMapBricks(const StoredDisplacementMap& s, int brick_texels) {
  IBR_CHECK(brick_texels >= 1);
  const glm::ivec3 n = s.dims;
  MapBricks bricks;
  bricks.dims = n;
  bricks.brick_texels = brick_texels;
  const TexelFlags flags = ClassifyTexels(s);
  const TexelRange active = ActiveTexels(n, flags);
  if (active.lo.x > active.hi.x) return bricks;  // the identity everywhere: no bricks
  bricks.lo = active.lo;
  bricks.hi = active.hi;
  bricks.grid = (bricks.hi - bricks.lo + brick_texels - 1) / brick_texels;
  // Counts of the texels that are not the identity / not cut.
  std::vector<uint8_t> moving_flags(flags.identity.size()), kept_flags(flags.cut.size());
  for (size_t t = 0; t < moving_flags.size(); ++t) {
    moving_flags[t] = !flags.identity[t];
    kept_flags[t] = !flags.cut[t];
  }
  const SummedVolume moving(n, moving_flags), kept(n, kept_flags);
  // Texels lo..hi inclusive, clamped to the map (CLAMP_TO_EDGE reads the faces).
  auto count = [&](const SummedVolume& table, glm::ivec3 lo, glm::ivec3 hi) {
    return table.Count(glm::clamp(lo, glm::ivec3(0), n - 1),
                       glm::clamp(hi, glm::ivec3(0), n - 1) + 1);
  };
  bricks.kinds.resize(static_cast<size_t>(bricks.grid.x) * bricks.grid.y * bricks.grid.z);
  for (int z = 0; z < bricks.grid.z; ++z)
    for (int y = 0; y < bricks.grid.y; ++y)
      for (int x = 0; x < bricks.grid.x; ++x) {
        // Brick texels [b0, b1); samples in it filter texels b0 - 1 .. b1
        // (trilinear), their derivatives b0 - 2 .. b1 + 1 (central
        // differences of the texels, or of the filtered map at half a texel).
        const glm::ivec3 b0 = bricks.lo + glm::ivec3(x, y, z) * brick_texels;
        const glm::ivec3 b1 = glm::min(b0 + brick_texels, bricks.hi);
        MapBrickKind kind = MapBrickKind::kDisplaced;
        if (s.bits != 8 && count(moving, b0 - 2, b1 + 1) == 0) {
          kind = MapBrickKind::kIdentity;
        } else if (count(kept, b0 - 1, b1) == 0) {
          kind = MapBrickKind::kCut;
        }
        bricks.kinds[(static_cast<size_t>(z) * bricks.grid.y + y) * bricks.grid.x + x] = kind;
      }
  return bricks;
}

}  // namespace core
