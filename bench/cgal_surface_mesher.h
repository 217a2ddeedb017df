// CGAL's Delaunay-refinement surface mesher (Boissonnat-Oudot 2005;
// CGAL::make_surface_mesh on an Implicit_surface_3) run on the export's
// object field: the alternative to OpenVDB's volumeToMesh that `ibr bench
// export` measures (docs/decisions/mesh-extraction.md). Bench only.
#pragma once

#include <functional>
#include <glm/glm.hpp>

#include "core/mesh.h"

namespace bench {

// `field` <= 0 inside; `centre` must be inside, the object within `radius`
// of it. Facets of at most `size` (radius bound) and `distance` (centre to
// surface), angles >= 30 degrees. Manifold output, oriented outwards.
core::TriangleMesh CgalSurfaceMesh(const std::function<double(const glm::dvec3&)>& field,
                                   const glm::dvec3& centre, double radius, double size,
                                   double distance);

}  // namespace bench
