// Plain CPU inputs of the image-based object passes (Kautz-Seidel 2001,
// sec. 4-5): registered images with depth (and/or silhouettes) and the box
// that encloses the object. Filled from a capture::Dataset
// (ibr/dataset_maps.h) or directly by tests. No GL.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/image.h"

namespace ibr {

// An undistorted camera: pinhole (u = fx x/z + cx) or orthographic
// (u = sx x + cx, with fx/fy holding sx/sy in pixels per scene unit). Sparse
// pixel convention: pixel (col, row) has its centre at (col + 0.5, row + 0.5).
struct MapCamera {
  bool orthographic = false;
  double fx = 1, fy = 1, cx = 0, cy = 0;  // pixels (orthographic: fx, fy in pixels per unit)
  int width = 0, height = 0;              // pixels

  static MapCamera Pinhole(int width, int height, double fx, double fy, double cx, double cy) {
    return {false, fx, fy, cx, cy, width, height};
  }
  static MapCamera Orthographic(int width, int height, double sx, double sy, double cx, double cy) {
    return {true, sx, sy, cx, cy, width, height};
  }
  // Throws core::InputError ("where: ...") unless sizes and scales are positive and finite.
  void Check(const std::string& where) const;
  // Image coordinates (u, v) of camera point q; false when a pinhole sees q
  // behind it (q.z <= 0).
  bool Project(const glm::dvec3& q, double& u, double& v) const {
    if (orthographic) {
      u = fx * q.x + cx;
      v = fy * q.y + cy;
      return true;
    }
    if (!(q.z > 0)) return false;
    u = fx * q.x / q.z + cx;
    v = fy * q.y / q.z + cy;
    return true;
  }
  bool InImage(double u, double v) const { return u >= 0 && u < width && v >= 0 && v < height; }
};

// One registered input image ("displacement map" in the paper's terms).
struct ImageMap {
  std::string name;
  MapCamera camera;
  glm::dmat4 cam_from_world{1.0};  // rigid, OpenCV axes (z forward)
  // 1 channel camera z of the surface seen (orthographic: distance from the
  // image plane); 0 or non-finite = invalid. Empty = no depth (visual hulls only).
  core::ImageF depth;
  // 3 or 4 channels RGB(A); empty = white.
  core::Image8 color;
  // 1 channel, > 127 = object. Empty = no silhouette (visual hulls then use depth > 0).
  core::Image8 mask;
};

// The novel view.
struct ViewCamera {
  MapCamera camera;                // its width/height are the output size
  glm::dmat4 cam_from_world{1.0};  // rigid, OpenCV axes
};

// The most maps one depth object or visual hull takes: an input limit, not
// the size of a shader table (the map table is a storage buffer, the images
// texture arrays, sized to the maps). Checked on the manifest
// (ibr::ReadMapDataset) before any view is parsed or image loaded, and by
// MapSet::Check. The GL implementation's own limits (array layers, texture
// size, storage block size, memory) are checked when the maps are uploaded
// (DepthObjectRenderer), each failure one InputError naming the maps' source.
inline constexpr int kMaxMaps = 4096;

struct MapSet {
  std::vector<ImageMap> maps;
  // The object's bounding box: [0,1]^3 -> world, affine (the paper's cube;
  // its faces are the base polygons in the cube configuration).
  glm::dmat4 world_from_box{1.0};
  // Where the maps came from (a dataset's directory), for error messages; may be empty.
  std::string source;

  // Throws core::InputError naming the map and the problem: image sizes that
  // disagree with the camera, channel counts, a singular box, no maps.
  void Check(const std::string& where) const;
};

// world_from_box for the axis-aligned box [lo, hi].
glm::dmat4 BoxFromBounds(const glm::dvec3& lo, const glm::dvec3& hi);

// The paper's cube configuration (sec. 4): six orthographic maps, one per face
// of the cube [centre - half, centre + half]^3, each looking inward along
// -/+x, -/+y, -/+z, `size` pixels square covering the face exactly. Returns the
// cameras and poses (images are left empty, for the caller to render).
std::vector<ImageMap> CubeRigMaps(const glm::dvec3& centre, double half, int size);

// Camera centre in the world (orthographic: the image plane's centre).
glm::dvec3 CameraCentre(const glm::dmat4& cam_from_world);
// The camera's +z axis in the world.
glm::dvec3 CameraAxis(const glm::dmat4& cam_from_world);

}  // namespace ibr
