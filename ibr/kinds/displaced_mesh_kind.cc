// Displaced meshes (Kautz-Seidel 2001, sec. 3; Chen-Chang NCS and the ray
// methods): a base mesh carried to the world (the displacement scaled with
// it) and a height map, drawn by the method's pass (ibr/displaced_mesh.h).
#include "ibr/kinds/displaced_mesh_kind.h"

#include <fmt/format.h>

#include <optional>

#include "core/error.h"
#include "core/image_io.h"
#include "ibr/kinds/kinds.h"
#include "ibr/scene_options.h"

namespace ibr {
namespace {

struct DisplacedMeshState {
  DisplacedMeshData data;  // base in the world
  DisplacedMeshOptions options;
};

class DisplacedMeshObjectPass final : public ObjectPass {
 public:
  DisplacedMeshObjectPass(render::ProgramCache& programs, const DisplacedMeshState& s)
      : name_("displacement:" + DisplacementMethodName(s.options.method)),
        renderer_(programs, s.data, s.options) {}
  render::Pass& pass() override { return renderer_.pass(); }
  std::string name() const override { return name_; }
  const DisplacedMeshRenderer& renderer() const { return renderer_; }

 private:
  std::string name_;
  DisplacedMeshRenderer renderer_;
};

class DisplacedMeshKindImpl final : public ObjectKind {
 public:
  scene::ObjectType type() const override { return scene::ObjectType::kDisplacedMesh; }
  std::any Options(const scene::Settings& settings) const override {
    return DisplacedMeshOptionsFrom(settings);
  }
  LoadedObject Load(render::ProgramCache&, const scene::Object& o) const override {
    const double scale = kinds::UniformScale(o.world_from_object, o.where);
    DisplacedMeshOptions options = DisplacedMeshOptionsFrom(o.settings);
    options.max_displacement *= static_cast<float>(scale);
    DisplacedMeshData data;
    data.base =
        kinds::Transformed(kinds::LoadMesh(o.mesh, /*displaced=*/true), o.world_from_object, scale);
    try {
      data.height = o.height.file.empty()
                        ? DisplacementHeightMap(core::HeightPatternFromName(o.height.generator),
                                                o.height.texels)
                        : ReadHeightMap(o.height.file);
    } catch (const core::InputError& e) {
      throw core::InputError(fmt::format("{}: {}", o.height.where, e.what()));
    }
    if (!o.texture.empty()) data.color = core::ReadImage<uint8_t>(o.texture);
    return LoadedDisplacedMesh(o.name, std::move(data), options);
  }
  std::unique_ptr<ObjectPass> MakePass(render::ProgramCache& programs,
                                       const LoadedObject& object) const override {
    return std::make_unique<DisplacedMeshObjectPass>(programs,
                                                     KindState<DisplacedMeshState>(object));
  }
};

}  // namespace

LoadedObject LoadedDisplacedMesh(std::string name, DisplacedMeshData data,
                                 const DisplacedMeshOptions& options) {
  LoadedObject l;
  l.name = std::move(name);
  l.type = scene::ObjectType::kDisplacedMesh;
  DisplacedMeshState s{std::move(data), options};
  l.bounds = kinds::MeshBounds(s.data.base, s.options.max_displacement);
  l.data = std::move(s);
  return l;
}

const DisplacedMeshRenderer& DisplacedRendererOf(const ObjectPass& pass) {
  const auto* p = dynamic_cast<const DisplacedMeshObjectPass*>(&pass);
  IBR_CHECK(p != nullptr);
  return p->renderer();
}

const ObjectKind& DisplacedMeshKind() {
  static const DisplacedMeshKindImpl kind;
  return kind;
}

}  // namespace ibr
