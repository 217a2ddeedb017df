#include "core/surface_quadric.h"

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include "core/error.h"

namespace core {

std::vector<glm::vec2> FitVertexQuadrics(const TriangleMesh& mesh,
                                         const std::vector<glm::vec3>& tangents,
                                         const std::vector<glm::vec3>& bitangents) {
  mesh.Validate("FitVertexQuadrics");
  const size_t n = mesh.positions.size();
  if (mesh.normals.empty()) ThrowInputError("FitVertexQuadrics", "the mesh needs normals");
  if (tangents.size() != n || bitangents.size() != n) {
    ThrowInputError("FitVertexQuadrics", "{} tangents and {} bitangents for {} vertices",
                    tangents.size(), bitangents.size(), n);
  }
  // One id per surface point: vertices at the same position (to 1e-5 scene
  // units, as analytic seams differ by rounding) are one point.
  std::vector<size_t> point_of(n);
  std::vector<size_t> representative;
  {
    std::map<std::tuple<float, float, float>, size_t> ids;
    for (size_t k = 0; k < n; ++k) {
      const glm::vec3& p = mesh.positions[k];
      const auto key =
          std::make_tuple(std::round(p.x * 1e5f), std::round(p.y * 1e5f), std::round(p.z * 1e5f));
      const auto [it, inserted] = ids.emplace(key, representative.size());
      if (inserted) representative.push_back(k);
      point_of[k] = it->second;
    }
  }
  std::vector<std::set<size_t>> ring(representative.size());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const size_t a = point_of[mesh.indices[3 * t + e]];
      const size_t b = point_of[mesh.indices[3 * t + (e + 1) % 3]];
      if (a == b) continue;  // degenerate edge (a pole's collapsed row)
      ring[a].insert(b);
      ring[b].insert(a);
    }
  }
  std::vector<glm::vec2> out(n, glm::vec2(0.0f));
  for (size_t k = 0; k < n; ++k) {
    const glm::dvec3 p = mesh.positions[k];
    const glm::dvec3 nrm = glm::normalize(glm::dvec3(mesh.normals[k]));
    const glm::dvec3 t = tangents[k], b = bitangents[k];
    // Normal equations of kappa_j = [c^2, 2 c s, s^2] . (kappa_T, tau, kappa_B).
    std::array<std::array<double, 3>, 3> m{};
    std::array<double, 3> rhs{};
    double kappa_sum = 0;
    int count = 0;
    std::set<long> directions;  // chord directions, to 1e-6 rad
    for (size_t j : ring[point_of[k]]) {
      const glm::dvec3 e = glm::dvec3(mesh.positions[representative[j]]) - p;
      const double len2 = glm::dot(e, e);
      const double x = glm::dot(e, t), y = glm::dot(e, b);
      const double planar = std::hypot(x, y);
      if (!(len2 > 0) || !(planar > 0)) continue;
      const double kappa = -2.0 * glm::dot(e, nrm) / len2;
      const double c = x / planar, s = y / planar;
      const std::array<double, 3> row = {c * c, 2 * c * s, s * s};
      for (int r = 0; r < 3; ++r) {
        for (int q = 0; q < 3; ++q) m[r][q] += row[r] * row[q];
        rhs[r] += row[r] * kappa;
      }
      kappa_sum += kappa;
      ++count;
      // A chord and its opposite give the same row.
      const double angle = std::atan2(s, c);
      const double folded = angle < 0 ? angle + M_PI : angle;
      directions.insert(std::lround(folded * 1e6) % std::lround(M_PI * 1e6));
    }
    if (count == 0) continue;
    const double mean = kappa_sum / count;
    glm::dvec2 kappa(mean);
    if (directions.size() >= 3) {
      const glm::dmat3 a(m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1], m[0][2], m[1][2],
                         m[2][2]);
      const double det = glm::determinant(a);
      // Relative to the scale of the rows (entries are at most `count`).
      if (std::abs(det) > 1e-9 * count * count * count) {
        const glm::dvec3 x = glm::inverse(a) * glm::dvec3(rhs[0], rhs[1], rhs[2]);
        kappa = glm::dvec2(x[0], x[2]);
      }
    }
    out[k] = glm::vec2(0.5 * kappa);
  }
  return out;
}

}  // namespace core
