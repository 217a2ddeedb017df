// The object kinds (ibr/object_kind.h), one file each in ibr/kinds/; a new
// kind adds its accessor here and one line to ibr::ObjectKinds().
#pragma once

#include "ibr/object_kind.h"

namespace ibr {

const ObjectKind& DepthObjectKind();    // depth_object_kind.cc
const ObjectKind& VisualHullKind();     // depth_object_kind.cc
const ObjectKind& DisplacedMeshKind();  // displaced_mesh_kind.cc
const ObjectKind& MeshKind();           // mesh_kind.cc
const ObjectKind& VolumeKind();         // volume_kind.cc
const ObjectKind& DeformKind();         // deform_kind.cc

}  // namespace ibr
