// CPU triangle meshes and analytic shapes. Plain data, no GL: the GPU upload
// lives in render/gl/gpu_mesh.h.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace core {

struct TriangleMesh {
  std::vector<glm::vec3> positions;  // object space
  std::vector<glm::vec3> normals;    // per vertex, unit length (may be empty)
  std::vector<glm::vec2> uvs;        // per vertex texture coordinates (may be empty)
  std::vector<uint32_t> indices;     // 3 per triangle, counter-clockwise seen from outside

  size_t triangle_count() const { return indices.size() / 3; }
  // Axis-aligned bounds of the positions.
  void Bounds(glm::vec3& lo, glm::vec3& hi) const;
  // Throws core::InputError if indices are out of range, sizes disagree or a
  // value is not finite. `where` names the source for the message.
  void Validate(const std::string& where) const;
};

// Replaces mesh.normals by area-weighted vertex normals (the sum of the
// incident triangles' cross products, normalised; +z where they cancel).
void SetAreaWeightedNormals(TriangleMesh& mesh);

// UV sphere of `radius`, `rings` x `segments` quads; uv = (longitude, latitude) in [0,1].
TriangleMesh MakeSphere(float radius, int rings = 32, int segments = 64);
// Capsule around +z: a cylinder of `radius` and length `length` between two
// hemispherical caps (total height length + 2 radius), as a user's UV-mapped
// capsule comes: one chart, u around the axis (periodic), v from the south
// pole (v = 0) to the north pole (v = 1) proportional to arc length along
// the profile, so texels keep their size across cap and side; a pole is a
// row of coincident vertices. `cap_rings` quads per cap, `stacks` along the
// side (length > 0).
TriangleMesh MakeCapsule(float radius, float length, int cap_rings = 12, int stacks = 4,
                         int segments = 48);
// Torus around +z: ring radius `major`, tube radius `minor`; u along the ring,
// v around the tube. The paper's 625-polygon donut is MakeTorus(R, r, 25, 25)
// (Kautz-Seidel 2001, sec. 3.4): 625 quads.
TriangleMesh MakeTorus(float major, float minor, int ring_segments = 48, int tube_segments = 24);
// Axis-aligned box [-half, half], 24 vertices with face normals; uv per face.
TriangleMesh MakeBox(glm::vec3 half_extent);
// Square in the z = 0 plane, [-half, half]^2, normal +z, uv in [0,1]^2,
// `cells` x `cells` quads.
TriangleMesh MakePlane(float half_size, int cells = 1);

}  // namespace core

namespace core {

// A concave cup around +z (a lathed closed profile): outer radius `radius`,
// height `height`, wall and floor thickness `wall`; the cavity opens towards
// +z. Flat normals per profile segment (bottom, outer wall, rim, inner wall,
// inner floor); `segments` around the axis. Its surface points satisfy the
// 2D profile distance used by the capture tests.
TriangleMesh MakeCup(float radius, float height, float wall, int segments = 128);

// A mug: MakeCup(radius, height, wall) with a torus handle (ring radius
// `handle_radius`, tube `handle_tube`) in the xz-plane, at half height, its
// inner part buried in the wall (a quarter wall short of the cavity), leaving a hole
// between handle and wall that looks along +-y. Two overlapping closed
// surfaces (no boolean union): renders and captures as their union.
TriangleMesh MakeMug(float radius, float height, float wall, float handle_radius, float handle_tube,
                     int segments = 128);

}  // namespace core

namespace core {

// Open cylinder side around +z (no caps: one continuous chart), radius
// `radius`, z in [-height/2, height/2]; u around the axis (periodic), v along
// +z; `segments` x `stacks` quads, outward normals.
TriangleMesh MakeCylinder(float radius, float height, int segments = 48, int stacks = 8);

// An irregular mesh with a continuous parameterisation (NCS needs one,
// Chen-Chang sec. 3.1): a bumpy vase -- a surface of revolution about +z whose
// radius varies with both height and angle -- sampled at jittered (u, v)
// grid points with randomly chosen quad diagonals, so triangle sizes, shapes
// and orientations all vary. u around the axis (periodic, the seam columns
// coincide), v along +z in [0, 1] (open ends). Positions and normals are
// evaluated from the analytic surface at each vertex's uv. Deterministic in `seed`.
TriangleMesh MakeIrregularVase(float radius, float height, int segments = 40, int stacks = 16,
                               uint32_t seed = 7);

}  // namespace core
