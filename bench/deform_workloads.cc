// The workloads of `ibr bench deform` that issue 35 asked for
// (bench/deform_bench.h): the wedge cut-away with real volume, the
// forward-mesh peer and the spread across tessellations of one shape.
#include <fmt/format.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <unordered_map>

#include "bench/deform_bench.h"
#include "bench/paper_tables.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/look_at.h"
#include "core/memory_budget.h"
#include "core/metrics.h"
#include "render/gl/frame_timer.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/mesh_pass.h"

namespace bench {

std::string DeformWedgeFigures::Line() const {
  return fmt::format(
      "wedge: cut_skip/baseline {:.2f}, skip removes {:.0f} % of the cut's extra samples, ray "
      "fraction {:.2f}",
      ratio, skip_removes_percent, ray_fraction);
}

std::string DeformForwardFigures::Line() const {
  if (equal_level < 0) {
    return fmt::format(
        "forward-mesh: no subdivision level run reaches the ray pass's p95 depth error {:.5f} "
        "({:.1f} ms)",
        ray_p95, ray_ms);
  }
  const bool ray_wins = ray_ms < equal_ms;
  return fmt::format(
      "forward-mesh: at the ray pass's p95 depth error {:.5f} ({:.1f} ms) the forward mesh "
      "needs level {} ({} triangles, p95 {:.5f}): {:.1f} ms ({:.1f} ms at that error, "
      "log-log between levels); {} wins by {:.2f}x",
      ray_p95, ray_ms, equal_level, equal_triangles, equal_p95, equal_ms, interpolated_ms,
      ray_wins ? "the ray pass" : "the forward mesh",
      ray_wins ? equal_ms / ray_ms : ray_ms / equal_ms);
}

std::string DeformSpreadFigures::Line() const {
  return fmt::format(
      "spread: ray stage max/min over tessellations {:.3f}, mesh stage / plain mesh pass at "
      "most {:.3f} ({} interleaved rounds)",
      ray_spread, mesh_over_plain_max, rounds);
}

const DeformPullFigures::Policy* DeformPullFigures::Find(const std::string& name) const {
  for (const Policy& p : policies)
    if (p.name == name) return &p;
  return nullptr;
}

std::string DeformPullFigures::Line() const {
  std::string counts, samples;
  int64_t compared = 0;
  for (const Policy& p : policies) {
    counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", p.name, p.misses);
    samples += fmt::format("{}{} {:.1f}", samples.empty() ? "" : ", ", p.name, p.samples_per_ray);
    compared = std::max(compared, p.compared);
  }
  return fmt::format(
      "narrow pull (Fig. 3): rays that miss the pulled column: {} of {} compared pixels (samples "
      "per ray: {})",
      counts, compared, samples);
}

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

core::Box3d MeshBox(const core::TriangleMesh& mesh) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return {glm::dvec3(lo), glm::dvec3(hi)};
}

double Median(std::vector<double> v) { return core::Median(std::move(v)); }

// Per-round ratios a[i] / b[i]: their median and 95 % interval.
core::MedianInterval RatioInterval(const std::vector<double>& a, const std::vector<double>& b,
                                   double* median) {
  std::vector<double> r;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) r.push_back(b[i] > 0 ? a[i] / b[i] : NAN);
  *median = Median(r);
  return core::MedianConfidenceInterval(r);
}

// One timed measurement of a round: `frames` frames after none of warm-up
// (every pass drew once before the rounds), the median.
double TimeRound(const std::function<void()>& draw, int frames) {
  render::FrameTimerOptions timer;
  timer.warmup_frames = 0;
  timer.timed_frames = frames;
  return render::TimeFrames(draw, timer).median_ms;
}

// Interleaved rounds over `draws` (round r starts at draw r mod n, so slow
// phases of a shared machine fall on every draw alike); ms[draw][round].
std::vector<std::vector<double>> InterleavedRounds(const std::vector<std::function<void()>>& draws,
                                                   int rounds, int frames) {
  for (const auto& draw : draws) TimeRound(draw, 1);  // shader compilation, uploads
  std::vector<std::vector<double>> ms(draws.size());
  for (int r = 0; r < rounds; ++r) {
    for (size_t k = 0; k < draws.size(); ++k) {
      const size_t d = (k + r) % draws.size();
      ms[d].push_back(TimeRound(draws[d], frames));
    }
  }
  return ms;
}

// An empty row of the frames table, its columns by name.
struct FrameRow {
  const Table& table;
  std::vector<std::string> cells;
  explicit FrameRow(const Table& t) : table(t), cells(t.columns().size()) {}
  FrameRow& Set(const std::string& column, std::string value) {
    cells[table.Column(column)] = std::move(value);
    return *this;
  }
};

// The outcome columns of a deform pass frame.
void SetOutcomes(FrameRow& row, const DeformOutcomes& o, bool rejects) {
  row.Set("samples_per_ray", Num(o.mean_samples, 2))
      .Set("rejected_per_ray", Num(o.mean_rejected, 3));
  if (rejects && o.rays > 0)
    row.Set("cut_ray_fraction", Num(double(o.rejecting_rays) / double(o.rays), 4));
}

// The share of cast rays of `frame` (a frame without the cut) whose hit lies
// where the cut alpha is > 0: the rays that meet the cut's material.
double CutHitFraction(const render::Frame& frame, const DeformPinholeView& view,
                      const core::DeformationSum& deformation, const core::Placement& placement) {
  const glm::dmat4 world_from_cam = glm::inverse(view.cam_from_world);
  const int n = view.size;
  int64_t rays = 0, cut = 0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      if ((frame.outcome.at(x, y) >> render::kDeformSamplesShift) == 0) continue;
      ++rays;
      const double z = frame.depth.at(x, y);
      if (!(z > 0)) continue;
      const glm::dvec3 p_cam((x + 0.5 - n / 2.0) / view.focal_px * z,
                             (y + 0.5 - n / 2.0) / view.focal_px * z, z);
      const glm::dvec3 p = glm::dvec3(world_from_cam * glm::dvec4(p_cam, 1.0));
      cut += core::DeformObjectPoint(deformation, placement, p).w > 0.0;
    }
  }
  return rays > 0 ? double(cut) / double(rays) : NAN;
}

// Spot normalised, in a box enclosing it (AroundMesh), and its exact distance.
struct SpotInBox {
  explicit SpotInBox(const DeformBenchOptions& options)
      : file(options.shared_data / "meshes" / "spot.obj"),
        mesh(LoadNormalisedMesh(file)),
        placement(AroundMesh(mesh)),
        distance(mesh, false, file.string()) {}
  std::filesystem::path file;
  core::TriangleMesh mesh;
  core::Placement placement;
  core::MeshDistance distance;
};

}  // namespace

// Spot (normalised) in a box enclosing it (grown by 0.05), a wedge of 150
// degrees about the box's z axis opened towards +x, its floor at z = 0.1,
// seen from the orbit view at azimuth 90 degrees (on +x, looking into the
// opening): rays that meet the cut march through the removed material to its
// faces, the paper's case of a large cut. The opening and the view set the
// share of the box's rays that meet the cut's material (some of the box's
// rays miss the object altogether).
constexpr double kWedgeAzimuthDeg = 90.0;
namespace {

// A mode of the wedge's sweep, as the sweep's Table 1 modes.
struct WedgeMode {
  std::string name;
  bool cut, skip, search, skip_object;
  // The cut's shader (CutMode::kSolid) even without the cut's alpha.
  bool SolidShader() const { return cut || search; }
};

// The paper's search without and with the cut's skipping, our CSG field; the
// paper_* modes without the skipping by the object's distance (the paper's
// own shader).
std::vector<WedgeMode> WedgeModes() {
  return {{"baseline", false, false, false, true},
          {"cut", true, false, true, true},
          {"cut_skip", true, true, true, true},
          {"cut_csg", true, false, false, true},
          {"paper_baseline", false, false, false, false},
          {"paper_cut", true, false, true, false},
          {"paper_cut_skip", true, true, true, false},
          // Why cut_skip costs more than its samples: its shader (the search,
          // the reject tests, the cut's skip) on the baseline's texture without
          // alpha, so the same rays and samples as the baseline.
          {"cut_skip_shader_no_cut", false, true, true, true}};
}

// One wedge mode's frame against the reference: its row of `frames`, its
// progress line, and (cut_skip) the figures of `fig`.
DeformOutcomes MeasureWedgeMode(const render::Frame& frame, const DeformReferenceFrame& truth,
                                const WedgeMode& mode, const std::vector<double>& ms, int size,
                                size_t triangles, DeformWedgeFigures& fig, Table& frames) {
  const DeformOutcomes outcomes = CountDeformOutcomes(frame);
  const core::ViewMetrics metrics = core::CompareDepth(frame.depth, truth.depth, 1.0);
  // The baselines draw the uncut object: their truth is another picture.
  const bool cut = mode.cut;
  const DeformClassAgreement agree = CompareDeformClasses(frame, truth);
  FrameRow row(frames);
  row.Set("workload", "wedge")
      .Set("mesh", fig.mesh)
      .Set("triangles", std::to_string(triangles))
      .Set("mode", mode.name)
      .Set("series", fig.mesh + " wedge " + mode.name)
      .Set("region_scale", Num(1.0, 2))
      .Set("area_fraction", Num(double(outcomes.rays) / (double(size) * size), 4))
      .Set("ms", Num(Median(ms), 2))
      .Set("ray_ms", Num(Median(ms), 2))  // the box holds the object: no mesh stage
      .Set("mesh_ms", Num(0.0, 2));
  SetOutcomes(row, outcomes, mode.search);
  if (cut) {
    row.Set("p95_depth_error", Num(metrics.depth.p95, 6))
        .Set("agree_fraction", Num(agree.Fraction(), 5));
  }
  frames.AddRow(row.cells);
  if (mode.name == "cut_skip") {
    fig.agree_fraction = agree.Fraction();
    fig.p95_depth_error = metrics.depth.p95;
    fig.ray_fraction =
        outcomes.rays > 0 ? double(outcomes.rejecting_rays) / double(outcomes.rays) : NAN;
  }
  std::fprintf(
      stderr,
      "bench deform: wedge %s: %.2f ms, %.2f samples and %.3f rejected crossings per "
      "ray%s\n",
      mode.name.c_str(), Median(ms), outcomes.mean_samples, outcomes.mean_rejected,
      cut ? fmt::format(", {:.2f} % of pixels agree with the reference", 100.0 * agree.Fraction())
                .c_str()
          : "");
  return outcomes;
}

}  // namespace

DeformWedgeFigures RunDeformWedge(render::ProgramCache& programs, const DeformBenchOptions& options,
                                  int size, int field_resolution, Table& frames) {
  DeformWedgeFigures fig;
  fig.mesh = "spot";
  const SpotInBox spot(options);
  const auto& [file, mesh, placement, distance] = spot;
  core::Deformation wedge;
  wedge.kind = core::DeformationKind::kWedge;
  wedge.amount = fig.opening_rad = 5.0 * M_PI / 6.0;
  wedge.width = fig.bottom = 0.1;
  const core::DeformationSum deformation{{wedge}};
  const core::DeformationTexture texture = core::SampleDeformation(deformation, 64);
  // The baseline: the same D (zero) without its alpha.
  core::DeformationTexture no_alpha = texture;
  for (size_t i = 3; i < no_alpha.rgba.size(); i += 4) no_alpha.rgba[i] = -1.0f;
  const core::DistanceField sdf =
      DeformDistanceField(distance, placement.ObjectBounds(), 0.0, field_resolution);
  const DeformPinholeView view = DeformOrbitView(size, kWedgeAzimuthDeg, 20.0);
  const render::ViewSetup setup = view.Setup();

  const auto traced = Clock::now();
  const core::DeformReference reference(distance, deformation, placement, core::CutMode::kSolid,
                                        0.0);
  const DeformReferenceFrame truth = TraceDeformReference(reference, placement, view);
  std::fprintf(stderr, "bench deform: wedge: the double reference at %d px in %.1f s\n", size,
               SecondsSince(traced));

  const std::vector<WedgeMode> modes = WedgeModes();
  render::RenderTarget target(render::FrameTargetOptions(size, size));
  std::vector<std::unique_ptr<render::DeformPass>> passes;
  std::vector<std::function<void()>> draws;
  for (const WedgeMode& m : modes) {
    render::DeformPassOptions o;
    o.cut = m.SolidShader() ? core::CutMode::kSolid : core::CutMode::kNone;
    o.skip_empty = m.skip;
    o.solid_search = m.search;
    o.skip_object = m.skip_object;
    passes.push_back(std::make_unique<render::DeformPass>(
        programs, render::DeformInputs{&mesh, &sdf, m.cut ? &texture : &no_alpha, placement}, o));
    render::DeformPass* pass = passes.back().get();
    draws.push_back([&target, pass, &setup] { render::DrawFrame(target, *pass, setup); });
  }
  const int rounds = options.quick ? 6 : 15;
  const auto ms = InterleavedRounds(draws, rounds, options.quick ? 1 : 3);
  std::vector<DeformOutcomes> outcomes;
  render::Frame baseline_frame;
  for (size_t k = 0; k < modes.size(); ++k) {
    draws[k]();
    render::Frame frame = render::ReadFrame(target);
    outcomes.push_back(
        MeasureWedgeMode(frame, truth, modes[k], ms[k], size, mesh.triangle_count(), fig, frames));
    if (modes[k].name == "baseline") baseline_frame = std::move(frame);
  }
  fig.ray_fraction_cpu = CutHitFraction(baseline_frame, view, deformation, placement);
  const core::MedianInterval ci = RatioInterval(ms[2], ms[0], &fig.ratio);
  fig.ratio_lo = ci.lo, fig.ratio_hi = ci.hi;
  RatioInterval(ms[3], ms[0], &fig.csg_ratio);
  RatioInterval(ms[6], ms[4], &fig.paper_ratio);
  RatioInterval(ms[7], ms[0], &fig.shader_overhead);
  fig.samples_baseline = outcomes[0].mean_samples;
  fig.samples_cut = outcomes[1].mean_samples;
  fig.samples_skip = outcomes[2].mean_samples;
  fig.skip_removes_percent =
      100.0 * (fig.samples_cut - fig.samples_skip) / (fig.samples_cut - fig.samples_baseline);
  std::fprintf(stderr,
               "bench deform: wedge: cut_skip/baseline %.3f (95 %% interval %.3f-%.3f, %d "
               "rounds), cut_csg/baseline %.3f; samples per ray %.2f baseline, %.2f cut, %.2f "
               "cut_skip; rays meeting the cut %.4f (CPU, from the baseline's hits: %.4f); the "
               "paper's shader (no object skip): paper_cut_skip/paper_baseline %.3f; the "
               "cut_skip shader without the cut / baseline (same samples) %.3f\n",
               fig.ratio, fig.ratio_lo, fig.ratio_hi, rounds, fig.csg_ratio, fig.samples_baseline,
               fig.samples_cut, fig.samples_skip, fig.ray_fraction, fig.ray_fraction_cpu,
               fig.paper_ratio, fig.shader_overhead);
  return fig;
}

Table RunDeformNarrowPull(render::ProgramCache& programs, int size, DeformPullFigures& figures) {
  // The scene of Fig. 3 on a flat top: a box mesh whose top face lies at
  // box z = 0.58 of the deformation box [-0.5, 0.5]^3, pulled up along +z by
  // a Gaussian of amplitude 0.5 (Fig. 3's) and width 0.015 (box units) into
  // a column thinner than a step that leaves through the box's top face
  // (where 1 - 0.5 g(r) < 0.58: r < 0.6 width); the pull vanishes on the
  // box's bottom face. With the column's tip inside the box instead, the
  // 128^3 deformation texture blunts the tip (two texels a width), which
  // the analytic reference does not: misses of every policy there.
  core::TriangleMesh mesh = core::MakeBox(glm::vec3(0.45f, 0.45f, 0.3f));
  for (glm::vec3& p : mesh.positions) p.z -= 0.22f;  // top face at box z 0.58
  core::Deformation pull;
  pull.kind = core::DeformationKind::kPull;
  pull.amount = 0.5;
  pull.width = 0.015;
  const core::DeformationSum deformation{{pull}};
  const core::Placement placement =
      core::Placement::FromRegion({{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}});
  const core::MeshDistance distance(mesh, false, "box");
  constexpr int kFieldResolution = 64;  // the base step: one voxel of this field
  const double grow = core::MaxObjectDisplacement(deformation, placement, 128);
  core::DistanceFieldOptions field_options;
  field_options.resolution = kFieldResolution;
  const core::DistanceField sdf = core::BuildDistanceField(
      distance, placement.ObjectBounds().Grown(grow + 0.02), field_options);
  const core::DeformationTexture texture = core::SampleDeformation(deformation, 128);
  // Seen from the side, zoomed onto the spike's upper half (its tip is
  // thinner than one step there): 2.6 away, a field of view of about 9
  // degrees at any size.
  DeformPinholeView view;
  view.size = size;
  view.focal_px = 6.25 * size;
  view.cam_from_world =
      core::CamFromWorldLookAtDouble({2.4, 0.9, 0.35}, {0.0, 0.0, 0.33}, {0.0, 0.0, 1.0});
  const render::ViewSetup setup = view.Setup();
  const core::DeformReference reference(distance, deformation, placement, core::CutMode::kNone,
                                        0.0);
  const DeformReferenceFrame truth = TraceDeformReference(reference, placement, view);

  Table table({"policy", "size_px", "field_resolution", "step_voxels", "misses", "wrong_pixels",
               "compared_pixels", "samples_per_ray", "ms_per_frame"});
  figures.policies.clear();
  render::RenderTarget target(render::FrameTargetOptions(size, size));
  for (const render::RayStepPolicy policy :
       {render::RayStepPolicy::kFixed, render::RayStepPolicy::kThreshold,
        render::RayStepPolicy::kJacobian}) {
    render::DeformPassOptions o;
    o.step_policy = policy;
    o.threshold = 0.04f;  // Fig. 3(c)'s thresh = 0.04
    o.step_voxels = 1.0f;
    o.draw_mesh = false;  // the box holds the spike: the rays alone
    render::DeformPass pass(programs, render::DeformInputs{&mesh, &sdf, &texture, placement}, o);
    render::FrameTimerOptions timer;
    timer.warmup_frames = 1;
    timer.timed_frames = 3;
    const double ms =
        render::TimeFrames([&] { render::DrawFrame(target, pass, setup); }, timer).median_ms;
    const render::Frame frame = render::ReadFrame(target);
    // Class agreement and misses outside the reference's one-pixel band
    // (CompareDeformClasses' rule).
    DeformPullFigures::Policy p;
    p.name = render::RayStepPolicyName(policy);
    p.ms = ms;
    const DeformClassAgreement agree = CompareDeformClasses(frame, truth);
    p.compared = agree.compared;
    p.wrong = agree.compared - agree.agree;
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const int c = truth.classes.at(x, y, 0);
        if (c == 0 || frame.Covered(x, y)) continue;
        bool band = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            band |= truth.classes.at(std::clamp(x + dx, 0, size - 1),
                                     std::clamp(y + dy, 0, size - 1), 0) != c;
        p.misses += !band;
      }
    }
    p.samples_per_ray = CountDeformOutcomes(frame).mean_samples;
    table.AddRow({p.name, std::to_string(size), std::to_string(kFieldResolution), Num(1.0, 2),
                  std::to_string(p.misses), std::to_string(p.wrong), std::to_string(p.compared),
                  Num(p.samples_per_ray, 2), Num(ms, 2)});
    std::fprintf(stderr,
                 "bench deform: narrow pull, %s: %lld rays miss, %lld of %lld pixels wrong, %.1f "
                 "samples per ray, %.2f ms\n",
                 p.name.c_str(), static_cast<long long>(p.misses), static_cast<long long>(p.wrong),
                 static_cast<long long>(p.compared), p.samples_per_ray, ms);
    figures.policies.push_back(p);
  }
  return table;
}

// Midpoint subdivision, 1:4 (new vertices at the edges' midpoints, shared
// between the two triangles of an edge): the same flat surface, four times
// the triangles.
core::TriangleMesh SubdivideMidpoint(const core::TriangleMesh& mesh) {
  const size_t triangles = mesh.triangle_count();
  // Positions grow by at most one per edge (3 per triangle), indices 4x.
  core::CheckMemory((mesh.positions.size() + 3 * triangles) * sizeof(glm::vec3) +
                        12 * triangles * sizeof(uint32_t) + 3 * triangles * 16,
                    "ibr bench deform", "a subdivided mesh");
  core::TriangleMesh out;
  out.positions = mesh.positions;
  out.indices.reserve(12 * triangles);
  std::unordered_map<uint64_t, uint32_t> midpoint;
  midpoint.reserve(3 * triangles);
  const auto mid = [&](uint32_t a, uint32_t b) {
    const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    auto [it, inserted] = midpoint.emplace(key, static_cast<uint32_t>(out.positions.size()));
    if (inserted) out.positions.push_back(0.5f * (mesh.positions[a] + mesh.positions[b]));
    return it->second;
  };
  for (size_t t = 0; t < triangles; ++t) {
    const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1],
                   c = mesh.indices[3 * t + 2];
    const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    for (uint32_t i : {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca}) out.indices.push_back(i);
  }
  return out;
}

// The forward map of one deformation applied to every vertex inside the box
// (outside, D = 0): p' = M T(M^-1 p).
void DeformVertices(core::TriangleMesh& mesh, const core::Deformation& deformation,
                    const core::Placement& placement) {
  const glm::dmat4 box_from_object = placement.BoxFromObject();
  for (glm::vec3& p : mesh.positions) {
    const glm::dvec3 u(box_from_object * glm::dvec4(glm::dvec3(p), 1.0));
    if (glm::any(glm::lessThan(u, glm::dvec3(0.0))) ||
        glm::any(glm::greaterThan(u, glm::dvec3(1.0))))
      continue;
    p = glm::vec3(placement.object_from_box * glm::dvec4(deformation.Forward(u), 1.0));
  }
  core::SetAreaWeightedNormals(mesh);
}

DeformForwardFigures RunDeformForwardMesh(render::ProgramCache& programs,
                                          const DeformBenchOptions& options, int size,
                                          int field_resolution, Table& frames) {
  DeformForwardFigures fig;
  fig.mesh = "spot";
  // The box encloses the object (the twist vanishes on every face but the
  // top: none meets it); the sweep's continuous twist.
  const SpotInBox spot(options);
  const auto& [file, mesh, placement, distance] = spot;
  core::Deformation twist;
  twist.kind = core::DeformationKind::kTwist, twist.amount = 2.0, twist.width = 0.35;
  const core::DeformationSum deformation{{twist}};
  const core::DeformationTexture texture = core::SampleDeformation(deformation, 64);
  const double grow = core::MaxObjectDisplacement(deformation, placement, 32);
  const core::DistanceField sdf =
      DeformDistanceField(distance, placement.ObjectBounds(), grow, field_resolution);
  const DeformPinholeView view = DeformOrbitView(size);
  const render::ViewSetup setup = view.Setup();
  const auto traced = Clock::now();
  const core::DeformReference reference(distance, deformation, placement, core::CutMode::kNone,
                                        0.0);
  const DeformReferenceFrame truth = TraceDeformReference(reference, placement, view);
  std::fprintf(stderr, "bench deform: forward-mesh: the double reference at %d px in %.1f s\n",
               size, SecondsSince(traced));

  render::RenderTarget target(render::FrameTargetOptions(size, size));
  render::DeformPass ray(programs, {&mesh, &sdf, &texture, placement}, render::DeformPassOptions{});
  std::vector<std::function<void()>> draws = {[&] { render::DrawFrame(target, ray, setup); }};
  const int levels = options.quick ? 3 : 4;  // 0 .. levels - 1
  std::vector<core::TriangleMesh> deformed;
  core::TriangleMesh level = mesh;
  for (int l = 0; l < levels; ++l) {
    if (l > 0) level = SubdivideMidpoint(level);
    deformed.push_back(level);
    DeformVertices(deformed.back(), twist, placement);
  }
  std::vector<std::unique_ptr<render::GpuMesh>> gpu;
  std::vector<std::unique_ptr<render::MeshPass>> mesh_passes;
  for (const core::TriangleMesh& m : deformed) {
    gpu.push_back(std::make_unique<render::GpuMesh>(m));
    mesh_passes.push_back(std::make_unique<render::MeshPass>(programs, *gpu.back()));
    render::MeshPass* pass = mesh_passes.back().get();
    draws.push_back([&target, pass, &setup] { render::DrawFrame(target, *pass, setup); });
  }
  const int rounds = options.quick ? 3 : 9;
  const auto ms = InterleavedRounds(draws, rounds, options.quick ? 1 : 3);
  std::vector<std::pair<double, double>> mesh_points;  // (p95, ms) per level
  for (size_t k = 0; k < draws.size(); ++k) {
    draws[k]();
    const render::Frame frame = render::ReadFrame(target);
    const core::ViewMetrics metrics = core::CompareDepth(frame.depth, truth.depth, 1.0);
    const DeformClassAgreement agree = CompareDeformClasses(frame, truth);
    const bool is_ray = k == 0;
    const int l = static_cast<int>(k) - 1;
    const int64_t triangles =
        int64_t(is_ray ? mesh.triangle_count() : deformed[l].triangle_count());
    const std::string mode = is_ray ? "continuous" : "forward-mesh";
    FrameRow row(frames);
    row.Set("workload", "forward")
        .Set("mesh", fig.mesh)
        .Set("triangles", std::to_string(triangles))
        .Set("mode", mode)
        .Set("series", is_ray ? fig.mesh + " forward continuous"
                              : fmt::format("{} forward-mesh level {}", fig.mesh, l))
        .Set("region_scale", Num(1.0, 2))
        .Set("ms", Num(Median(ms[k]), 2))
        .Set("p95_depth_error", Num(metrics.depth.p95, 6))
        .Set("agree_fraction", Num(agree.Fraction(), 5));
    if (is_ray) {
      const DeformOutcomes o = CountDeformOutcomes(frame);
      row.Set("area_fraction", Num(double(o.rays) / (double(size) * size), 4))
          .Set("ray_ms", Num(Median(ms[k]), 2))
          .Set("mesh_ms", Num(0.0, 2));
      SetOutcomes(row, o, false);
      fig.ray_ms = Median(ms[k]);
      fig.ray_p95 = metrics.depth.p95;
    } else {
      mesh_points.emplace_back(metrics.depth.p95, Median(ms[k]));
    }
    if (!is_ray && fig.equal_level < 0 && metrics.depth.p95 <= fig.ray_p95) {
      fig.equal_level = l;
      fig.equal_triangles = triangles;
      fig.equal_ms = Median(ms[k]);
      fig.equal_p95 = metrics.depth.p95;
    }
    frames.AddRow(row.cells);
    std::fprintf(stderr,
                 "bench deform: forward %s (%lld triangles): %.2f ms, p95 depth error %.5f, "
                 "%.2f %% of pixels agree with the reference\n",
                 is_ray ? "ray pass" : fmt::format("mesh level {}", l).c_str(),
                 static_cast<long long>(triangles), Median(ms[k]), metrics.depth.p95,
                 100.0 * agree.Fraction());
  }
  fig.interpolated_ms = Interpolate(mesh_points, fig.ray_p95, /*log=*/true);
  return fig;
}

namespace {

// meshoptimizer's simplifier down to about `triangles` triangles (borders
// locked: the closed mesh has none), vertices compacted.
core::TriangleMesh Simplified(const core::TriangleMesh& mesh, size_t triangles) {
  if (triangles >= mesh.triangle_count()) return mesh;
  std::vector<uint32_t> indices(mesh.indices.size());
  const size_t count =
      meshopt_simplify(indices.data(), mesh.indices.data(), mesh.indices.size(),
                       &mesh.positions[0].x, mesh.positions.size(), sizeof(glm::vec3),
                       3 * triangles, /*target_error=*/1.0f, meshopt_SimplifyLockBorder, nullptr);
  indices.resize(count);
  core::TriangleMesh out;
  std::vector<uint32_t> remap(mesh.positions.size(), UINT32_MAX);
  for (uint32_t& i : indices) {
    if (remap[i] == UINT32_MAX) {
      remap[i] = static_cast<uint32_t>(out.positions.size());
      out.positions.push_back(mesh.positions[i]);
    }
    i = remap[i];
  }
  out.indices = std::move(indices);
  core::SetAreaWeightedNormals(out);
  return out;
}

// Every triangle split 1:4 at its edge midpoints, `levels` times: the same
// surface point for point with 4^levels as many triangles (CGAL's Loop or
// sqrt(3) subdivision would also smooth it, another shape: the spread
// measures triangle count at a fixed shape). Normals interpolated.
core::TriangleMesh MidpointSubdivided(core::TriangleMesh mesh, int levels) {
  for (int level = 0; level < levels; ++level) {
    std::unordered_map<uint64_t, uint32_t> midpoint;
    auto mid = [&](uint32_t a, uint32_t b) {
      const uint64_t key = (uint64_t{std::min(a, b)} << 32) | std::max(a, b);
      const auto [it, added] = midpoint.try_emplace(key, uint32_t(mesh.positions.size()));
      if (added) {
        mesh.positions.push_back(0.5f * (mesh.positions[a] + mesh.positions[b]));
        if (!mesh.normals.empty())
          mesh.normals.push_back(glm::normalize(mesh.normals[a] + mesh.normals[b]));
      }
      return it->second;
    };
    std::vector<uint32_t> indices;
    indices.reserve(4 * mesh.indices.size());
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
      const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      indices.insert(indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    mesh.indices = std::move(indices);
  }
  mesh.uvs.clear();
  return mesh;
}

}  // namespace

Table RunDeformSpread(render::ProgramCache& programs, const DeformBenchOptions& options, int size,
                      int field_resolution, DeformSpreadFigures& fig) {
  Table table({"mesh", "triangles", "rounds", "ray_ms", "ray_over_scan", "ray_over_scan_lo",
               "ray_over_scan_hi", "mesh_stage_ms", "plain_mesh_ms", "mesh_over_plain",
               "mesh_over_plain_lo", "mesh_over_plain_hi", "samples_per_ray"});
  const std::filesystem::path file = options.shared_data / "meshes" / "stanford-bunny.obj";
  const core::TriangleMesh open = LoadNormalisedMesh(file);
  // The capped, welded bunny: what the deform pass draws and the field of.
  const core::MeshDistance capped_distance(open, true, file.string());
  const core::TriangleMesh& scan = capped_distance.closed_mesh();
  const core::Box3d bounds = MeshBox(scan);
  // Sec. 3's placement of a twist (zero on every face but the top, z = 1):
  // the top and the sides beyond the object, the bottom across its middle.
  core::Box3d region = bounds.Grown(0.05);
  region.lo.z = 0.5 * (bounds.lo.z + bounds.hi.z);
  const core::Placement placement = core::Placement::FromRegion(region);
  core::Deformation twist;
  twist.kind = core::DeformationKind::kTwist, twist.amount = 2.0, twist.width = 0.35;
  const core::DeformationSum deformation{{twist}};
  const core::DeformationTexture texture = core::SampleDeformation(deformation, 64);
  const double grow = core::MaxObjectDisplacement(deformation, placement, 32);
  const DeformPinholeView view = DeformOrbitView(size);
  const render::ViewSetup setup = view.Setup();
  render::RenderTarget target(render::FrameTargetOptions(size, size));

  struct Tessellation {
    std::string name;
    core::TriangleMesh mesh;
    std::unique_ptr<core::MeshDistance> distance;
    core::DistanceField sdf;
    std::unique_ptr<render::DeformPass> full, ray, mesh_stage;
    std::unique_ptr<render::GpuMesh> gpu;
    std::unique_ptr<render::MeshPass> plain;
  };
  std::vector<Tessellation> meshes;
  // Simplified down to 6k-35k, the bunny itself (0), and (full sweep) split
  // up to about Table 1's dragon (871k triangles) and beyond: 16 x 70k.
  std::vector<int64_t> tessellations = {6000, 18000, 35000, 0};
  if (!options.quick) tessellations.push_back(-2);  // two midpoint splits
  for (const int64_t target_triangles : tessellations) {
    Tessellation t;
    const auto built = Clock::now();
    const core::TriangleMesh simplified =
        target_triangles == 0  ? scan
        : target_triangles < 0 ? MidpointSubdivided(scan, static_cast<int>(-target_triangles))
                               : Simplified(scan, static_cast<size_t>(target_triangles));
    t.name = fmt::format("bunny-capped {}k", (simplified.triangle_count() + 500) / 1000);
    // The simplifier may open a few edges (collapses meeting at a seam):
    // capped again, and the capped mesh is the one drawn, as ibr deform does.
    t.distance = std::make_unique<core::MeshDistance>(simplified, true, t.name);
    t.mesh = t.distance->closed_mesh();
    if (t.mesh.normals.size() != t.mesh.positions.size()) core::SetAreaWeightedNormals(t.mesh);
    t.sdf = DeformDistanceField(*t.distance, placement.ObjectBounds(), grow, field_resolution);
    std::fprintf(stderr, "bench deform: spread %s: %zu triangles, field %d in %.1f s\n",
                 t.name.c_str(), t.mesh.triangle_count(), field_resolution, SecondsSince(built));
    meshes.push_back(std::move(t));
  }
  std::vector<std::function<void()>> draws;
  for (Tessellation& t : meshes) {
    const render::DeformInputs inputs{&t.mesh, &t.sdf, &texture, placement};
    render::DeformPassOptions ray_only, mesh_only;
    ray_only.draw_mesh = false;
    mesh_only.draw_rays = false;
    t.full = std::make_unique<render::DeformPass>(programs, inputs, render::DeformPassOptions{});
    t.ray = std::make_unique<render::DeformPass>(programs, inputs, ray_only);
    t.mesh_stage = std::make_unique<render::DeformPass>(programs, inputs, mesh_only);
    t.gpu = std::make_unique<render::GpuMesh>(t.mesh);
    t.plain = std::make_unique<render::MeshPass>(programs, *t.gpu);
    for (render::Pass* pass :
         {static_cast<render::Pass*>(t.full.get()), static_cast<render::Pass*>(t.ray.get()),
          static_cast<render::Pass*>(t.mesh_stage.get()),
          static_cast<render::Pass*>(t.plain.get())}) {
      draws.push_back([&target, pass, &setup] { render::DrawFrame(target, *pass, setup); });
    }
  }
  // At least 6 rounds: the fewest with a 95 % interval of the median.
  fig.rounds = options.quick ? 6 : 15;
  const auto ms = InterleavedRounds(draws, fig.rounds, options.quick ? 1 : 3);
  const size_t scan_index = 3;  // the bunny as scanned
  std::vector<double> ray_ratios, mesh_ratios;
  for (size_t m = 0; m < meshes.size(); ++m) {
    // The mesh stage timed by itself (draw_rays off), not as the frame minus
    // its ray stage: that difference of two ~50 ms frames buried a ~5 ms
    // stage in their noise.
    const auto &ray = ms[4 * m + 1], &stage = ms[4 * m + 2], &plain = ms[4 * m + 3];
    double ray_ratio = NAN, mesh_ratio = NAN;
    const core::MedianInterval ray_ci = RatioInterval(ray, ms[4 * scan_index + 1], &ray_ratio);
    const core::MedianInterval mesh_ci = RatioInterval(stage, plain, &mesh_ratio);
    render::DrawFrame(target, *meshes[m].ray, setup);
    const DeformOutcomes o = CountDeformOutcomes(render::ReadFrame(target));
    ray_ratios.push_back(ray_ratio);
    mesh_ratios.push_back(mesh_ratio);
    table.AddRow({meshes[m].name, std::to_string(meshes[m].mesh.triangle_count()),
                  std::to_string(fig.rounds), Num(Median(ray), 2), Num(ray_ratio, 3),
                  Num(ray_ci.lo, 3), Num(ray_ci.hi, 3), Num(Median(stage), 2),
                  Num(Median(plain), 2), Num(mesh_ratio, 3), Num(mesh_ci.lo, 3), Num(mesh_ci.hi, 3),
                  Num(o.mean_samples, 2)});
    std::fprintf(stderr,
                 "bench deform: spread %s: ray stage %.2f ms (%.3f of the scanned bunny's, 95 %% "
                 "interval %.3f-%.3f), mesh stage %.2f ms over a plain mesh pass %.2f ms: %.3f "
                 "(%.3f-%.3f), %.2f samples per ray\n",
                 meshes[m].name.c_str(), Median(ray), ray_ratio, ray_ci.lo, ray_ci.hi,
                 Median(stage), Median(plain), mesh_ratio, mesh_ci.lo, mesh_ci.hi, o.mean_samples);
  }
  // Over the per-round ratios' medians (the scanned bunny's is 1): the spread of
  // the ray stage with the machine's drift divided out round by round.
  const auto [lo, hi] = std::minmax_element(ray_ratios.begin(), ray_ratios.end());
  fig.ray_spread = *lo > 0 ? *hi / *lo : NAN;
  fig.mesh_over_plain_max = *std::max_element(mesh_ratios.begin(), mesh_ratios.end());
  fig.min_triangles = meshes.front().mesh.triangle_count();
  fig.max_triangles = meshes.back().mesh.triangle_count();
  return table;
}

}  // namespace bench
