#include "ibr/object_kind.h"

#include <fmt/format.h>

#include <cmath>

#include "capture/synthetic.h"
#include "core/error.h"
#include "ibr/displaced_mesh.h"
#include "ibr/kinds/kinds.h"

namespace ibr {

const std::vector<const ObjectKind*>& ObjectKinds() {
  // The registry: one line per kind (ibr/kinds/kinds.h).
  static const std::vector<const ObjectKind*> kinds = {
      &DepthObjectKind(), &VisualHullKind(), &DisplacedMeshKind(),
      &MeshKind(),        &VolumeKind(),     &DeformKind(),
  };
  return kinds;
}

const ObjectKind& KindOf(scene::ObjectType type) {
  for (const ObjectKind* kind : ObjectKinds()) {
    if (kind->type() == type) return *kind;
  }
  IBR_CHECK(false);  // every scene::ObjectType has a kind in the registry
  return *ObjectKinds().front();
}

const scene::ObjectKindSpec& ObjectKind::spec() const {
  const scene::ObjectKindSpec* spec = scene::FindObjectKind(scene::ObjectTypeName(type()));
  IBR_CHECK(spec != nullptr);
  return *spec;
}

namespace kinds {

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

capture::Bounds MeshBounds(const core::TriangleMesh& mesh, double grow) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return {glm::dvec3(lo) - grow, glm::dvec3(hi) + grow};
}

LoadedObject Named(const scene::Object& object) {
  LoadedObject l;
  l.name = object.name;
  l.type = object.type;
  return l;
}

}  // namespace kinds
}  // namespace ibr
