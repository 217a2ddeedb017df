// A plain rasterised mesh (render::MeshPass), carried to the world, with an
// optional colour texture on its uvs.
#include <optional>

#include "capture/synthetic.h"
#include "core/image_io.h"
#include "ibr/kinds/kinds.h"
#include "render/gl/gpu_mesh.h"
#include "render/gl/texture_upload.h"
#include "render/passes/mesh_pass.h"

namespace ibr {
namespace {

// An RGBA8 colour texture, bilinear, repeating (as capture's textured meshes).
render::Texture UploadRgba8(const core::Image8& image) {
  return render::UploadRgba8Texture(image, render::TextureWrap::kRepeat,
                                    render::TextureWrap::kRepeat);
}

render::MeshPassOptions WithTexture(const std::optional<render::Texture>& texture) {
  render::MeshPassOptions options;
  if (texture) options.texture = &*texture;
  return options;
}

class MeshObjectPass final : public ObjectPass {
 public:
  MeshObjectPass(render::ProgramCache& programs, const capture::SceneMesh& mesh)
      : mesh_(mesh.mesh),
        texture_(mesh.texture.empty() ? std::nullopt
                                      : std::optional<render::Texture>(UploadRgba8(mesh.texture))),
        pass_(programs, mesh_, WithTexture(texture_)) {}
  render::Pass& pass() override { return pass_; }
  std::string name() const override { return "mesh"; }

 private:
  render::GpuMesh mesh_;
  std::optional<render::Texture> texture_;
  render::MeshPass pass_;
};

class MeshKindImpl final : public ObjectKind {
 public:
  scene::ObjectType type() const override { return scene::ObjectType::kMesh; }
  std::any Options(const scene::Settings&) const override { return {}; }
  LoadedObject Load(render::ProgramCache&, const scene::Object& o) const override {
    LoadedObject l = kinds::Named(o);
    const double scale = kinds::UniformScale(o.world_from_object, o.where);
    capture::SceneMesh mesh;  // in the world
    mesh.mesh = kinds::Transformed(kinds::LoadMesh(o.mesh, /*displaced=*/false),
                                   o.world_from_object, scale);
    if (!o.texture.empty()) mesh.texture = core::ReadImage<uint8_t>(o.texture, 4);
    l.bounds = kinds::MeshBounds(mesh.mesh, 0.0);
    l.data = std::move(mesh);
    return l;
  }
  std::unique_ptr<ObjectPass> MakePass(render::ProgramCache& programs,
                                       const LoadedObject& object) const override {
    return std::make_unique<MeshObjectPass>(programs, KindState<capture::SceneMesh>(object));
  }
};

}  // namespace

const ObjectKind& MeshKind() {
  static const MeshKindImpl kind;
  return kind;
}

}  // namespace ibr
