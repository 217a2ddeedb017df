#include "verify/independent_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/check.h"
#include "core/error.h"

// Nothing here calls PrepareFrame, render::MakeSlices or verify/reference.h: the
// planes, transforms, silhouette codes and stencil outcome are derived again
// from the MapSet and the view, in double precision.

namespace ibr {
namespace {

constexpr double kU = 0x1p-24;        // unit roundoff of IEEE single precision
constexpr double kDivision = 5 * kU;  // GLSL division: 2.5 ULP, and 1 ULP <= 2u relative
constexpr double kSafety = 2;         // second-order terms of the running bound

// Three-valued decision: a map test, a coverage test or a slice outcome.
enum class Tri { kNo, kYes, kMaybe };

Tri Merge(Tri a, Tri b) { return a == b ? a : Tri::kMaybe; }

// A value with its error bound (absolute) as the GPU's float chain computes it.
struct Bounded {
  double v = 0;
  double e = 0;
};

// a * b + c with float inputs (each rounded: u) and two roundings.
Bounded MulAdd(double a, const Bounded& b, double c) {
  const double v = a * b.v + c;
  return {v, std::abs(a) * b.e + 3 * kU * (std::abs(a * b.v) + std::abs(c)) + kU * std::abs(v)};
}

Bounded Divide(const Bounded& a, const Bounded& b) {
  const double v = a.v / b.v;
  return {v, (a.e + std::abs(v) * b.e) / std::abs(b.v) + kDivision * std::abs(v)};
}

// Silhouette/depth code of one texel, from the map's own images: < 0 outside
// the silhouette, 0 invalid depth inside it, > 0 camera z (sec. 4-5: depth
// objects test depth, visual hulls test the silhouette).
double TexelCode(const ImageMap& m, Method method, int col, int row) {
  double d = m.depth.empty() ? 0.0 : static_cast<double>(m.depth.at(col, row));
  if (!(std::isfinite(d) && d > 0)) d = 0;
  bool in_silhouette;
  if (!m.mask.empty()) {
    in_silhouette = m.mask.at(col, row) > 127;
  } else {
    in_silhouette = method == Method::kVisualHull ? d > 0 : true;
  }
  return in_silhouette ? d : -1.0;
}

// The texel's RGBA in [0, 1] as the map's own colour image gives it (no
// colour image: white; RGB: alpha 1).
glm::dvec4 TexelColour(const ImageMap& m, int col, int row) {
  if (m.color.empty()) return glm::dvec4(1.0);
  glm::dvec4 c(1.0);
  for (int k = 0; k < std::min(m.color.channels(), 4); ++k) c[k] = m.color.at(col, row, k) / 255.0;
  return c;
}

// The world direction a camera looks at the box centre: orthographic: its
// +z axis; pinhole: from its centre towards the box centre (the axis if the
// centre is the box centre). Row 2 of R is +z in world; the centre is -R^T t.
glm::dvec3 LookAtBox(bool orthographic, const glm::dmat4& cam_from_world,
                     const glm::dvec3& box_centre) {
  const glm::dmat3 r(cam_from_world);
  const glm::dvec3 axis = glm::normalize(glm::dvec3(r[0][2], r[1][2], r[2][2]));
  if (orthographic) return axis;
  const glm::dvec3 t(cam_from_world[3]);
  const glm::dvec3 centre = -glm::dvec3(glm::dot(glm::dvec3(r[0][0], r[0][1], r[0][2]), t),
                                        glm::dot(glm::dvec3(r[1][0], r[1][1], r[1][2]), t),
                                        glm::dot(glm::dvec3(r[2][0], r[2][1], r[2][2]), t));
  const glm::dvec3 d = box_centre - centre;
  return glm::length(d) > 1e-12 ? glm::normalize(d) : axis;
}

// Where a view point falls in a map: q (map camera) with its bound, and the
// candidate texel columns / rows (-1 or the size = outside the image).
struct Projection {
  glm::dvec3 q{0.0}, dq{0.0};
  bool maybe_behind = false;   // pinhole: q.z within its bound of 0 or below
  bool surely_behind = false;  // pinhole: q.z below minus its bound
  bool nonfinite = false;
  int cols[2] = {-1, -1}, rows[2] = {-1, -1};
  int nc = 0, nr = 0;
  bool InImage(int i, int j, const MapCamera& c) const {
    return cols[i] >= 0 && cols[i] < c.width && rows[j] >= 0 && rows[j] < c.height;
  }
};

struct Plane {
  glm::dvec3 n;  // view camera space
  double w = 0;  // dot(n, p) = w
  // Float error of the GPU's plane: absolute on w, and on each normal component.
  double w_error = 0, n_error = 0;
};

struct MapSetup {
  const ImageMap* map = nullptr;
  glm::dmat4 map_from_view{1.0};
};

class Evaluator {
 public:
  Evaluator(const MapSet& maps, const ViewCamera& view, const DepthObjectOptions& options,
            const IndependentOptions& independent)
      : maps_(maps), view_(view), options_(options), independent_(independent) {}

  IndependentFrame Run();

 private:
  void ChooseActive(const glm::dvec3& view_dir);
  void ComputeWeights(const glm::dvec3& view_dir);
  void MakePlanes(const glm::dvec3& view_dir);
  void RunSlices();
  void RunRay();
  Projection Project(const MapSetup& m, const glm::dvec3& p, const glm::dvec3& p_error) const;
  // Map m's test at the view point p (bounded). With `lo`/`hi`: the colour
  // range c over the candidate texels that accept (0 outside the image).
  Tri MapDecision(const MapSetup& m, const glm::dvec3& p, const glm::dvec3& p_error,
                  glm::dvec4* lo = nullptr, glm::dvec4* hi = nullptr) const;
  // Every active map's test at p: finished (the count reached), the count of
  // sure accepts and of uncertain decisions; colour of the accepting maps.
  Tri ObjectDecision(const glm::dvec3& p, const glm::dvec3& p_error, int* yes, int* maybe,
                     IndependentPixel* colour) const;
  // The ray path's colour at p: every weighted map that sees p in its image.
  void RayColour(const glm::dvec3& p, const glm::dvec3& p_error, IndependentPixel& px) const;
  void AddColour(int map, const glm::dvec4& lo, const glm::dvec4& hi, IndependentPixel& px) const;
  Tri Coverage(const glm::dvec3& p, const glm::dvec3& p_dx, const glm::dvec3& p_dy) const;
  bool PointOnPlane(const Plane& plane, double u, double v, glm::dvec3& p,
                    glm::dvec3* p_error) const;

  const MapSet& maps_;
  const ViewCamera& view_;
  const DepthObjectOptions& options_;
  const IndependentOptions& independent_;
  IndependentFrame frame_;
  glm::dmat4 box_from_cam_{1.0};
  std::vector<Plane> planes_;
  std::vector<MapSetup> active_maps_;
  std::vector<MapSetup> every_map_;  // by map index (the ray path's colour)
  double near_band_ = 0;  // camera z below which the GPU's near plane may clip (perspective)
  glm::dvec3 view_dir_{0.0};
};

void Evaluator::ChooseActive(const glm::dvec3& view_dir) {
  // Visual hulls in the cube rig: of two orthographic maps looking exactly
  // opposite ways, only the one looking along the view carves (sec. 5: the
  // opposite silhouettes are mirror images); exact ties keep the lower index.
  const int n = static_cast<int>(maps_.maps.size());
  auto axis = [&](int i) {
    const glm::dmat3 r(maps_.maps[i].cam_from_world);
    return glm::normalize(glm::dvec3(r[0][2], r[1][2], r[2][2]));  // row 2 of R
  };
  for (int i = 0; i < n; ++i) {
    bool skip = false;
    if (options_.method == Method::kVisualHull && options_.hull_skip_opposite &&
        maps_.maps[i].camera.orthographic) {
      for (int j = 0; j < n && !skip; ++j) {
        if (j == i || !maps_.maps[j].camera.orthographic) continue;
        if (glm::dot(axis(i), axis(j)) > -1.0 + 1e-9) continue;
        const double si = glm::dot(axis(i), view_dir), sj = glm::dot(axis(j), view_dir);
        skip = sj > si || (sj == si && j < i);
      }
    }
    if (skip) continue;
    frame_.active.push_back(i);
    active_maps_.push_back(
        {&maps_.maps[i], maps_.maps[i].cam_from_world * glm::inverse(view_.cam_from_world)});
  }
  const int count = static_cast<int>(frame_.active.size());
  frame_.robust = options_.robust_k > 0;
  frame_.required = std::max(count - options_.robust_k, 0);
}

// Sec. 4.2 with the unstructured-lumigraph penalty (k = 3) that
// ibr/view_weights.h states, evaluated here from the poses (not through
// ViewDependentWeights or PrepareFrame): the reference must catch a mistake
// in either.
void Evaluator::ComputeWeights(const glm::dvec3& view_dir) {
  // Over every map, active or not (a hull's skipped opposite maps included).
  const glm::dvec3 centre(maps_.world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0));
  const int n = static_cast<int>(maps_.maps.size());
  frame_.weights.assign(maps_.maps.size(), 0.0);
  if (n == 0) return;
  std::vector<double> theta(n);
  for (int j = 0; j < n; ++j) {
    const ImageMap& m = maps_.maps[j];
    const glm::dvec3 d = LookAtBox(m.camera.orthographic, m.cam_from_world, centre);
    theta[j] = std::atan2(glm::length(glm::cross(d, view_dir)), glm::dot(d, view_dir));
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return theta[a] < theta[b]; });
  if (theta[order[0]] == 0) {
    frame_.weights[order[0]] = 1;
    return;
  }
  const int k = std::min(3, n);
  const double theta_k = n > k ? theta[order[k]] : M_PI;
  double sum = 0;
  std::vector<double> w(k);
  for (int j = 0; j < k; ++j) {
    w[j] = std::max(0.0, 1.0 - theta[order[j]] / theta_k) / theta[order[j]];
    sum += w[j];
  }
  for (int j = 0; j < k; ++j) frame_.weights[order[j]] = sum > 0 ? w[j] / sum : 1.0 / k;
}

// The box's camera-z range over its eight corners.
void BoxDepthRange(const glm::dmat4& cam_from_box, double& zmin, double& zmax) {
  zmin = INFINITY;
  zmax = -INFINITY;
  for (int i = 0; i < 8; ++i) {
    const double z = (cam_from_box * glm::dvec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0)).z;
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
}

void Evaluator::MakePlanes(const glm::dvec3& view_dir) {
  const int n = options_.slices;
  double zmin, zmax;
  BoxDepthRange(view_.cam_from_world * maps_.world_from_box, zmin, zmax);
  const double extent = std::max(zmax - zmin, 1e-300);
  if (!view_.camera.orthographic) near_band_ = 2e-5 * (std::max(zmax, 0.0) + extent);
  if (options_.slicing == Slicing::kScreen) {
    // Sec. 3.3: planes parallel to the view plane, camera z = const, through
    // the box's depth range (perspective: in front of the eye), each at the
    // centre of its cell.
    frame_.axis = -1;
    if (!view_.camera.orthographic) zmin = std::max(zmin, 0.0);
    const double range = std::max(zmax - zmin, 0.0);
    for (int i = 0; i < n; ++i) {
      const double z = zmin + (i + 0.5) * range / n;
      frame_.plane_values.push_back(z);
      // The GPU derives z from float corner depths: error ~ a few u of them.
      planes_.push_back(
          {{0, 0, 1}, z, 8 * kU * (std::abs(zmin) + std::abs(zmax) + std::abs(z)), 4 * kU});
    }
    return;
  }
  // Sec. 3.2: the box axis whose planes face the viewer most directly: the
  // world gradient of box coordinate k is row k of box_from_world.
  const glm::dmat3 box_from_world(glm::inverse(maps_.world_from_box));
  double score[3];
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 g(box_from_world[0][k], box_from_world[1][k], box_from_world[2][k]);
    score[k] = std::abs(glm::dot(glm::normalize(g), view_dir));
  }
  int best = 0;
  for (int k = 1; k < 3; ++k) best = score[k] > score[best] ? k : best;
  int lowest_tied = best;
  for (int k = 0; k < 3; ++k) {
    if (k != best && score[best] - score[k] <= independent_.axis_tie * score[best]) {
      frame_.axis_tie = true;
      lowest_tied = std::min(lowest_tied, k);
    }
  }
  frame_.axis =
      frame_.axis_tie ? (independent_.tie_axis >= 0 ? independent_.tie_axis : lowest_tied) : best;
  const int k = frame_.axis;
  // Plane box_k = c in view camera space: box_k = dot(row k of box_from_cam, p) + b_k.
  const glm::dvec3 a(box_from_cam_[0][k], box_from_cam_[1][k], box_from_cam_[2][k]);
  const double b = box_from_cam_[3][k];
  for (int i = 0; i < n; ++i) {
    const double c = (i + 0.5) / n;
    frame_.plane_values.push_back(c);
    const double w = c - b;
    planes_.push_back(
        {a, w, 8 * kU * (std::abs(c) + std::abs(b) + std::abs(w)), 8 * kU * glm::length(a)});
  }
}

bool Evaluator::PointOnPlane(const Plane& plane, double u, double v, glm::dvec3& p,
                             glm::dvec3* p_error) const {
  const MapCamera& c = view_.camera;
  const double ax = 1.0 / c.fx, ay = 1.0 / c.fy, bx = -c.cx / c.fx, by = -c.cy / c.fy;
  const Bounded rx = MulAdd(u, {ax, kU * std::abs(ax)}, bx);
  const Bounded ry = MulAdd(v, {ay, kU * std::abs(ay)}, by);
  const glm::dvec3& n = plane.n;
  if (c.orthographic) {
    // Ray (rx, ry, 0) + z (0, 0, 1): n.xy . r.xy + n.z z = w.
    if (std::abs(n.z) < 1e-300) return false;
    const double dot_xy = n.x * rx.v + n.y * ry.v;
    const Bounded s{plane.w - dot_xy,
                    plane.w_error + std::abs(n.x) * rx.e + std::abs(n.y) * ry.e +
                        plane.n_error * (std::abs(rx.v) + std::abs(ry.v)) +
                        4 * kU * (std::abs(plane.w) + std::abs(n.x * rx.v) + std::abs(n.y * ry.v))};
    const Bounded z = Divide(s, {n.z, plane.n_error + kU * std::abs(n.z)});
    p = {rx.v, ry.v, z.v};
    if (p_error) *p_error = {rx.e, ry.e, z.e};
    return std::isfinite(z.v);
  }
  // Ray t (rx, ry, 1): t = w / dot(n, dir), in front iff t > 0.
  const double den = n.x * rx.v + n.y * ry.v + n.z;
  if (std::abs(den) < 1e-300) return false;
  const Bounded bden{den,
                     std::abs(n.x) * rx.e + std::abs(n.y) * ry.e +
                         plane.n_error * (std::abs(rx.v) + std::abs(ry.v) + 1) +
                         4 * kU * (std::abs(n.x * rx.v) + std::abs(n.y * ry.v) + std::abs(n.z))};
  const Bounded t = Divide({plane.w, plane.w_error + kU * std::abs(plane.w)}, bden);
  if (!(t.v > 0) || !std::isfinite(t.v)) return false;
  p = {t.v * rx.v, t.v * ry.v, t.v};
  if (p_error) {
    *p_error = {t.v * rx.e + std::abs(rx.v) * t.e + kU * std::abs(p.x),
                t.v * ry.e + std::abs(ry.v) * t.e + kU * std::abs(p.y), t.e};
  }
  return true;
}

Tri Evaluator::Coverage(const glm::dvec3& p, const glm::dvec3& p_dx, const glm::dvec3& p_dy) const {
  // The slice polygon is the plane's part inside the box; rasterisation snaps
  // its vertices to 2^-subpixel_bits pixels, so a pixel centre that close to
  // an edge may fall on either side.
  const double tol_px = std::ldexp(1.0, -independent_.subpixel_bits) + 1e-3;
  const glm::dvec3 b(box_from_cam_ * glm::dvec4(p, 1.0));
  const glm::dvec3 bx(box_from_cam_ * glm::dvec4(p_dx, 1.0));
  const glm::dvec3 by(box_from_cam_ * glm::dvec4(p_dy, 1.0));
  Tri inside = Tri::kYes;
  for (int k = 0; k < 3; ++k) {
    if (k == frame_.axis) continue;  // on the plane by construction
    const double per_px = std::hypot(bx[k] - b[k], by[k] - b[k]);
    const double margin_px = std::min(b[k], 1.0 - b[k]) / std::max(per_px, 1e-300);  // < 0 outside
    if (margin_px < -tol_px) return Tri::kNo;
    if (margin_px <= tol_px) inside = Tri::kMaybe;
  }
  if (near_band_ > 0 && p.z < near_band_) inside = inside == Tri::kYes ? Tri::kMaybe : inside;
  return inside;
}

Projection Evaluator::Project(const MapSetup& s, const glm::dvec3& p,
                              const glm::dvec3& p_error) const {
  const glm::dmat4& mv = s.map_from_view;
  Projection r;
  for (int c = 0; c < 3; ++c) {
    r.q[c] = mv[0][c] * p.x + mv[1][c] * p.y + mv[2][c] * p.z + mv[3][c];
    const double mag = std::abs(mv[0][c] * p.x) + std::abs(mv[1][c] * p.y) +
                       std::abs(mv[2][c] * p.z) + std::abs(mv[3][c]);
    r.dq[c] = kSafety * (std::abs(mv[0][c]) * p_error.x + std::abs(mv[1][c]) * p_error.y +
                         std::abs(mv[2][c]) * p_error.z + 6 * kU * mag);
  }
  const MapCamera& cam = s.map->camera;
  if (!cam.orthographic) {
    r.maybe_behind = r.q.z <= r.dq.z;
    r.surely_behind = r.q.z < -r.dq.z;
    if (r.surely_behind) return r;
  }
  Bounded u, v;
  if (cam.orthographic) {
    u = MulAdd(cam.fx, {r.q.x, r.dq.x}, cam.cx);
    v = MulAdd(cam.fy, {r.q.y, r.dq.y}, cam.cy);
  } else {
    const Bounded rx = Divide({r.q.x, r.dq.x}, {r.q.z, r.dq.z}),
                  ry = Divide({r.q.y, r.dq.y}, {r.q.z, r.dq.z});
    u = MulAdd(cam.fx, rx, cam.cx);
    v = MulAdd(cam.fy, ry, cam.cy);
  }
  u.e *= kSafety;
  v.e *= kSafety;
  if (!std::isfinite(u.v) || !std::isfinite(v.v)) {
    r.nonfinite = true;
    return r;
  }
  // Candidate texel columns/rows: floor(u), and its neighbour when u lies
  // within the bound of the boundary between them (-1 / width = outside).
  auto candidates = [](const Bounded& x, int size, int out[2]) {
    const double lo = std::floor(x.v - x.e), hi = std::floor(x.v + x.e);
    const auto clamp = [size](double c) {
      return static_cast<int>(std::clamp(c, -1.0, static_cast<double>(size)));
    };
    out[0] = clamp(lo);
    out[1] = clamp(hi);
    return out[0] == out[1] ? 1 : 2;
  };
  r.nc = candidates(u, cam.width, r.cols);
  r.nr = candidates(v, cam.height, r.rows);
  return r;
}

Tri Evaluator::MapDecision(const MapSetup& s, const glm::dvec3& p, const glm::dvec3& p_error,
                           glm::dvec4* lo, glm::dvec4* hi) const {
  const ImageMap& m = *s.map;
  const Projection pr = Project(s, p, p_error);
  const bool outside_passes = options_.outside == OutsidePolicy::kPass;
  Tri result = Tri::kNo;
  bool have = false;
  bool have_colour = false;
  auto add = [&](Tri t, const glm::dvec4& c) {
    result = have ? Merge(result, t) : t;
    have = true;
    if (lo != nullptr && t != Tri::kNo) {
      *lo = have_colour ? glm::min(*lo, c) : c;
      *hi = have_colour ? glm::max(*hi, c) : c;
      have_colour = true;
    }
  };
  if (lo != nullptr) *lo = *hi = glm::dvec4(0.0);
  const glm::dvec4 none(0.0);
  if (pr.maybe_behind) {
    add(outside_passes ? Tri::kYes : Tri::kNo, none);  // behind the map (or may be)
    if (pr.surely_behind) return result;
  }
  if (pr.nonfinite) {
    add(Tri::kMaybe, none);
    return result;
  }
  for (int i = 0; i < pr.nc; ++i) {
    for (int j = 0; j < pr.nr; ++j) {
      if (!pr.InImage(i, j, m.camera)) {
        add(outside_passes ? Tri::kYes : Tri::kNo, none);
        continue;
      }
      const int col = pr.cols[i], row = pr.rows[j];
      // The colour only where a caller collects it (the front slice's colour).
      const glm::dvec4 c = lo != nullptr ? TexelColour(m, col, row) : none;
      const double d = TexelCode(m, options_.method, col, row);
      if (d < 0) {
        add(Tri::kNo, c);
      } else if (options_.method == Method::kVisualHull) {
        add(Tri::kYes, c);
      } else if (d > 0) {
        // Sec. 4.1: the point is at or behind the surface the map saw.
        const double dz = pr.q.z - d;
        add(dz > pr.dq.z ? Tri::kYes : dz < -pr.dq.z ? Tri::kNo : Tri::kMaybe, c);
      } else {
        add(options_.invalid_depth == InvalidDepthPolicy::kNoConstraint ? Tri::kYes : Tri::kNo, c);
      }
    }
  }
  return result;
}

void Evaluator::AddColour(int map, const glm::dvec4& lo, const glm::dvec4& hi,
                          IndependentPixel& px) const {
  const double w = frame_.weights[map];
  if (!(w > 0)) return;
  px.color_lo += w * lo;
  px.color_hi += w * hi;
  // The weight as the GPU holds it (float of a double ULR: 1e-6 covers the
  // rounding and any difference in the directions' last bits), the texel
  // scaled by a float 1/255 and the product (2 u), the additive blend (u per
  // map in the sum, n maps).
  const double n = static_cast<double>(frame_.active.size());
  for (int k = 0; k < 4; ++k)
    px.color_bound += 1e-6 * hi[k] + (4 + n) * 2 * kU * w * std::abs(hi[k]);
}

Tri Evaluator::ObjectDecision(const glm::dvec3& p, const glm::dvec3& p_error, int* yes_out,
                              int* maybe_out, IndependentPixel* colour) const {
  int yes = 0, maybe = 0;
  const int n = static_cast<int>(active_maps_.size());
  for (int j = 0; j < n; ++j) {
    glm::dvec4 lo, hi;
    const Tri d =
        MapDecision(active_maps_[j], p, p_error, colour ? &lo : nullptr, colour ? &hi : nullptr);
    yes += d == Tri::kYes;
    maybe += d == Tri::kMaybe;
    if (colour != nullptr && d != Tri::kNo) AddColour(frame_.active[j], lo, hi, *colour);
  }
  if (yes_out) *yes_out = yes;
  if (maybe_out) *maybe_out = maybe;
  // Steps 2(a)-(f) / the ray's object field: inside iff the count reaches
  // the requirement (exact: every map).
  const int need = frame_.robust ? frame_.required : n;
  return yes >= need ? Tri::kYes : yes + maybe >= need ? Tri::kMaybe : Tri::kNo;
}

void Evaluator::RayColour(const glm::dvec3& p, const glm::dvec3& p_error,
                          IndependentPixel& px) const {
  for (size_t i = 0; i < maps_.maps.size(); ++i) {
    if (!(frame_.weights[i] > 0)) continue;
    const MapSetup& s = every_map_[i];
    const Projection pr = Project(s, p, p_error);
    glm::dvec4 lo(INFINITY), hi(-INFINITY);
    auto add = [&](const glm::dvec4& c) {
      lo = glm::min(lo, c);
      hi = glm::max(hi, c);
    };
    if (pr.maybe_behind || pr.nonfinite) add(glm::dvec4(0.0));
    if (!pr.surely_behind && !pr.nonfinite) {
      for (int a = 0; a < pr.nc; ++a) {
        for (int b = 0; b < pr.nr; ++b) {
          add(pr.InImage(a, b, s.map->camera) ? TexelColour(*s.map, pr.cols[a], pr.rows[b])
                                              : glm::dvec4(0.0));
        }
      }
    }
    AddColour(static_cast<int>(i), lo, hi, px);
  }
}

IndependentFrame Evaluator::Run() {
  if (options_.slices == DepthObjectOptions::kAutoSlices) {
    core::ThrowInputError("RenderIndependent", "needs an explicit slice count (not auto)");
  }
  if (options_.subtexel_depth) {
    core::ThrowInputError("RenderIndependent", "covers nearest-texel depth only (subtexel off)");
  }
  options_.Check();
  maps_.Check("RenderIndependent");
  view_.camera.Check("RenderIndependent: view");
  const MapCamera& vc = view_.camera;
  frame_.width = vc.width;
  frame_.height = vc.height;
  box_from_cam_ = glm::inverse(view_.cam_from_world * maps_.world_from_box);
  // The direction the viewer looks at the box.
  const glm::dmat4 world_from_cam = glm::inverse(view_.cam_from_world);
  const glm::dvec3 axis = glm::normalize(glm::dvec3(world_from_cam * glm::dvec4(0, 0, 1, 0)));
  view_dir_ = axis;
  if (!vc.orthographic) {
    const glm::dvec3 centre(maps_.world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0));
    const glm::dvec3 d = centre - glm::dvec3(world_from_cam[3]);
    if (glm::length(d) > 1e-12) view_dir_ = glm::normalize(d);
  }
  ChooseActive(view_dir_);
  ComputeWeights(view_dir_);
  for (const ImageMap& m : maps_.maps)
    every_map_.push_back({&m, m.cam_from_world * world_from_cam});
  frame_.pixels.assign(static_cast<size_t>(vc.width) * vc.height, {});
  if (options_.slicing == Slicing::kRay) {
    RunRay();
  } else {
    RunSlices();
  }
  return frame_;
}

void Evaluator::RunSlices() {
  const MapCamera& vc = view_.camera;
  MakePlanes(view_dir_);
  const int slices = static_cast<int>(planes_.size());
  const int n = static_cast<int>(active_maps_.size());
  frame_.slice_depths.assign(frame_.pixels.size() * slices,
                             std::numeric_limits<double>::quiet_NaN());
  std::vector<glm::dvec3> points(slices), errors(slices);
  std::vector<char> hit(slices);
  std::vector<int> order(slices);
  for (int row = 0; row < vc.height; ++row) {
    for (int col = 0; col < vc.width; ++col) {
      const double u = col + 0.5, v = row + 0.5;
      const size_t pix = static_cast<size_t>(row) * vc.width + col;
      for (int s = 0; s < slices; ++s) {
        hit[s] = PointOnPlane(planes_[s], u, v, points[s], &errors[s]);
        if (hit[s]) frame_.slice_depths[pix * slices + s] = points[s].z;
      }
      // Front to back along this ray: by camera z (the ray parameter).
      order.resize(slices);
      std::iota(order.begin(), order.end(), 0);
      std::erase_if(order, [&](int s) { return !hit[s]; });
      std::stable_sort(order.begin(), order.end(),
                       [&](int a, int b) { return points[a].z < points[b].z; });
      IndependentPixel& px = frame_.pixels[pix];
      // A view with no maps to intersect never writes a covered fragment.
      if (n == 0 && !frame_.robust) continue;
      for (int s : order) {
        glm::dvec3 pdx, pdy;
        if (!PointOnPlane(planes_[s], u + 1, v, pdx, nullptr) ||
            !PointOnPlane(planes_[s], u, v + 1, pdy, nullptr)) {
          pdx = pdy = points[s] + glm::dvec3(1e300);
        }
        const Tri covered = Coverage(points[s], pdx, pdy);
        if (covered == Tri::kNo) continue;
        int yes = 0, maybe = 0;
        const Tri finished = ObjectDecision(points[s], errors[s], &yes, &maybe, nullptr);
        frame_.decisions += n;
        frame_.uncertain_decisions += maybe;
        const Tri outcome = covered == Tri::kYes   ? finished
                            : finished == Tri::kNo ? Tri::kNo
                                                   : Tri::kMaybe;
        if (outcome == Tri::kMaybe) px.band = true;
        if (finished == Tri::kYes && covered == Tri::kYes) {
          // The robust count stored with the finished bit depends on every decision.
          if (frame_.robust && maybe > 0) px.band = true;
          px.front_slice = s;
          px.count = frame_.robust ? yes : n;
          px.stencil = frame_.robust ? (0x80 | yes) : n;
          // Robust with k >= N: finished without any accepting fragment, so no depth is written.
          if (px.count > 0) {
            px.depth = points[s].z;
            px.depth_bound = kSafety * errors[s].z;
            // Sec. 4.2: the colour blended by the maps that accept here.
            ObjectDecision(points[s], errors[s], nullptr, nullptr, &px);
          }
          break;
        }
      }
    }
  }
}

void Evaluator::RunRay() {
  frame_.ray = true;
  const MapCamera& vc = view_.camera;
  const int n_slices = options_.slices;
  // The step: the box's camera-z range (perspective: in front of the eye)
  // over the slice count, what the screen slices would be spaced.
  double zmin, zmax;
  BoxDepthRange(view_.cam_from_world * maps_.world_from_box, zmin, zmax);
  if (!vc.orthographic) zmin = std::max(zmin, 0.0);
  const double dz = std::max(zmax - zmin, 0.0) / n_slices;
  frame_.ray_step = dz;
  const int max_steps = n_slices + 2;
  const int n = static_cast<int>(active_maps_.size());
  const glm::dmat4& m = box_from_cam_;
  const double ax = 1.0 / vc.fx, ay = 1.0 / vc.fy, bx = -vc.cx / vc.fx, by = -vc.cy / vc.fy;
  for (int row = 0; row < vc.height; ++row) {
    for (int col = 0; col < vc.width; ++col) {
      IndependentPixel& px = frame_.pixels[static_cast<size_t>(row) * vc.width + col];
      // The pixel ray (camera z = t along it) and its float bound.
      const Bounded rx = MulAdd(col + 0.5, {ax, kU * std::abs(ax)}, bx);
      const Bounded ry = MulAdd(row + 0.5, {ay, kU * std::abs(ay)}, by);
      glm::dvec3 o(0.0), d(rx.v, ry.v, 1.0), o_err(0.0), d_err(rx.e, ry.e, 0.0);
      if (vc.orthographic) {
        o = {rx.v, ry.v, 0.0};
        d = {0.0, 0.0, 1.0};
        o_err = {rx.e, ry.e, 0.0};
        d_err = glm::dvec3(0.0);
      }
      // Box interval (slabs), each end with its bound.
      double t0 = -1e30, t1 = 1e30, e0 = 0, e1 = 0;
      Tri covered = Tri::kYes;
      for (int k = 0; k < 3; ++k) {
        const double ob = m[0][k] * o.x + m[1][k] * o.y + m[2][k] * o.z + m[3][k];
        const double db = m[0][k] * d.x + m[1][k] * d.y + m[2][k] * d.z;
        const double e_ob = 6 * kU *
                                (std::abs(m[0][k] * o.x) + std::abs(m[1][k] * o.y) +
                                 std::abs(m[2][k] * o.z) + std::abs(m[3][k])) +
                            std::abs(m[0][k]) * o_err.x + std::abs(m[1][k]) * o_err.y;
        const double e_db =
            6 * kU * (std::abs(m[0][k] * d.x) + std::abs(m[1][k] * d.y) + std::abs(m[2][k] * d.z)) +
            std::abs(m[0][k]) * d_err.x + std::abs(m[1][k]) * d_err.y;
        if (std::abs(db) <= std::max(1e-12, e_db)) {
          // Parallel to the slab (or may be, in float): inside iff between its planes.
          const double margin = std::min(ob, 1.0 - ob);
          if (margin < -e_ob) covered = Tri::kNo;
          if (std::abs(margin) <= e_ob && covered != Tri::kNo) covered = Tri::kMaybe;
          if (std::abs(db) > 1e-12 && covered != Tri::kNo) covered = Tri::kMaybe;
          if (std::abs(db) <= 1e-12) continue;
        }
        const double a = -ob / db, b = (1.0 - ob) / db;
        const double ea = kSafety * ((e_ob + kU * std::abs(ob)) / std::abs(db) +
                                     std::abs(a) * e_db / std::abs(db) + kDivision * std::abs(a));
        const double eb = kSafety * ((e_ob + kU * std::abs(1 - ob)) / std::abs(db) +
                                     std::abs(b) * e_db / std::abs(db) + kDivision * std::abs(b));
        const double near = std::min(a, b), far = std::max(a, b);
        const double en = a < b ? ea : eb, ef = a < b ? eb : ea;
        if (near > t0) t0 = near, e0 = en;
        if (far < t1) t1 = far, e1 = ef;
      }
      if (covered == Tri::kNo) continue;
      // Only in front of the eye; with the eye in the box, from half a step in front of it.
      if (!vc.orthographic && t0 <= 0) t0 = 0.5 * dz, e0 = kU * t0;
      if (t1 - t0 < -(e0 + e1)) continue;
      if (t1 - t0 <= e0 + e1) covered = Tri::kMaybe;
      if (covered == Tri::kMaybe) px.band = true;
      const double t_max = t1 - t0, e_tmax = e0 + e1;
      // Sample i at t0 + t_i along d; t_i accumulates one rounding per step.
      auto sample = [&](double t, int steps, glm::dvec3& p, glm::dvec3& err) {
        p = o + (t0 + t) * d;
        const double et = e0 + (steps + 2) * kU * (std::abs(t0) + std::abs(t));
        for (int c = 0; c < 3; ++c) {
          err[c] = kSafety * (o_err[c] + std::abs(d[c]) * et + std::abs(t0 + t) * d_err[c] +
                              3 * kU * (std::abs(o[c]) + std::abs((t0 + t) * d[c])));
        }
      };
      // Bisection between the last outside sample and the first inside one
      // (the ray core's RayRefineCrossing). An uncertain midpoint decision
      // leaves the result somewhere in that step's bracket: the bound widens
      // to it.
      auto refine = [&](const glm::dvec3& a, const glm::dvec3& ae, const glm::dvec3& b,
                        const glm::dvec3& be, double& depth, double& bound, bool& exact) {
        double ta = 0, tb = 1, widen = 0;
        const glm::dvec3 em = glm::max(ae, be) + 2 * kU * (glm::abs(a) + glm::abs(b));
        for (int k = 0; k < options_.refine_steps; ++k) {
          const double tm = 0.5 * (ta + tb);
          int maybe = 0;
          const Tri fm = ObjectDecision(a + tm * (b - a), em, nullptr, &maybe, nullptr);
          frame_.decisions += n;
          frame_.uncertain_decisions += maybe;
          if (fm == Tri::kMaybe && widen == 0) widen = (tb - ta) * std::abs(b.z - a.z);
          (fm == Tri::kYes ? tb : ta) = tm;
        }
        const glm::dvec3 hit = a + 0.5 * (ta + tb) * (b - a);
        depth = hit.z;
        bound = kSafety * em.z + widen;
        exact = widen == 0;
        return hit;
      };
      // An uncertain "inside" lets the GPU stop there: that hit is an
      // alternative outcome; the nominal march goes on as if outside.
      auto alternative = [&](double depth, double bound) {
        if (px.alternatives.size() >= 8) {
          px.band = true;  // too many to list: any outcome
        } else {
          px.alternatives.push_back({depth, bound});
        }
      };
      glm::dvec3 p, pe;
      sample(0, 0, p, pe);
      int maybe = 0;
      Tri inside = ObjectDecision(p, pe, nullptr, &maybe, nullptr);
      frame_.decisions += n;
      frame_.uncertain_decisions += maybe;
      // A ray starting inside is a hit at its origin, not refined.
      if (inside == Tri::kMaybe) alternative(p.z, kSafety * pe.z);
      glm::dvec3 hit_p(0.0), hit_e(0.0);
      double hit_bound = 0;
      bool found = inside == Tri::kYes;
      int found_step = 0;
      if (found) {
        hit_p = p;
        hit_e = pe;
        hit_bound = kSafety * pe.z;
      } else {
        double t = 0;
        glm::dvec3 prev = p, prev_e = pe;
        for (int i = 0; i < max_steps; ++i) {
          double dt = dz;
          // The sample that would pass the exit lands exactly on it.
          const double slack = (i + 3) * kU * (std::abs(t) + dt) + e_tmax;
          const double to_exit = t + dt - (t_max - 1e-4 * dt);
          if (std::abs(to_exit) <= slack) px.band = true;
          const bool last = to_exit >= 0;
          if (last) dt = t_max - t;
          glm::dvec3 q, qe;
          sample(t + dt, i + 1, q, qe);
          if (last) {
            q = o + t1 * d;  // exactly on the exit
            for (int c = 0; c < 3; ++c) qe[c] = std::max(qe[c], kSafety * std::abs(d[c]) * e1);
          }
          inside = ObjectDecision(q, qe, nullptr, &maybe, nullptr);
          frame_.decisions += n;
          frame_.uncertain_decisions += maybe;
          if (inside != Tri::kNo) {
            double depth, bound;
            bool exact = true;
            const glm::dvec3 hit = refine(prev, prev_e, q, qe, depth, bound, exact);
            if (inside == Tri::kMaybe) {
              alternative(depth, bound);
            } else {
              hit_p = hit;
              hit_e = glm::max(prev_e, qe) + 2 * kU * (glm::abs(prev) + glm::abs(q));
              hit_bound = bound;
              px.color_known = exact;
              found = true;
              found_step = i + 1;
              break;
            }
          }
          prev = q;
          prev_e = qe;
          t += dt;
          if (last) break;
        }
      }
      if (!found) continue;
      px.front_slice = found_step;
      px.count = 1;
      px.depth = hit_p.z;
      px.depth_bound = hit_bound;
      RayColour(hit_p, hit_e, px);
    }
  }
}

}  // namespace

IndependentFrame RenderIndependent(const MapSet& maps, const ViewCamera& view,
                                   const DepthObjectOptions& options,
                                   const IndependentOptions& independent) {
  return Evaluator(maps, view, options, independent).Run();
}

IndependentComparison CompareWithIndependent(const IndependentFrame& ref,
                                             const core::Image8& gpu_stencil,
                                             const core::ImageF& gpu_color,
                                             const core::ImageF& gpu_depth_covered) {
  if (!ref.ray) {
    IBR_CHECK_EQ(gpu_stencil.width(), ref.width);
    IBR_CHECK_EQ(gpu_stencil.height(), ref.height);
  }
  IBR_CHECK_EQ(gpu_depth_covered.width(), ref.width);
  IBR_CHECK_GE(gpu_depth_covered.channels(), 2);
  IBR_CHECK_EQ(gpu_color.width(), ref.width);
  IBR_CHECK_EQ(gpu_color.channels(), 4);
  IndependentComparison c;
  c.diff = core::Image8(ref.width, ref.height, 1, 0);
  const int slices = static_cast<int>(ref.plane_values.size());
  for (int row = 0; row < ref.height; ++row) {
    for (int col = 0; col < ref.width; ++col) {
      const IndependentPixel& px = ref.at(col, row);
      ++c.pixels;
      c.covered += px.count > 0;
      const bool gpu_covered = gpu_depth_covered.at(col, row, 1) > 0.5f;
      const double gpu_z = gpu_depth_covered.at(col, row, 0);
      // The GPU's front slice: the plane whose point on this ray is nearest its depth.
      int gpu_front = px.front_slice;
      if (!ref.ray && gpu_covered) {
        double best = INFINITY;
        for (int s = 0; s < slices; ++s) {
          const double z = ref.SliceDepth(col, row, s);
          if (std::isfinite(z) && std::abs(z - gpu_z) < best)
            best = std::abs(z - gpu_z), gpu_front = s;
        }
      }
      const bool ref_covered = px.count > 0;
      bool agree = gpu_covered == ref_covered;
      if (!ref.ray) agree = agree && gpu_stencil.at(col, row) == px.stencil;
      double color_error = 0;
      if (agree && ref_covered) {
        const double err = std::abs(gpu_z - px.depth);
        agree = gpu_front == px.front_slice && err <= px.depth_bound;
        if (agree) {
          c.max_depth_error = std::max(c.max_depth_error, err);
          if (px.depth_bound > 0)
            c.max_depth_error_over_bound =
                std::max(c.max_depth_error_over_bound, err / px.depth_bound);
        }
        for (int k = 0; k < 4; ++k) {
          const double g = gpu_color.at(col, row, k);
          color_error = std::max({color_error, px.color_lo[k] - g, g - px.color_hi[k]});
        }
        if (agree && !px.band && px.color_known) {
          ++c.color_checked;
          c.color_interval += px.color_lo != px.color_hi;
          if (color_error > px.color_bound) {
            ++c.color_errors;
            agree = false;
          }
          c.max_color_error = std::max(c.max_color_error, color_error);
        }
      }
      // Ray path: the GPU may have taken an alternative outcome (an
      // uncertain "inside" where it stopped); it must then match one.
      bool alternative = false;
      if (!agree && !px.band && gpu_covered) {
        for (const glm::dvec2& a : px.alternatives) {
          alternative = alternative || std::abs(gpu_z - a.x) <= a.y;
        }
      }
      c.agree += agree || alternative;
      c.band += px.band;
      c.alternative_pixels += !px.band && !px.alternatives.empty();
      c.alternative_taken += alternative;
      if (alternative) continue;
      if (!agree && px.band) {
        ++c.band_disagree;
        c.diff.at(col, row) = 128;
      } else if (!agree) {
        ++c.real_errors;
        c.diff.at(col, row) = 255;
      }
    }
  }
  return c;
}

void IndependentComparison::Add(const IndependentComparison& o) {
  pixels += o.pixels;
  agree += o.agree;
  band += o.band;
  band_disagree += o.band_disagree;
  real_errors += o.real_errors;
  alternative_pixels += o.alternative_pixels;
  alternative_taken += o.alternative_taken;
  covered += o.covered;
  color_checked += o.color_checked;
  color_interval += o.color_interval;
  color_errors += o.color_errors;
  max_depth_error = std::max(max_depth_error, o.max_depth_error);
  max_depth_error_over_bound = std::max(max_depth_error_over_bound, o.max_depth_error_over_bound);
  max_color_error = std::max(max_color_error, o.max_color_error);
}

}  // namespace ibr
