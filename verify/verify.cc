#include "verify/verify.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <optional>
#include <random>

#include "core/check.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/image_io.h"
#include "core/mesh.h"
#include "core/projection.h"
#include "core/sphere.h"
#include "ibr/depth_object.h"
#include "render/gl/gl.h"
#include "render/gl/gl_queries.h"
#include "render/gl/render_target.h"
#include "render/passes/displacement_pass.h"
#include "render/passes/relief_surface_pass.h"
#include "verify/independent_reference.h"
#include "verify/reference.h"

namespace ibr {

void VerifyOptions::Check() const {
  // Checked before the cases run, not when the first diff image is written.
  std::error_code ec;
  if (!out.empty() && std::filesystem::exists(out, ec) && !std::filesystem::is_directory(out, ec))
    core::ThrowFileError("ibr verify", out, "--out exists and is not a folder");
  if (cases < 1 || cases > 10'000'000)
    core::ThrowInputError("ibr verify", "--cases {} outside 1..10000000", cases);
  if (method != "depth-object" && method != "hull" && method != "all" &&
      !(hard && (method == "displacement" || method == "ncs" || method == "relief" ||
                 method == "pom" || method == "crm"))) {
    core::ThrowInputError("ibr verify", "--method '{}' (depth-object, hull, all{})", method,
                          hard ? ", displacement, ncs, relief, pom, crm" : "");
  }
  if (first_case < 0 || first_case > 10'000'000)
    core::ThrowInputError("ibr verify", "--first-case {} outside 0..10000000", first_case);
  if (inject_fault < 0 || inject_fault > 2)
    core::ThrowInputError("ibr verify", "unknown fault {}", inject_fault);
}

namespace {

// ---- random scenes (plain CPU maps, ray cast exactly) ----

void CastBalls(const std::vector<core::Sphere>& balls, ImageMap& m) {
  const MapCamera& c = m.camera;
  m.depth = core::ImageF(c.width, c.height, 1, 0.0f);
  m.mask = core::Image8(c.width, c.height, 1, 0);
  m.color = core::Image8(c.width, c.height, 3, 0);
  const glm::dmat4 world_from_cam = glm::inverse(m.cam_from_world);
  for (int row = 0; row < c.height; ++row) {
    for (int col = 0; col < c.width; ++col) {
      const double x = (col + 0.5 - c.cx) / c.fx, y = (row + 0.5 - c.cy) / c.fy;
      const glm::dvec3 o_cam = c.orthographic ? glm::dvec3(x, y, 0) : glm::dvec3(0);
      const glm::dvec3 d_cam = c.orthographic ? glm::dvec3(0, 0, 1) : glm::dvec3(x, y, 1);
      const glm::dvec3 o(world_from_cam * glm::dvec4(o_cam, 1.0)),
          d(world_from_cam * glm::dvec4(d_cam, 0.0));
      const auto t = core::NearestSphereHit(balls, o, d);
      if (!t) continue;
      m.depth.at(col, row) = static_cast<float>(o_cam.z + *t);
      m.mask.at(col, row) = 255;
      const glm::dvec3 p = o + *t * d;
      for (int k = 0; k < 3; ++k)
        m.color.at(col, row, k) = static_cast<uint8_t>(std::clamp(128 + 100 * p[k], 0.0, 255.0));
    }
  }
}

glm::dmat4 LookAt(const glm::dvec3& eye, const glm::dvec3& target) {
  const glm::dvec3 dir = glm::normalize(target - eye);
  const glm::dvec3 up = std::abs(dir.y) > 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(0, 1, 0);
  return glm::dmat4(core::CamFromWorldLookAt(glm::vec3(eye), glm::vec3(target), glm::vec3(up)));
}

// Pinhole maps around the origin: a ring (raised) or a Fibonacci sphere.
std::vector<ImageMap> PinholeRig(bool sphere, int count, double radius, int size,
                                 std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  std::vector<ImageMap> maps;
  for (int i = 0; i < count; ++i) {
    glm::dvec3 eye;
    if (sphere) {
      const double z = 1 - (2 * i + 1.0) / count, r = std::sqrt(1 - z * z),
                   a = i * 2.399963229728653;
      eye = radius * glm::dvec3(r * std::cos(a), z, r * std::sin(a));
    } else {
      const double a = 2 * M_PI * i / count;
      eye = glm::dvec3(radius * std::cos(a), 0.8 + u(rng), radius * std::sin(a));
    }
    ImageMap m;
    m.name = fmt::format("{}_{}", sphere ? "sphere" : "ring", i);
    const double f = size * std::uniform_real_distribution<double>(0.8, 1.3)(rng);
    m.camera = MapCamera::Pinhole(size, size, f, f, size / 2.0, size / 2.0);
    m.cam_from_world = LookAt(eye, {u(rng) * 0.3, u(rng) * 0.3, u(rng) * 0.3});
    maps.push_back(std::move(m));
  }
  return maps;
}

enum class Boundary { kNone, kDepthOnSlice, kAxisTie };

struct Case {
  MapSet maps;
  ViewCamera view;
  DepthObjectOptions options;
  Boundary boundary = Boundary::kNone;
  std::string description;
};

ViewCamera RandomView(std::mt19937& rng, const glm::dvec3& dir, double distance,
                      bool orthographic) {
  std::uniform_int_distribution<int> size(24, 80);
  const int w = size(rng), h = std::bernoulli_distribution(0.7)(rng) ? w : size(rng);
  ViewCamera v;
  if (orthographic) {
    const double s = std::min(w, h) / (2.0 * std::uniform_real_distribution<double>(1.2, 2.0)(rng));
    v.camera = MapCamera::Orthographic(w, h, s, s, w / 2.0, h / 2.0);
  } else {
    const double f = std::min(w, h) * std::uniform_real_distribution<double>(0.8, 1.8)(rng);
    v.camera = MapCamera::Pinhole(w, h, f, f, w / 2.0, h / 2.0);
  }
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  const glm::dvec3 target(jitter(rng), jitter(rng), jitter(rng));
  v.cam_from_world = LookAt(target + distance * dir, target);
  return v;
}

glm::dvec3 RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  glm::dvec3 v(n(rng), n(rng), n(rng));
  return glm::length(v) > 1e-9 ? glm::normalize(v) : glm::dvec3(0, 0, 1);
}

// Texel noise (depth anywhere in the box), holes (invalid depth) and mask
// flips, so decisions fall on every side of every comparison.
void AddNoise(std::mt19937& rng, ImageMap& m, double amount) {
  std::uniform_real_distribution<float> u(0, 1);
  for (int y = 0; y < m.depth.height(); ++y) {
    for (int x = 0; x < m.depth.width(); ++x) {
      const float r = u(rng);
      if (r < amount * 0.4) {
        m.depth.at(x, y) = 0.0f;
      } else if (r < amount) {
        m.depth.at(x, y) = 5.0f * u(rng);
        m.mask.at(x, y) = 255;
      }
    }
  }
}

// The constructed boundary case (cf. tests/verify/stencil_reference_test): the
// view looks along a cube axis, the map looking the same way gets, for every
// texel a pixel of slice `target` uses, exactly that point's map depth (a
// depth exactly on a slice; target = last: N reached on the last slice); the
// other maps carve nothing (depth 0, invalid depth passes).
void MakeDepthOnSlice(Case& c, std::mt19937& rng) {
  const FrameParams frame = PrepareFrame(c.maps, c.view, c.options);
  const glm::dvec3 axis = CameraAxis(c.view.cam_from_world);
  int facing = -1;
  for (size_t i = 0; i < c.maps.maps.size(); ++i) {
    if (glm::dot(CameraAxis(c.maps.maps[i].cam_from_world), axis) > 0.999)
      facing = static_cast<int>(i);
  }
  IBR_CHECK_GE(facing, 0);
  const int last = static_cast<int>(frame.planes.size()) - 1;
  const int target = std::bernoulli_distribution(0.5)(rng)
                         ? last
                         : std::uniform_int_distribution<int>(0, last)(rng);
  for (size_t i = 0; i < c.maps.maps.size(); ++i) {
    ImageMap& m = c.maps.maps[i];
    m.depth = core::ImageF(m.camera.width, m.camera.height, 1, 0.0f);
    m.mask =
        core::Image8(m.camera.width, m.camera.height, 1, static_cast<int>(i) == facing ? 0 : 255);
  }
  ImageMap& f = c.maps.maps[facing];
  for (int row = 0; row < frame.height; ++row) {
    for (int col = 0; col < frame.width; ++col) {
      const glm::vec2 uv(col + 0.5f, frame.view_height - ((frame.height - 1 - row) + 0.5f));
      const glm::vec3 p = ReferenceViewPointOnPlane(frame, uv, frame.planes[target]);
      glm::vec3 q;
      glm::ivec3 texel;
      // Pixels sharing a texel: the largest depth, so none passes before `target`.
      if (ReferenceMapLookup(frame.maps[facing], p, q, texel) && q.z > 0) {
        float& d = f.depth.at(texel.x, texel.y);
        d = std::max(d, q.z);
        f.mask.at(texel.x, texel.y) = 255;
      }
    }
  }
  c.description +=
      target == last ? " depth-on-last-slice" : fmt::format(" depth-on-slice-{}", target);
}

// `forced`: the boundary kind, or nullopt to draw one (15 % depth on a
// slice, 15 % axis ties, else a general configuration).
Case RandomCase(std::mt19937& rng, const std::string& method_filter,
                std::optional<Boundary> forced = std::nullopt) {
  Case c;
  std::uniform_real_distribution<double> u(0, 1);
  const double kind = u(rng);
  c.boundary = kind < 0.15  ? Boundary::kDepthOnSlice
               : kind < 0.3 ? Boundary::kAxisTie
                            : Boundary::kNone;
  if (forced) c.boundary = *forced;
  // Rig.
  const int map_size = std::uniform_int_distribution<int>(16, 64)(rng);
  const int rig =
      c.boundary == Boundary::kDepthOnSlice ? 0 : std::uniform_int_distribution<int>(0, 2)(rng);
  std::string rig_name;
  if (rig == 0) {
    c.maps.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
    c.maps.maps = CubeRigMaps({0, 0, 0}, 1.0, map_size);
    rig_name = "cube";
  } else {
    const int count = std::uniform_int_distribution<int>(3, 9)(rng);
    const double e = u(rng) * 0.3;
    c.maps.world_from_box = BoxFromBounds({-1 - e, -1, -1 + e}, {1, 1 + e, 1});
    c.maps.maps = PinholeRig(rig == 2, count, 3.0 + u(rng), map_size, rng);
    rig_name = fmt::format("{}:{}", rig == 2 ? "sphere" : "ring", count);
  }
  std::vector<core::Sphere> balls;
  const int nballs = std::uniform_int_distribution<int>(1, 5)(rng);
  for (int i = 0; i < nballs; ++i) {
    balls.push_back({{0.5 * (2 * u(rng) - 1), 0.5 * (2 * u(rng) - 1), 0.5 * (2 * u(rng) - 1)},
                     0.15 + 0.4 * u(rng)});
  }
  const double noise = u(rng) < 0.5 ? 0.0 : 0.2 * u(rng);
  for (ImageMap& m : c.maps.maps) {
    CastBalls(balls, m);
    AddNoise(rng, m, noise);
  }
  // Options.
  DepthObjectOptions& o = c.options;
  const bool hull = method_filter == "hull" || (method_filter == "all" && u(rng) < 0.4);
  o.method = hull ? Method::kVisualHull : Method::kDepthObject;
  o.slicing = u(rng) < 0.5 ? Slicing::kOrthogonal : Slicing::kScreen;
  o.slices = std::uniform_int_distribution<int>(4, 56)(rng);
  const int n = static_cast<int>(c.maps.maps.size());
  const double rk = u(rng);
  o.robust_k = rk < 0.6   ? 0
               : rk < 0.8 ? 1
               : rk < 0.9 ? 2
                          : n + std::uniform_int_distribution<int>(0, 2)(rng);
  o.outside = u(rng) < 0.5 ? OutsidePolicy::kPass : OutsidePolicy::kFail;
  o.invalid_depth = u(rng) < 0.5 ? InvalidDepthPolicy::kEmpty : InvalidDepthPolicy::kNoConstraint;
  o.hull_skip_opposite = u(rng) < 0.8;
  // View.
  bool orthographic = u(rng) < 0.4;
  glm::dvec3 dir = RandomUnit(rng);
  if (c.boundary == Boundary::kDepthOnSlice) {
    const int a = std::uniform_int_distribution<int>(0, 2)(rng);
    dir = glm::dvec3(0);
    dir[a] = u(rng) < 0.5 ? 1 : -1;
    o.method = Method::kDepthObject;
    o.slicing = Slicing::kOrthogonal;
    o.robust_k = 0;
    o.outside = OutsidePolicy::kFail;
    o.invalid_depth = InvalidDepthPolicy::kNoConstraint;
  } else if (c.boundary == Boundary::kAxisTie) {
    // Diagonals: two or three box axes equally parallel to the view.
    const int pattern = std::uniform_int_distribution<int>(0, 3)(rng);
    dir = glm::dvec3(pattern == 1 ? 0 : 1, pattern == 2 ? 0 : 1, pattern == 3 ? 0 : 1);
    for (int k = 0; k < 3; ++k) dir[k] *= u(rng) < 0.5 ? -1 : 1;
    dir = glm::normalize(dir);
    o.slicing = Slicing::kOrthogonal;
    if (rig != 0) c.maps.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  }
  const double distance = orthographic ? 3.0 : 2.4 + 2.5 * u(rng);
  c.view = RandomView(rng, dir, distance, orthographic);
  if (c.boundary != Boundary::kNone) {
    // Exactly along the axis / diagonal through the box centre.
    c.view.cam_from_world = LookAt(distance * dir, {0, 0, 0});
  }
  c.description =
      fmt::format("{} maps {}px, view {}x{} {}, {} {} x{}, k {}, outside {}, invalid {}", rig_name,
                  map_size, c.view.camera.width, c.view.camera.height,
                  orthographic ? "ortho" : "persp", MethodName(o.method), SlicingName(o.slicing),
                  o.slices, o.robust_k, o.outside == OutsidePolicy::kPass ? "pass" : "fail",
                  o.invalid_depth == InvalidDepthPolicy::kEmpty ? "empty" : "pass");
  if (c.boundary == Boundary::kDepthOnSlice) MakeDepthOnSlice(c, rng);
  if (c.boundary == Boundary::kAxisTie) c.description += " axis-tie";
  return c;
}

// ---- the spec's division tolerance ----

// Every float within 2.5 ULP of the exact quotient a / b (GLSL 4.50 sec.
// 4.7.1), ascending; just the IEEE quotient when it is not finite or zero.
std::vector<float> AdmissibleQuotients(float a, float b) {
  const float r0 = a / b;
  const double x = static_cast<double>(a) / static_cast<double>(b);
  if (!std::isfinite(r0) || x == 0) return {r0};
  const double ulp = std::ldexp(1.0, std::ilogb(x) - 23);
  std::vector<float> out;
  for (float r = r0; std::abs(r - x) <= 2.5 * ulp; r = std::nextafter(r, -INFINITY))
    out.insert(out.begin(), r);
  for (float r = std::nextafter(r0, INFINITY); std::abs(r - x) <= 2.5 * ulp;
       r = std::nextafter(r, INFINITY)) {
    out.push_back(r);
  }
  if (out.empty()) out.push_back(r0);
  return out;
}

// Picks the choice[site]-th admissible quotient at each division site.
class ChosenDivision : public ReferenceDivision {
 public:
  int choice[3] = {0, 0, 0};
  float Divide(float a, float b, Site site) const override {
    const std::vector<float> q = AdmissibleQuotients(a, b);
    return q[std::min<size_t>(choice[site], q.size() - 1)];
  }
};

// The outcomes of one fragment's map test under every admissible quotient,
// grouped by what steers the stencil program (accepted, texel); the depth it
// would write is a set, since it never feeds a decision and only the last
// accepted fragment's survives (branching on it would multiply the search).
struct FragmentOutcome {
  bool accept = false;
  glm::ivec3 texel{-1};
  std::vector<float> pz;  // camera z values it may write (accepted only)
};

struct PixelState {
  uint8_t stencil = 0;
  float color[4] = {0, 0, 0, 0};
  const std::vector<float>* depth = nullptr;  // nullptr = (0, 0) written, else (any of these, 1)
};

// The GPU's buffers at one pixel.
struct GpuPixel {
  uint8_t stencil = 0;
  float color[4] = {0, 0, 0, 0};
  float depth[2] = {0, 0};
};

bool SameBits(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }

// Replays one pixel of the stencil algorithm with every admissible division
// result at every fragment and reports whether the GPU's buffers are
// reachable (the stencil program of verify/reference.cc's RenderReference, with
// each map test's outcome a set instead of a value).
class PixelReplay {
 public:
  PixelReplay(const FrameParams& f, const MapTables& t, const ReferenceVariant& v,
              const std::vector<core::Image8>& coverage, int col, int row)
      : f_(f), t_(t), v_(v), uv_(col + 0.5f, f.view_height - ((f.height - 1 - row) + 0.5f)) {
    for (size_t s = 0; s < coverage.size(); ++s) {
      const int times = coverage[s].at(col, row);
      if (times > 0) slices_.push_back({static_cast<int>(s), times});
    }
  }

  enum class Verdict { kReachable, kUnreachable, kUndecided };
  Verdict Run(const GpuPixel& gpu) {
    gpu_ = gpu;
    leaves_ = 0;
    const bool found = Step(0, 0, 0, PixelState{});
    if (found) return Verdict::kReachable;
    return leaves_ > kMaxLeaves ? Verdict::kUndecided : Verdict::kUnreachable;
  }

 private:
  static constexpr int64_t kMaxLeaves = 1 << 16;

  const std::vector<FragmentOutcome>& Outcomes(int s, int j) {
    auto [it, inserted] = cache_.try_emplace({s, j});
    if (!inserted) return it->second;
    const MapRecord& m = f_.maps[f_.active[j]];
    ChosenDivision div;
    for (div.choice[0] = 0; div.choice[0] < 6; ++div.choice[0]) {
      for (div.choice[1] = 0; div.choice[1] < 6; ++div.choice[1]) {
        for (div.choice[2] = 0; div.choice[2] < 6; ++div.choice[2]) {
          const glm::vec3 p = ReferenceViewPointOnPlane(f_, uv_, f_.planes[s], &div);
          glm::ivec3 texel;
          const bool accept = ReferenceMapAccepts(t_, m, v_, p, texel, nullptr, &div);
          if (!accept) texel = glm::ivec3(-1);
          auto same = std::find_if(
              it->second.begin(), it->second.end(),
              [&](const FragmentOutcome& o) { return o.accept == accept && o.texel == texel; });
          if (same == it->second.end())
            same = it->second.insert(it->second.end(), {accept, texel, {}});
          if (accept && std::none_of(same->pz.begin(), same->pz.end(),
                                     [&](float z) { return SameBits(z, p.z); })) {
            same->pz.push_back(p.z);
          }
        }
      }
    }
    return it->second;
  }

  // Slice i (index into slices_), map j, repetition rep.
  bool Step(size_t i, int j, int rep, PixelState st) {
    if (leaves_ > kMaxLeaves) return false;
    const int n = static_cast<int>(f_.active.size());
    if (i == slices_.size()) {
      ++leaves_;
      bool same = st.stencil == gpu_.stencil;
      for (int c = 0; c < 4; ++c) same = same && SameBits(st.color[c], gpu_.color[c]);
      if (st.depth == nullptr) {
        return same && SameBits(gpu_.depth[0], 0.0f) && SameBits(gpu_.depth[1], 0.0f);
      }
      return same && SameBits(gpu_.depth[1], 1.0f) &&
             std::any_of(st.depth->begin(), st.depth->end(),
                         [&](float z) { return SameBits(z, gpu_.depth[0]); });
    }
    const auto [s, times] = slices_[i];
    if (j == n) {
      // Steps (c)-(f).
      const bool clear = f_.robust ? f_.required > st.stencil : st.stencil != n;
      if (clear) {
        st = PixelState{};
      } else if (f_.robust && (st.stencil & 0x80) == 0 && (st.stencil & 0x7F) >= f_.required) {
        st.stencil |= 0x80;
      }
      return Step(i + 1, 0, 0, st);
    }
    const int next_j = rep + 1 < times ? j : j + 1, next_rep = rep + 1 < times ? rep + 1 : 0;
    const bool passes = f_.robust ? (st.stencil & 0x80) == 0 : st.stencil == j;
    if (!passes) return Step(i, next_j, next_rep, st);
    const MapRecord& m = f_.maps[f_.active[j]];
    for (const FragmentOutcome& o : Outcomes(s, j)) {
      PixelState next = st;
      if (o.accept) {
        next.stencil =
            f_.robust
                ? static_cast<uint8_t>((st.stencil & 0x80) | (((st.stencil & 0x7F) + 1) & 0x7F))
                : static_cast<uint8_t>(std::min(st.stencil + 1, 255));
        for (int c = 0; c < 4; ++c) {
          float add = 0;
          if (o.texel.x >= 0 && m.extra.x > 0.0f) {
            const float cc =
                static_cast<float>(t_.color[t_.Index(o.texel.z, o.texel.x, o.texel.y) * 4 + c]) *
                f_.inv255;
            add = cc * m.extra.x;
          }
          next.color[c] = st.color[c] + add;
        }
        next.depth = &o.pz;
      }
      if (Step(i, next_j, next_rep, next)) return true;
    }
    return false;
  }

  const FrameParams& f_;
  const MapTables& t_;
  const ReferenceVariant& v_;
  const glm::vec2 uv_;
  std::vector<std::pair<int, int>> slices_;  // (slice, times covered)
  std::map<std::pair<int, int>, std::vector<FragmentOutcome>> cache_;
  GpuPixel gpu_;
  int64_t leaves_ = 0;
};

// Test-only: what a driver whose view-point division returns the largest
// admissible quotient (about +2 ULP, allowed by GLSL) would write as depth.
void SimulateLooseDivision(const FrameParams& f, const std::vector<core::Image8>& coverage,
                           core::ImageF& depth) {
  ChosenDivision loose;
  loose.choice[ReferenceDivision::kViewPoint] = 5;  // clamped to the largest admissible
  for (int row = 0; row < f.height; ++row) {
    for (int col = 0; col < f.width; ++col) {
      if (depth.at(col, row, 1) == 0) continue;
      const glm::vec2 uv(col + 0.5f, f.view_height - ((f.height - 1 - row) + 0.5f));
      for (size_t s = 0; s < coverage.size(); ++s) {
        if (coverage[s].at(col, row) == 0) continue;
        if (!SameBits(ReferenceViewPointOnPlane(f, uv, f.planes[s]).z, depth.at(col, row, 0)))
          continue;
        depth.at(col, row, 0) = ReferenceViewPointOnPlane(f, uv, f.planes[s], &loose).z;
        break;
      }
    }
  }
}

void Add(VerifyCaseResult& total, const VerifyCaseResult& r) {
  total.pixels += r.pixels;
  total.mismatched += r.mismatched;
  total.permitted += r.permitted;
  total.real_errors += r.real_errors;
  total.undecided += r.undecided;
  total.kinds.stencil += r.kinds.stencil;
  total.kinds.depth += r.kinds.depth;
  total.kinds.color += r.kinds.color;
  total.ties += r.ties;
  total.finished_on_last_slice += r.finished_on_last_slice;
  total.independent.Add(r.independent);
  total.ray.Add(r.ray);
}

VerifyCaseResult VerifyCase(render::ProgramCache& programs, const Case& c,
                            const VerifyOptions& options, int subpixel_bits, int index) {
  VerifyCaseResult r;
  r.index = index;
  r.description = c.description;
  DepthObjectRenderer renderer(programs, c.maps);
  const FrameParams frame = PrepareFrame(renderer.maps(), c.view, c.options);
  render::RenderTarget accum(DepthObjectRenderer::AccumTargetOptions(frame.width, frame.height));
  renderer.DrawSlices(frame, c.options, accum);
  const core::Image8 stencil = accum.ReadStencil();
  const core::ImageF color = accum.ReadColorF(0);
  core::ImageF depth = accum.ReadColorF(1);
  const std::vector<core::Image8> coverage = renderer.SliceCoverage(frame);
  if (options.inject_fault == 2) SimulateLooseDivision(frame, coverage, depth);
  // The mirror's frame (with the test-only fault: each slice evaluated at the next slice's plane).
  FrameParams mirror = frame;
  if (options.inject_fault == 1) {
    for (size_t s = 0; s + 1 < mirror.planes.size(); ++s) mirror.planes[s] = frame.planes[s + 1];
  }
  const MapTables& tables = renderer.tables(c.options.method);
  const ReferenceVariant variant = ReferenceVariant::From(c.options);
  const ReferenceBuffers ref = RenderReference(mirror, tables, variant, coverage);
  r.ties = ref.ties;
  r.finished_on_last_slice = ref.finished_on_last_slice;
  // 0 agree, 1 permitted, 2 real error, 3 undecided.
  core::Image8 verdicts(frame.width, frame.height, 1, 0);
  for (int row = 0; row < frame.height; ++row) {
    for (int col = 0; col < frame.width; ++col) {
      ++r.pixels;
      GpuPixel gpu;
      gpu.stencil = stencil.at(col, row);
      bool st_bad = gpu.stencil != ref.stencil.at(col, row), c_bad = false, d_bad = false;
      for (int k = 0; k < 4; ++k) {
        gpu.color[k] = color.at(col, row, k);
        c_bad = c_bad || !SameBits(gpu.color[k], ref.color.at(col, row, k));
      }
      for (int k = 0; k < 2; ++k) {
        gpu.depth[k] = depth.at(col, row, k);
        d_bad = d_bad || !SameBits(gpu.depth[k], ref.depth.at(col, row, k));
      }
      if (!st_bad && !c_bad && !d_bad) continue;
      ++r.mismatched;
      r.kinds.stencil += st_bad;
      r.kinds.color += c_bad;
      r.kinds.depth += d_bad;
      PixelReplay replay(mirror, tables, variant, coverage, col, row);
      switch (replay.Run(gpu)) {
        case PixelReplay::Verdict::kReachable:
          ++r.permitted, verdicts.at(col, row) = 1;
          break;
        case PixelReplay::Verdict::kUnreachable:
          ++r.real_errors, verdicts.at(col, row) = 2;
          break;
        case PixelReplay::Verdict::kUndecided:
          ++r.undecided, verdicts.at(col, row) = 3;
          break;
      }
    }
  }
  core::Image8 independent_diff;
  if (options.independent && c.options.slicing != Slicing::kRay) {
    IndependentOptions io;
    io.subpixel_bits = subpixel_bits;
    io.tie_axis = frame.stack.axis;
    const IndependentFrame ind = RenderIndependent(renderer.maps(), c.view, c.options, io);
    const IndependentComparison ic = CompareWithIndependent(ind, stencil, color, depth);
    r.independent = ic;
    independent_diff = std::move(r.independent.diff);
    r.independent.diff = {};
    // The ray path on the same case (empty-space skipping on every other case).
    DepthObjectOptions ray_options = c.options;
    ray_options.slicing = Slicing::kRay;
    ray_options.skip_grid = index % 2 == 0 ? 64 : 0;
    const FrameParams ray_frame = PrepareFrame(renderer.maps(), c.view, ray_options);
    render::RenderTarget ray_accum(
        DepthObjectRenderer::AccumTargetOptions(ray_frame.width, ray_frame.height));
    renderer.DrawRay(ray_frame, ray_options, ray_accum);
    const IndependentFrame ray_ref = RenderIndependent(renderer.maps(), c.view, ray_options, io);
    const IndependentComparison rc =
        CompareWithIndependent(ray_ref, {}, ray_accum.ReadColorF(0), ray_accum.ReadColorF(1));
    r.ray = rc;
    r.ray.diff = {};
    if (rc.real_errors > 0 && !options.out.empty()) {
      std::filesystem::create_directories(options.out);
      const std::string name = fmt::format("case_{:05d}_ray_diff.png", index);
      core::WriteImage(options.out / name, rc.diff);
      r.diff_images.push_back((options.out / name).string());
    }
  }
  if (!options.out.empty() && (r.real_errors > 0 || r.independent.real_errors > 0)) {
    // RGB diff: red = real error (mirror), yellow = permitted, magenta =
    // undecided, blue = independent disagreement outside the band, grey = in it.
    core::Image8 diff(frame.width, frame.height, 3, 0);
    for (int row = 0; row < frame.height; ++row) {
      for (int col = 0; col < frame.width; ++col) {
        static constexpr uint8_t kColours[4][3] = {
            {0, 0, 0}, {255, 255, 0}, {255, 0, 0}, {255, 0, 255}};
        const uint8_t* rgb = kColours[verdicts.at(col, row)];
        if (!independent_diff.empty() && verdicts.at(col, row) == 0) {
          static constexpr uint8_t kBlue[3] = {0, 0, 255}, kGrey[3] = {96, 96, 96};
          if (independent_diff.at(col, row) == 255) rgb = kBlue;
          if (independent_diff.at(col, row) == 128) rgb = kGrey;
        }
        for (int k = 0; k < 3; ++k) diff.at(col, row, k) = rgb[k];
      }
    }
    std::filesystem::create_directories(options.out);
    const std::string stem = fmt::format("case_{:05d}", index);
    core::WriteImage(options.out / (stem + "_diff.png"), diff);
    core::WriteImage(options.out / (stem + "_gpu_stencil.png"), stencil);
    core::WriteImage(options.out / (stem + "_cpu_stencil.png"), ref.stencil);
    r.diff_images.push_back((options.out / (stem + "_diff.png")).string());
  }
  return r;
}

}  // namespace

VerifyReport RunVerify(render::ProgramCache& programs, const VerifyOptions& options,
                       const std::function<void(const VerifyCaseResult&)>& on_case) {
  options.Check();
  VerifyReport report;
  report.driver = render::CurrentDriverName();
  const int subpixel_bits = render::CurrentSubpixelBits();
  const auto start = std::chrono::steady_clock::now();
  std::mt19937 rng(options.seed);
  for (int i = 0; i < options.first_case; ++i) rng();  // the cases before the first
  for (int i = options.first_case; i < options.first_case + options.cases; ++i) {
    // One generator per case, seeded from the run's: case i is the same
    // whatever ran before it (--first-case i --cases 1 reruns it alone).
    std::mt19937 case_rng(rng());
    const Case c = RandomCase(case_rng, options.method);
    const VerifyCaseResult r = VerifyCase(programs, c, options, subpixel_bits, i);
    Add(report.total, r);
    report.failing_cases +=
        r.real_errors > 0 || r.independent.real_errors > 0 || r.ray.real_errors > 0;
    report.boundary_cases[0] += c.boundary == Boundary::kDepthOnSlice && r.ties > 0;
    report.boundary_cases[1] += r.finished_on_last_slice > 0;
    report.boundary_cases[2] += c.boundary == Boundary::kAxisTie;
    ++report.cases;
    if (on_case) on_case(r);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace ibr

// ======================= hard-case sweeps =======================

namespace ibr {
namespace {

// Every world point p becomes scale p + offset: maps, box and view (rigid
// poses absorb the offset; camera z and orthographic scales absorb the scale).
void TransformScene(Case& c, double scale, const glm::dvec3& offset) {
  const glm::dmat4 w =
      glm::translate(glm::dmat4(1.0), offset) * glm::scale(glm::dmat4(1.0), glm::dvec3(scale));
  c.maps.world_from_box = w * c.maps.world_from_box;
  auto pose = [&](glm::dmat4& cam_from_world, MapCamera& cam) {
    const glm::dmat3 r(cam_from_world);
    const glm::dvec3 t = scale * glm::dvec3(cam_from_world[3]) - r * offset;
    cam_from_world[3] = glm::dvec4(t, 1.0);
    if (cam.orthographic) {
      cam.fx /= scale;
      cam.fy /= scale;
    }
  };
  for (ImageMap& m : c.maps.maps) {
    pose(m.cam_from_world, m.camera);
    for (float& d : m.depth.values()) d = static_cast<float>(d * scale);
  }
  pose(c.view.cam_from_world, c.view.camera);
}

// The view at another pixel size (same field of view).
void ResizeView(ViewCamera& v, int w, int h) {
  const double sx = static_cast<double>(w) / v.camera.width,
               sy = static_cast<double>(h) / v.camera.height;
  const double s = std::min(sx, sy);
  v.camera.fx *= s;
  v.camera.fy *= s;
  v.camera.cx = w / 2.0;
  v.camera.cy = h / 2.0;
  v.camera.width = w;
  v.camera.height = h;
}

// A unit direction with component `axis` equal to `along` (0: in the
// plane of that axis's faces: edge-on; tiny: grazing).
glm::dvec3 DirectionNearPlane(std::mt19937& rng, int axis, double along) {
  const double a = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
  glm::dvec3 d(0);
  d[(axis + 1) % 3] = std::cos(a);
  d[(axis + 2) % 3] = std::sin(a);
  d[axis] = along;
  return glm::normalize(d);
}

struct Tally {
  HardTechniqueResult result;
  std::map<std::string, std::pair<int, int>> kinds;  // cases, failing cases
  std::string current;                               // the kind of the case being checked
  int index = 0;                                     // the case's index (--first-case)
  std::vector<int> failing;                          // indices of failing cases (first 20)
  std::vector<std::string> failing_descriptions;     // ... with what they drew
  std::string description;                           // the current case's configuration
  std::map<std::string, int64_t> reasons;            // inconsistent pixels by rule broken
  int64_t bad = 0;                                   // in the current case
  void Start(const std::string& kind) {
    current = kind;
    description.clear();
    ++kinds[kind].first;
    bad = 0;
  }
  void Inconsistent(const std::string& reason) {
    ++result.inconsistent;
    ++bad;
    ++reasons[fmt::format("{} ({})", reason, current)];
  }
  void NonFinite() {
    ++result.nonfinite;
    ++bad;
    ++reasons[fmt::format("NaN/Inf ({})", current)];
  }
  void EndCase() {
    ++result.cases;
    result.failing_cases += bad > 0;
    kinds[current].second += bad > 0;
    if (bad > 0 && failing.size() < 20) {
      failing.push_back(index);
      failing_descriptions.push_back(fmt::format("case {}: {} ({} pixels)", index,
                                                 description.empty() ? current : description, bad));
    }
  }
  void Finish() {
    for (const auto& [k, n] : kinds) {
      result.kinds.push_back(fmt::format("{}: {} cases, {} failing", k, n.first, n.second));
    }
    for (const auto& [k, n] : reasons)
      result.kinds.push_back(fmt::format("inconsistent: {}: {} pixels", k, n));
    for (const std::string& d : failing_descriptions) result.kinds.push_back(d);
    if (!failing.empty())
      result.kinds.push_back(fmt::format(
          "failing cases (rerun one with --first-case I --cases 1): {}", fmt::join(failing, " ")));
  }
};

const char* const kObjectKinds[] = {
    "grazing",        "edge-on",    "eye-inside", "coincident-maps", "opposite-maps", "pole",
    "depth-on-slice", "scale-1e-6", "scale-1e6",  "far-offset-1e6",  "empty-maps",    "single-map"};

// One degenerate depth-object / visual-hull configuration, rendered in full
// (slices or ray + resolve); every depth finite, the coverage mask and the
// depth consistent, uncovered pixels the background, covered depths inside
// the box's camera-z range.
void HardObjectCase(render::ProgramCache& programs, std::mt19937& rng, Method method, int index,
                    Tally& tally) {
  const int nk = static_cast<int>(std::size(kObjectKinds));
  const std::string kind = kObjectKinds[index % nk];
  std::uniform_real_distribution<double> u(0, 1);
  const std::string filter = method == Method::kDepthObject ? "depth-object" : "hull";
  Case c = RandomCase(rng, filter,
                      kind == "depth-on-slice" ? std::optional(Boundary::kDepthOnSlice)
                                               : std::optional(Boundary::kNone));
  DepthObjectOptions& o = c.options;
  o.method = method;
  if (kind != "depth-on-slice") {
    const double r = u(rng);
    o.slicing = r < 0.4 ? Slicing::kOrthogonal : r < 0.8 ? Slicing::kScreen : Slicing::kRay;
  }
  o.texturing = static_cast<Texturing>(std::uniform_int_distribution<int>(0, 2)(rng));
  o.refine_steps = std::uniform_int_distribution<int>(0, 8)(rng);
  const bool ortho = c.view.camera.orthographic;
  const double dist = ortho ? 3.0 : 2.5 + 2 * u(rng);
  if (kind == "grazing" || kind == "edge-on") {
    const glm::dvec3 d =
        DirectionNearPlane(rng, std::uniform_int_distribution<int>(0, 2)(rng),
                           kind == "edge-on" ? 0.0 : std::pow(10.0, -2 - 5 * u(rng)));
    // Edge-on through a box face's plane: the eye on the face plane's line.
    const glm::dvec3 target = kind == "edge-on" ? glm::dvec3(0) : glm::dvec3(0.3 * u(rng), 0, 0);
    c.view.cam_from_world = LookAt(target + dist * d, target);
  } else if (kind == "eye-inside") {
    const MapCamera old = c.view.camera;
    const double f = old.width * (0.5 + u(rng));
    c.view.camera =
        MapCamera::Pinhole(old.width, old.height, f, f, old.width / 2.0, old.height / 2.0);
    const glm::dvec3 eye(0.9 * (2 * u(rng) - 1), 0.9 * (2 * u(rng) - 1), 0.9 * (2 * u(rng) - 1));
    c.view.cam_from_world = LookAt(eye, eye + RandomUnit(rng));
  } else if (kind == "coincident-maps") {
    const ImageMap copy = c.maps.maps[0];
    c.maps.maps.push_back(copy);
  } else if (kind == "opposite-maps") {
    // A map at the mirrored position looking back (the cube rig's pairs, for any rig).
    ImageMap m = c.maps.maps[0];
    const glm::dvec3 centre = CameraCentre(m.cam_from_world), axis = CameraAxis(m.cam_from_world);
    const glm::dvec3 eye = m.camera.orthographic ? centre + 2.0 * axis : -centre;
    m.cam_from_world = LookAt(eye, eye - axis);
    c.maps.maps.push_back(m);
    o.hull_skip_opposite = u(rng) < 0.5;
  } else if (kind == "pole") {
    const double sign = u(rng) < 0.5 ? 1 : -1;
    c.view.cam_from_world = LookAt({0, sign * dist, 0}, {0, 0, 0});
  } else if (kind == "scale-1e-6" || kind == "scale-1e6") {
    TransformScene(c, kind == "scale-1e-6" ? 1e-6 : 1e6, glm::dvec3(0));
  } else if (kind == "far-offset-1e6") {
    TransformScene(c, 1.0, 2e6 * RandomUnit(rng));
  } else if (kind == "empty-maps") {
    for (ImageMap& m : c.maps.maps) m.mask = core::Image8(m.camera.width, m.camera.height, 1, 0);
  } else if (kind == "single-map") {
    c.maps.maps.resize(1);
  }
  const int w = std::uniform_int_distribution<int>(32, 64)(rng);
  ResizeView(c.view, w, u(rng) < 0.7 ? w : std::uniform_int_distribution<int>(32, 64)(rng));
  tally.Start(kind);
  tally.description = fmt::format("{} {}, {} {} x{}, k {}, refine {}, view {}", kind, c.description,
                                  SlicingName(o.slicing), TexturingName(o.texturing), o.slices,
                                  o.robust_k, o.refine_steps, ortho ? "ortho" : "persp");
  DepthObjectRenderer renderer(programs, c.maps);
  const render::Frame frame = renderer.RenderFrame(c.view, o);
  // Camera-z range of the box (orthographic views: the whole range is valid).
  const glm::dmat4 cam_from_box = c.view.cam_from_world * c.maps.world_from_box;
  double zmin = INFINITY, zmax = -INFINITY;
  for (int i = 0; i < 8; ++i) {
    const double z = (cam_from_box * glm::dvec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0)).z;
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  // The resolve pass refines between the finishing slice and the one before,
  // whose point on a grazing ray may lie outside the box: allow one box depth.
  const double slack = (zmax - zmin) + 1e-4 * std::max(std::abs(zmin), std::abs(zmax));
  HardTechniqueResult& r = tally.result;
  for (int y = 0; y < frame.depth.height(); ++y) {
    for (int x = 0; x < frame.depth.width(); ++x) {
      ++r.pixels;
      const float z = frame.depth.at(x, y);
      const bool covered = frame.Covered(x, y);
      if (!std::isfinite(z)) {
        tally.NonFinite();
        continue;
      }
      r.covered += covered;
      if (covered && !(z >= zmin - slack && z <= zmax + slack))
        tally.Inconsistent("depth outside the box");
      if (covered && !ortho && !(z > 0)) tally.Inconsistent("depth behind the eye");
      if (!covered && z != 0) tally.Inconsistent("depth without coverage");
      bool background = true;
      for (int k = 0; k < 4; ++k) background = background && frame.color.at(x, y, k) == 0;
      if (!covered && !background) tally.Inconsistent("colour without coverage");
    }
  }
  tally.EndCase();
}

core::TriangleMesh HardBaseMesh(std::mt19937& rng, int shape, bool zero_area_faces) {
  std::uniform_int_distribution<int> k(3, 8);
  core::TriangleMesh m = shape == 0   ? core::MakePlane(1.0f, k(rng) / 2)
                         : shape == 1 ? core::MakeSphere(1.0f, k(rng), 2 * k(rng))
                                      : core::MakeTorus(0.8f, 0.3f, 2 * k(rng), k(rng));
  if (zero_area_faces) {
    // Degenerate triangles: a repeated vertex and three collinear vertices
    // (the midpoint of an edge appended as a new vertex).
    const uint32_t a = m.indices[0], b = m.indices[1];
    m.positions.push_back(0.5f * (m.positions[a] + m.positions[b]));
    m.normals.push_back(glm::normalize(m.normals[a] + m.normals[b] + glm::vec3(0, 0, 1e-3f)));
    m.uvs.push_back(0.5f * (m.uvs[a] + m.uvs[b]));
    const uint32_t mid = static_cast<uint32_t>(m.positions.size() - 1);
    for (uint32_t i : {a, a, b, a, mid, b}) m.indices.push_back(i);
  }
  return m;
}

const char* const kSurfaceKinds[] = {
    "grazing",           "edge-on",    "eye-inside", "pole",           "zero-area-faces",
    "heights-on-slices", "scale-1e-6", "scale-1e6",  "far-offset-1e6", "random"};

struct SurfaceCase {
  std::string kind;
  int shape = 0;  // 0 plane (z = 0, normal +z), 1 sphere (poles on z), 2 torus
  core::TriangleMesh base;
  double scale = 1;
  glm::dvec3 offset{0};
  render::ViewSetup view;
  int width = 32, height = 32;
  float max_displacement = 0.2f;
  core::ImageF height_map;
  bool orthographic = false;
  glm::dvec3 eye{0}, target{0};
};

// A degenerate view of a displaced surface (displacement pass or ray passes).
SurfaceCase RandomSurfaceCase(std::mt19937& rng, int index) {
  std::uniform_real_distribution<double> u(0, 1);
  SurfaceCase c;
  c.kind = kSurfaceKinds[index % std::size(kSurfaceKinds)];
  c.shape = c.kind == "pole" ? 1 : std::uniform_int_distribution<int>(0, 2)(rng);
  c.base = HardBaseMesh(rng, c.shape, c.kind == "zero-area-faces");
  c.max_displacement = static_cast<float>(0.02 + 0.3 * u(rng));
  core::HeightMapOptions h;
  h.size = 32;
  h.seed = static_cast<uint32_t>(rng());
  h.pattern = static_cast<core::HeightPattern>(std::uniform_int_distribution<int>(0, 5)(rng));
  h.level = static_cast<float>(u(rng) < 0.3 ? 1.0 : 0.2 + 0.8 * u(rng));
  if (c.kind == "heights-on-slices") {
    h.pattern = core::HeightPattern::kConstant;
    h.level = static_cast<float>(std::uniform_int_distribution<int>(0, 8)(rng)) /
              8;  // on slice planes of 8, 16, ...
  }
  c.height_map = core::MakeHeightMap(h);
  c.orthographic = u(rng) < 0.3;
  c.width = std::uniform_int_distribution<int>(32, 64)(rng);
  c.height = u(rng) < 0.7 ? c.width : std::uniform_int_distribution<int>(32, 64)(rng);
  const double dist = 2.5 + 2 * u(rng);
  glm::dvec3 dir = RandomUnit(rng);
  c.target = glm::dvec3(0.2 * (2 * u(rng) - 1), 0.2 * (2 * u(rng) - 1), 0);
  if (c.kind == "grazing" || c.kind == "edge-on") {
    // In (or just above) the base plane z = 0 of the plane, the equator of the others.
    dir = DirectionNearPlane(rng, 2, c.kind == "edge-on" ? 0.0 : std::pow(10.0, -2 - 5 * u(rng)));
    if (c.kind == "edge-on") c.target = glm::dvec3(0);
  } else if (c.kind == "pole") {
    dir = glm::dvec3(0, 0, u(rng) < 0.5 ? 1 : -1);
    c.target = glm::dvec3(0);
  }
  c.eye = c.target + dist * dir;
  if (c.kind == "eye-inside") {
    // Between the base and the shell: above the plane / outside the sphere's
    // or torus's surface by a fraction of the displacement.
    const double f = 0.5 * c.max_displacement;
    c.orthographic = false;
    if (c.shape == 0) {
      c.eye = glm::dvec3(0.5 * (2 * u(rng) - 1), 0.5 * (2 * u(rng) - 1), f);
    } else if (c.shape == 1) {
      c.eye = (1.0 + f) * RandomUnit(rng);
    } else {
      const double a = 2 * M_PI * u(rng);
      c.eye = glm::dvec3((0.8 + 0.3 + f) * std::cos(a), (0.8 + 0.3 + f) * std::sin(a), 0);
    }
    c.target = c.eye + RandomUnit(rng);
  }
  if (c.kind == "scale-1e-6") c.scale = 1e-6;
  if (c.kind == "scale-1e6") c.scale = 1e6;
  if (c.kind == "far-offset-1e6") c.offset = 2e6 * RandomUnit(rng);
  // World = scale * object + offset; the camera follows.
  const glm::dvec3 eye_w = c.scale * c.eye + c.offset, target_w = c.scale * c.target + c.offset;
  const glm::dmat4 cam_from_world = LookAt(eye_w, target_w);
  c.view.cam_from_world = glm::mat4(cam_from_world);
  c.view.orthographic = c.orthographic;
  // Beyond every displaced point and every point a march may stop at:
  // relief / POM march up to l = md / min_view_cos = 50 shell thicknesses,
  // CRM up to 2 l = 100,
  // NCS up to c l (Algorithm 2: num_step steps of c l / num_step, c =
  // step_enlargement <= 3.5 here), 175. A hit beyond the far plane is
  // clipped (window depth 1 fails LESS), flagged and rightly not drawn: with
  // the earlier 60 that was the cause of NCS's "hit not drawn" pixels (4
  // cases of 1000, grazing rays bent far along the shell).
  const double reach = c.scale * (glm::length(c.eye) + 2.0 + 200.0 * c.max_displacement);
  // The near plane as before the far one grew (it clips views from inside the shell).
  const double near = 1e-4 * c.scale * (glm::length(c.eye) + 2.0 + 60.0 * c.max_displacement);
  if (c.orthographic) {
    const double s = std::min(c.width, c.height) / (2.0 * c.scale * (1.5 + u(rng)));
    c.view.clip_from_cam = core::ClipFromCamOrthographic(s, s, c.width / 2.0, c.height / 2.0,
                                                         c.width, c.height, -reach, reach);
  } else {
    const double f = std::min(c.width, c.height) * (0.6 + u(rng));
    c.view.clip_from_cam = core::ClipFromCamPerspective(f, f, c.width / 2.0, c.height / 2.0,
                                                        c.width, c.height, near, reach);
  }
  return c;
}

glm::mat4 WorldFromObject(const SurfaceCase& c) {
  return glm::mat4(glm::translate(glm::dmat4(1.0), c.offset) *
                   glm::scale(glm::dmat4(1.0), glm::dvec3(c.scale)));
}

// Colour alpha 255 <=> a non-zero depth was written. Ray passes (`flags`):
// only the ray core's outcome bits; NCS and CRM (`carves`) draw exactly the
// pixels with a hit (early terminations and exits are discarded); relief and POM draw
// wherever the march stopped (any outcome) and discard only back-facing
// fragments (marked exited), so a drawn pixel has an outcome and a hit or an
// early termination is always drawn.
void CheckSurfaceFrame(Tally& tally, const render::Frame& frame, bool ray_pass, bool carves) {
  const core::ImageF& depth = frame.depth;
  const core::ImageF* normal = &frame.normal;
  const core::Image<uint32_t>* flags = ray_pass ? &frame.outcome : nullptr;
  HardTechniqueResult& r = tally.result;
  const uint32_t hit = 1u << static_cast<int>(render::RayOutcome::kHit);
  const uint32_t exited = 1u << static_cast<int>(render::RayOutcome::kExited);
  const uint32_t early = 1u << static_cast<int>(render::RayOutcome::kEarlyTermination);
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      ++r.pixels;
      const float z = depth.at(x, y);
      bool finite = std::isfinite(z);
      if (normal != nullptr) {
        for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(normal->at(x, y, k));
      }
      if (!finite) {
        tally.NonFinite();
        continue;
      }
      const bool covered = frame.Covered(x, y);
      r.covered += covered;
      if (covered != (z != 0))
        tally.Inconsistent(covered ? "drawn with depth 0" : "depth without coverage");
      if (flags == nullptr) continue;
      const uint32_t f = flags->at(x, y);
      if ((f & ~(hit | exited | early)) != 0) tally.Inconsistent("unknown outcome bits");
      if (carves) {
        if (covered && (f & hit) == 0) tally.Inconsistent("drawn without a hit");
        if (!covered && (f & hit) != 0) tally.Inconsistent("hit not drawn");
      } else {
        if (covered && f == 0) tally.Inconsistent("drawn without an outcome");
        if (!covered && (f & (hit | early)) != 0)
          tally.Inconsistent("hit / early termination not drawn");
      }
    }
  }
  tally.EndCase();
}

void HardDisplacementCase(render::ProgramCache& programs, std::mt19937& rng, int index,
                          Tally& tally) {
  SurfaceCase c = RandomSurfaceCase(rng, index);
  std::uniform_real_distribution<double> u(0, 1);
  tally.Start(c.kind);
  // The pass has no object transform: scale and offset the mesh itself.
  for (glm::vec3& p : c.base.positions) p = glm::vec3(c.scale * glm::dvec3(p) + c.offset);
  render::DisplacementPassOptions o;
  o.max_displacement = static_cast<float>(c.scale * c.max_displacement);
  o.tiling = static_cast<float>(1 + std::uniform_int_distribution<int>(0, 2)(rng));
  const double fam = u(rng);
  o.slicing.family = fam < 0.33   ? render::SliceFamily::kSurfaceAligned
                     : fam < 0.66 ? render::SliceFamily::kOrthogonal
                                  : render::SliceFamily::kScreen;
  o.slicing.count = c.kind == "heights-on-slices"
                        ? 8 * std::uniform_int_distribution<int>(1, 4)(rng)
                        : std::uniform_int_distribution<int>(1, 40)(rng);
  o.slicing.full_size_screen_slices = u(rng) < 0.3;
  render::DisplacementTextureOptions t;
  t.internal_format = u(rng) < 0.5 ? GL_RGBA8 : GL_RGBA32F;
  t.linear_filter = u(rng) < 0.5;
  const render::Texture texture =
      render::UploadDisplacementTexture(render::MakeDisplacementTexels(c.height_map), t);
  render::DisplacementPass pass(programs, c.base, texture, o);
  const render::Frame frame = render::RenderFrame(pass, c.view, c.width, c.height);
  CheckSurfaceFrame(tally, frame, false, false);
}

void HardReliefCase(render::ProgramCache& programs, std::mt19937& rng, render::ReliefMethod method,
                    int index, Tally& tally) {
  const SurfaceCase c = RandomSurfaceCase(rng, index);
  std::uniform_real_distribution<double> u(0, 1);
  tally.Start(c.kind);
  render::ReliefGeometryOptions g;
  g.max_displacement = c.max_displacement;
  g.tangent_maps.size = 32;
  g.tangent_maps.wrap_u = c.shape != 0;
  g.tangent_maps.wrap_v = c.shape == 2;
  g.height_bilinear = u(rng) < 0.5;
  render::ReliefSurface surface(programs, c.base, c.height_map, g);
  render::ReliefSurfaceOptions o;
  o.method = method;
  o.steps = std::uniform_int_distribution<int>(1, 48)(rng);
  o.refine_steps = std::uniform_int_distribution<int>(0, 8)(rng);
  o.pom_min_steps = std::uniform_int_distribution<int>(1, o.steps)(rng);
  o.step_enlargement = static_cast<float>(0.5 + 3 * u(rng));
  o.tiling = static_cast<float>(1 + std::uniform_int_distribution<int>(0, 2)(rng));
  // min_view_cos stays at its default: far smaller caps (1e-6) let relief,
  // POM and NCS stop rays thousands of shell thicknesses away, beyond any far
  // plane, so a pixel flagged "hit" is not drawn (the frame's contract holds
  // only with a far plane that contains the march).
  o.step_policy = u(rng) < 0.5 ? render::RayStepPolicy::kFixed : render::RayStepPolicy::kThreshold;
  o.world_from_object = WorldFromObject(c);
  const render::Frame frame = surface.Render(c.view, c.width, c.height, o);
  CheckSurfaceFrame(tally, frame, true,
                    method == render::ReliefMethod::kNcs || method == render::ReliefMethod::kCrm);
}

}  // namespace

bool HardReport::ok() const {
  for (const HardTechniqueResult& t : techniques) {
    if (t.nonfinite > 0 || t.inconsistent > 0) return false;
  }
  return true;
}

HardReport RunHardSweeps(render::ProgramCache& programs, VerifyOptions options,
                         const std::function<void(const std::string&)>& progress) {
  options.hard = true;
  options.Check();
  HardReport report;
  const auto start = std::chrono::steady_clock::now();
  // Each technique's generator comes from the seed and its place in the full
  // list, so `--method ncs` draws the same cases as `--method all`.
  // CRM came last, so the earlier techniques kept their seeds.
  const std::vector<std::string> all = {"depth-object", "hull", "displacement", "ncs",
                                        "relief",       "pom",  "crm"};
  std::mt19937 seeds(options.seed);
  std::vector<uint32_t> technique_seeds;
  for (size_t i = 0; i < all.size(); ++i) technique_seeds.push_back(seeds());
  for (size_t ti = 0; ti < all.size(); ++ti) {
    const std::string& name = all[ti];
    if (options.method != "all" && options.method != name) continue;
    const auto technique_start = std::chrono::steady_clock::now();
    Tally tally;
    tally.result.technique = name;
    std::mt19937 rng(technique_seeds[ti]);
    for (int i = 0; i < options.first_case; ++i) rng();  // the cases before the first
    for (int i = options.first_case; i < options.first_case + options.cases; ++i) {
      std::mt19937 case_rng(rng());
      tally.index = i;
      if (name == "depth-object" || name == "hull") {
        HardObjectCase(programs, case_rng,
                       name == "hull" ? Method::kVisualHull : Method::kDepthObject, i, tally);
      } else if (name == "displacement") {
        HardDisplacementCase(programs, case_rng, i, tally);
      } else {
        HardReliefCase(programs, case_rng, render::ReliefMethodFromName(name), i, tally);
      }
      const int done = i + 1 - options.first_case;
      if (progress && (done % 100 == 0 || done == options.cases)) {
        progress(fmt::format("hard {}: {}/{} cases, {} NaN/Inf, {} inconsistent pixels", name, done,
                             options.cases, tally.result.nonfinite, tally.result.inconsistent));
      }
    }
    tally.Finish();
    tally.result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - technique_start).count();
    report.techniques.push_back(tally.result);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace ibr
