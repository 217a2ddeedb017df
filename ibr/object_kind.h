// Object kinds as plug-ins (pbrt's `Shape::Create(parameters)`): each kind of
// scene object is one file in ibr/kinds/ holding its settings -> options
// conversion, its load (files -> plain CPU data), the pass it makes and, for
// the kinds the viewer edits, what an edit rebuilds. Its settings table (key,
// type, default, range, help, CLI flag) is scene::ObjectKindSpec
// (scene/scene_keys.h, below this layer so the scene reader checks keys
// without the GL library; docs/decisions/object-kinds.md). One line in
// ObjectKinds() (ibr/object_kind.cc) makes a kind known; ibr::LoadScene and
// ibr::SceneRenderer only go through this interface.
#pragma once

#include <any>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "core/check.h"
#include "core/mesh.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"
#include "scene/scene.h"
#include "scene/scene_keys.h"

namespace ibr {

// One enabled object's plain CPU data, in world space.
struct LoadedObject {
  std::string name;
  scene::ObjectType type = scene::ObjectType::kMesh;
  // The transform a view is carried into the object's frame by (rigid for
  // depth objects, a similarity for deform objects; identity for objects whose
  // geometry is already in the world).
  glm::dmat4 world_from_object{1.0};
  capture::Bounds bounds;  // world
  // The kind's own data (its file's state type, e.g. ibr::DeformState), read
  // through the kind's accessor (ibr::DeformOf, ibr::VolumeOf).
  std::any data;
};

// A kind's state in `object`; a broken invariant when the object is of
// another kind.
template <typename T>
T& KindState(LoadedObject& object) {
  T* state = std::any_cast<T>(&object.data);
  IBR_CHECK(state != nullptr);
  return *state;
}
template <typename T>
const T& KindState(const LoadedObject& object) {
  const T* state = std::any_cast<T>(&object.data);
  IBR_CHECK(state != nullptr);
  return *state;
}

// One enabled object's GPU side: the pass it draws with.
class ObjectPass {
 public:
  virtual ~ObjectPass() = default;
  virtual render::Pass& pass() = 0;
  // "depth-object", "displacement:METHOD", "volume:dvr", ... (PassNames).
  virtual std::string name() const = 0;
};

class ObjectKind {
 public:
  virtual ~ObjectKind() = default;
  virtual scene::ObjectType type() const = 0;
  // The kind's settings table (scene/scene_keys.h).
  const scene::ObjectKindSpec& spec() const;
  // Settings -> the kind's options struct (e.g. ibr::DeformObjectOptions;
  // empty for a kind without settings); InputError naming the key's `where`.
  // A disabled object's settings are checked by it.
  virtual std::any Options(const scene::Settings& settings) const = 0;
  // Files -> plain CPU data (a synthetic capture needs a context and `programs`).
  virtual LoadedObject Load(render::ProgramCache& programs, const scene::Object& object) const = 0;
  // GPU upload and the object's pass.
  virtual std::unique_ptr<ObjectPass> MakePass(render::ProgramCache& programs,
                                               const LoadedObject& object) const = 0;
};

// Every kind, in the scene guide's order; the kind of `type`.
const std::vector<const ObjectKind*>& ObjectKinds();
const ObjectKind& KindOf(scene::ObjectType type);

// Shared by the kinds' loads.
namespace kinds {
// The uniform scale of a rigid-times-uniform-scale transform; InputError
// (naming `where`) for shear or non-uniform scale.
double UniformScale(const glm::dmat4& m, const std::string& where);
// World-space copy of a mesh (positions by the transform, normals by its rotation).
core::TriangleMesh Transformed(core::TriangleMesh mesh, const glm::dmat4& world_from_object,
                               double scale);
// A scene mesh source; `displaced`: a displacement base (with uvs).
core::TriangleMesh LoadMesh(const scene::MeshSource& source, bool displaced);
capture::Bounds MeshBounds(const core::TriangleMesh& mesh, double grow);
// An object's name, type and rigid-times-scale check, for a kind's Load.
LoadedObject Named(const scene::Object& object);
}  // namespace kinds

}  // namespace ibr
