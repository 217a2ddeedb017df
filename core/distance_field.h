// Signed distance fields of closed triangle meshes (Correa-Silver-Chen 2007,
// sec. 3: the implicit f whose zero set is the part of the surface a
// deformation or cut shader ray casts). CPU, double precision. Exact
// closest-point distances come from CGAL's AABB tree and the sign from CGAL's
// Side_of_triangle_mesh (robust predicates); CGAL lives in one translation
// unit (distance_field_cgal.cc) behind MeshDistance.
//
// Sign convention: > 0 OUTSIDE the solid, < 0 inside (OpenVDB's and the ray
// core's "field > 0 empty"). Correa's paper uses the opposite sign (f > 0
// inside); the deformation pass converts once, where it writes RayField.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace core {

// Axis-aligned box in world (object) units.
struct Box3d {
  glm::dvec3 lo{0.0};
  glm::dvec3 hi{0.0};
  glm::dvec3 size() const { return hi - lo; }
  bool Contains(const glm::dvec3& p) const {
    return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
  }
  // The box grown by `margin` on every side.
  Box3d Grown(double margin) const { return {lo - glm::dvec3(margin), hi + glm::dvec3(margin)}; }
  bool operator==(const Box3d&) const = default;
};

// Vertex welding: for every vertex, the index of the first vertex within
// `tolerance` of it (OBJ loaders split vertices along UV seams, analytic
// shapes repeat their seam column with rounding differences; those are not
// holes). tolerance < 0 picks 1e-6 of the bounding-box diagonal.
std::vector<uint32_t> WeldVertices(const std::vector<glm::vec3>& positions,
                                   double tolerance = -1.0);

// Topology of a triangle mesh after WeldVertices.
struct MeshBoundary {
  size_t boundary_edges = 0;     // edges used by exactly one triangle
  size_t boundary_loops = 0;     // closed chains of boundary edges (holes)
  size_t nonmanifold_edges = 0;  // edges used by three or more triangles
};
MeshBoundary FindMeshBoundary(const TriangleMesh& mesh);

// Whether a rasteriser that culls back faces still draws every pixel a ray
// from outside the solid meets first: after welding bit-equal positions only
// (triangles cover a shared edge's pixels exactly once only when their
// corners are the same floats), every triangle has three distinct corners,
// every directed edge is used by one triangle and its reverse by one other
// (closed, edge-manifold, consistently oriented, no T-junction), and every
// connected component has a positive signed volume (outward normals). Then
// a ray from outside crosses a front face before any back face, unless the
// mesh intersects itself into regions of negative winding, which this does
// not detect.
bool IsClosedOutward(const TriangleMesh& mesh);

// Exact distance and inside queries against a closed triangle mesh. The mesh
// is welded (equal positions), repaired and oriented by CGAL's polygon-soup
// functions; an open mesh is refused with an InputError naming its boundary
// edge count unless `cap_holes`, which fills every boundary loop with CGAL's
// hole triangulation (Liepa 2003; a fan is its fallback). Queries are const
// and thread-safe.
class MeshDistance {
 public:
  // `where` names the mesh's source for error messages.
  MeshDistance(const TriangleMesh& mesh, bool cap_holes, const std::string& where);
  ~MeshDistance();
  MeshDistance(const MeshDistance&) = delete;
  MeshDistance& operator=(const MeshDistance&) = delete;

  double UnsignedDistance(const glm::dvec3& p) const;
  // Closest surface point to p and the unit normal of its triangle (outward).
  void ClosestPoint(const glm::dvec3& p, glm::dvec3* closest, glm::dvec3* normal) const;
  // True when p is strictly inside the solid (on the surface counts as outside).
  bool Inside(const glm::dvec3& p) const;
  // UnsignedDistance with the sign of Inside: > 0 outside.
  double SignedDistance(const glm::dvec3& p) const;

  size_t triangle_count() const;
  size_t capped_holes() const { return capped_holes_; }
  // The closed, welded mesh the queries run on (capping triangles included).
  const TriangleMesh& closed_mesh() const { return closed_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  size_t capped_holes_ = 0;
  TriangleMesh closed_;
};

struct DistanceFieldOptions {
  // Samples along the longest axis of the box (>= 2); the voxels are cubic,
  // the other axes get as many samples as fit. 128 is the paper's 128^3.
  int resolution = 128;
  // Fill boundary loops of an open mesh instead of refusing it.
  bool cap_holes = false;
  // Worker threads over z slabs; 0 = std::thread::hardware_concurrency().
  int threads = 0;
  // Print progress on stderr (per finished slab fraction).
  bool progress = false;
  // Nodes within this many voxels of the surface get the exact distance;
  // farther nodes get the exact sign and a magnitude > the band (trilinear
  // interpolation of exact distances at the corners of their 4^3-voxel block,
  // error below the block diagonal). The deform shader needs the exact value
  // only near the surface: the fixed and Jacobian steps read the sign, the
  // threshold policy |f| < T (T <= the band), the normals differences half a
  // voxel from the zero set. Default 4 voxels (0.04 of the unit object at 128:
  // the paper's threshold); <= 0 = exact everywhere (as slow as 1 query per node).
  double exact_band_voxels = 4.0;

  void Check() const;
};

// Index of node (i, j, k) in an array over a grid of `size` nodes, x fastest,
// then y, then z.
inline size_t GridIndex(const glm::ivec3& size, int i, int j, int k) {
  return (static_cast<size_t>(k) * size.y + j) * size.x + i;
}

// A signed distance field sampled at the nodes of a regular grid:
// sample (i, j, k) sits at origin + spacing * (i, j, k). Stored as an R32F 3D
// texture with texel centres on the nodes: texture coordinate
// ((p - origin) / spacing + 0.5) / size.
struct DistanceField {
  glm::ivec3 size{0};
  glm::dvec3 origin{0.0};
  double spacing = 0.0;       // world units between samples
  std::vector<float> values;  // signed distance (> 0 outside), x fastest, then y, then z
  // Values with |value| <= exact_band are exact (infinity: all are); beyond
  // it the sign is exact and |value| > exact_band (DistanceFieldOptions).
  double exact_band = 0.0;
  int64_t distance_queries = 0;  // exact closest-point queries the build made

  // Index of node (i, j, k) in `values`.
  size_t Index(int i, int j, int k) const { return GridIndex(size, i, j, k); }
  float At(int i, int j, int k) const { return values[Index(i, j, k)]; }
  Box3d Bounds() const { return {origin, origin + spacing * glm::dvec3(size - 1)}; }
  // The most |Sample(p)| (or a GL LINEAR lookup) can exceed p's true
  // distance to the surface, inside the grid: a trilinear blend of a
  // 1-Lipschitz function's node values exceeds it by at most the voxel
  // diagonal, and nodes beyond the exact band (interpolated from their
  // block's corners) by at most half the block's diagonal. What an empty-space skip by the field
  // must subtract to stay a lower bound.
  double LookupOverestimate() const;
  // Trilinear interpolation with coordinates clamped to the grid, as a GL
  // LINEAR lookup with CLAMP_TO_EDGE does.
  double Sample(const glm::dvec3& p) const;
  // Texture coordinate of p (see above).
  glm::dvec3 TexCoord(const glm::dvec3& p) const {
    return ((p - origin) / spacing + 0.5) / glm::dvec3(size);
  }
};

// Samples the signed distance of `distance`'s mesh over `box` (typically the
// deformation region grown by the deformation's maximum displacement).
DistanceField BuildDistanceField(const MeshDistance& distance, const Box3d& box,
                                 const DistanceFieldOptions& options);

// MeshDistance + BuildDistanceField in one call; `where` names the mesh.
DistanceField BuildDistanceField(const TriangleMesh& mesh, const Box3d& box,
                                 const DistanceFieldOptions& options, const std::string& where);

}  // namespace core
