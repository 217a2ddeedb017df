#include "ibr/scene_renderer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/check.h"
#include "core/error.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/kinds/depth_object_kind.h"
#include "render/passes/pass.h"

namespace ibr {
namespace {

capture::Bounds Union(const capture::Bounds& a, const capture::Bounds& b) {
  return {glm::min(a.min, b.min), glm::max(a.max, b.max)};
}

// The world bounds of every enabled object.
capture::Bounds SceneBounds(const std::vector<LoadedObject>& objects) {
  capture::Bounds bounds = objects.front().bounds;
  for (size_t i = 1; i < objects.size(); ++i) bounds = Union(bounds, objects[i].bounds);
  return bounds;
}

}  // namespace

MapSet CaptureMaps(render::ProgramCache& programs, const capture::SceneMesh& mesh,
                   const std::string& rig, int size) {
  glm::vec3 lo, hi;
  mesh.mesh.Bounds(lo, hi);
  const capture::Bounds bounds{glm::dvec3(lo), glm::dvec3(hi)};
  capture::CaptureOptions co;
  co.size = size;
  co.rig = rig;
  co.Check();
  MapSet maps;
  const glm::dvec3 ext = bounds.extent();
  const double edge = std::max({ext.x, ext.y, ext.z});
  maps.world_from_box = BoxFromBounds(bounds.min - 0.02 * edge, bounds.max + 0.02 * edge);
  maps.source = fmt::format("{} captured by {}", mesh.source, rig);
  for (const capture::RigView& rv : capture::MakeRig(capture::RigSpec::Parse(rig), bounds, co)) {
    const capture::CapturedView cv = capture::RenderView(programs, mesh, rv, co);
    maps.maps.push_back({rv.name, MapCameraFrom(rv.camera, rv.name), Mat4From(rv.cam_from_world),
                         cv.depth, cv.color, cv.mask});
  }
  return maps;
}

LoadedScene OneObjectScene(LoadedObject object, std::vector<NamedView> views) {
  LoadedScene scene;
  scene.name = object.name;
  scene.bounds = object.bounds;
  scene.objects.push_back(std::move(object));
  scene.views = std::move(views);
  return scene;
}

LoadedScene LoadScene(render::ProgramCache& programs, const scene::Scene& s) {
  LoadedScene loaded;
  loaded.name = s.name;
  for (const scene::Object& o : s.objects) {
    const ObjectKind& kind = KindOf(o.type);
    if (!o.enabled) {
      // Named but disabled: its options are still checked, nothing is loaded.
      kind.Options(o.settings);
      loaded.disabled.push_back(o.name);
      continue;
    }
    spdlog::info("scene {}: loading {} '{}'", s.name, scene::ObjectTypeName(o.type), o.name);
    loaded.objects.push_back(kind.Load(programs, o));
  }
  if (loaded.objects.empty()) {
    core::ThrowInputError("LoadScene", "'{}': every object is disabled: nothing to render", s.name);
  }
  loaded.bounds = SceneBounds(loaded.objects);
  loaded.views = SceneCameraViews(s.cameras, BoxFromBounds(loaded.bounds.min, loaded.bounds.max));
  // Every frame size the scene asks for, before any frame target exists.
  for (const NamedView& v : loaded.views) {
    render::CheckFrameSize("LoadScene", fmt::format("'{}' /cameras: view '{}'", s.name, v.name),
                           v.view.camera.width, v.view.camera.height);
  }
  return loaded;
}

SceneRenderer::SceneRenderer(render::ProgramCache& programs, const LoadedScene& scene)
    : programs_(&programs), bounds_(scene.bounds) {
  for (const LoadedObject& o : scene.objects) {
    passes_.push_back({KindOf(o.type).MakePass(programs, o), o.world_from_object});
  }
}

DeformObjectChange SceneRenderer::UpdateDeform(LoadedScene& scene, size_t index,
                                               DeformObjectOptions options, bool defer_reach,
                                               DeformFieldBuild* prebuilt) {
  IBR_CHECK_LT(index, scene.objects.size());
  IBR_CHECK_EQ(scene.objects.size(), passes_.size());
  Built& b = passes_[index];
  const DeformObjectChange change = UpdateDeformKind(*programs_, scene.objects[index], *b.pass,
                                                     std::move(options), defer_reach, prebuilt);
  if (!change.Any()) return change;
  ++b.builds;
  scene.bounds = SceneBounds(scene.objects);
  bounds_ = scene.bounds;
  return change;
}

VolumeObjectChange SceneRenderer::UpdateVolume(LoadedScene& scene, size_t index,
                                               const VolumeObjectOptions& options, bool preview) {
  IBR_CHECK_LT(index, scene.objects.size());
  IBR_CHECK_EQ(scene.objects.size(), passes_.size());
  const VolumeObjectChange change =
      UpdateVolumeKind(scene.objects[index], *passes_[index].pass, options, preview);
  if (change.maps) {
    scene.bounds = SceneBounds(scene.objects);
    bounds_ = scene.bounds;
  }
  return change;
}

void SceneRenderer::UpdateDepthObject(LoadedScene& scene, size_t index,
                                      const DepthObjectOptions& options) {
  IBR_CHECK_LT(index, scene.objects.size());
  IBR_CHECK_EQ(scene.objects.size(), passes_.size());
  UpdateDepthObjectKind(scene.objects[index], *passes_[index].pass, options);
}

const ObjectPass& SceneRenderer::object_pass(size_t index) const {
  IBR_CHECK_LT(index, passes_.size());
  return *passes_[index].pass;
}

int SceneRenderer::PassBuilds(size_t index) const {
  IBR_CHECK_LT(index, passes_.size());
  return passes_[index].builds;
}

SceneRenderer::~SceneRenderer() = default;

std::vector<std::string> SceneRenderer::PassNames() const {
  std::vector<std::string> names;
  for (const Built& b : passes_) names.push_back(b.pass->name());
  return names;
}

const render::RenderTarget& SceneRenderer::Draw(const ViewCamera& view) {
  const int w = view.camera.width, h = view.camera.height;
  const render::ViewSetup setup = ViewSetupFor(view, bounds_);
  if (!target_ || target_->width() != w || target_->height() != h) {
    target_.emplace(render::FrameTargetOptions(w, h));
  }
  // Every pass into the one frame: the depth test composites them.
  render::BeginFrame(*target_);
  // Translucent passes (render::Pass::translucent, volume DVR) after every
  // opaque one, so they blend over what the depth test lets through.
  for (bool translucent : {false, true}) {
    for (Built& b : passes_) {
      render::Pass& pass = b.pass->pass();
      if (pass.translucent() != translucent) continue;
      // A similarity leaves camera z (and so the composite) unchanged.
      render::ViewSetup object_setup = setup;
      object_setup.cam_from_world = glm::mat4(view.cam_from_world * b.world_from_object);
      pass.Draw(*target_, object_setup);
    }
  }
  return *target_;
}

render::Frame SceneRenderer::ReadLast() const {
  IBR_CHECK(target_.has_value());
  return render::ReadFrame(*target_);
}

render::Frame SceneRenderer::Render(const ViewCamera& view) {
  return render::ReadFrame(Draw(view));
}

SceneRenderStats RenderViewsToDataset(
    SceneRenderer& renderer, const std::vector<NamedView>& views, const std::filesystem::path& out,
    const DatasetManifest& manifest, const std::function<void(const std::string&)>& progress,
    const std::function<std::string(const NamedView&, const render::Frame&)>& measure) {
  if (views.empty()) core::ThrowInputError("RenderViewsToDataset", "no cameras to render from");
  SceneRenderStats stats;
  stats.passes = renderer.PassNames();
  capture::DatasetWriter writer(out);
  renderer.Render(views.front().view);  // warm-up: shader compilation
  for (size_t i = 0; i < views.size(); ++i) {
    const NamedView& v = views[i];
    core::Stopwatch watch;
    const render::Frame frame = renderer.Render(v.view);
    stats.frame_ms.push_back(watch.ElapsedMs());
    const int64_t covered = frame.CoveredPixels();
    stats.object_pixels.push_back(covered);
    const int cam = writer.AddCamera(CaptureCamera(v.view.camera));
    writer.AddView(v.name, cam, RigidFromMat4(v.view.cam_from_world), frame.color,
                   DatasetDepth(frame.depth), render::CoverageMask(frame),
                   manifest.normals ? frame.normal : core::ImageF());
    const std::string note = measure ? measure(v, frame) : std::string();
    if (progress) {
      progress(fmt::format("view {}/{} {} {}x{}: {:.1f} ms, {} object pixels{}", i + 1,
                           views.size(), v.name, v.view.camera.width, v.view.camera.height,
                           stats.frame_ms.back(), covered, note));
    }
  }
  if (manifest.bounds) writer.SetBounds(*manifest.bounds);
  writer.SetDepthUnits(manifest.depth_units);
  writer.Commit();
  return stats;
}

SceneRenderStats RenderSceneToDataset(render::ProgramCache& programs, const LoadedScene& scene,
                                      const std::filesystem::path& out,
                                      const std::function<void(const std::string&)>& progress) {
  SceneRenderer renderer(programs, scene);
  return RenderViewsToDataset(renderer, scene.views, out, {.bounds = scene.bounds}, progress);
}

}  // namespace ibr
