// Surface-to-surface accuracy of a reconstructed mesh against a true one:
// the Chamfer distance both ways and normal consistency, from area-uniform
// samples and exact closest points (CGAL's AABB tree over the triangles; the
// meshes need not be closed).
#pragma once

#include <cstdint>

#include "core/mesh.h"

namespace core {

struct MeshComparison {
  // Distances from samples of one surface to the other, divided by `unit`.
  double a_to_b_mean = 0, a_to_b_p95 = 0, a_to_b_max = 0;  // accuracy of a (a = reconstruction)
  double b_to_a_mean = 0, b_to_a_p95 = 0, b_to_a_max = 0;  // completeness of a
  // Mean |cos| between a sample's triangle normal and that of its closest
  // triangle on the other surface, over both directions (1 = parallel).
  double normal_consistency = 0;
  // Mean signed cos of the same (1: both oriented alike; -1: one inverted).
  double normal_agreement = 0;
};

// `samples` points per surface, deterministic for a `seed`. `unit` > 0
// (e.g. the true mesh's bounding-box diagonal).
MeshComparison CompareMeshes(const TriangleMesh& a, const TriangleMesh& b, int samples, double unit,
                             uint32_t seed = 1);

// Signed volume of a closed triangle mesh (divergence theorem, in double):
// positive when its triangles are counter-clockwise seen from outside.
double SignedVolume(const TriangleMesh& mesh);

// The diagonal of the positions' bounding box.
double BoundsDiagonal(const TriangleMesh& mesh);

}  // namespace core
