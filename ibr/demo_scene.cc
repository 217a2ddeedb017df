#include "ibr/demo_scene.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>

#include "capture/builtin_scenes.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/metrics.h"
#include "core/timing.h"
#include "datasets/embedded.h"
#include "ibr/dataset_maps.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "render/gl/gl.h"
#include "scene/scene.h"

namespace ibr {

void DepthObjectDemoOptions::Check() const {
  if (size < 16 || size > 8192)
    core::ThrowInputError("DepthObjectDemoOptions", "size {} outside 16..8192", size);
  if (frames < 1 || frames > 1000)
    core::ThrowInputError("DepthObjectDemoOptions", "frames {} outside 1..1000", frames);
}

std::filesystem::path SharedDataDir() { return capture::DefaultSharedDataDir(); }

MeshAccuracy CompareToMesh(render::ProgramCache& programs, const capture::SceneMesh& scene,
                           const ViewCamera& view, const core::ImageF& depth, double edge) {
  glm::vec3 lo, hi;
  scene.mesh.Bounds(lo, hi);
  const capture::RigView rv =
      RigViewFor(view, capture::Bounds{glm::dvec3(lo), glm::dvec3(hi)}, "truth");
  capture::CaptureOptions co;
  co.size = std::max(view.camera.width, 16);
  const capture::CapturedView truth = capture::RenderView(programs, scene, rv, co);
  MeshAccuracy a;
  const core::ViewMetrics accuracy = core::CompareDepth(depth, truth.depth, edge);
  a.iou = accuracy.iou;
  a.rendered_pixels = accuracy.rendered_pixels;
  a.truth_pixels = accuracy.truth_pixels;
  a.depth_errors.assign(accuracy.depth_errors.begin(), accuracy.depth_errors.end());
  a.truth = core::Image8(truth.color.width(), truth.color.height(), 4, 255);
  for (int y = 0; y < truth.color.height(); ++y) {
    for (int x = 0; x < truth.color.width(); ++x) {
      for (int c = 0; c < 3; ++c) a.truth.at(x, y, c) = truth.color.at(x, y, c);
      if (truth.mask.at(x, y) == 0) a.truth.at(x, y, 3) = 0;
    }
  }
  return a;
}

DepthObjectDemoResult RunDepthObjectDemo(render::ProgramCache& programs,
                                         const DepthObjectDemoOptions& options) {
  options.Check();
  const std::string file = options.scene + ".json";
  std::string_view text;
  for (const auto& f : datasets::EmbeddedFiles()) {
    if (f.name == file) text = f.source;
  }
  if (text.empty())
    core::ThrowInputError("RunDepthObjectDemo", "no built-in scene '{}'", options.scene);
  scene::ReadOptions read;
  read.shared_data = SharedDataDir();
  std::istringstream in{std::string(text)};
  scene::Scene s = scene::ReadScene(in, file, read);
  const scene::Object& object = s.objects.front();
  if ((object.type != scene::ObjectType::kDepthObject &&
       object.type != scene::ObjectType::kVisualHull) ||
      object.images.capture_mesh.file.empty()) {
    core::ThrowInputError("RunDepthObjectDemo",
                          "scene '{}': the first object must be captured from a mesh file",
                          options.scene);
  }
  s.cameras = scene::Cameras{};
  s.cameras.orbit_count = options.frames;
  s.cameras.orbit_size = options.size;
  DepthObjectDemoResult result;
  result.description = s.description;
  result.capture_size = object.images.capture_size;
  core::Stopwatch watch;
  const LoadedScene loaded = LoadScene(programs, s);
  result.capture_seconds = watch.ElapsedMs() / 1000.0;
  result.render = loaded.objects.front().depth_object;
  const capture::SceneMesh truth_mesh = capture::LoadSceneMesh(object.images.capture_mesh.file);
  glm::vec3 lo, hi;
  truth_mesh.mesh.Bounds(lo, hi);
  const glm::vec3 ext = hi - lo;
  const double edge = std::max({ext.x, ext.y, ext.z});

  SceneRenderer renderer(programs, loaded);
  renderer.Render(loaded.views.front().view);  // warm-up: shader compilation
  std::vector<double> times, depth_errors;
  double iou_sum = 0;
  for (const NamedView& v : loaded.views) {
    core::Stopwatch frame_watch;
    SceneFrame frame = renderer.Render(v.view);
    times.push_back(frame_watch.ElapsedMs());
    MeshAccuracy acc = CompareToMesh(programs, truth_mesh, v.view, frame.depth, edge);
    depth_errors.insert(depth_errors.end(), acc.depth_errors.begin(), acc.depth_errors.end());
    iou_sum += acc.iou;
    result.iou_min = std::min(result.iou_min, acc.iou);
    result.names.push_back(v.name);
    result.frames.push_back(std::move(frame.color));
    result.depths.push_back(std::move(frame.depth));
    result.truth.push_back(std::move(acc.truth));
  }
  result.timing = core::Summarize(times);
  result.iou_mean = iou_sum / static_cast<double>(loaded.views.size());
  const core::ErrorStats depth = core::SummarizeErrors(std::move(depth_errors));
  result.depth_mean = depth.mean;
  result.depth_p95 = depth.p95;
  return result;
}

}  // namespace ibr
