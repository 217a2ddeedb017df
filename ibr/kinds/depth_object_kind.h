// The depth-object and visual-hull kinds (ibr/kinds/depth_object_kind.cc).
#pragma once

#include <string>

#include "ibr/depth_object.h"
#include "ibr/image_maps.h"
#include "ibr/object_kind.h"
#include "ibr/scene_renderer.h"

namespace ibr {

// A loaded depth object (or visual hull, by options.method) of maps already
// in memory, placed in the world by the rigid `world_from_object`: what
// LoadScene makes of a scene's object, for a one-object scene made in code
// (`ibr render DATASET`).
LoadedObject LoadedDepthObject(std::string name, MapSet maps, const DepthObjectOptions& options,
                               const glm::dmat4& world_from_object = glm::dmat4(1.0));

// Changes a depth object's (or visual hull's) options to `options`: the pass
// takes them as they are (DepthObjectPass::set_options; no map upload, the
// other method's tables on its first frame); the object's type follows the
// method. InputError (nothing changed) on invalid options. `pass` is the one
// the kind made for `object`.
void UpdateDepthObjectKind(LoadedObject& object, ObjectPass& pass,
                           const DepthObjectOptions& options);

// The one-object scene of LoadedDepthObject(name, maps, options), its bounds
// the object's: what `ibr render DATASET` and `ibr view DATASET` draw.
LoadedScene DepthObjectScene(std::string name, MapSet maps, const DepthObjectOptions& options);

}  // namespace ibr
