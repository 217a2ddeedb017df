// From camera space to GL clip space, for the project's camera convention:
// x right, y down, z forward (OpenCV/COLMAP), depth = camera z. Image
// coordinates (u, v) have the top-left pixel CORNER at (0, 0), so pixel
// (col, row) has its centre at (col + 0.5, row + 0.5) (COLMAP's sparse
// convention). GL window x = u and window y = height - v, so a framebuffer
// read back with rows flipped (render::RenderTarget) is the image itself.
#pragma once

#include <glm/glm.hpp>

namespace core {

// Pinhole: u = fx X/Z + cx, v = fy Y/Z + cy; Z in [near, far] maps to NDC z
// in [-1, 1]. Sizes in pixels, near/far in scene units.
glm::mat4 ClipFromCamPerspective(double fx, double fy, double cx, double cy, int width, int height,
                                 double near, double far);

// Orthographic: u = sx X + cx, v = sy Y + cy (sx, sy in pixels per scene
// unit); Z in [near, far] maps to NDC z in [-1, 1].
glm::mat4 ClipFromCamOrthographic(double sx, double sy, double cx, double cy, int width, int height,
                                  double near, double far);

// The inverse of either ClipFromCam* in z: the camera z of the near and far
// clip planes (NDC z = -1 and 1) of a perspective or orthographic
// clip_from_cam, as (smaller, larger), in scene units. NDC z = (P22 z + P32)
// / (P23 z + P33) solved for z.
glm::dvec2 ClipRangeZ(const glm::mat4& clip_from_cam);

// A camera at `eye` looking at `target`, image "up" along `up` (OpenCV axes:
// the camera's -y is as close to `up` as possible). Returns cam_from_world.
glm::mat4 CamFromWorldLookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up);

}  // namespace core
