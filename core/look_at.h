// The look-at camera pose in double: core's float view matrices
// (core::CamFromWorldLookAt in projection.h) and capture's rigid poses
// (capture::LookAt) are both this one, rounded or not.
#pragma once

#include <glm/glm.hpp>

namespace core {

// A camera at `eye` looking at `target`, image "up" along `up` (OpenCV axes:
// the camera's -y is as close to `up` as possible; an `up` along the view
// falls back to x, then y). Returns cam_from_world.
glm::dmat4 CamFromWorldLookAtDouble(const glm::dvec3& eye, const glm::dvec3& target,
                                    const glm::dvec3& up);

}  // namespace core
