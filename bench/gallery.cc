#include "bench/gallery.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "bench/peer.h"
#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/check.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "ibr/dataset_maps.h"
#include "ibr/demo_scene.h"
#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "ibr/views.h"

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
  render::ViewSetup view;
  const double el = kElevation * std::numbers::pi / 180.0;
  const float distance = 3.3f;
  view.cam_from_world =
      core::CamFromWorldLookAt({0.0f, -distance * static_cast<float>(std::cos(el)),
                                distance * static_cast<float>(std::sin(el))},
                               {0, 0, 0}, {0, 0, 1});
  const double f = 1.0 * n;
  view.clip_from_cam = core::ClipFromCamPerspective(f, f, n / 2.0, n / 2.0, n, n, 0.1, 20.0);
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
      const ibr::DepthObjectFrame frame = renderer.RenderImages(view, o);
      const core::ViewMetrics m = core::CompareDepth(frame.depth, truth.depth, edge);
      out.push_back(
          {"depth_object",
           fmt::format("{}: {}, oblique view ({:.0f} deg)", name, v.label, orbit.elevation_deg),
           fmt::format("silhouette IoU {:.4f}; depth error p95 {:.4f} cube edges; heat "
                       "map saturates at 0.02 cube edges",
                       m.iou, m.depth.p95),
           frame.color, truth.color,
           DepthErrorHeatMap(frame.mask, frame.depth, truth_covered, truth.depth, 0.02 * edge)});
    }
  }
}

}  // namespace

std::vector<GalleryEntry> RenderGallery(render::ProgramCache& programs,
                                        const GalleryOptions& options) {
  std::vector<GalleryEntry> out;
  DisplacedEntries(programs, options, out);
  DepthObjectEntries(programs, options, out);
  return out;
}

}  // namespace bench
