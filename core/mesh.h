// CPU triangle meshes and analytic shapes. Plain data, no GL: the GPU upload
// lives in render/gpu_mesh.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

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

// UV sphere of `radius`, `rings` x `segments` quads; uv = (longitude, latitude) in [0,1].
TriangleMesh MakeSphere(float radius, int rings = 32, int segments = 64);
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
