#include "bench/cgal_surface_mesher.h"

#include <CGAL/Complex_2_in_triangulation_3.h>
#include <CGAL/IO/facets_in_complex_2_to_triangle_mesh.h>
#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_default_triangulation_3.h>
#include <CGAL/make_surface_mesh.h>

#include <vector>

#include "core/error.h"

namespace bench {

core::TriangleMesh CgalSurfaceMesh(const std::function<double(const glm::dvec3&)>& field,
                                   const glm::dvec3& centre, double radius, double size,
                                   double distance) {
  using Tr = CGAL::Surface_mesh_default_triangulation_3;
  using C2t3 = CGAL::Complex_2_in_triangulation_3<Tr>;
  using GT = Tr::Geom_traits;
  using Point = GT::Point_3;
  using Function = std::function<GT::FT(Point)>;
  using Surface = CGAL::Implicit_surface_3<GT, Function>;
  if (!(field(centre) < 0)) core::ThrowInputError("CgalSurfaceMesh", "the centre is not inside");
  Tr tr;
  C2t3 c2t3(tr);
  const Function f = [&](Point p) { return field(glm::dvec3(p.x(), p.y(), p.z())); };
  const Surface surface(f, GT::Sphere_3(Point(centre.x, centre.y, centre.z), radius * radius),
                        1e-6);
  const CGAL::Surface_mesh_default_criteria_3<Tr> criteria(30.0, size, distance);
  CGAL::make_surface_mesh(c2t3, surface, criteria, CGAL::Manifold_tag());
  CGAL::Surface_mesh<Point> sm;
  CGAL::facets_in_complex_2_to_triangle_mesh(c2t3, sm);
  core::TriangleMesh mesh;
  for (auto v : sm.vertices()) {
    const Point& p = sm.point(v);
    mesh.positions.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto face : sm.faces()) {
    for (auto v : CGAL::vertices_around_face(sm.halfedge(face), sm)) {
      mesh.indices.push_back(static_cast<uint32_t>(v.idx()));
    }
  }
  return mesh;
}

}  // namespace bench
