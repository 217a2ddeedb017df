// Cameras: intrinsics (COLMAP's camera models with their parameter orders, plus
// an orthographic camera) and rigid poses. CPU-only, no GL.
//
// Conventions (ARCHITECTURE.md, "Cameras and datasets"; for users:
// docs/guide/importing.md, "Axes, frames and units in one place"):
// - Pose: `cam_from_world` maps world points into the camera frame,
//   p_in_cam = R * p_in_world + t (COLMAP's images.txt pose).
// - Camera frame: x right, y down, z forward (OpenCV/COLMAP).
// - Depth = camera z of the surface point (perspective: not the ray length;
//   orthographic: distance from the image plane along the view axis).
//   Invalid depth = 0 or non-finite.
// - Image coordinates: the top-left pixel CORNER is (0, 0), so pixel (col, row)
//   has its centre at (col + 0.5, row + 0.5). This is COLMAP's SPARSE
//   convention (keypoints, cameras.txt cx/cy), so our intrinsics equal COLMAP's
//   sparse intrinsics. COLMAP's DENSE maps (patch-match depth/normal .bin, read
//   by stereo_fusion) put the centre of pixel (col, row) at the INTEGER
//   coordinate: a dense workspace camera has cx_dense = cx - 0.5,
//   cy_dense = cy - 0.5 (DenseFromCamera / CameraFromDense).
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.h"

namespace capture {

// Ids 0..10 are COLMAP's model ids (cameras.bin). kOrthographic is ours
// (params sx, sy, cx, cy: pixels per scene unit and principal point) and never
// appears in a COLMAP file.
enum class CameraModel : int {
  kSimplePinhole = 0,        // f, cx, cy
  kPinhole = 1,              // fx, fy, cx, cy
  kSimpleRadial = 2,         // f, cx, cy, k
  kRadial = 3,               // f, cx, cy, k1, k2
  kOpenCv = 4,               // fx, fy, cx, cy, k1, k2, p1, p2
  kOpenCvFisheye = 5,        // fx, fy, cx, cy, k1, k2, k3, k4
  kFullOpenCv = 6,           // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6
  kFov = 7,                  // fx, fy, cx, cy, omega
  kSimpleRadialFisheye = 8,  // f, cx, cy, k
  kRadialFisheye = 9,        // f, cx, cy, k1, k2
  kThinPrismFisheye = 10,    // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1
  kOrthographic = 100,       // sx, sy, cx, cy (pixels per scene unit, pixels)
};

inline constexpr int kNumColmapModels = 11;

// "PINHOLE", "OPENCV", ..., "ORTHOGRAPHIC".
std::string_view CameraModelName(CameraModel model);
std::optional<CameraModel> CameraModelFromName(std::string_view name);
// COLMAP model id 0..10; nullopt for anything else (incl. orthographic).
std::optional<CameraModel> CameraModelFromColmapId(int id);
int CameraModelParamCount(CameraModel model);
// "fx, fy, cx, cy, k1, k2, p1, p2" (COLMAP's order strings).
std::string_view CameraModelParamOrder(CameraModel model);

// Ranges every camera obeys (docs/guide/limits.md, "Cameras"), beyond the
// image size limits of core/image_io.h. Span = image size / focal length: at unit depth for a
// perspective camera (2 tan(fov/2): 1e-4 is a 0.006 degree field of view,
// 1e3 is 179.9 degrees), in scene units for an orthographic one.
struct CameraLimits {
  double min_span = 1e-4;
  double max_perspective_span = 1e3;
  double max_orthographic_span = 2e6;  // twice the largest coordinate (dataset.h)
  double max_principal_offset = 10;    // |c - size/2| in image sizes
};
inline constexpr CameraLimits kCameraLimits;

struct Camera {
  CameraModel model = CameraModel::kPinhole;
  int width = 0;               // pixels
  int height = 0;              // pixels
  std::vector<double> params;  // in CameraModelParamOrder(model)

  static Camera Pinhole(int width, int height, double fx, double fy, double cx, double cy);
  static Camera Orthographic(int width, int height, double sx, double sy, double cx, double cy);

  // Throws core::InputError ("where: ...") unless the parameter count matches
  // the model, the size is within core's image limits, every parameter is
  // finite, focal lengths / scales and the principal point are within
  // kCameraLimits and any distortion is one-to-one over the image.
  void Check(std::string_view where) const;

  bool orthographic() const { return model == CameraModel::kOrthographic; }
  // True for every model except SIMPLE_PINHOLE, PINHOLE and ORTHOGRAPHIC.
  bool distorted() const;
  // Focal lengths in pixels (orthographic: pixels per scene unit) and the
  // principal point in the sparse convention, for every model.
  double fx() const;
  double fy() const;
  double cx() const;
  double cy() const;

  // Undistorted projection of a camera-frame point to image coordinates
  // (sparse convention). For distorted models the distortion is ignored:
  // undistort the images first (Undistort below).
  glm::dvec2 Project(const glm::dvec3& p_in_cam) const;
  // The camera-frame point at image coordinates `uv` with camera z = depth.
  glm::dvec3 Unproject(const glm::dvec2& uv, double depth) const;
  // The camera-frame point seen by the centre of pixel (col, row) at `depth`.
  glm::dvec3 UnprojectPixel(int col, int row, double depth) const {
    return Unproject({col + 0.5, row + 0.5}, depth);
  }
  // COLMAP's distortion function on normalised coordinates (x/z, y/z): where
  // an undistorted normalised point lands in the distorted image. Identity for
  // undistorted models.
  glm::dvec2 Distort(const glm::dvec2& normalized) const;

  bool operator==(const Camera&) const = default;
};

// Dense-workspace (integer pixel centre) camera from ours and back: cx, cy
// shift by 0.5 px. Orthographic cameras are rejected by the caller.
Camera DenseFromCamera(const Camera& camera);
Camera CameraFromDense(const Camera& dense);

// A rigid transform b_from_a: p_in_b = rotation * p_in_a + translation.
struct Rigid3 {
  glm::dmat3 rotation{1.0};
  glm::dvec3 translation{0.0};

  glm::dvec3 operator*(const glm::dvec3& p) const { return rotation * p + translation; }
  Rigid3 Inverse() const;
  // For cam_from_world: the camera centre in the world, -R^T t.
  glm::dvec3 Centre() const { return -glm::transpose(rotation) * translation; }
  // COLMAP's (qw, qx, qy, qz), Hamilton, unit, scalar first.
  std::array<double, 4> Quaternion() const;
  static Rigid3 FromQuaternion(const std::array<double, 4>& qwxyz, const glm::dvec3& t);
  // A float 4x4 for the GPU (render::ViewSetup::cam_from_world).
  glm::mat4 ToMat4() const;
  static Rigid3 FromMat4(const glm::dmat4& m);

  // Throws core::InputError unless rotation is orthonormal with det +1 (to
  // `tolerance`) and everything is finite.
  void Check(std::string_view where, double tolerance = 1e-6) const;
  bool operator==(const Rigid3&) const = default;
};

// The rotation nearest `m` (U V^T of its SVD): files write rotations to a
// few digits, orthonormal only to that precision.
glm::dmat3 NearestRotation(const glm::dmat3& m);

// A camera looking from `eye` at `target` with the image's up (-y) as close to
// `up` as possible.
Rigid3 LookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up);

// Removes lens distortion with OpenCV: returns the PINHOLE camera (same size,
// fx, fy, cx, cy) and remaps `image` (any channel count) into it, bilinear.
// OpenCV's own models (radial, OPENCV, FULL_OPENCV, the fisheye family) use
// cv::initUndistortRectifyMap / cv::fisheye::initUndistortRectifyMap; FOV and
// THIN_PRISM_FISHEYE, which OpenCV lacks, use a map built from Distort() and
// cv::remap. An undistorted camera is returned unchanged.
Camera UndistortedCamera(const Camera& camera);
core::Image8 UndistortImage(const Camera& camera, const core::Image8& image);
// The map itself: for every output pixel (col, row), the source position in
// the distorted image, sparse convention. 2 channels.
core::ImageF UndistortionMap(const Camera& camera);

}  // namespace capture
