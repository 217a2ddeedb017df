// Per-vertex quadrics of a base mesh for curved relief mapping (Oliveira and
// Policarpo 2005, "An efficient representation for surface details", UFRGS
// RP-351): near vertex i the surface is approximated, in the vertex's tangent
// frame (x along the tangent T, y along the bitangent B, both in scene units),
// by its depth below the tangent plane
//   z(x, y) = a x^2 + b y^2,
// so a = kappa_T / 2 and b = kappa_B / 2 with kappa the normal curvatures
// along T and B (> 0 where the surface bends away from its normal: a sphere
// of radius R has a = b = 1 / (2 R); a torus's inner equator has a < 0
// along the ring). The paper fits the two coefficients per vertex by least
// squares and lets the rasteriser interpolate them; render/passes/
// relief_surface_pass.h uses them to bend the depth of the tangent-space ray.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "core/mesh.h"

namespace core {

// (a, b) per vertex of `mesh` (needs normals). `tangents` and `bitangents`
// give each vertex's unit tangent frame (orthogonal to its normal; the
// relief pass passes render::ComputeTangentFrames' T and handedness *
// N x T). Each neighbour j of the vertex's one-ring (vertices at the same
// position, e.g. seam and pole duplicates, are one surface point and share
// their rings) gives the normal curvature of the circle through both points
// tangent to the plane at i, kappa_j = 2 (p_i - p_j).N_i / |p_i - p_j|^2
// (exact for any pair on a sphere, and along a torus's ring and tube
// circles), and Euler's form kappa(theta) = kappa_T cos^2 + 2 tau cos sin +
// kappa_B sin^2 (theta = the chord's angle from T in the tangent plane) is
// fitted to them by least squares. Fewer than three chord directions (or a
// singular fit) leave an umbilic: a = b = mean kappa_j / 2; no neighbour: 0.
std::vector<glm::vec2> FitVertexQuadrics(const TriangleMesh& mesh,
                                         const std::vector<glm::vec3>& tangents,
                                         const std::vector<glm::vec3>& bitangents);

}  // namespace core
