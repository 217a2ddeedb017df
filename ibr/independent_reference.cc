#include "ibr/independent_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/check.h"
#include "core/error.h"

// Nothing here calls PrepareFrame, render::MakeSlices or ibr/reference.h: the
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
  void MakePlanes(const glm::dvec3& view_dir);
  // Texel coordinates and q of the view point p (bounded) in map m.
  Tri MapDecision(const MapSetup& m, const glm::dvec3& p, const glm::dvec3& p_error) const;
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
  double near_band_ = 0;  // camera z below which the GPU's near plane may clip (perspective)
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

void Evaluator::MakePlanes(const glm::dvec3& view_dir) {
  const int n = options_.slices;
  const glm::dmat4 cam_from_box = view_.cam_from_world * maps_.world_from_box;
  double zmin = INFINITY, zmax = -INFINITY;
  for (int i = 0; i < 8; ++i) {
    const double z = (cam_from_box * glm::dvec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0)).z;
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
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

Tri Evaluator::MapDecision(const MapSetup& s, const glm::dvec3& p,
                           const glm::dvec3& p_error) const {
  const ImageMap& m = *s.map;
  const glm::dmat4& mv = s.map_from_view;
  glm::dvec3 q, dq;
  for (int c = 0; c < 3; ++c) {
    q[c] = mv[0][c] * p.x + mv[1][c] * p.y + mv[2][c] * p.z + mv[3][c];
    const double mag = std::abs(mv[0][c] * p.x) + std::abs(mv[1][c] * p.y) +
                       std::abs(mv[2][c] * p.z) + std::abs(mv[3][c]);
    dq[c] = kSafety * (std::abs(mv[0][c]) * p_error.x + std::abs(mv[1][c]) * p_error.y +
                       std::abs(mv[2][c]) * p_error.z + 6 * kU * mag);
  }
  const MapCamera& cam = m.camera;
  const bool outside_passes = options_.outside == OutsidePolicy::kPass;
  Tri result = Tri::kNo;
  bool have = false;
  auto add = [&](Tri t) {
    result = have ? Merge(result, t) : t;
    have = true;
  };
  if (!cam.orthographic && q.z <= dq.z) {
    add(outside_passes ? Tri::kYes : Tri::kNo);  // behind the map (or may be)
    if (q.z < -dq.z) return result;
  }
  Bounded u, v;
  if (cam.orthographic) {
    u = MulAdd(cam.fx, {q.x, dq.x}, cam.cx);
    v = MulAdd(cam.fy, {q.y, dq.y}, cam.cy);
  } else {
    const Bounded rx = Divide({q.x, dq.x}, {q.z, dq.z}), ry = Divide({q.y, dq.y}, {q.z, dq.z});
    u = MulAdd(cam.fx, rx, cam.cx);
    v = MulAdd(cam.fy, ry, cam.cy);
  }
  u.e *= kSafety;
  v.e *= kSafety;
  if (!std::isfinite(u.v) || !std::isfinite(v.v)) {
    add(Tri::kMaybe);
    return result;
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
  int cols[2], rows[2];
  const int nc = candidates(u, cam.width, cols), nr = candidates(v, cam.height, rows);
  for (int i = 0; i < nc; ++i) {
    for (int j = 0; j < nr; ++j) {
      if (cols[i] < 0 || cols[i] >= cam.width || rows[j] < 0 || rows[j] >= cam.height) {
        add(outside_passes ? Tri::kYes : Tri::kNo);
        continue;
      }
      const double d = TexelCode(m, options_.method, cols[i], rows[j]);
      if (d < 0) {
        add(Tri::kNo);
      } else if (options_.method == Method::kVisualHull) {
        add(Tri::kYes);
      } else if (d > 0) {
        // Sec. 4.1: the point is at or behind the surface the map saw.
        add(q.z - d > dq.z ? Tri::kYes : q.z - d < -dq.z ? Tri::kNo : Tri::kMaybe);
      } else {
        add(options_.invalid_depth == InvalidDepthPolicy::kNoConstraint ? Tri::kYes : Tri::kNo);
      }
    }
  }
  return result;
}

IndependentFrame Evaluator::Run() {
  if (options_.slicing == Slicing::kRay) {
    core::ThrowInputError("RenderIndependent",
                          "the independent reference covers slicing only (orthogonal, screen)");
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
  glm::dvec3 view_dir = axis;
  if (!vc.orthographic) {
    const glm::dvec3 centre(maps_.world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0));
    const glm::dvec3 d = centre - glm::dvec3(world_from_cam[3]);
    if (glm::length(d) > 1e-12) view_dir = glm::normalize(d);
  }
  ChooseActive(view_dir);
  MakePlanes(view_dir);
  const int slices = static_cast<int>(planes_.size());
  const int n = static_cast<int>(active_maps_.size());
  frame_.pixels.assign(static_cast<size_t>(vc.width) * vc.height, {});
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
        for (const MapSetup& m : active_maps_) {
          const Tri d = MapDecision(m, points[s], errors[s]);
          ++frame_.decisions;
          yes += d == Tri::kYes;
          maybe += d == Tri::kMaybe;
        }
        frame_.uncertain_decisions += maybe;
        // Steps 2(a)-(f): the pixel is finished on this slice iff the count
        // reaches the requirement (exact: every map, in loop order).
        const int need = frame_.robust ? frame_.required : n;
        const Tri finished = yes >= need ? Tri::kYes : yes + maybe >= need ? Tri::kMaybe : Tri::kNo;
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
          }
          break;
        }
      }
    }
  }
  return frame_;
}

}  // namespace

IndependentFrame RenderIndependent(const MapSet& maps, const ViewCamera& view,
                                   const DepthObjectOptions& options,
                                   const IndependentOptions& independent) {
  return Evaluator(maps, view, options, independent).Run();
}

IndependentComparison CompareWithIndependent(const IndependentFrame& ref,
                                             const core::Image8& gpu_stencil,
                                             const core::ImageF& gpu_depth_covered) {
  IBR_CHECK_EQ(gpu_stencil.width(), ref.width);
  IBR_CHECK_EQ(gpu_stencil.height(), ref.height);
  IBR_CHECK_EQ(gpu_depth_covered.width(), ref.width);
  IBR_CHECK_GE(gpu_depth_covered.channels(), 2);
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
      int gpu_front = -1;
      if (gpu_covered) {
        double best = INFINITY;
        for (int s = 0; s < slices; ++s) {
          const double z = ref.SliceDepth(col, row, s);
          if (std::isfinite(z) && std::abs(z - gpu_z) < best)
            best = std::abs(z - gpu_z), gpu_front = s;
        }
      }
      const bool ref_covered = px.count > 0;
      bool agree = gpu_stencil.at(col, row) == px.stencil && gpu_covered == ref_covered;
      if (agree && ref_covered) {
        const double err = std::abs(gpu_z - px.depth);
        agree = gpu_front == px.front_slice && err <= px.depth_bound;
        if (agree) {
          c.max_depth_error = std::max(c.max_depth_error, err);
          if (px.depth_bound > 0)
            c.max_depth_error_over_bound =
                std::max(c.max_depth_error_over_bound, err / px.depth_bound);
        }
      }
      c.agree += agree;
      c.band += px.band;
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

}  // namespace ibr
