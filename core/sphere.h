// Rays against a union of spheres: the analytic truth that `ibr verify` and
// the depth-object tests cast their maps and views from.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <vector>

namespace core {

struct Sphere {
  glm::dvec3 centre{0.0};
  double radius = 0.0;
};

// The nearest t > 0 at which o + t d meets one of the spheres' surfaces
// (d need not be unit; from inside a sphere, its far side); none when the
// ray misses them all.
std::optional<double> NearestSphereHit(const std::vector<Sphere>& spheres, const glm::dvec3& o,
                                       const glm::dvec3& d);

}  // namespace core
