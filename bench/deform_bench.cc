#include "bench/deform_bench.h"

#include <fmt/format.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <optional>
#include <sstream>

#include "bench/openvdb_sdf.h"
#include "bench/paper_tables.h"
#include "bench/peer.h"
#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/look_at.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "ibr/dataset_maps.h"
#include "ibr/views.h"
#include "render/gl/frame_timer.h"

namespace bench {

core::Deformation KnifeCut() {
  core::Deformation knife;
  knife.kind = core::DeformationKind::kKnife, knife.amount = 0.15, knife.width = 0.6;
  return knife;
}

core::TriangleMesh LoadNormalisedMesh(const std::filesystem::path& mesh_file) {
  core::TriangleMesh mesh = capture::LoadSceneMesh(mesh_file).mesh;
  ibr::NormaliseMesh(mesh);
  return mesh;
}

core::Placement AroundMesh(const core::TriangleMesh& mesh) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return core::Placement::FromRegion(core::Box3d{glm::dvec3(lo), glm::dvec3(hi)}.Grown(0.05));
}

KnifeCutScene::KnifeCutScene(const std::filesystem::path& mesh_file)
    : mesh(LoadNormalisedMesh(mesh_file)),
      placement(AroundMesh(mesh)),
      deformation{{KnifeCut()}},
      distance(mesh, false, mesh_file.string()),
      grow(core::MaxObjectDisplacement(deformation, placement, 32)),
      texture(core::SampleDeformation(deformation, 64)) {}

render::DeformInputs KnifeCutScene::Inputs(const core::DistanceField& sdf) const {
  return {&mesh, &sdf, &texture, placement};
}

core::DeformReference KnifeCutScene::Reference() const {
  return core::DeformReference(distance, deformation, placement, core::CutMode::kSolid, 0.0);
}

core::DistanceField DeformDistanceField(const core::MeshDistance& distance, const core::Box3d& box,
                                        double grow, int resolution) {
  core::DistanceFieldOptions sdf_options;
  sdf_options.resolution = resolution;
  return core::BuildDistanceField(
      distance, box.Grown(grow + 2.0 * glm::length(box.size()) / resolution), sdf_options);
}

render::ViewSetup DeformPinholeView::Setup() const {
  render::ViewSetup view;
  view.cam_from_world = glm::mat4(cam_from_world);
  view.clip_from_cam = core::ClipFromCamPerspective(focal_px, focal_px, size / 2.0, size / 2.0,
                                                    size, size, 0.05, 10.0);
  return view;
}

DeformPinholeView DeformObliqueView(int size) { return DeformOrbitView(size, -50.0, 35.0, 2.4); }

DeformReferenceFrame TraceDeformReference(const core::DeformReference& reference,
                                          const core::Placement& placement,
                                          const DeformPinholeView& view) {
  const int n = view.size;
  const glm::dmat4 world_from_cam = glm::inverse(view.cam_from_world);
  const glm::dvec3 eye(world_from_cam[3]);
  const glm::dmat4 box_from_object = placement.BoxFromObject();
  const glm::dvec3 o(box_from_object * glm::dvec4(eye, 1));
  DeformReferenceFrame out{core::ImageF(n, n, 1, 0.0f), core::Image8(n, n, 4, 0),
                           core::Image8(n, n, 1, 0)};
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const glm::dvec3 d_cam((x + 0.5 - n / 2.0) / view.focal_px,
                             (y + 0.5 - n / 2.0) / view.focal_px, 1.0);
      const glm::dvec3 dir = glm::normalize(glm::dmat3(world_from_cam) * d_cam);
      const glm::dvec3 d = glm::dmat3(box_from_object) * dir;
      // The ray's interval in the box [0, 1]^3 (slab test).
      double t0 = 0, t1 = 1e30;
      for (int a = 0; a < 3; ++a) {
        const double ta = (0 - o[a]) / d[a], tb = (1 - o[a]) / d[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
      }
      if (!(t0 < t1)) continue;
      const core::DeformReferenceHit hit = reference.Trace(eye, dir, t0, t1);
      if (!hit.hit) continue;
      out.classes.at(x, y, 0) = hit.cut_face ? 2 : 1;
      out.depth.at(x, y, 0) =
          static_cast<float>((view.cam_from_world * glm::dvec4(eye + hit.t * dir, 1.0)).z);
      // Head-light shading of the reference normal (cut faces tinted).
      const double shade = 0.25 + 0.75 * std::abs(glm::dot(hit.normal, dir));
      const glm::dvec3 base = hit.cut_face ? glm::dvec3(0.95, 0.75, 0.55) : glm::dvec3(0.8);
      for (int c = 0; c < 3; ++c)
        out.color.at(x, y, c) = static_cast<uint8_t>(std::lround(255 * shade * base[c]));
      out.color.at(x, y, 3) = 255;
    }
  }
  return out;
}

DeformPinholeView DeformOrbitView(int size, double azimuth_deg, double elevation_deg,
                                  double distance) {
  // The product's one orbit (ibr::OrbitCameraView: azimuth about +y from +z).
  const ibr::ViewCamera camera = ibr::OrbitCameraView(
      glm::dvec3(0.0), 1.0, ibr::DeformOrbit(azimuth_deg, elevation_deg, distance), size);
  DeformPinholeView view;
  view.cam_from_world = camera.cam_from_world;
  view.focal_px = camera.camera.fx;
  view.size = size;
  return view;
}

DeformClassAgreement CompareDeformClasses(const render::Frame& frame,
                                          const DeformReferenceFrame& truth) {
  const int w = truth.classes.width(), h = truth.classes.height();
  if (frame.color.width() != w || frame.color.height() != h) {
    core::ThrowInputError("CompareDeformClasses", "frame {}x{} against a reference of {}x{}",
                          frame.color.width(), frame.color.height(), w, h);
  }
  DeformClassAgreement a;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int c = truth.classes.at(x, y, 0);
      bool band = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = std::clamp(x + dx, 0, w - 1), yy = std::clamp(y + dy, 0, h - 1);
          band |= truth.classes.at(xx, yy, 0) != c;
        }
      }
      if (band) {
        ++a.band;
        continue;
      }
      ++a.compared;
      const int g = !frame.Covered(x, y)                                   ? 0
                    : (frame.outcome.at(x, y) & render::kDeformCutFaceBit) ? 2
                                                                           : 1;
      a.agree += g == c;
    }
  }
  return a;
}

}  // namespace bench

namespace bench {

void DeformBenchOptions::Check() const {
  if (csv.empty()) core::ThrowInputError("ibr bench deform", "--csv FILE is required");
  if (out.empty()) core::ThrowInputError("ibr bench deform", "--out DIR is required");
  if (size < 16 || size > 4096)
    core::ThrowInputError("ibr bench deform", "--size {} outside 16..4096", size);
}

namespace {

struct BenchMesh {
  std::string name, file;
  bool cap_holes;
};

// The OpenVDB peer: one Python run per mesh over every resolution, with our
// voxel size (the box's longest side / (resolution - 1)) and our exact band
// as its half width; returns (seconds, active voxels) per resolution, in order.
std::vector<std::pair<double, double>> RunOpenVdbPeer(const std::filesystem::path& obj,
                                                      const core::Box3d& box,
                                                      const std::vector<int>& resolutions,
                                                      double half_width_voxels) {
  const std::filesystem::path script =
      std::filesystem::path(IBR_BENCH_SOURCE_DIR) / "openvdb_peer.py";
  std::string cmd = fmt::format(
      "/usr/bin/python3 {} {} {} {}", ShellQuote(script.string()), ShellQuote(obj.string()),
      std::max({box.size().x, box.size().y, box.size().z}), half_width_voxels);
  for (int r : resolutions) cmd += fmt::format(" {}", r);
  cmd += " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) core::ThrowInputError("ibr bench deform", "cannot run {}", cmd);
  std::string text;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) text += buffer;
  const int status = pclose(pipe);
  if (status != 0) {
    core::ThrowInputError("ibr bench deform", "OpenVDB peer failed (exit status {}): {}",
                          WIFEXITED(status) ? WEXITSTATUS(status) : -1, text);
  }
  std::vector<std::pair<double, double>> times;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    int res = 0;
    double seconds = 0, active = 0;
    if (std::sscanf(line.c_str(), "res %d seconds %lf active %lf", &res, &seconds, &active) == 3)
      times.emplace_back(seconds, active);
  }
  if (times.size() != resolutions.size()) {
    core::ThrowInputError("ibr bench deform", "OpenVDB peer failed: {}", text);
  }
  return times;
}

void WriteObj(const core::TriangleMesh& mesh, const std::filesystem::path& path) {
  std::ofstream out(path);
  for (const glm::vec3& p : mesh.positions) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    out << "f " << mesh.indices[3 * t] + 1 << ' ' << mesh.indices[3 * t + 1] + 1 << ' '
        << mesh.indices[3 * t + 2] + 1 << '\n';
  }
  if (!out) core::ThrowInputError("ibr bench deform", "cannot write {}", path.string());
}

// The distance-field rows of one mesh (DeformBenchResult::sdf): ours, OpenVDB
// in C++ on the same nodes with their accuracy against CGAL, and (options.peer)
// the Python peer's time for the same call.
void AddSdfRows(const BenchMesh& m, const core::MeshDistance& distance, const core::Box3d& full,
                const std::vector<int>& resolutions, const DeformBenchOptions& options,
                Table* sdf) {
  std::vector<std::pair<double, double>> peer;
  if (options.peer) {
    const std::filesystem::path obj = options.out / (m.name + "_closed.obj");
    WriteObj(distance.closed_mesh(), obj);
    peer = RunOpenVdbPeer(obj, full, resolutions, core::DistanceFieldOptions().exact_band_voxels);
  }
  for (size_t r = 0; r < resolutions.size(); ++r) {
    core::DistanceFieldOptions sdf_options;  // the peers' half width is its exact band
    sdf_options.resolution = resolutions[r];
    const auto start = std::chrono::steady_clock::now();
    const core::DistanceField field = core::BuildDistanceField(distance, full, sdf_options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // OpenVDB in C++ on the same nodes, then both against CGAL's exact
    // signed distance at the same sample nodes.
    const OpenVdbLevelSet level_set(distance.closed_mesh(), field, sdf_options.exact_band_voxels);
    SdfAccuracy ours_accuracy, vdb_accuracy;
    MeasureSdfAccuracy(distance, field, &level_set, 20000, &ours_accuracy, &vdb_accuracy);
    auto accuracy_cells = [](const SdfAccuracy& a) {
      return std::vector<std::string>{
          std::to_string(a.band_samples), std::to_string(a.missing),
          Num(a.max_error_voxels, 4),     Num(a.p95_error_voxels, 4),
          std::to_string(a.sign_samples), std::to_string(a.sign_errors)};
    };
    auto add_row = [&](const std::string& builder, double row_seconds, double count,
                       std::vector<std::string> accuracy) {
      std::vector<std::string> row = {m.name,
                                      std::to_string(resolutions[r]),
                                      builder,
                                      m.name + " " + builder,
                                      Num(row_seconds, 4),
                                      Num(count, 0)};
      row.insert(row.end(), accuracy.begin(), accuracy.end());
      sdf->AddRow(std::move(row));
    };
    add_row("ours", seconds, double(field.distance_queries), accuracy_cells(ours_accuracy));
    add_row("openvdb", level_set.seconds(), double(level_set.active_voxels()),
            accuracy_cells(vdb_accuracy));
    if (options.peer) {
      // The Python peer times the same call: no accuracy of its own.
      add_row("openvdb_python", peer[r].first, peer[r].second, std::vector<std::string>(6, "nan"));
    }
    fmt::print(
        stderr,
        "bench deform: {} distance field {}: {:.3f} s ours (max {:.3g} / p95 {:.3g} "
        "voxels, {} sign errors), {:.3f} s OpenVDB C++ (max {:.3g} / p95 {:.3g} voxels, "
        "{} of {} band nodes missing, {} sign errors){}\n",
        m.name, resolutions[r], seconds, ours_accuracy.max_error_voxels,
        ours_accuracy.p95_error_voxels, ours_accuracy.sign_errors, level_set.seconds(),
        vdb_accuracy.max_error_voxels, vdb_accuracy.p95_error_voxels, vdb_accuracy.missing,
        vdb_accuracy.band_samples, vdb_accuracy.sign_errors,
        options.peer ? fmt::format(", {:.3f} s OpenVDB Python", peer[r].first) : std::string());
  }
}

// The bench's meshes: Spot, fandisk, the cow, the capped bunny (quick: Spot
// and the bunny).
std::vector<BenchMesh> BenchMeshes(bool quick) {
  // (GCC 12 warns falsely about string temporaries in braced lists under ?:.)
  std::vector<BenchMesh> meshes;
  meshes.push_back({"spot", "spot.obj", false});
  if (!quick) {
    meshes.push_back({"fandisk", "fandisk.obj", false});
    meshes.push_back({"cow", "cow.obj", false});
  }
  meshes.push_back({"bunny-capped", "stanford-bunny.obj", true});
  return meshes;
}

// Samples along the longest axis of the distance fields the sdf table builds.
std::vector<int> SdfResolutions(bool quick) {
  return quick ? std::vector<int>{32, 64} : std::vector<int>{64, 128, 256};
}

// The result's tables with their columns and no rows.
DeformBenchResult EmptyDeformBenchResult() {
  return DeformBenchResult{
      Table({"workload", "mesh", "triangles", "mode", "series", "region_scale", "area_fraction",
             "ms", "ray_ms", "samples_per_ray", "rejected_per_ray", "cut_ray_fraction", "mesh_ms",
             "mesh_both_sides_ms", "p95_depth_error", "agree_fraction"}),
      Table({"mesh", "mode", "weighted_ms", "over_continuous", "slope_ms", "intercept_ms", "r2",
             "ray_weighted_ms", "ray_over_continuous"}),
      Table({"mesh", "resolution", "builder", "series", "seconds", "queries_or_active",
             "band_samples", "missing_band_nodes", "max_error_voxels", "p95_error_voxels",
             "sign_samples", "sign_errors"}),
      Table(std::vector<std::string>{}),  // accuracy: DeformAccuracy's
      Table({"mesh", "size_px", "implicit", "resolution", "bytes", "build_seconds", "ms_per_frame",
             "samples_per_ray", "silhouette_iou", "wrong_pixels", "mean_depth_error",
             "p95_depth_error"})};
}

// What accuracy costs (DeformBenchOptions): Spot cut by the solid knife
// from the oblique view, each knob setting's frame time and its depth and
// silhouette against the double sphere tracer, traced once; and the two
// implicits (distance field, depth-map cube) at one resolution into
// `implicits`.
Table DeformAccuracy(render::ProgramCache& programs, const DeformBenchOptions& options, int size,
                     Table& implicits) {
  Table table({"mesh", "size_px", "knob", "value", "mode", "resolution", "step_voxels",
               "ms_per_frame", "samples_per_ray", "silhouette_iou", "wrong_pixels",
               "mean_depth_error", "p95_depth_error"});
  const KnifeCutScene scene(options.shared_data / "meshes" / "spot.obj");
  const DeformPinholeView view = DeformObliqueView(size);

  const auto start = std::chrono::steady_clock::now();
  const DeformReferenceFrame truth = TraceDeformReference(scene.Reference(), scene.placement, view);
  std::fprintf(stderr, "bench deform: accuracy: the double sphere tracer at %d px in %.1f s\n",
               size,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());

  // One field per resolution, built once (normalised units: the mesh size is 1).
  std::map<int, core::DistanceField> fields;
  std::map<int, double> field_seconds;
  auto field = [&](int resolution) -> const core::DistanceField& {
    auto it = fields.find(resolution);
    if (it == fields.end()) {
      const auto built = std::chrono::steady_clock::now();
      it = fields
               .emplace(resolution,
                        DeformDistanceField(scene.distance, scene.placement.ObjectBounds(),
                                            scene.grow, resolution))
               .first;
      field_seconds[resolution] =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
    }
    return it->second;
  };
  render::RenderTarget target(render::FrameTargetOptions(size, size));
  const render::ViewSetup setup = view.Setup();
  struct Run {
    double ms;
    core::ViewMetrics m;
    DeformOutcomes outcomes;
  };
  auto run = [&](const render::DeformPassOptions& pass_options,
                 const render::DeformInputs& inputs) {
    render::DeformPass pass(programs, inputs, pass_options);
    render::FrameTimerOptions timer;
    timer.warmup_frames = 1;
    timer.timed_frames = options.quick ? 1 : 5;
    // The last timed frame is the one compared.
    const double ms =
        render::TimeFrames([&] { render::DrawFrame(target, pass, setup); }, timer).median_ms;
    const render::Frame frame = render::ReadFrame(target);
    return Run{ms, core::CompareDepth(frame.depth, truth.depth, 1.0), CountDeformOutcomes(frame)};
  };
  auto measure = [&](const std::string& knob, const std::string& value, int resolution,
                     render::RayStepPolicy policy, float step_voxels) {
    render::DeformPassOptions pass_options;
    pass_options.cut = core::CutMode::kSolid;
    pass_options.step_policy = policy;
    pass_options.step_voxels = step_voxels;
    const auto [ms, m, outcomes] = run(pass_options, scene.Inputs(field(resolution)));
    const std::string mode = render::RayStepPolicyName(policy);
    table.AddRow({"spot", std::to_string(size), knob, value, mode, std::to_string(resolution),
                  Num(step_voxels, 2), Num(ms, 2), Num(outcomes.mean_samples, 1), Num(m.iou, 5),
                  std::to_string(m.wrong_pixels), Num(m.depth.mean, 6), Num(m.depth.p95, 6)});
    std::fprintf(stderr,
                 "bench deform: accuracy %s %s (%s, field %d, step %.2f voxels): %.1f ms, IoU "
                 "%.4f, p95 depth error %.5f\n",
                 knob.c_str(), value.c_str(), mode.c_str(), resolution, step_voxels, ms, m.iou,
                 m.depth.p95);
  };
  const std::vector<int> resolutions =
      options.quick ? std::vector<int>{32, 128} : std::vector<int>{32, 64, 128, 256};
  for (int r : resolutions)
    measure("resolution", std::to_string(r), r, render::RayStepPolicy::kFixed, 1.0f);
  // The step sweeps at one resolution: the default field of `ibr deform`.
  constexpr int kAccuracyStepResolution = 128;
  const std::vector<float> steps =
      options.quick ? std::vector<float>{1.0f, 4.0f} : std::vector<float>{0.5f, 1.0f, 2.0f, 4.0f};
  for (const render::RayStepPolicy policy :
       {render::RayStepPolicy::kFixed, render::RayStepPolicy::kThreshold,
        render::RayStepPolicy::kJacobian}) {
    for (float step : steps) measure("step", Num(step, 2), kAccuracyStepResolution, policy, step);
  }

  // The two implicits at the default resolution (fixed step of one voxel or
  // texel): the distance field over the box, the depth cube of the mesh's
  // bounding cube (six maps of that many pixels, sec. 6.1). The tracer uses
  // the true mesh, so what no face of the cube sees shows as error.
  const int resolution = kAccuracyStepResolution;
  const auto built = std::chrono::steady_clock::now();
  const render::DepthCube cube = ibr::MakeDepthCube(programs, scene.mesh, resolution);
  const double cube_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
  for (const render::DeformImplicit implicit :
       {render::DeformImplicit::kSdf, render::DeformImplicit::kDepthCube}) {
    const bool is_cube = implicit == render::DeformImplicit::kDepthCube;
    render::DeformPassOptions pass_options;
    pass_options.cut = core::CutMode::kSolid;
    pass_options.implicit = implicit;
    render::DeformInputs inputs = scene.Inputs(field(resolution));
    inputs.depth_cube = &cube;
    const auto [ms, m, outcomes] = run(pass_options, inputs);
    const int64_t bytes =
        is_cube ? cube.Bytes() : static_cast<int64_t>(field(resolution).values.size() * 4);
    const double seconds = is_cube ? cube_seconds : field_seconds.at(resolution);
    implicits.AddRow({"spot", std::to_string(size), render::DeformImplicitName(implicit),
                      std::to_string(resolution), std::to_string(bytes), Num(seconds, 4),
                      Num(ms, 2), Num(outcomes.mean_samples, 1), Num(m.iou, 5),
                      std::to_string(m.wrong_pixels), Num(m.depth.mean, 6), Num(m.depth.p95, 6)});
    std::fprintf(stderr,
                 "bench deform: implicit %s %d: %lld bytes, built in %.3f s, %.1f ms, IoU %.4f, "
                 "p95 depth error %.5f\n",
                 render::DeformImplicitName(implicit).c_str(), resolution,
                 static_cast<long long>(bytes), seconds, ms, m.iou, m.depth.p95);
  }
  return table;
}

// Table 1's rows: continuous; the paper's solid cut (sec. 5.1.2, the
// two-field search) without and with empty-space skipping (ESK); and our CSG
// solid cut (the field max(body, A)) without: all with the pass's default
// skipping by the object's distance field. Then the paper's own shader
// (paper_*): the same three without that skipping (sec. 6.2 skips by the
// cut's distance only), each over paper_continuous.
struct TableOneMode {
  std::string name;
  core::Deformation deformation;
  const core::DeformationTexture* texture;  // of `deformation`
  core::CutMode cut;
  bool skip;
  bool search;
  bool skip_object;
  std::string baseline;  // the continuous mode its ratios are over
};

// The twist and the knife with their textures, sampled once for the modes
// that share them.
struct TableOneDeformations {
  core::Deformation twist{core::DeformationKind::kTwist, 2.0, 0.35};
  core::Deformation knife = KnifeCut();
  core::DeformationTexture twist_texture = core::SampleDeformation({{twist}}, 64);
  core::DeformationTexture knife_texture = core::SampleDeformation({{knife}}, 64);

  std::vector<TableOneMode> Modes() const {
    const auto none = core::CutMode::kNone, solid = core::CutMode::kSolid;
    const auto* t = &twist_texture;
    const auto* k = &knife_texture;
    return {{"continuous", twist, t, none, false, false, true, "continuous"},
            {"cut", knife, k, solid, false, true, true, "continuous"},
            {"cut_skip", knife, k, solid, true, true, true, "continuous"},
            {"cut_csg", knife, k, solid, false, false, true, "continuous"},
            {"paper_continuous", twist, t, none, false, false, false, "paper_continuous"},
            {"paper_cut", knife, k, solid, false, true, false, "paper_continuous"},
            {"paper_cut_skip", knife, k, solid, true, true, false, "paper_continuous"}};
  }
};

// What every mode's frames of one mesh share.
struct MeshSweep {
  const BenchMesh& mesh;
  const core::TriangleMesh& drawn;  // as ibr deform draws it
  const core::DistanceField& sdf;
  core::Box3d region;
  render::ViewSetup view;
  int size;
  const std::vector<double>& scales;
  render::FrameTimerOptions timer;
};

// The mesh stage's time per region scale, timed alone (draw_rays off); the
// stage does not depend on the mode.
struct MeshStage {
  std::vector<double> ms, both_sides_ms;
};

struct ModeTimes {
  std::vector<double> areas, times, ray_times;
};

// Fitted ms at one common area per mode (the spread across meshes): whole
// frames, and the ray stage alone (the frame minus the mesh stage).
constexpr double kCommonArea = 0.2;
struct CommonArea {
  std::map<std::string, std::vector<double>> frame, ray;
};

// The continuous mode's mesh stage at one scale, and the same frame drawing
// both sides of the mesh everywhere (cull_back_faces off): what the culling
// saves, same run.
void TimeMeshStage(const std::function<double(const render::DeformPassOptions&)>& time_pass,
                   const render::DeformPassOptions& pass_options, bool culled,
                   const std::string& mesh, MeshStage& stage) {
  render::DeformPassOptions mesh_only = pass_options;
  mesh_only.draw_rays = false;
  stage.ms.push_back(time_pass(mesh_only));
  mesh_only.cull_back_faces = false;
  stage.both_sides_ms.push_back(time_pass(mesh_only));
  std::fprintf(stderr,
               "bench deform: %s mesh stage %.1f ms (back faces culled: %s), both sides "
               "%.1f ms\n",
               mesh.c_str(), stage.ms.back(), culled ? "yes" : "no", stage.both_sides_ms.back());
}

// One mode at every region scale: a `frames` row per scale.
ModeTimes TimeModeOverScales(render::ProgramCache& programs, const MeshSweep& f,
                             const TableOneMode& mode, render::RenderTarget& target,
                             MeshStage& stage, Table& frames) {
  const core::DeformationTexture& texture = *mode.texture;
  render::DeformPassOptions pass_options;
  pass_options.cut = mode.cut;
  pass_options.skip_empty = mode.skip;
  pass_options.solid_search = mode.search;
  pass_options.skip_object = mode.skip_object;
  const std::string& name = f.mesh.name;
  ModeTimes t;
  for (size_t si = 0; si < f.scales.size(); ++si) {
    const double scale = f.scales[si];
    const core::Placement placement = core::Placement::FromRegion(f.region, glm::dvec3(0.0), scale);
    // Median ms a frame of the pass with `o`.
    const auto time_pass = [&](const render::DeformPassOptions& o) {
      render::DeformPass timed(programs, {&f.drawn, &f.sdf, &texture, placement}, o);
      return render::TimeFrames([&] { render::DrawFrame(target, timed, f.view); }, f.timer)
          .median_ms;
    };
    render::DeformPass pass(programs, {&f.drawn, &f.sdf, &texture, placement}, pass_options);
    const double ms =
        render::TimeFrames([&] { render::DrawFrame(target, pass, f.view); }, f.timer).median_ms;
    const DeformOutcomes o = CountDeformOutcomes(render::ReadFrame(target));
    if (mode.name == "continuous")
      TimeMeshStage(time_pass, pass_options, pass.last_culled_back_faces(), name, stage);
    const double ray_ms = std::max(ms - stage.ms[si], 0.0);
    const double area = static_cast<double>(o.rays) / (double(f.size) * f.size);
    t.areas.push_back(area);
    t.times.push_back(ms);
    t.ray_times.push_back(ray_ms);
    const bool rejects = mode.search && o.rays > 0;
    frames.AddRow({"sweep", name, std::to_string(f.drawn.triangle_count()), mode.name,
                   name + " " + mode.name, Num(scale, 2), Num(area, 4), Num(ms, 2), Num(ray_ms, 2),
                   Num(o.mean_samples, 1), Num(o.mean_rejected, 3),
                   rejects ? Num(double(o.rejecting_rays) / double(o.rays), 4) : "",
                   Num(stage.ms[si], 2),
                   mode.name == "continuous" ? Num(stage.both_sides_ms[si], 2) : "", "", ""});
    std::fprintf(stderr,
                 "bench deform: %s %s scale %.2f: area %.3f, %.1f ms (ray stage %.1f), "
                 "%.1f samples per ray\n",
                 name.c_str(), mode.name.c_str(), scale, area, ms, ray_ms, o.mean_samples);
  }
  return t;
}

// A mode's summary row: area-weighted ms over its baseline's, the line fit
// of ms against area, and its value at kCommonArea for the spread rows.
void AddModeSummary(const std::string& mesh, const TableOneMode& mode, const ModeTimes& t,
                    std::map<std::string, std::pair<double, double>>& baseline_weighted,
                    CommonArea& common, Table& summary) {
  const auto weighted_mean = [&](const std::vector<double>& v) {
    double weighted = 0.0, weight = 0.0;
    for (size_t k = 0; k < t.areas.size(); ++k) weighted += t.areas[k] * v[k], weight += t.areas[k];
    return weight > 0 ? weighted / weight : 0.0;
  };
  const double weighted = weighted_mean(t.times), ray_weighted = weighted_mean(t.ray_times);
  if (mode.name == mode.baseline) baseline_weighted[mode.name] = {weighted, ray_weighted};
  const auto [base, ray_base] = baseline_weighted.at(mode.baseline);
  const LineFit fit = FitLine(t.areas, t.times), ray_fit = FitLine(t.areas, t.ray_times);
  common.frame[mode.name].push_back(fit.slope * kCommonArea + fit.intercept);
  common.ray[mode.name].push_back(ray_fit.slope * kCommonArea + ray_fit.intercept);
  summary.AddRow({mesh, mode.name, Num(weighted, 2), Num(base > 0 ? weighted / base : 0.0, 3),
                  Num(fit.slope, 2), Num(fit.intercept, 2), Num(fit.r2, 4), Num(ray_weighted, 2),
                  Num(ray_base > 0 ? ray_weighted / ray_base : 0.0, 3)});
}

// One mesh: its distance-field rows (ours and the peers', over the full
// region), then every Table 1 mode at every region scale from RunDeform's
// default orbit view.
void SweepMesh(render::ProgramCache& programs, const DeformBenchOptions& options,
               const BenchMesh& m, int size, int render_resolution,
               const std::vector<double>& scales, DeformBenchResult& result, CommonArea& common) {
  capture::SceneMesh scene = capture::LoadSceneMesh(options.shared_data / "meshes" / m.file);
  core::TriangleMesh& mesh = scene.mesh;
  ibr::NormaliseMesh(mesh);
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const core::Box3d region = core::Box3d{glm::dvec3(lo), glm::dvec3(hi)}.Grown(0.05);
  core::MeshDistance distance(mesh, m.cap_holes, m.file);
  const std::optional<core::TriangleMesh> capped = ibr::CappedMesh(distance);
  const core::TriangleMesh& drawn = capped ? *capped : mesh;  // as ibr deform draws it
  std::fprintf(stderr, "bench deform: %s, %zu triangles\n", m.name.c_str(), drawn.triangle_count());
  const core::Box3d full = core::Placement::FromRegion(region).ObjectBounds();
  AddSdfRows(m, distance, full, SdfResolutions(options.quick), options, &result.sdf);

  // One field for every region scale: the largest box grown by the largest
  // displacement (the knife's and the twist's, at scale 1).
  const TableOneDeformations deformations;
  const std::vector<TableOneMode> modes = deformations.Modes();
  double grow = 0.0;
  for (const TableOneMode& mode : modes) {
    grow = std::max(grow, core::MaxObjectDisplacement({{mode.deformation}},
                                                      core::Placement::FromRegion(region), 32));
  }
  const core::DistanceField sdf = DeformDistanceField(distance, full, grow, render_resolution);

  // RunDeform's default orbit view of the normalised mesh (centre 0, longest
  // side 1), its clip range holding every region scale's result.
  const ibr::DeformRenderOptions run_defaults;
  const ibr::ViewCamera camera = ibr::OrbitCameraView(
      glm::dvec3(0.0), 1.0, ibr::DeformOrbit(run_defaults.azimuth_deg, run_defaults.elevation_deg),
      size);
  const core::Box3d clip_box = ibr::DeformedBounds({glm::dvec3(lo), glm::dvec3(hi)}, full, grow);
  capture::Bounds bounds;
  bounds.min = clip_box.lo;
  bounds.max = clip_box.hi;
  MeshSweep sweep{m, drawn, sdf, region, ibr::ViewSetupFor(camera, bounds), size, scales, {}};
  sweep.timer.warmup_frames = 1;
  sweep.timer.timed_frames = options.quick ? 1 : 5;
  render::RenderTarget target(render::FrameTargetOptions(size, size));
  MeshStage stage;
  // Each continuous mode's weighted ms (frame, ray stage), for the ratios.
  std::map<std::string, std::pair<double, double>> baseline_weighted;
  for (const TableOneMode& mode : modes) {
    const ModeTimes t = TimeModeOverScales(programs, sweep, mode, target, stage, result.frames);
    AddModeSummary(m.name, mode, t, baseline_weighted, common, result.summary);
  }
}

}  // namespace

DeformBenchResult RunDeformBench(render::ProgramCache& programs,
                                 const DeformBenchOptions& options) {
  options.Check();
  const int size = options.quick ? 128 : options.size;
  std::vector<BenchMesh> meshes;
  if (!options.workloads_only) meshes = BenchMeshes(options.quick);
  const std::vector<double> scales = options.quick ? std::vector<double>{0.5, 1.0}
                                                   : std::vector<double>{0.4, 0.55, 0.7, 0.85, 1.0};
  const int render_resolution = options.quick ? 64 : 128;
  std::filesystem::create_directories(options.out);

  DeformBenchResult result = EmptyDeformBenchResult();
  CommonArea common;
  for (const BenchMesh& m : meshes)
    SweepMesh(programs, options, m, size, render_resolution, scales, result, common);
  if (!options.workloads_only)
    result.accuracy = DeformAccuracy(programs, options, size, result.implicits);
  result.wedge = RunDeformWedge(programs, options, size, render_resolution, result.frames);
  result.forward = RunDeformForwardMesh(programs, options, size, render_resolution, result.frames);
  result.spread =
      RunDeformSpread(programs, options, size, render_resolution, result.spread_figures);
  result.pull = RunDeformNarrowPull(programs, size, result.pull_figures);
  for (const auto& [mode, values] : common.frame) {
    const auto spread = [](const std::vector<double>& v) {
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      return "max/min " + Num(*lo > 0 ? *hi / *lo : 0.0, 3);
    };
    result.summary.AddRow({"across meshes at area " + Num(kCommonArea, 2), mode, "", "", "", "",
                           spread(values), "", spread(common.ray[mode])});
  }
  return result;
}

Table RunDeformSdfBench(const DeformBenchOptions& options) {
  options.Check();
  std::filesystem::create_directories(options.out);
  DeformBenchResult result = EmptyDeformBenchResult();
  for (const BenchMesh& m : BenchMeshes(options.quick)) {
    capture::SceneMesh scene = capture::LoadSceneMesh(options.shared_data / "meshes" / m.file);
    ibr::NormaliseMesh(scene.mesh);
    glm::vec3 lo, hi;
    scene.mesh.Bounds(lo, hi);
    const core::Box3d region = core::Box3d{glm::dvec3(lo), glm::dvec3(hi)}.Grown(0.05);
    const core::MeshDistance distance(scene.mesh, m.cap_holes, m.file);
    AddSdfRows(m, distance, core::Placement::FromRegion(region).ObjectBounds(),
               SdfResolutions(options.quick), options, &result.sdf);
  }
  return result.sdf;
}

void WriteDeformBench(const DeformBenchResult& result, const DeformBenchOptions& options) {
  std::filesystem::create_directories(options.out);
  result.frames.WriteCsv(options.csv);
  result.summary.WriteCsv(options.out / "deform_summary.csv");
  result.sdf.WriteCsv(options.out / "deform_sdf.csv");
  result.accuracy.WriteCsv(options.out / "deform_accuracy.csv");
  result.implicits.WriteCsv(options.out / "deform_implicit.csv");
  result.spread.WriteCsv(options.out / "deform_spread.csv");
  result.pull.WriteCsv(options.out / "deform_pull.csv");
  Correa2007GoalsTable(result.wedge, result.forward, result.spread_figures)
      .WriteCsv(options.out / "deform_goals.csv");
  PlotOptions frames;
  frames.title = "Deformation and cut shaders: ms per frame against the deformed screen area";
  frames.x_column = "area_fraction";
  frames.y_column = "ms";
  frames.series_column = "series";
  frames.x_label = "relative screen area of the deformation box";
  frames.y_label = "ms per frame";
  // The paper's Fig. 7 series: the paper_* modes (no object skipping) are
  // in the CSV and the summary, left out here to keep 16 lines readable.
  // The region-scale sweep only (the workloads' rows have one scale each).
  const Table shown = Filtered(result.frames, [&](const std::vector<std::string>& r) {
    return r[result.frames.Column("workload")] == "sweep" &&
           r[result.frames.Column("mode")].rfind("paper_", 0) != 0;
  });
  if (options.workloads_only) return;  // nothing swept to plot
  PlotPng(shown, frames, options.out / "deform_ms_vs_area.png");
  PlotOptions sdf;
  sdf.title = "Distance-field build time (ours: exact in a 4-voxel band; OpenVDB level set)";
  sdf.x_column = "resolution";
  sdf.y_column = "seconds";
  sdf.series_column = "series";
  sdf.x_label = "samples along the longest axis";
  sdf.y_label = "seconds";
  sdf.log_y = true;
  PlotPng(result.sdf, sdf, options.out / "deform_sdf_build.png");
}

}  // namespace bench
