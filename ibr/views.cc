#include "ibr/views.h"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "core/look_at.h"
#include "core/parse_number.h"
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
    const std::optional<double> x = core::ParseFiniteNumber(token);
    if (!x) core::ThrowInputError(where, "'{}' is not x, y, z, -x, -y, -z or three numbers", text);
    v.push_back(*x);
  }
  if (v.size() != 3)
    core::ThrowInputError(where, "'{}' is not x, y, z, -x, -y, -z or three numbers", text);
  const glm::dvec3 up(v[0], v[1], v[2]);
  if (!(glm::length(up) > 1e-12)) core::ThrowInputError(where, "up '{}' is the zero vector", text);
  return glm::normalize(up);
}

void OrbitCamera::Check() const {
  constexpr const char* kWhere = "OrbitCamera";
  if (!(elevation_deg >= -90 && elevation_deg <= 90) || !std::isfinite(azimuth_deg)) {
    core::ThrowInputError(kWhere, "elevation {} outside [-90, 90] or azimuth {} not finite",
                          elevation_deg, azimuth_deg);
  }
  if (!(distance >= 0) || !std::isfinite(distance)) {
    core::ThrowInputError(kWhere, "distance {} must be finite and >= 0 (0 = framed)", distance);
  }
  if (!(fov_deg > 0 && fov_deg < 180))
    core::ThrowInputError(kWhere, "field of view {} degrees outside (0, 180)", fov_deg);
  if (!(glm::length(up) > 1e-9) || !std::isfinite(glm::length(up)))
    core::ThrowInputError(kWhere, "the up direction must be finite and non-zero");
}

glm::vec3 UpAxisFromName(const std::string& name, std::string_view where) {
  const bool negative = name.size() == 2 && name[0] == '-';
  const std::string axis = negative ? name.substr(1) : name;
  glm::vec3 up(0);
  if (axis == "x") up.x = 1;
  if (axis == "y") up.y = 1;
  if (axis == "z") up.z = 1;
  if (axis.size() != 1 || up == glm::vec3(0)) {
    core::ThrowInputError(where, "up axis '{}' is none of x, y, z, -x, -y, -z", name);
  }
  return negative ? -up : up;
}

namespace {

// The orbit's horizontal frame: h1 the axis after up's largest component,
// made perpendicular to up; h2 = up x h1.
void OrbitFrame(const glm::dvec3& up, glm::dvec3& h1, glm::dvec3& h2) {
  const glm::dvec3 a = glm::abs(up);
  const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
  glm::dvec3 next(0.0);
  next[(axis + 1) % 3] = 1;
  h1 = glm::normalize(next - glm::dot(next, up) * up);
  h2 = glm::cross(up, h1);
}

}  // namespace

ViewCamera OrbitCameraView(const glm::dvec3& centre, double radius, const OrbitCamera& orbit,
                           int width, int height) {
  orbit.Check();
  if (width < 1 || height < 1)
    core::ThrowInputError("OrbitCameraView", "size {}x{} px must be >= 1", width, height);
  if (!(radius > 0) || !std::isfinite(radius))
    core::ThrowInputError("OrbitCameraView", "radius {} must be finite and > 0", radius);
  const double half_fov = 0.5 * glm::radians(orbit.fov_deg);
  const double distance = orbit.distance > 0 ? orbit.distance : radius / std::sin(half_fov);
  const glm::dvec3 up = glm::normalize(orbit.up);
  glm::dvec3 h1, h2;
  OrbitFrame(up, h1, h2);
  const double el = glm::radians(orbit.elevation_deg), az = glm::radians(orbit.azimuth_deg);
  const glm::dvec3 horizontal = std::cos(az) * h1 + std::sin(az) * h2;
  const glm::dvec3 to_eye = std::cos(el) * horizontal + std::sin(el) * up;
  // The camera's up: perpendicular to the view, towards `up` (away from the
  // eye at a top view, where `up` itself is along the view).
  const glm::dvec3 cam_up = -std::sin(el) * horizontal + std::cos(el) * up;
  const double f = height / (2.0 * std::tan(half_fov));
  ViewCamera view;
  view.camera = MapCamera::Pinhole(width, height, f, f, width / 2.0, height / 2.0);
  view.cam_from_world = core::CamFromWorldLookAtDouble(centre + distance * to_eye, centre, cam_up);
  return view;
}

render::ViewSetup OrbitViewSetup(const glm::dvec3& centre, double radius, const OrbitCamera& orbit,
                                 int size_px) {
  const ViewCamera v = OrbitCameraView(centre, radius, orbit, size_px);
  const double distance = glm::length(glm::dvec3(glm::inverse(v.cam_from_world)[3]) - centre);
  render::ViewSetup setup;
  setup.cam_from_world = glm::mat4(v.cam_from_world);
  // Near at most 1.5 radii in front of the centre, never at or behind the
  // eye (an eye inside the sphere sees from 1/1000 of its distance on).
  setup.clip_from_cam = core::ClipFromCamPerspective(
      v.camera.fx, v.camera.fy, v.camera.cx, v.camera.cy, size_px, size_px,
      std::max(1e-3 * distance, distance - 1.5 * radius), distance + 1.5 * radius);
  return setup;
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
  OrbitCamera orbit{.elevation_deg = options.elevation_deg, .fov_deg = options.fov_deg};
  orbit.up = glm::normalize(options.up);
  // An arc is centred on `towards` across up (none: on the orbit's h1).
  double middle_deg = 0;
  const glm::dvec3 towards = options.towards - glm::dot(options.towards, orbit.up) * orbit.up;
  if (options.arc_deg < 360 && glm::length(towards) > 1e-9) {
    glm::dvec3 h1, h2;
    OrbitFrame(orbit.up, h1, h2);
    middle_deg = glm::degrees(std::atan2(glm::dot(towards, h2), glm::dot(towards, h1)));
  }
  std::vector<NamedView> views;
  for (int i = 0; i < options.count; ++i) {
    orbit.azimuth_deg =
        options.arc_deg >= 360 ? 360.0 * i / options.count
        : options.count == 1
            ? middle_deg
            : middle_deg + options.arc_deg * (static_cast<double>(i) / (options.count - 1) - 0.5);
    views.push_back(
        {fmt::format("orbit_{:03d}", i), OrbitCameraView(centre, radius, orbit, options.size)});
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

capture::Bounds BoxBounds(const glm::dmat4& world_from_box) {
  capture::Bounds b{glm::dvec3(1e300), glm::dvec3(-1e300)};
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 c(world_from_box * glm::dvec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0));
    b.min = glm::min(b.min, c);
    b.max = glm::max(b.max, c);
  }
  return b;
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
