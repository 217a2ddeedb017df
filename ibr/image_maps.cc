#include "ibr/image_maps.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/projection.h"

namespace ibr {

void MapCamera::Check(const std::string& where) const {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    core::ThrowInputError(where, "image size {}x{} is outside 1..16384", width, height);
  }
  if (!(fx > 0) || !(fy > 0) || !std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(cx) ||
      !std::isfinite(cy)) {
    core::ThrowInputError(where,
                          "camera scales must be positive and finite (fx {}, fy {}, cx {}, cy {})",
                          fx, fy, cx, cy);
  }
}

void MapSet::Check(const std::string& where) const {
  if (maps.empty()) core::ThrowInputError(where, "no maps");
  if (maps.size() > static_cast<size_t>(kMaxMaps))
    core::ThrowInputError(where, "{} maps; at most {} are supported", maps.size(), kMaxMaps);
  const double det = glm::determinant(glm::dmat3(world_from_box));
  if (!(std::abs(det) > 0) || !std::isfinite(det)) {
    core::ThrowInputError(where, "the bounding box transform is singular");
  }
  // No map has depth or a mask (a sparse-only import): say what the import
  // said, not the first map's name.
  if (std::all_of(maps.begin(), maps.end(),
                  [](const ImageMap& m) { return m.depth.empty() && m.mask.empty(); })) {
    core::ThrowInputError(
        where,
        "its {} views have poses and colour but no depth and no masks (a sparse-only import), so "
        "neither a depth object nor a visual hull can be made from them; its cameras serve as "
        "novel views (ibr render OTHER --cameras DATASET). Import COLMAP's dense workspace "
        "instead, or import again with --masks DIR",
        maps.size());
  }
  for (const ImageMap& m : maps) {
    const std::string w = where + ": map '" + m.name + "'";
    m.camera.Check(w);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) {
        if (!std::isfinite(m.cam_from_world[c][r])) core::ThrowInputError(w, "pose is not finite");
      }
    }
    auto check_size = [&](int width, int height, bool empty, const char* what) {
      if (!empty && (width != m.camera.width || height != m.camera.height)) {
        core::ThrowInputError(w, "{} image is {}x{}, camera is {}x{}", what, width, height,
                              m.camera.width, m.camera.height);
      }
    };
    check_size(m.depth.width(), m.depth.height(), m.depth.empty(), "depth");
    check_size(m.color.width(), m.color.height(), m.color.empty(), "colour");
    check_size(m.mask.width(), m.mask.height(), m.mask.empty(), "mask");
    if (!m.depth.empty() && m.depth.channels() != 1)
      core::ThrowInputError(w, "depth must have 1 channel");
    if (!m.mask.empty() && m.mask.channels() != 1)
      core::ThrowInputError(w, "mask must have 1 channel");
    if (!m.color.empty() && m.color.channels() != 3 && m.color.channels() != 4) {
      core::ThrowInputError(w, "colour must have 3 or 4 channels, has {}", m.color.channels());
    }
    if (m.depth.empty() && m.mask.empty()) core::ThrowInputError(w, "has neither depth nor mask");
  }
}

glm::dmat4 BoxFromBounds(const glm::dvec3& lo, const glm::dvec3& hi) {
  glm::dmat4 m(1.0);
  for (int k = 0; k < 3; ++k) m[k][k] = hi[k] - lo[k];
  m[3] = glm::dvec4(lo, 1.0);
  return m;
}

std::vector<ImageMap> CubeRigMaps(const glm::dvec3& centre, double half, int size) {
  struct Face {
    const char* name;
    glm::dvec3 axis;  // viewing direction
    glm::dvec3 up;
  };
  const Face faces[6] = {{"+x", {-1, 0, 0}, {0, 0, 1}}, {"-x", {1, 0, 0}, {0, 0, 1}},
                         {"+y", {0, -1, 0}, {0, 0, 1}}, {"-y", {0, 1, 0}, {0, 0, 1}},
                         {"+z", {0, 0, -1}, {0, 1, 0}}, {"-z", {0, 0, 1}, {0, 1, 0}}};
  std::vector<ImageMap> maps;
  for (const Face& f : faces) {
    ImageMap m;
    m.name = std::string("face") + f.name;
    // The image plane is the cube face the camera sits on (depth 0 there), so
    // depth runs 0..2*half across the cube.
    const glm::dvec3 eye = centre - f.axis * half;
    m.cam_from_world =
        glm::dmat4(core::CamFromWorldLookAt(glm::vec3(eye), glm::vec3(centre), glm::vec3(f.up)));
    const double s = size / (2.0 * half);
    m.camera = MapCamera::Orthographic(size, size, s, s, size / 2.0, size / 2.0);
    maps.push_back(std::move(m));
  }
  return maps;
}

glm::dvec3 CameraCentre(const glm::dmat4& cam_from_world) {
  const glm::dmat3 r(cam_from_world);
  return -(glm::transpose(r) * glm::dvec3(cam_from_world[3]));
}

glm::dvec3 CameraAxis(const glm::dmat4& cam_from_world) {
  return glm::normalize(glm::transpose(glm::dmat3(cam_from_world)) * glm::dvec3(0, 0, 1));
}

}  // namespace ibr
