// Depth objects and visual hulls (Kautz-Seidel 2001, sec. 4-5): maps from a
// dataset or a synthetic capture, drawn by ibr::DepthObjectPass in the
// object's rigid frame (the maps are in scene units: no scale).
#include "ibr/kinds/depth_object_kind.h"

#include <fmt/format.h>

#include <cmath>

#include "capture/synthetic.h"
#include "core/check.h"
#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object_pass.h"
#include "ibr/kinds/kinds.h"
#include "ibr/scene_options.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"

namespace ibr {
namespace {

struct DepthObjectState {
  MapSet maps;  // in the object's frame
  DepthObjectOptions options;
};

class DepthObjectObjectPass final : public ObjectPass {
 public:
  DepthObjectObjectPass(render::ProgramCache& programs, const DepthObjectState& s)
      : pass_(programs, s.maps, s.options) {}
  render::Pass& pass() override { return pass_; }
  std::string name() const override { return std::string(pass_.name()); }
  DepthObjectPass& depth_object_pass() { return pass_; }

 private:
  DepthObjectPass pass_;
};

MapSet LoadMaps(render::ProgramCache& programs, const scene::Object& o) {
  if (!o.images.dataset.empty()) return MapsFromDataset(ReadMapDataset(o.images.dataset));
  capture::SceneMesh mesh;
  try {
    mesh = o.images.capture_mesh.shape.empty()
               ? capture::LoadSceneMesh(o.images.capture_mesh.file)
               : capture::MakeShapeScene(o.images.capture_mesh.shape);
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", o.images.capture_mesh.where, e.what()));
  }
  try {
    return CaptureMaps(programs, mesh, o.images.capture_rig, o.images.capture_size);
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}/images/capture: {}", o.where, e.what()));
  }
}

class DepthObjectKindImpl final : public ObjectKind {
 public:
  explicit DepthObjectKindImpl(scene::ObjectType type) : type_(type) {}
  scene::ObjectType type() const override { return type_; }
  // The method is the kind (the scene reader also sets it from "type").
  std::any Options(const scene::Settings& settings) const override {
    if (settings.Has("method")) return DepthObjectOptionsFrom(settings);
    scene::Settings with_method = settings;
    with_method.Set("method", scene::ObjectTypeName(type_), "type");
    return DepthObjectOptionsFrom(with_method);
  }
  LoadedObject Load(render::ProgramCache& programs, const scene::Object& o) const override {
    LoadedObject l = kinds::Named(o);
    DepthObjectState s;
    s.options = std::any_cast<DepthObjectOptions>(Options(o.settings));
    if (std::abs(kinds::UniformScale(o.world_from_object, o.where) - 1.0) > 1e-6) {
      throw core::InputError(
          fmt::format("{}/transform: a depth object or visual hull takes rotation and "
                      "translation only (its depth maps are in scene units)",
                      o.where));
    }
    l.world_from_object = o.world_from_object;
    s.maps = LoadMaps(programs, o);
    l.bounds = BoxBounds(o.world_from_object * s.maps.world_from_box);
    l.data = std::move(s);
    return l;
  }
  std::unique_ptr<ObjectPass> MakePass(render::ProgramCache& programs,
                                       const LoadedObject& object) const override {
    return std::make_unique<DepthObjectObjectPass>(programs, KindState<DepthObjectState>(object));
  }

 private:
  scene::ObjectType type_;
};

}  // namespace

LoadedObject LoadedDepthObject(std::string name, MapSet maps, const DepthObjectOptions& options,
                               const glm::dmat4& world_from_object) {
  LoadedObject l;
  l.name = std::move(name);
  l.type = options.method == Method::kVisualHull ? scene::ObjectType::kVisualHull
                                                 : scene::ObjectType::kDepthObject;
  l.world_from_object = world_from_object;
  l.bounds = BoxBounds(world_from_object * maps.world_from_box);
  l.data = DepthObjectState{std::move(maps), options};
  return l;
}

void UpdateDepthObjectKind(LoadedObject& object, ObjectPass& pass,
                           const DepthObjectOptions& options) {
  auto* p = dynamic_cast<DepthObjectObjectPass*>(&pass);
  IBR_CHECK(p != nullptr);
  p->depth_object_pass().set_options(options);  // checks first
  KindState<DepthObjectState>(object).options = options;
  object.type = options.method == Method::kVisualHull ? scene::ObjectType::kVisualHull
                                                      : scene::ObjectType::kDepthObject;
}

LoadedScene DepthObjectScene(std::string name, MapSet maps, const DepthObjectOptions& options) {
  return OneObjectScene(LoadedDepthObject(std::move(name), std::move(maps), options));
}

const ObjectKind& DepthObjectKind() {
  static const DepthObjectKindImpl kind(scene::ObjectType::kDepthObject);
  return kind;
}

const ObjectKind& VisualHullKind() {
  static const DepthObjectKindImpl kind(scene::ObjectType::kVisualHull);
  return kind;
}

}  // namespace ibr
