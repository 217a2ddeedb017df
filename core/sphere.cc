#include "core/sphere.h"

#include <cmath>

namespace core {

std::optional<double> NearestSphereHit(const std::vector<Sphere>& spheres, const glm::dvec3& o,
                                       const glm::dvec3& d) {
  std::optional<double> best;
  for (const Sphere& s : spheres) {
    const glm::dvec3 oc = o - s.centre;
    const double a = glm::dot(d, d), b = glm::dot(oc, d),
                 c = glm::dot(oc, oc) - s.radius * s.radius;
    const double disc = b * b - a * c;
    if (!(disc >= 0) || !(a > 0)) continue;
    const double r = std::sqrt(disc);
    double t = (-b - r) / a;
    if (t <= 0) t = (-b + r) / a;
    if (t <= 0) continue;
    if (!best || t < *best) best = t;
  }
  return best;
}

}  // namespace core
