// The displaced-mesh kind (ibr/kinds/displaced_mesh_kind.cc): a loaded object
// made in code and the method's renderer behind its pass.
#pragma once

#include <string>

#include "ibr/displaced_mesh.h"
#include "ibr/object_kind.h"

namespace ibr {

// A loaded displaced mesh whose base is already in the world: what LoadScene
// makes of a scene's displaced-mesh object, for the one-object scenes of
// `ibr displace` and `ibr demo`.
LoadedObject LoadedDisplacedMesh(std::string name, DisplacedMeshData data,
                                 const DisplacedMeshOptions& options);
// The method's renderer behind the pass DisplacedMeshKind().MakePass made
// (its counts of the last frame, the tessellated truth's plan).
const DisplacedMeshRenderer& DisplacedRendererOf(const ObjectPass& pass);

}  // namespace ibr
