// Novel cameras for rendering image-based objects: turntable orbits around
// the object's box, and other datasets' cameras resized to an output size.
#pragma once

#include <string>
#include <vector>

#include "ibr/image_maps.h"

namespace ibr {

struct NamedView {
  std::string name;  // used for output file names
  ViewCamera view;
};

struct OrbitOptions {
  int count = 24;              // views around the full circle (>= 1)
  int size = 512;              // pixels, square
  glm::dvec3 up{0, 1, 0};      // turntable axis (OBJ meshes are y-up; capture's default)
  double elevation_deg = 20;   // camera height above the box centre's horizontal plane
  double fov_deg = 40;         // full field of view; the distance frames the box's bounding sphere
  void Check() const;
};

// `count` pinhole views on a circle around the box centre, looking at it,
// named "orbit_000", ...
std::vector<NamedView> OrbitViews(const MapSet& maps, const OrbitOptions& options);

// A camera scaled to `width` pixels wide (height keeps the aspect ratio).
MapCamera ResizeCamera(const MapCamera& camera, int width);

}  // namespace ibr
