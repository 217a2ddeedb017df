// Test inputs for the ibr/ passes, synthesised on the CPU: analytic objects
// (unions of spheres, boxes with a cavity) ray-cast exactly into depth maps,
// so tests know the truth without a capture step.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <optional>
#include <random>
#include <vector>

#include "core/projection.h"
#include "core/sphere.h"
#include "ibr/depth_object.h"
#include "ibr/image_maps.h"

namespace ibr::testing {

using core::Sphere;

// Nearest hit t > 0 of o + t d with a union of spheres (core/sphere.h).
inline std::optional<double> HitSpheres(const std::vector<Sphere>& spheres, glm::dvec3 o,
                                        glm::dvec3 d) {
  return core::NearestSphereHit(spheres, o, d);
}

// Camera-frame ray through pixel centre (col, row): origin and direction with
// direction.z = 1, so the hit's t is the camera z.
inline void PixelRay(const MapCamera& cam, int col, int row, glm::dvec3& o, glm::dvec3& d) {
  const double u = col + 0.5, v = row + 0.5;
  if (cam.orthographic) {
    o = {(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 0.0};
    d = {0, 0, 1};
  } else {
    o = {0, 0, 0};
    d = {(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0};
  }
}

// Fills depth (camera z of the nearest hit, 0 = miss), mask and a colour that
// encodes the world position (so texturing is checkable).
inline void RenderSpheres(const std::vector<Sphere>& spheres, ImageMap& map) {
  const MapCamera& cam = map.camera;
  map.depth = core::ImageF(cam.width, cam.height, 1, 0.0f);
  map.mask = core::Image8(cam.width, cam.height, 1, 0);
  map.color = core::Image8(cam.width, cam.height, 3, 0);
  const glm::dmat4 world_from_cam = glm::inverse(map.cam_from_world);
  for (int row = 0; row < cam.height; ++row) {
    for (int col = 0; col < cam.width; ++col) {
      glm::dvec3 o, d;
      PixelRay(cam, col, row, o, d);
      const glm::dvec3 ow(world_from_cam * glm::dvec4(o, 1.0));
      const glm::dvec3 dw(world_from_cam * glm::dvec4(d, 0.0));
      const auto t = HitSpheres(spheres, ow, dw);
      if (!t) continue;
      map.depth.at(col, row) = static_cast<float>(o.z + *t * d.z);
      map.mask.at(col, row) = 255;
      const glm::dvec3 p = ow + *t * dw;
      for (int c = 0; c < 3; ++c) {
        map.color.at(col, row, c) =
            static_cast<uint8_t>(std::clamp(128.0 + 100.0 * p[c], 0.0, 255.0));
      }
    }
  }
}

// A view from `eye` looking at `target`.
inline ViewCamera PerspectiveView(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, int size,
                                  double focal_factor = 1.2) {
  ViewCamera v;
  const double f = focal_factor * size;
  v.camera = MapCamera::Pinhole(size, size, f, f, size / 2.0, size / 2.0);
  v.cam_from_world =
      glm::dmat4(core::CamFromWorldLookAt(glm::vec3(eye), glm::vec3(target), glm::vec3(up)));
  return v;
}

inline ViewCamera OrthographicView(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, int size,
                                   double half_width) {
  ViewCamera v;
  const double s = size / (2.0 * half_width);
  v.camera = MapCamera::Orthographic(size, size, s, s, size / 2.0, size / 2.0);
  v.cam_from_world =
      glm::dmat4(core::CamFromWorldLookAt(glm::vec3(eye), glm::vec3(target), glm::vec3(up)));
  return v;
}

// A ring of `count` pinhole maps at `radius` around the origin, looking at
// it, raised by `height`.
inline std::vector<ImageMap> RingMaps(int count, double radius, double height, int size) {
  std::vector<ImageMap> maps;
  for (int i = 0; i < count; ++i) {
    const double a = 2 * M_PI * i / count;
    ImageMap m;
    m.name = "ring_" + std::to_string(i);
    const glm::dvec3 eye(radius * std::cos(a), radius * std::sin(a), height);
    const ViewCamera v = PerspectiveView(eye, {0, 0, 0}, {0, 0, 1}, size, 1.0);
    m.camera = v.camera;
    m.cam_from_world = v.cam_from_world;
    maps.push_back(std::move(m));
  }
  return maps;
}

inline glm::dvec3 RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  glm::dvec3 v(n(rng), n(rng), n(rng));
  return glm::normalize(v);
}

}  // namespace ibr::testing
