// The deform kind (ibr/kinds/deform_kind.cc): its state in a loaded object
// and what an edit rebuilds.
#pragma once

#include <memory>
#include <string>

#include "ibr/deform_object.h"
#include "ibr/object_kind.h"

namespace ibr {

// LoadedObject::world_from_object = the object's transform *
// data->object_from_norm (a similarity).
struct DeformState {
  // The normalised mesh, distance field and deformation (large, shared
  // between copies; the pass refers to them).
  std::shared_ptr<const DeformObjectData> data;
  DeformObjectOptions options;
};
DeformState& DeformOf(LoadedObject& object);
const DeformState& DeformOf(const LoadedObject& object);

// A loaded deform object of data already built (ibr::MakeDeformObject with
// `options`), placed by the similarity `world_from_object` (its file's frame
// to the world): what LoadScene makes of a scene's deform object, for the
// one-object scene of `ibr deform`.
LoadedObject LoadedDeformObject(std::string name, DeformObjectData data,
                                const DeformObjectOptions& options,
                                const glm::dmat4& world_from_object = glm::dmat4(1.0));

// Changes a deform object's options to `options`, rebuilding only what the
// change invalidates (ibr::UpdateDeformObject, on a copy of the data so the
// old stays valid until the new pass exists), then `pass` (the one
// DeformKind().MakePass made for `object`; render::DeformPass takes its
// options at construction) and the object's bounds. `defer_reach` and
// `prebuilt` as ibr::UpdateDeformObject's. InputError (nothing changed) on
// invalid options.
DeformObjectChange UpdateDeformKind(render::ProgramCache& programs, LoadedObject& object,
                                    ObjectPass& pass, DeformObjectOptions options, bool defer_reach,
                                    DeformFieldBuild* prebuilt);

}  // namespace ibr
