// The volume kind (ibr/kinds/volume_kind.cc): its state in a loaded object
// and what an edit rebuilds.
#pragma once

#include <memory>
#include <string>

#include "ibr/object_kind.h"
#include "ibr/volume_object.h"

namespace ibr {

struct VolumeState {
  std::shared_ptr<const VolumeObjectData> data;  // large, shared between copies
  VolumeObjectOptions options;
};
VolumeState& VolumeOf(LoadedObject& object);
const VolumeState& VolumeOf(const LoadedObject& object);

// A loaded volume object of a volume already read and sampled
// (ibr::MakeVolumeObject; its world_from_volume places it): what LoadScene
// makes of a scene's volume object, for the one-object scene of `ibr volume`.
LoadedObject LoadedVolumeObject(std::string name, LoadedVolume volume);
// The pass VolumeKind().MakePass made (its last frame's slice counts).
const render::VolumePass& VolumePassOf(const ObjectPass& pass);

// Changes a volume object's options to `options` (ibr::UpdateVolumeObject):
// pass options go to render::VolumePass::SetOptions (no volume upload);
// deformation or map-size changes resample the maps and hand them to
// render::VolumePass::SetMaps (the volume's texture is kept), and the
// object's bounds follow. InputError naming the object (nothing changed) on
// invalid options. `pass` is the one VolumeKind().MakePass made for `object`.
VolumeObjectChange UpdateVolumeKind(LoadedObject& object, ObjectPass& pass,
                                    const VolumeObjectOptions& options, bool preview);

}  // namespace ibr
