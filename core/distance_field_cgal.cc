// The one translation unit that includes CGAL (compile time): MeshDistance's
// welding, repair, hole capping, AABB tree and inside test.
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <iterator>
#include <vector>

#include "core/distance_field.h"
#include "core/error.h"

namespace core {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<SurfaceMesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
using Side = CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel>;
namespace PMP = CGAL::Polygon_mesh_processing;

Point ToCgal(const glm::dvec3& p) { return Point(p.x, p.y, p.z); }
glm::dvec3 FromCgal(const Point& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

struct MeshDistance::Impl {
  SurfaceMesh mesh;
  std::unique_ptr<Tree> tree;
  std::unique_ptr<Side> side;
};

MeshDistance::MeshDistance(const TriangleMesh& mesh, bool cap_holes, const std::string& where)
    : impl_(std::make_unique<Impl>()) {
  mesh.Validate(where);
  if (mesh.triangle_count() == 0)
    ThrowInputError("MeshDistance", "{}: the mesh has no triangles", where);
  std::vector<Point> points;
  points.reserve(mesh.positions.size());
  for (const glm::vec3& p : mesh.positions) points.push_back(ToCgal(glm::dvec3(p)));
  std::vector<uint32_t> weld = WeldVertices(mesh.positions);
  std::vector<std::array<size_t, 3>> polygons;
  polygons.reserve(mesh.triangle_count());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    std::array<size_t, 3> v = {weld[mesh.indices[3 * t]], weld[mesh.indices[3 * t + 1]],
                               weld[mesh.indices[3 * t + 2]]};
    if (v[0] != v[1] && v[1] != v[2] && v[2] != v[0])
      polygons.push_back(v);  // collapsed by welding
  }
  // Drops unused points, degenerate and duplicate triangles.
  PMP::repair_polygon_soup(points, polygons);
  if (polygons.empty()) ThrowInputError("MeshDistance", "{}: every triangle is degenerate", where);
  // Consistent orientation; non-manifold vertices are duplicated.
  PMP::orient_polygon_soup(points, polygons);
  PMP::polygon_soup_to_polygon_mesh(points, polygons, impl_->mesh);
  SurfaceMesh& sm = impl_->mesh;

  std::vector<SurfaceMesh::Halfedge_index> cycles;
  PMP::extract_boundary_cycles(sm, std::back_inserter(cycles));
  if (!cycles.empty()) {
    size_t border_edges = 0;
    for (auto h : sm.halfedges()) border_edges += sm.is_border(h) ? 1 : 0;
    if (!cap_holes) {
      ThrowInputError("MeshDistance",
                      "{}: the mesh is open ({} boundary edges in {} loops); a signed distance "
                      "needs a closed surface (use --cap-holes to fill the holes)",
                      where, border_edges, cycles.size());
    }
    for (auto h : cycles) {
      std::vector<SurfaceMesh::Face_index> patch;
      PMP::triangulate_hole(sm, h, std::back_inserter(patch));
    }
    capped_holes_ = cycles.size();
    if (!CGAL::is_closed(sm)) {
      ThrowInputError("MeshDistance", "{}: capping {} holes did not close the mesh", where,
                      cycles.size());
    }
  }
  if (CGAL::is_closed(sm) && !PMP::is_outward_oriented(sm)) PMP::reverse_face_orientations(sm);

  impl_->tree = std::make_unique<Tree>(faces(sm).first, faces(sm).second, sm);
  impl_->tree->build();
  impl_->tree->accelerate_distance_queries();
  impl_->side = std::make_unique<Side>(*impl_->tree);

  // The closed mesh as plain data (references, the forward-truth renders).
  std::vector<uint32_t> remap(sm.number_of_vertices() + sm.number_of_removed_vertices(), 0);
  for (auto v : sm.vertices()) {
    remap[v.idx()] = static_cast<uint32_t>(closed_.positions.size());
    closed_.positions.push_back(glm::vec3(FromCgal(sm.point(v))));
  }
  for (auto f : sm.faces()) {
    for (auto v : sm.vertices_around_face(sm.halfedge(f)))
      closed_.indices.push_back(remap[v.idx()]);
  }
}

MeshDistance::~MeshDistance() = default;

size_t MeshDistance::triangle_count() const { return impl_->mesh.number_of_faces(); }

double MeshDistance::UnsignedDistance(const glm::dvec3& p) const {
  return std::sqrt(impl_->tree->squared_distance(ToCgal(p)));
}

void MeshDistance::ClosestPoint(const glm::dvec3& p, glm::dvec3* closest,
                                glm::dvec3* normal) const {
  auto [point, face] = impl_->tree->closest_point_and_primitive(ToCgal(p));
  if (closest) *closest = FromCgal(point);
  if (normal) {
    auto n = PMP::compute_face_normal(face, impl_->mesh);
    *normal = glm::dvec3(n.x(), n.y(), n.z());
  }
}

bool MeshDistance::Inside(const glm::dvec3& p) const {
  return (*impl_->side)(ToCgal(p)) == CGAL::ON_BOUNDED_SIDE;
}

double MeshDistance::SignedDistance(const glm::dvec3& p) const {
  double d = UnsignedDistance(p);
  return Inside(p) ? -d : d;
}

}  // namespace core
