#include "ibr/demo_scene.h"

#include <algorithm>
#include <cstdlib>

#include "capture/synthetic.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/views.h"
#include "capture/builtin_scenes.h"
#include "core/metrics.h"
#include "render/gl/gl.h"

namespace ibr {

void DepthObjectDemoOptions::Check() const {
  if (capture_size < 16 || capture_size > 8192 || size < 16 || size > 8192) {
    core::ThrowInputError("DepthObjectDemoOptions", "sizes {} / {} outside 16..8192", capture_size, size);
  }
  if (frames < 1 || frames > 1000) core::ThrowInputError("DepthObjectDemoOptions", "frames {} outside 1..1000", frames);
  render.Check();
}

std::filesystem::path SharedDataDir() { return capture::DefaultSharedDataDir(); }

MeshAccuracy CompareToMesh(render::ProgramCache& programs, const capture::SceneMesh& scene,
                           const ViewCamera& view, const core::ImageF& depth, double edge) {
  glm::vec3 lo, hi;
  scene.mesh.Bounds(lo, hi);
  const glm::dvec3 centre = 0.5 * (glm::dvec3(lo) + glm::dvec3(hi));
  const double radius = 0.5 * glm::length(glm::dvec3(hi) - glm::dvec3(lo));
  capture::RigView rv;
  rv.name = "truth";
  rv.camera = view.camera.orthographic
                  ? capture::Camera::Orthographic(view.camera.width, view.camera.height, view.camera.fx,
                                                  view.camera.fy, view.camera.cx, view.camera.cy)
                  : capture::Camera::Pinhole(view.camera.width, view.camera.height, view.camera.fx,
                                             view.camera.fy, view.camera.cx, view.camera.cy);
  rv.cam_from_world.rotation = glm::dmat3(view.cam_from_world);
  rv.cam_from_world.translation = glm::dvec3(view.cam_from_world[3]);
  const double d = glm::length(rv.cam_from_world.Centre() - centre);
  rv.near = std::max(d - 2 * radius, 1e-3 * d);
  rv.far = d + 2 * radius;
  capture::CaptureOptions co;
  co.size = std::max(view.camera.width, 16);
  const capture::CapturedView truth = capture::RenderView(programs, scene, rv, co);
  MeshAccuracy a;
  const core::ViewMetrics accuracy = core::CompareDepth(depth, truth.depth, edge);
  a.iou = accuracy.iou;
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

DepthObjectDemoResult RunDepthObjectDemo(render::ProgramCache& programs, const DepthObjectDemoOptions& options) {
  options.Check();
  DepthObjectDemoResult result;
  core::Stopwatch watch;
  const capture::SceneMesh scene = capture::LoadSceneMesh(options.mesh);
  glm::vec3 lo, hi;
  scene.mesh.Bounds(lo, hi);
  const capture::Bounds bounds{glm::dvec3(lo), glm::dvec3(hi)};
  capture::CaptureOptions co;
  co.size = options.capture_size;
  co.rig = "cube";
  MapSet maps;
  const glm::dvec3 ext = bounds.extent();
  const double edge = std::max({ext.x, ext.y, ext.z});
  maps.world_from_box = BoxFromBounds(bounds.min - 0.02 * edge, bounds.max + 0.02 * edge);
  for (const capture::RigView& rv : capture::MakeRig(capture::RigSpec::Parse("cube"), bounds, co)) {
    const capture::CapturedView cv = capture::RenderView(programs, scene, rv, co);
    maps.maps.push_back({rv.name, MapCameraFrom(rv.camera, rv.name), Mat4From(rv.cam_from_world), cv.depth,
                         cv.color, cv.mask});
  }
  result.capture_seconds = watch.ElapsedMs() / 1000.0;

  DepthObjectRenderer renderer(programs, std::move(maps));
  OrbitOptions orbit;
  orbit.count = options.frames;
  orbit.size = options.size;
  const std::vector<NamedView> views = OrbitViews(renderer.maps(), orbit);
  render::RenderTarget output(DepthObjectRenderer::OutputTargetOptions(options.size, options.size));
  renderer.Render(views[0].view, options.render, output);  // warm-up: shader compilation
  glFinish();
  std::vector<double> times, depth_errors;
  double iou_sum = 0;
  for (const NamedView& v : views) {
    core::Stopwatch frame_watch;
    renderer.Render(v.view, options.render, output);
    glFinish();
    times.push_back(frame_watch.ElapsedMs());
    const core::Image8 color = output.ReadColor8(0);
    const core::ImageF zc = output.ReadColorF(1);
    core::ImageF depth(zc.width(), zc.height(), 1);
    for (int y = 0; y < zc.height(); ++y) {
      for (int x = 0; x < zc.width(); ++x) depth.at(x, y) = zc.at(x, y, 1) > 0.5f ? zc.at(x, y, 0) : 0.0f;
    }
    MeshAccuracy acc = CompareToMesh(programs, scene, v.view, depth, edge);
    depth_errors.insert(depth_errors.end(), acc.depth_errors.begin(), acc.depth_errors.end());
    iou_sum += acc.iou;
    result.iou_min = std::min(result.iou_min, acc.iou);
    result.names.push_back(v.name);
    result.frames.push_back(color);
    result.depths.push_back(depth);
    result.truth.push_back(std::move(acc.truth));
  }
  result.timing = core::Summarize(times);
  result.iou_mean = iou_sum / views.size();
  const core::ErrorStats depth = core::SummarizeErrors(std::move(depth_errors));
  result.depth_mean = depth.mean;
  result.depth_p95 = depth.p95;
  return result;
}

}  // namespace ibr
