#include "ibr/views.h"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>

#include "core/error.h"
#include "core/projection.h"
#include "ibr/dataset_maps.h"

namespace ibr {

void OrbitOptions::Check() const {
  if (count < 1 || count > 100000)
    core::ThrowInputError("OrbitOptions", "count {} outside 1..100000", count);
  if (size < 8 || size > 16384)
    core::ThrowInputError("OrbitOptions", "size {} outside 8..16384", size);
  if (!(fov_deg > 1 && fov_deg < 170))
    core::ThrowInputError("OrbitOptions", "fov {} outside (1, 170)", fov_deg);
  if (!(std::abs(elevation_deg) < 89.9)) {
    core::ThrowInputError("OrbitOptions", "elevation {} outside (-89.9, 89.9)", elevation_deg);
  }
  if (!(glm::length(up) > 0)) core::ThrowInputError("OrbitOptions", "up axis is zero");
}

std::vector<NamedView> OrbitViews(const MapSet& maps, const OrbitOptions& options) {
  return OrbitViews(maps.world_from_box, options);
}

std::vector<NamedView> OrbitViews(const glm::dmat4& world_from_box, const OrbitOptions& options) {
  options.Check();
  const glm::dvec3 centre(world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0));
  double radius = 0;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 c(world_from_box * glm::dvec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0));
    radius = std::max(radius, glm::length(c - centre));
  }
  const glm::dvec3 up = glm::normalize(options.up);
  glm::dvec3 a = glm::cross(up, glm::dvec3(1, 0, 0));
  if (glm::length(a) < 1e-6) a = glm::cross(up, glm::dvec3(0, 1, 0));
  a = glm::normalize(a);
  const glm::dvec3 b = glm::cross(a, up);
  const double half_fov = options.fov_deg * M_PI / 360;
  const double distance = radius / std::sin(half_fov);
  const double f = 0.5 * options.size / std::tan(half_fov);
  const double el = options.elevation_deg * M_PI / 180;
  std::vector<NamedView> views;
  for (int i = 0; i < options.count; ++i) {
    const double az = 2 * M_PI * i / options.count;
    const glm::dvec3 dir = std::cos(el) * (std::cos(az) * a + std::sin(az) * b) + std::sin(el) * up;
    const glm::dvec3 eye = centre + distance * dir;
    NamedView v;
    v.name = fmt::format("orbit_{:03d}", i);
    v.view.camera = MapCamera::Pinhole(options.size, options.size, f, f, options.size / 2.0,
                                       options.size / 2.0);
    v.view.cam_from_world =
        glm::dmat4(core::CamFromWorldLookAt(glm::vec3(eye), glm::vec3(centre), glm::vec3(up)));
    views.push_back(v);
  }
  return views;
}

capture::Camera CaptureCamera(const MapCamera& c) {
  return c.orthographic ? capture::Camera::Orthographic(c.width, c.height, c.fx, c.fy, c.cx, c.cy)
                        : capture::Camera::Pinhole(c.width, c.height, c.fx, c.fy, c.cx, c.cy);
}

capture::Rigid3 RigidFromMat4(const glm::dmat4& m) {
  capture::Rigid3 r;
  r.rotation = glm::dmat3(m);
  r.translation = glm::dvec3(m[3]);
  return r;
}

ViewCamera ViewCameraFrom(const capture::RigView& view) {
  return {MapCameraFrom(view.camera, view.name), Mat4From(view.cam_from_world)};
}

capture::RigView RigViewFor(const ViewCamera& view, const capture::Bounds& bounds,
                            const std::string& name) {
  capture::RigView rv;
  rv.name = name;
  rv.camera = CaptureCamera(view.camera);
  rv.cam_from_world = RigidFromMat4(view.cam_from_world);
  const double radius = 0.5 * glm::length(bounds.extent());
  const double d = glm::length(rv.cam_from_world.Centre() - bounds.centre());
  rv.near = std::max(d - 2 * radius, 1e-3 * d);
  rv.far = d + 2 * radius;
  return rv;
}

render::ViewSetup ViewSetupFor(const ViewCamera& view, const capture::Bounds& bounds) {
  const MapCamera& c = view.camera;
  // Camera z range of the bounds' corners, widened a little; near stays in
  // front of the camera.
  double lo = 1e300, hi = -1e300;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 corner(i & 1 ? bounds.max.x : bounds.min.x,
                            i & 2 ? bounds.max.y : bounds.min.y,
                            i & 4 ? bounds.max.z : bounds.min.z);
    const double z = (view.cam_from_world * glm::dvec4(corner, 1.0)).z;
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  const double margin = 0.05 * (hi - lo) + 1e-6;
  render::ViewSetup setup;
  setup.cam_from_world = glm::mat4(view.cam_from_world);
  setup.orthographic = c.orthographic;
  if (c.orthographic) {
    setup.clip_from_cam = core::ClipFromCamOrthographic(c.fx, c.fy, c.cx, c.cy, c.width, c.height,
                                                        lo - margin, hi + margin);
  } else {
    const double near = std::max(lo - margin, 1e-4 * (hi - lo + 1e-6));
    setup.clip_from_cam = core::ClipFromCamPerspective(c.fx, c.fy, c.cx, c.cy, c.width, c.height,
                                                       near, std::max(hi + margin, 2 * near));
  }
  return setup;
}

core::ImageF DatasetDepth(const core::ImageF& camera_z) {
  core::ImageF depth = camera_z;
  for (float& z : depth.values()) {
    if (z < 0) z = 0;
  }
  return depth;
}

MapCamera ResizeCamera(const MapCamera& camera, int width) {
  const double s = static_cast<double>(width) / camera.width;
  MapCamera c = camera;
  c.width = width;
  // Clamped so that an absurd width gives an absurd (checked) size, not an overflow.
  c.height = static_cast<int>(std::clamp(std::lround(camera.height * s), 1L, long{INT_MAX}));
  const double sy = static_cast<double>(c.height) / camera.height;
  c.fx *= s;
  c.cx *= s;
  c.fy *= sy;
  c.cy *= sy;
  return c;
}

}  // namespace ibr
