#include "ibr/scene_renderer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "core/check.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object_pass.h"
#include "ibr/scene_options.h"
#include "render/gl/gl.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/pass.h"

namespace ibr {
namespace {

using scene::ObjectType;

capture::Bounds MeshBounds(const core::TriangleMesh& mesh, double grow) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return {glm::dvec3(lo) - grow, glm::dvec3(hi) + grow};
}

capture::Bounds Union(const capture::Bounds& a, const capture::Bounds& b) {
  return {glm::min(a.min, b.min), glm::max(a.max, b.max)};
}

// The uniform scale of a rigid-times-uniform-scale transform; InputError
// (naming `where`) for shear or non-uniform scale.
double UniformScale(const glm::dmat4& m, const std::string& where) {
  const glm::dmat3 a(m);
  const double s = std::cbrt(glm::determinant(a));
  if (!(s > 0))
    throw core::InputError(fmt::format("{}/transform: not a proper rotation and scale", where));
  const glm::dmat3 r = a / s;
  const glm::dmat3 should_be_identity = glm::transpose(r) * r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (std::abs(should_be_identity[i][j] - (i == j ? 1.0 : 0.0)) > 1e-6) {
        throw core::InputError(
            fmt::format("{}/transform: only rotation, translation and uniform scale are "
                        "supported",
                        where));
      }
    }
  }
  return s;
}

// World-space copy of a mesh (positions by the transform, normals by its rotation).
core::TriangleMesh Transformed(core::TriangleMesh mesh, const glm::dmat4& world_from_object,
                               double scale) {
  const glm::dmat3 rotation = glm::dmat3(world_from_object) / scale;
  for (glm::vec3& p : mesh.positions)
    p = glm::vec3(world_from_object * glm::dvec4(glm::dvec3(p), 1.0));
  for (glm::vec3& n : mesh.normals) n = glm::vec3(glm::normalize(rotation * glm::dvec3(n)));
  return mesh;
}

core::TriangleMesh LoadMesh(const scene::MeshSource& source, bool displaced) {
  try {
    if (source.shape.empty()) {
      return displaced ? ReadDisplacementBase(source.file)
                       : capture::LoadSceneMesh(source.file).mesh;
    }
    if (displaced) return DisplacementBaseMesh(source.shape);
    if (source.shape == "plane") return DisplacementBaseMesh("plane");
    return capture::MakeShapeScene(source.shape).mesh;
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", source.where, e.what()));
  }
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

namespace {

// An RGBA8 colour texture, bilinear, repeating (as capture's textured meshes).
render::Texture UploadRgba8(const core::Image8& image) {
  render::Texture t = render::Texture::Create2D(GL_RGBA8, image.width(), image.height());
  glTextureSubImage2D(t.id(), 0, 0, 0, image.width(), image.height(), GL_RGBA, GL_UNSIGNED_BYTE,
                      image.data());
  for (GLenum p : {GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER})
    glTextureParameteri(t.id(), p, GL_LINEAR);
  for (GLenum p : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T}) glTextureParameteri(t.id(), p, GL_REPEAT);
  return t;
}

// A deform object's world box: what its normalised frame can hold, carried
// to the world.
capture::Bounds DeformWorldBounds(const LoadedObject& l) {
  const core::Box3d& b = l.deform->norm_bounds;
  return BoxBounds(l.world_from_object *
                   glm::scale(glm::translate(glm::dmat4(1.0), b.lo), b.hi - b.lo));
}

// The world bounds of every enabled object.
capture::Bounds SceneBounds(const std::vector<LoadedObject>& objects) {
  capture::Bounds bounds = objects.front().bounds;
  for (size_t i = 1; i < objects.size(); ++i) bounds = Union(bounds, objects[i].bounds);
  return bounds;
}

// A volume object (ibr/volume_object.h): its data and the world box its
// proxy covers.
void LoadVolumeInto(const scene::Object& o, LoadedObject& l) {
  LoadedVolume v = LoadVolumeObject(o);
  l.volume = std::make_shared<const VolumeObjectData>(std::move(v.data));
  l.volume_options = v.options;
  l.bounds = BoxBounds(WorldFromProxy(*l.volume));
}

LoadedObject LoadObject(render::ProgramCache& programs, const scene::Object& o) {
  LoadedObject l;
  l.name = o.name;
  l.type = o.type;
  const double scale = UniformScale(o.world_from_object, o.where);
  switch (o.type) {
    case ObjectType::kDepthObject:
    case ObjectType::kVisualHull: {
      l.depth_object = DepthObjectOptionsFrom(o.settings);
      if (std::abs(scale - 1.0) > 1e-6) {
        throw core::InputError(
            fmt::format("{}/transform: a depth object or visual hull takes rotation and "
                        "translation only (its depth maps are in scene units)",
                        o.where));
      }
      l.world_from_object = o.world_from_object;
      if (!o.images.dataset.empty()) {
        l.maps = MapsFromDataset(ReadMapDataset(o.images.dataset));
      } else {
        capture::SceneMesh mesh;
        try {
          mesh = o.images.capture_mesh.shape.empty()
                     ? capture::LoadSceneMesh(o.images.capture_mesh.file)
                     : capture::MakeShapeScene(o.images.capture_mesh.shape);
        } catch (const core::InputError& e) {
          throw core::InputError(fmt::format("{}: {}", o.images.capture_mesh.where, e.what()));
        }
        try {
          l.maps = CaptureMaps(programs, mesh, o.images.capture_rig, o.images.capture_size);
        } catch (const core::InputError& e) {
          throw core::InputError(fmt::format("{}/images/capture: {}", o.where, e.what()));
        }
      }
      l.bounds = BoxBounds(o.world_from_object * l.maps.world_from_box);
      break;
    }
    case ObjectType::kDisplacedMesh: {
      l.displacement = DisplacedMeshOptionsFrom(o.settings);
      l.displacement.max_displacement *= static_cast<float>(scale);
      l.displaced.base =
          Transformed(LoadMesh(o.mesh, /*displaced=*/true), o.world_from_object, scale);
      try {
        l.displaced.height =
            o.height.file.empty()
                ? DisplacementHeightMap(core::HeightPatternFromName(o.height.generator),
                                        o.height.texels)
                : ReadHeightMap(o.height.file);
      } catch (const core::InputError& e) {
        throw core::InputError(fmt::format("{}: {}", o.height.where, e.what()));
      }
      if (!o.texture.empty()) l.displaced.color = core::ReadImage<uint8_t>(o.texture);
      l.bounds = MeshBounds(l.displaced.base, l.displacement.max_displacement);
      break;
    }
    case ObjectType::kMesh: {
      l.mesh.mesh = Transformed(LoadMesh(o.mesh, /*displaced=*/false), o.world_from_object, scale);
      if (!o.texture.empty()) l.mesh.texture = core::ReadImage<uint8_t>(o.texture, 4);
      l.bounds = MeshBounds(l.mesh.mesh, 0.0);
      break;
    }
    case ObjectType::kVolume:
      LoadVolumeInto(o, l);
      break;
    case ObjectType::kDeform: {
      // ibr/deform_object.h, as `ibr deform`: the mesh in its file's frame,
      // normalised for the pass; the pass's frame carried to the world.
      l.deform_options = DeformObjectOptionsFrom(o.settings);
      l.deform = std::make_shared<DeformObjectData>(
          MakeDeformObject(LoadMesh(o.mesh, /*displaced=*/false), l.deform_options, o.where,
                           /*progress=*/false, &programs));
      l.world_from_object = o.world_from_object * l.deform->object_from_norm;
      l.bounds = DeformWorldBounds(l);
      break;
    }
  }
  return l;
}

}  // namespace

LoadedScene LoadScene(render::ProgramCache& programs, const scene::Scene& s) {
  LoadedScene loaded;
  loaded.name = s.name;
  for (const scene::Object& o : s.objects) {
    if (!o.enabled) {
      // Named but disabled: its options are still checked, nothing is loaded.
      if (o.type == ObjectType::kDisplacedMesh) DisplacedMeshOptionsFrom(o.settings);
      if (o.type == ObjectType::kDepthObject || o.type == ObjectType::kVisualHull)
        DepthObjectOptionsFrom(o.settings);
      if (o.type == ObjectType::kVolume) VolumeObjectOptionsFrom(o.settings);
      if (o.type == ObjectType::kDeform) DeformObjectOptionsFrom(o.settings);
      loaded.disabled.push_back(o.name);
      continue;
    }
    spdlog::info("scene {}: loading {} '{}'", s.name, scene::ObjectTypeName(o.type), o.name);
    loaded.objects.push_back(LoadObject(programs, o));
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

// One enabled object's GPU side.
struct SceneRenderer::ObjectPass {
  std::string name;
  // depth object / visual hull
  std::optional<DepthObjectPass> depth_object;
  // The transform the view is carried into the object's frame by (rigid for
  // depth objects, a similarity for deform objects; identity for the other
  // objects, whose geometry is already in the world).
  glm::dmat4 world_from_object{1.0};
  // displaced mesh
  std::optional<DisplacedMeshRenderer> displaced;
  // mesh
  std::optional<render::GpuMesh> mesh;
  std::optional<render::Texture> mesh_texture;
  std::optional<render::MeshPass> mesh_pass;
  // volume
  std::optional<render::VolumePass> volume;
  // deform (the pass's textures are uploaded; the mesh stays referred to)
  std::shared_ptr<const DeformObjectData> deform_data;
  std::optional<render::DeformPass> deform;
  // the object's pass (one of the above)
  render::Pass* pass = nullptr;
  int builds = 0;  // times the pass was built
};

SceneRenderer::SceneRenderer(render::ProgramCache& programs, const LoadedScene& scene)
    : programs_(&programs), bounds_(scene.bounds) {
  for (const LoadedObject& o : scene.objects) {
    auto p = std::make_unique<ObjectPass>();
    switch (o.type) {
      case ObjectType::kDepthObject:
      case ObjectType::kVisualHull:
        p->name = MethodName(o.depth_object.method);
        p->depth_object.emplace(programs, o.maps, o.depth_object);
        p->world_from_object = o.world_from_object;
        p->pass = &*p->depth_object;
        break;
      case ObjectType::kDisplacedMesh:
        p->name = "displacement:" + DisplacementMethodName(o.displacement.method);
        p->displaced.emplace(programs, o.displaced, o.displacement);
        p->pass = &p->displaced->pass();
        break;
      case ObjectType::kVolume: {
        const VolumeObjectData& v = *o.volume;
        p->volume.emplace(programs, v.volume, v.transfer, v.maps, v.world_from_volume,
                          o.volume_options.pass);
        p->name =
            o.volume_options.pass.mode == render::VolumeMode::kDvr ? "volume:dvr" : "volume:iso";
        p->pass = &*p->volume;
        break;
      }
      case ObjectType::kDeform:
        p->name = "deform";
        p->deform_data = o.deform;
        p->deform.emplace(programs, o.deform->Inputs(), o.deform_options.pass);
        p->world_from_object = o.world_from_object;
        p->pass = &*p->deform;
        break;
      default:
        p->name = "mesh";
        p->mesh.emplace(o.mesh.mesh);
        if (!o.mesh.texture.empty()) p->mesh_texture.emplace(UploadRgba8(o.mesh.texture));
        {
          render::MeshPassOptions mo;
          if (p->mesh_texture) mo.texture = &*p->mesh_texture;
          p->mesh_pass.emplace(programs, *p->mesh, mo);
        }
        p->pass = &*p->mesh_pass;
        break;
    }
    p->builds = 1;
    passes_.push_back(std::move(p));
  }
}

DeformObjectChange SceneRenderer::UpdateDeform(LoadedScene& scene, size_t index,
                                               DeformObjectOptions options, bool defer_reach,
                                               DeformFieldBuild* prebuilt) {
  IBR_CHECK_LT(index, scene.objects.size());
  IBR_CHECK_EQ(scene.objects.size(), passes_.size());
  LoadedObject& l = scene.objects[index];
  IBR_CHECK(l.type == ObjectType::kDeform);
  // A copy, changed aside: the old data stays valid until the new pass exists.
  auto data = std::make_shared<DeformObjectData>(*l.deform);
  const DeformObjectChange change =
      UpdateDeformObject(*data, l.deform_options, options, fmt::format("object '{}'", l.name),
                         programs_, defer_reach, prebuilt);
  if (!change.Any()) return change;
  l.deform = std::move(data);
  l.deform_options = options;
  l.bounds = DeformWorldBounds(l);
  scene.bounds = SceneBounds(scene.objects);
  bounds_ = scene.bounds;
  ObjectPass& p = *passes_[index];
  p.deform.reset();
  p.deform_data = l.deform;
  p.deform.emplace(*programs_, l.deform->Inputs(), l.deform_options.pass);
  p.pass = &*p.deform;
  ++p.builds;
  return change;
}

VolumeObjectChange SceneRenderer::UpdateVolume(LoadedScene& scene, size_t index,
                                               const VolumeObjectOptions& options, bool preview) {
  IBR_CHECK_LT(index, scene.objects.size());
  IBR_CHECK_EQ(scene.objects.size(), passes_.size());
  LoadedObject& l = scene.objects[index];
  IBR_CHECK(l.type == ObjectType::kVolume);
  const std::string where = fmt::format("object '{}'", l.name);
  // The maps changed aside (the volume itself is copied only when they do).
  VolumeObjectData maps_only;
  maps_only.maps = l.volume->maps;
  maps_only.preview_maps = l.volume->preview_maps;
  const VolumeObjectChange change =
      UpdateVolumeObject(maps_only, l.volume_options, options, where, preview);
  if (!change.Any()) return change;
  ObjectPass& p = *passes_[index];
  if (change.transfer) {
    // Only the 1D table is rewritten; none: back to the function loaded.
    try {
      p.volume->SetTransferFunction(
          options.transfer
              ? core::NormalizedTransfer(*options.transfer, l.volume->volume.NormalizationRange())
              : l.volume->transfer);
    } catch (const core::InputError& e) {
      throw core::InputError(fmt::format("{}: {}", where, e.what()));
    }
  }
  if (change.maps) {
    // The volume's texture stays: only the maps are stored and uploaded
    // anew (what a drag of the effect's parameter changes), then the options.
    try {
      p.volume->SetMaps(maps_only.maps);
      p.volume->SetOptions(options.pass);
    } catch (const core::InputError& e) {
      throw core::InputError(fmt::format("{}: {}", where, e.what()));
    }
    auto data = std::make_shared<VolumeObjectData>(*l.volume);
    data->maps = std::move(maps_only.maps);
    data->preview_maps = maps_only.preview_maps;
    l.volume = std::move(data);
    l.volume_options = options;
    l.bounds = BoxBounds(WorldFromProxy(*l.volume));
    scene.bounds = SceneBounds(scene.objects);
    bounds_ = scene.bounds;
  } else {
    try {
      p.volume->SetOptions(options.pass);
    } catch (const core::InputError& e) {
      throw core::InputError(fmt::format("{}: {}", where, e.what()));
    }
    l.volume_options = options;
  }
  p.name = options.pass.mode == render::VolumeMode::kDvr ? "volume:dvr" : "volume:iso";
  return change;
}

int SceneRenderer::PassBuilds(size_t index) const {
  IBR_CHECK_LT(index, passes_.size());
  return passes_[index]->builds;
}

SceneRenderer::~SceneRenderer() = default;

std::vector<std::string> SceneRenderer::PassNames() const {
  std::vector<std::string> names;
  for (const auto& p : passes_) names.push_back(p->name);
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
    for (auto& p : passes_) {
      if (p->pass->translucent() != translucent) continue;
      // A similarity leaves camera z (and so the composite) unchanged.
      render::ViewSetup object_setup = setup;
      object_setup.cam_from_world = glm::mat4(view.cam_from_world * p->world_from_object);
      p->pass->Draw(*target_, object_setup);
    }
  }
  return *target_;
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
                   DatasetDepth(frame.depth), render::CoverageMask(frame), {});
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
