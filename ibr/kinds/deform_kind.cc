// Meshes deformed and cut by an inverse displacement (Correa, Silver, Chen
// 2007): the mesh in its file's frame, normalised for render::DeformPass
// (ibr/deform_object.h, as `ibr deform` builds it), the pass's frame carried
// to the world.
#include "ibr/kinds/deform_kind.h"

#include <fmt/format.h>

#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "ibr/kinds/kinds.h"
#include "ibr/views.h"
#include "render/passes/deform_pass.h"

namespace ibr {
namespace {

// What the normalised frame can hold, carried to the world.
capture::Bounds DeformWorldBounds(const LoadedObject& l) {
  const core::Box3d& b = DeformOf(l).data->norm_bounds;
  return BoxBounds(l.world_from_object *
                   glm::scale(glm::translate(glm::dmat4(1.0), b.lo), b.hi - b.lo));
}

class DeformObjectPass final : public ObjectPass {
 public:
  DeformObjectPass(render::ProgramCache& programs, const DeformState& s) { Build(programs, s); }
  render::Pass& pass() override { return *pass_; }
  std::string name() const override { return "deform"; }
  // A new pass on `s`'s data (kept alive here: the pass refers to it).
  void Build(render::ProgramCache& programs, const DeformState& s) {
    pass_.reset();
    data_ = s.data;
    pass_.emplace(programs, data_->Inputs(), s.options.pass);
  }

 private:
  std::shared_ptr<const DeformObjectData> data_;
  std::optional<render::DeformPass> pass_;
};

class DeformKindImpl final : public ObjectKind {
 public:
  scene::ObjectType type() const override { return scene::ObjectType::kDeform; }
  std::any Options(const scene::Settings& settings) const override {
    return DeformObjectOptionsFrom(settings);
  }
  LoadedObject Load(render::ProgramCache& programs, const scene::Object& o) const override {
    kinds::UniformScale(o.world_from_object, o.where);
    const DeformObjectOptions options = DeformObjectOptionsFrom(o.settings);
    LoadedObject l = LoadedDeformObject(
        o.name,
        MakeDeformObject(kinds::LoadMesh(o.mesh, /*displaced=*/false), options, o.where,
                         /*progress=*/false, &programs),
        options, o.world_from_object);
    l.type = o.type;
    return l;
  }
  std::unique_ptr<ObjectPass> MakePass(render::ProgramCache& programs,
                                       const LoadedObject& object) const override {
    return std::make_unique<DeformObjectPass>(programs, DeformOf(object));
  }
};

}  // namespace

const ObjectKind& DeformKind() {
  static const DeformKindImpl kind;
  return kind;
}

LoadedObject LoadedDeformObject(std::string name, DeformObjectData data,
                                const DeformObjectOptions& options,
                                const glm::dmat4& world_from_object) {
  LoadedObject l;
  l.name = std::move(name);
  l.type = scene::ObjectType::kDeform;
  DeformState s{std::make_shared<const DeformObjectData>(std::move(data)), options};
  l.world_from_object = world_from_object * s.data->object_from_norm;
  l.data = std::move(s);
  l.bounds = DeformWorldBounds(l);
  return l;
}

DeformState& DeformOf(LoadedObject& object) { return KindState<DeformState>(object); }
const DeformState& DeformOf(const LoadedObject& object) { return KindState<DeformState>(object); }

DeformObjectChange UpdateDeformKind(render::ProgramCache& programs, LoadedObject& l,
                                    ObjectPass& object_pass, DeformObjectOptions options,
                                    bool defer_reach, DeformFieldBuild* prebuilt) {
  auto* p = dynamic_cast<DeformObjectPass*>(&object_pass);
  IBR_CHECK(p != nullptr);
  DeformState& s = DeformOf(l);
  // A copy, changed aside: the old data stays valid until the new pass exists.
  auto data = std::make_shared<DeformObjectData>(*s.data);
  const DeformObjectChange change =
      UpdateDeformObject(*data, s.options, options, fmt::format("object '{}'", l.name), &programs,
                         defer_reach, prebuilt);
  if (!change.Any()) return change;
  s.data = std::move(data);
  s.options = options;
  l.bounds = DeformWorldBounds(l);
  p->Build(programs, s);
  return change;
}

}  // namespace ibr
