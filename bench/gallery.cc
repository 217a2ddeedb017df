#include "bench/gallery.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "bench/deform_bench.h"
#include "bench/peer.h"
#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/check.h"
#include "core/deform_reference.h"
#include "core/deformation.h"
#include "core/distance_field.h"
#include "core/image_compose.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "core/volume_io.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "ibr/jobs/demo_job.h"
#include "ibr/jobs/volume_job.h"
#include "ibr/views.h"
#include "ibr/volume_object.h"
#include "render/passes/deform_pass.h"
#include "render/passes/volume_pass.h"
#include "verify/volume_reference.h"

namespace bench {
namespace fs = std::filesystem;

void HeatRamp(double t, uint8_t rgb[3]) {
  t = std::clamp(std::isfinite(t) ? t : 1.0, 0.0, 1.0);
  // Thirds: black -> red, red -> yellow, yellow -> white.
  const double r = std::min(1.0, 3 * t), g = std::clamp(3 * t - 1, 0.0, 1.0),
               b = std::clamp(3 * t - 2, 0.0, 1.0);
  rgb[0] = static_cast<uint8_t>(std::lround(255 * r));
  rgb[1] = static_cast<uint8_t>(std::lround(255 * g));
  rgb[2] = static_cast<uint8_t>(std::lround(255 * b));
}

core::Image8 DepthErrorHeatMap(const core::Image8& covered, const core::ImageF& depth,
                               const core::Image8& truth_covered, const core::ImageF& truth_depth,
                               double scale) {
  IBR_CHECK(covered.width() == truth_covered.width() && covered.height() == truth_covered.height());
  IBR_CHECK(depth.width() == covered.width() && truth_depth.width() == covered.width());
  IBR_CHECK(scale > 0);
  core::Image8 out(covered.width(), covered.height(), 4, 255);
  for (int y = 0; y < out.height(); ++y) {
    for (int x = 0; x < out.width(); ++x) {
      const bool a = covered.at(x, y, 0) != 0, b = truth_covered.at(x, y, 0) != 0;
      uint8_t rgb[3] = {40, 40, 40};
      if (a && b) {
        HeatRamp(std::abs(depth.at(x, y, 0) - truth_depth.at(x, y, 0)) / scale, rgb);
      } else if (a) {
        rgb[0] = 255, rgb[1] = 0, rgb[2] = 255;  // extra surface
      } else if (b) {
        rgb[0] = 0, rgb[1] = 255, rgb[2] = 255;  // missing surface
      }
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = rgb[c];
    }
  }
  return out;
}

std::vector<double> ColorErrors(const core::ImageF& color, const core::ImageF& truth) {
  IBR_CHECK(color.width() == truth.width() && color.height() == truth.height());
  IBR_CHECK(color.channels() == 4 && truth.channels() == 4);
  std::vector<double> errors;
  for (int y = 0; y < color.height(); ++y)
    for (int x = 0; x < color.width(); ++x) {
      if (color.at(x, y, 3) == 0 && truth.at(x, y, 3) == 0) continue;
      double e = 0;
      for (int c = 0; c < 4; ++c)
        e = std::max(e, std::abs(static_cast<double>(color.at(x, y, c)) - truth.at(x, y, c)));
      errors.push_back(255 * e);
    }
  return errors;
}

core::Image8 ColorErrorHeatMap(const core::ImageF& color, const core::ImageF& truth_color,
                               double scale) {
  IBR_CHECK(color.width() == truth_color.width() && color.height() == truth_color.height());
  IBR_CHECK(color.channels() == 4 && truth_color.channels() == 4);
  IBR_CHECK(scale > 0);
  core::Image8 out(color.width(), color.height(), 4, 255);
  for (int y = 0; y < out.height(); ++y) {
    for (int x = 0; x < out.width(); ++x) {
      double error = 0;
      bool empty = true;
      for (int c = 0; c < 4; ++c) {
        const float a = color.at(x, y, c), b = truth_color.at(x, y, c);
        error = std::max(error, static_cast<double>(std::abs(a - b)));
        empty = empty && a == 0 && b == 0;
      }
      uint8_t rgb[3] = {40, 40, 40};
      if (!empty) HeatRamp(error / scale, rgb);
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = rgb[c];
    }
  }
  return out;
}

namespace {

// The displaced torus (the paper's donut, bumps) at a grazing view: the far
// inner side through the hole, where silhouettes come from the displacement.
void DisplacedEntries(render::ProgramCache& programs, const GalleryOptions& options,
                      std::vector<GalleryEntry>& out) {
  constexpr float kMaxDisplacement = 0.15f;
  constexpr double kElevation = 8;
  ibr::DisplacedMeshData data;
  data.base = ibr::DisplacementBaseMesh("torus");
  data.height = ibr::DisplacementHeightMap(core::HeightPattern::kBumps, options.quick ? 64 : 128);
  const int n = options.size;
  // The torus (R 1, r 0.4) lies in z = 0: the eye 8 degrees above its plane,
  // close enough that the torus spans most of the frame.
  // The product's orbit from -y (a focal length of n pixels).
  const ibr::OrbitCamera orbit{.elevation_deg = kElevation,
                               .azimuth_deg = -90,
                               .distance = 3.3,
                               .fov_deg = 2 * glm::degrees(std::atan(0.5))};
  const ibr::ViewCamera camera = ibr::OrbitCameraView(glm::dvec3(0.0), 1.4, orbit, n);
  render::ViewSetup view;
  view.cam_from_world = glm::mat4(camera.cam_from_world);
  view.clip_from_cam = core::ClipFromCamPerspective(camera.camera.fx, camera.camera.fy, n / 2.0,
                                                    n / 2.0, n, n, 0.1, 20.0);
  auto draw = [&](ibr::DisplacementMethod method) {
    ibr::DisplacedMeshOptions o;
    o.method = method;
    o.max_displacement = kMaxDisplacement;
    o.tiling = 2;
    o.slices = 32;
    o.steps = 32;
    ibr::DisplacedMeshRenderer renderer(programs, data, o);
    renderer.Draw(view, n, n);
    return renderer.Read();
  };
  const render::Frame truth = draw(ibr::DisplacementMethod::kTessellated);
  const core::Image8 truth_covered = core::CoverageFromAlpha(truth.color);
  // Every method of the one method table but the truth and two slicing
  // families (the orthogonal one stands for slicing).
  for (const std::string& name : ibr::DisplacementMethodNames()) {
    if (name == "tessellated" || name == "slices-surface" || name == "slices-screen") continue;
    const render::Frame frame = draw(ibr::DisplacementMethodFromName(name));
    const core::ViewMetrics m =
        core::CompareFrames(frame.color, frame.depth, truth.color, truth.depth, kMaxDisplacement);
    out.push_back(
        {"displacement",
         fmt::format("{}, displaced torus, grazing view ({:.0f} deg)", name, kElevation),
         fmt::format("silhouette IoU {:.4f}, {} wrong pixels; depth error p95 {:.3f} of the "
                     "maximum displacement; heat map saturates at 0.25 of it",
                     m.iou, m.wrong_pixels, m.depth.p95),
         frame.color, truth.color,
         DepthErrorHeatMap(core::CoverageFromAlpha(frame.color), frame.depth, truth_covered,
                           truth.depth, 0.25 * kMaxDisplacement)});
  }
}

// Depth objects and the visual hull of a concave object (the cup; the bunny
// too in the full report) from an oblique view, six cube maps.
void DepthObjectEntries(render::ProgramCache& programs, const GalleryOptions& options,
                        std::vector<GalleryEntry>& out) {
  struct Object {
    std::string name;
    capture::SceneMesh scene;
    glm::dvec3 up;  // the turntable axis: the cup opens towards +z, OBJ meshes are y-up
  };
  std::vector<Object> objects;
  objects.push_back({"cup", capture::MakeShapeScene("cup"), {0, 0, 1}});
  const fs::path bunny = ibr::SharedDataDir() / "meshes" / "stanford-bunny.obj";
  if (!options.quick && fs::exists(bunny))
    objects.push_back({"bunny", capture::LoadSceneMesh(bunny), {0, 1, 0}});
  const fs::path work = fs::temp_directory_path() / fmt::format("ibr_report_gallery_{}", getpid());
  struct Remove {
    fs::path path;
    ~Remove() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } remove{work};
  for (const auto& [name, scene, up] : objects) {
    capture::CaptureOptions co;
    co.rig = "cube";
    co.size = options.map_size;
    co.shade = false;
    capture::CaptureDataset(programs, scene, co, work / name);
    const capture::Dataset dataset = capture::ReadDataset(work / name);
    const ibr::MapSet maps = ibr::MapsFromDataset(dataset);
    const capture::Bounds bounds = *dataset.bounds;
    const double edge = CubeEdge(bounds);
    ibr::OrbitOptions orbit;
    orbit.count = 8;
    orbit.size = options.size;
    orbit.elevation_deg = 50;  // oblique to every cube face; into the cup
    orbit.up = up;
    const ibr::ViewCamera view = ibr::OrbitViews(maps, orbit)[1].view;
    capture::CaptureOptions to;
    to.size = options.size;  // shaded, so that the truth's shape reads
    const capture::CapturedView truth =
        capture::RenderView(programs, scene, ibr::RigViewFor(view, bounds, "truth"), to);
    const core::Image8 truth_covered = core::CoverageFromDepth(truth.depth);
    ibr::DepthObjectRenderer renderer(programs, maps);
    struct Variant {
      std::string label;
      ibr::Method method;
      ibr::Slicing slicing;
      int slices;
    };
    for (const Variant& v : std::vector<Variant>{
             {"depth object, orthogonal slices", ibr::Method::kDepthObject,
              ibr::Slicing::kOrthogonal, 64},
             {"depth object, ray path", ibr::Method::kDepthObject, ibr::Slicing::kRay, 0},
             {"visual hull, screen slices", ibr::Method::kVisualHull, ibr::Slicing::kScreen, 0}}) {
      ibr::DepthObjectOptions o;
      o.method = v.method;
      o.slicing = v.slicing;
      o.slices = v.slices;  // 0 = auto (Kautz-Seidel sec. 3.4)
      o.texturing = ibr::Texturing::kNone;
      const render::Frame frame = renderer.RenderFrame(view, o);
      const core::ViewMetrics m = core::CompareDepth(frame.depth, truth.depth, edge);
      out.push_back(
          {"depth_object",
           fmt::format("{}: {}, oblique view ({:.0f} deg)", name, v.label, orbit.elevation_deg),
           fmt::format("silhouette IoU {:.4f}; depth error p95 {:.4f} cube edges; heat "
                       "map saturates at 0.02 cube edges",
                       m.iou, m.depth.p95),
           frame.color, truth.color,
           DepthErrorHeatMap(render::CoverageMask(frame), frame.depth, truth_covered, truth.depth,
                             0.02 * edge)});
    }
  }
}

// Spot cut by a solid knife (Correa, Silver, Chen 2007, eq. 6), the region
// around the whole mesh, from an oblique view, against the double sphere
// tracer of core/deform_reference.h (the exact mesh distance, the analytic
// deformation and cut) traced through every pixel centre.
void DeformEntries(render::ProgramCache& programs, const GalleryOptions& options,
                   std::vector<GalleryEntry>& out) {
  const fs::path spot = ibr::SharedDataDir() / "meshes" / "spot.obj";
  if (!fs::exists(spot)) return;
  const KnifeCutScene scene(spot);
  const core::DistanceField sdf = DeformDistanceField(
      scene.distance, scene.placement.ObjectBounds(), scene.grow, options.quick ? 64 : 128);
  render::DeformPassOptions pass_options;
  pass_options.cut = core::CutMode::kSolid;
  render::DeformPass pass(programs, scene.Inputs(sdf), pass_options);

  const DeformPinholeView view = DeformObliqueView(options.size);
  render::RenderTarget target(render::FrameTargetOptions(view.size, view.size));
  render::DrawFrame(target, pass, view.Setup());
  const render::Frame frame = render::ReadFrame(target);
  const DeformReferenceFrame truth = TraceDeformReference(scene.Reference(), scene.placement, view);
  const core::ViewMetrics m = core::CompareDepth(frame.depth, truth.depth, 1.0);
  out.push_back({"deform", "spot, solid knife cut (Correa 2007, eq. 6), oblique view",
                 fmt::format("against the double sphere tracer: silhouette IoU {:.4f}; depth error "
                             "p95 {:.4f} of the mesh size; heat map saturates at 0.01 of it",
                             m.iou, m.depth.p95),
                 frame.color, truth.color,
                 DepthErrorHeatMap(core::CoverageFromDepth(frame.depth), frame.depth,
                                   core::CoverageFromDepth(truth.depth), truth.depth, 0.01)});
}

// Premultiplied RGBA in [0, 1] -> RGBA8 (rounded), for OverBackground.
core::Image8 ToImage8(const core::ImageF& premultiplied) {
  core::Image8 out(premultiplied.width(), premultiplied.height(), premultiplied.channels());
  for (size_t i = 0; i < out.values().size(); ++i)
    out.values()[i] =
        static_cast<uint8_t>(std::lround(255 * std::clamp(premultiplied.values()[i], 0.0f, 1.0f)));
  return out;
}

// The tooth with a layer of its crown peeled back (Correa, Silver, Chen
// 2006; the peel of `ibr bench volume`): DVR through the pass's screen slices
// into a float colour target, seen from above on the side of the cut, against
// the double reference of verify/volume_reference.h at the same slices. Unlit:
// the reference has no lighting. The colour error is what compares, as the
// translucent slices have no single depth.
void VolumeEntries(render::ProgramCache& programs, const GalleryOptions& options,
                   std::vector<GalleryEntry>& out) {
  const fs::path dat = ibr::SharedDataDir() / "volumes" / "tooth_103x94x161_uint8.dat";
  if (!fs::exists(dat)) return;
  constexpr double kAzimuthDeg = 20, kElevationDeg = 50;
  // The top layer z in [0.6, 0.8], x > 0.5, turned by 160 degrees.
  const std::vector<core::Deformation> peel = {
      {.kind = core::DeformationKind::kPeel, .amount = 160 * M_PI / 180, .width = 0.2}};
  const int map_size = options.quick ? 32 : 64;
  const ibr::VolumeObjectData data = ibr::MakeVolumeObject(
      core::ReadVolume(dat), ibr::TransferForVolume("", dat), peel, map_size, "ibr report gallery");
  render::VolumePassOptions pass_options;
  pass_options.lighting = render::VolumeLighting::kNone;
  render::VolumePass pass(programs, data.volume, data.transfer, data.maps, data.world_from_volume,
                          pass_options);
  const int n = options.size;
  const render::ViewSetup view =
      ibr::VolumeOrbitView(kAzimuthDeg, kElevationDeg, 3.2 * data.radius, n, data.radius);
  const core::ImageF color = ibr::DrawVolumeFloat(pass, view, n);

  const auto start = std::chrono::steady_clock::now();
  const ibr::DvrReferenceImage ref =
      ibr::DvrReference(data.volume, data.transfer, data.maps, pass, view, n, n);
  spdlog::info("gallery: volume DVR reference ({} x {} px, {} slices) in {:.2f} s", n, n,
               pass.last_stats().slices,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  core::ImageF truth(n, n, 4, 0.0f);
  for (size_t i = 0; i < truth.values().size(); ++i)
    truth.values()[i] = static_cast<float>(ref.color.values()[i]);
  // Over every pixel either covers, the reference's proxy-face ties
  // (DvrReferenceImage::ambiguous) included: the figures bound them too.
  const std::vector<double> errors = ColorErrors(color, truth);
  const double above = static_cast<double>(std::count_if(errors.begin(), errors.end(),
                                                         [](double e) { return e > 1.0; })) /
                       static_cast<double>(std::max<size_t>(errors.size(), 1));
  const core::ErrorStats stats = core::SummarizeErrors(errors);
  // The errors are far below what 8 bits show: the heat map saturates at
  // the largest one (floored at 0.001/255), so that where they are is seen.
  const double heat_scale = std::max(stats.max, 1e-3) / 255;
  const glm::vec3 background(0.08f, 0.08f, 0.1f);
  out.push_back(
      {"volume",
       fmt::format("tooth, crown layer peeled (Correa 2006), DVR, oblique view into the cut "
                   "({:.0f} deg)",
                   kElevationDeg),
       fmt::format("against the double DVR reference at the pass's {} slices: max colour error "
                   "{:.3f}/255, p95 {:.3f}/255 (premultiplied RGBA, worst channel) over {} "
                   "pixels; {:.2f}% above 1/255; heat map saturates at {:.3f}/255",
                   pass.last_stats().slices, stats.max, stats.p95, stats.count, 100 * above,
                   heat_scale * 255),
       core::OverBackground(ToImage8(color), background),
       core::OverBackground(ToImage8(truth), background),
       ColorErrorHeatMap(color, truth, heat_scale)});
}

}  // namespace

std::vector<GalleryEntry> RenderGallery(render::ProgramCache& programs,
                                        const GalleryOptions& options) {
  const auto wanted = [&](const std::string& family) {
    return options.families.empty() || std::find(options.families.begin(), options.families.end(),
                                                 family) != options.families.end();
  };
  std::vector<GalleryEntry> out;
  if (wanted("displacement")) DisplacedEntries(programs, options, out);
  if (wanted("depth_object")) DepthObjectEntries(programs, options, out);
  if (wanted("deform")) DeformEntries(programs, options, out);
  if (wanted("volume")) VolumeEntries(programs, options, out);
  return out;
}

}  // namespace bench
