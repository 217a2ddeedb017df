// CGAL (header-only) lives here and in distance_field_cgal.cc only.
#include "core/mesh_compare.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <random>
#include <vector>

#include "core/check.h"
#include "core/error.h"
#include "core/metrics.h"

namespace core {
namespace {

using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

struct Surface {
  std::vector<Triangle> triangles;
  std::vector<double> cumulative_area;
  std::vector<glm::dvec3> normals;
};

Surface MakeSurface(const TriangleMesh& m) {
  Surface s;
  double total = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]),
        c(m.positions[m.indices[t + 2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double area = 0.5 * glm::length(n);
    if (!(area > 0)) continue;  // CGAL's closest point needs non-degenerate triangles
    s.triangles.emplace_back(K::Point_3(a.x, a.y, a.z), K::Point_3(b.x, b.y, b.z),
                             K::Point_3(c.x, c.y, c.z));
    total += area;
    s.cumulative_area.push_back(total);
    s.normals.push_back(glm::normalize(n));
  }
  if (s.triangles.empty())
    ThrowInputError("CompareMeshes", "a mesh has no triangle of non-zero area");
  return s;
}

struct Direction {
  double mean = 0, p95 = 0, max = 0, abs_cos = 0, cos = 0;
};

Direction Measure(const Surface& from, const Surface& to, int samples, uint32_t seed) {
  Tree tree(to.triangles.begin(), to.triangles.end());
  tree.accelerate_distance_queries();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> d(samples);
  Direction r;
  for (int i = 0; i < samples; ++i) {
    const double pick = unit(rng) * from.cumulative_area.back();
    const size_t t = std::min<size_t>(
        std::lower_bound(from.cumulative_area.begin(), from.cumulative_area.end(), pick) -
            from.cumulative_area.begin(),
        from.triangles.size() - 1);
    double u = unit(rng), v = unit(rng);
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    const Triangle& tri = from.triangles[t];
    const K::Point_3 p = tri[0] + u * (tri[1] - tri[0]) + v * (tri[2] - tri[0]);
    const auto [closest, primitive] = tree.closest_point_and_primitive(p);
    d[i] = std::sqrt(CGAL::squared_distance(p, closest));
    const glm::dvec3 n_to = to.normals[primitive - to.triangles.begin()];
    const double c = glm::dot(from.normals[t], n_to);
    r.cos += c;
    r.abs_cos += std::abs(c);
  }
  r.cos /= samples;
  r.abs_cos /= samples;
  double sum = 0;
  for (double x : d) sum += x;
  r.mean = sum / samples;
  r.max = *std::max_element(d.begin(), d.end());
  r.p95 = Percentile(std::move(d), 0.95);
  return r;
}

}  // namespace

double SignedVolume(const TriangleMesh& mesh) {
  double six_v = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const glm::dvec3 a(mesh.positions[mesh.indices[t]]), b(mesh.positions[mesh.indices[t + 1]]),
        c(mesh.positions[mesh.indices[t + 2]]);
    six_v += glm::dot(a, glm::cross(b, c));
  }
  return six_v / 6.0;
}

double BoundsDiagonal(const TriangleMesh& mesh) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return glm::length(glm::dvec3(hi - lo));
}

MeshComparison CompareMeshes(const TriangleMesh& a, const TriangleMesh& b, int samples, double unit,
                             uint32_t seed) {
  IBR_CHECK_GT(samples, 0);
  IBR_CHECK_GT(unit, 0.0);
  const Surface sa = MakeSurface(a), sb = MakeSurface(b);
  const Direction ab = Measure(sa, sb, samples, seed), ba = Measure(sb, sa, samples, seed + 1);
  MeshComparison c;
  c.a_to_b_mean = ab.mean / unit;
  c.a_to_b_p95 = ab.p95 / unit;
  c.a_to_b_max = ab.max / unit;
  c.b_to_a_mean = ba.mean / unit;
  c.b_to_a_p95 = ba.p95 / unit;
  c.b_to_a_max = ba.max / unit;
  c.normal_consistency = 0.5 * (ab.abs_cos + ba.abs_cos);
  c.normal_agreement = 0.5 * (ab.cos + ba.cos);
  return c;
}

}  // namespace core
