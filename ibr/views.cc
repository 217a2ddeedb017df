#include "ibr/views.h"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>
#include <utility>

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
  if (!(arc_deg > 0 && arc_deg <= 360))
    core::ThrowInputError("OrbitOptions", "arc {} degrees outside (0, 360]", arc_deg);
}

glm::dvec3 ParseUp(const std::string& text, const std::string& where) {
  static const std::pair<const char*, glm::dvec3> kAxes[] = {
      {"x", {1, 0, 0}},   {"y", {0, 1, 0}},   {"z", {0, 0, 1}},
      {"-x", {-1, 0, 0}}, {"-y", {0, -1, 0}}, {"-z", {0, 0, -1}}};
  for (const auto& [name, axis] : kAxes)
    if (text == name) return axis;
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  std::istringstream in(spaced);
  std::vector<double> v;
  for (std::string token; in >> token;) {
    size_t used = 0;
    double x = 0;
    try {
      x = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size() || !std::isfinite(x)) {
      core::ThrowInputError(where, "'{}' is not x, y, z, -x, -y, -z or three numbers", text);
    }
    v.push_back(x);
  }
  if (v.size() != 3)
    core::ThrowInputError(where, "'{}' is not x, y, z, -x, -y, -z or three numbers", text);
  const glm::dvec3 up(v[0], v[1], v[2]);
  if (!(glm::length(up) > 1e-12)) core::ThrowInputError(where, "up '{}' is the zero vector", text);
  return glm::normalize(up);
}

std::vector<NamedView> SceneCameraViews(const scene::Cameras& c, const glm::dmat4& world_from_box) {
  std::vector<NamedView> views;
  switch (c.kind) {
    case scene::Cameras::Kind::kOrbit: {
      OrbitOptions orbit;
      orbit.count = c.orbit_count;
      orbit.size = c.orbit_size;
      orbit.elevation_deg = c.orbit_elevation_deg;
      orbit.fov_deg = c.orbit_fov_deg;
      orbit.up = c.orbit_up;
      views = OrbitViews(world_from_box, orbit);
      break;
    }
    case scene::Cameras::Kind::kDataset:
      views = NamedViewsFromDataset(capture::ReadCameras(c.dataset), c.dataset_size);
      break;
    case scene::Cameras::Kind::kList:
      for (const scene::ExplicitCamera& e : c.list) {
        NamedView v;
        v.name = e.name;
        v.view.camera = e.orthographic
                            ? MapCamera::Orthographic(e.width, e.height, e.fx, e.fy, e.cx, e.cy)
                            : MapCamera::Pinhole(e.width, e.height, e.fx, e.fy, e.cx, e.cy);
        v.view.cam_from_world = e.cam_from_world;
        views.push_back(v);
      }
      break;
  }
  return views;
}

glm::dvec3 MeanViewDirection(const std::vector<ViewCamera>& views) {
  glm::dvec3 sum(0.0);
  // Row 2 of cam_from_world's rotation: the camera's z axis in world.
  for (const ViewCamera& v : views)
    sum += glm::dvec3(v.cam_from_world[0][2], v.cam_from_world[1][2], v.cam_from_world[2][2]);
  const double length = glm::length(sum);
  return length > 1e-9 ? sum / length : glm::dvec3(0.0);
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
  // An arc is centred on `towards` across up.
  const glm::dvec3 towards = options.towards - glm::dot(options.towards, up) * up;
  if (options.arc_deg < 360 && glm::length(towards) > 1e-9) a = towards;
  a = glm::normalize(a);
  const glm::dvec3 b = glm::cross(a, up);
  const double half_fov = options.fov_deg * M_PI / 360;
  const double distance = radius / std::sin(half_fov);
  const double f = 0.5 * options.size / std::tan(half_fov);
  const double el = options.elevation_deg * M_PI / 180;
  std::vector<NamedView> views;
  for (int i = 0; i < options.count; ++i) {
    const double arc = options.arc_deg * M_PI / 180;
    const double az = options.arc_deg >= 360 ? 2 * M_PI * i / options.count
                      : options.count == 1
                          ? 0.0
                          : arc * (static_cast<double>(i) / (options.count - 1) - 0.5);
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
