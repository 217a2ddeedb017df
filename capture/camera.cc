#include "capture/camera.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "core/check.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/look_at.h"

namespace capture {
namespace {

struct ModelInfo {
  CameraModel model;
  std::string_view name;
  int param_count;
  std::string_view order;
};

constexpr ModelInfo kModels[] = {
    {CameraModel::kSimplePinhole, "SIMPLE_PINHOLE", 3, "f, cx, cy"},
    {CameraModel::kPinhole, "PINHOLE", 4, "fx, fy, cx, cy"},
    {CameraModel::kSimpleRadial, "SIMPLE_RADIAL", 4, "f, cx, cy, k"},
    {CameraModel::kRadial, "RADIAL", 5, "f, cx, cy, k1, k2"},
    {CameraModel::kOpenCv, "OPENCV", 8, "fx, fy, cx, cy, k1, k2, p1, p2"},
    {CameraModel::kOpenCvFisheye, "OPENCV_FISHEYE", 8, "fx, fy, cx, cy, k1, k2, k3, k4"},
    {CameraModel::kFullOpenCv, "FULL_OPENCV", 12, "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6"},
    {CameraModel::kFov, "FOV", 5, "fx, fy, cx, cy, omega"},
    {CameraModel::kSimpleRadialFisheye, "SIMPLE_RADIAL_FISHEYE", 4, "f, cx, cy, k"},
    {CameraModel::kRadialFisheye, "RADIAL_FISHEYE", 5, "f, cx, cy, k1, k2"},
    {CameraModel::kThinPrismFisheye, "THIN_PRISM_FISHEYE", 12,
     "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1"},
    {CameraModel::kOrthographic, "ORTHOGRAPHIC", 4, "sx, sy, cx, cy"},
};

const ModelInfo& Info(CameraModel model) {
  for (const auto& info : kModels) {
    if (info.model == model) return info;
  }
  IBR_CHECK(false && "unknown camera model");
  return kModels[0];
}

// Models whose first parameter is a single focal length f.
bool SingleFocal(CameraModel m) {
  return m == CameraModel::kSimplePinhole || m == CameraModel::kSimpleRadial ||
         m == CameraModel::kRadial || m == CameraModel::kSimpleRadialFisheye ||
         m == CameraModel::kRadialFisheye;
}

}  // namespace

std::string_view CameraModelName(CameraModel model) { return Info(model).name; }

std::optional<CameraModel> CameraModelFromName(std::string_view name) {
  for (const auto& info : kModels) {
    if (info.name == name) return info.model;
  }
  return std::nullopt;
}

std::optional<CameraModel> CameraModelFromColmapId(int id) {
  if (id < 0 || id >= kNumColmapModels) return std::nullopt;
  return static_cast<CameraModel>(id);
}

int CameraModelParamCount(CameraModel model) { return Info(model).param_count; }
std::string_view CameraModelParamOrder(CameraModel model) { return Info(model).order; }

Camera Camera::Pinhole(int width, int height, double fx, double fy, double cx, double cy) {
  return {CameraModel::kPinhole, width, height, {fx, fy, cx, cy}};
}

Camera Camera::Orthographic(int width, int height, double sx, double sy, double cx, double cy) {
  return {CameraModel::kOrthographic, width, height, {sx, sy, cx, cy}};
}

namespace {

// The distortion must be one-to-one over the image, or no undistortion
// exists: along rays from the principal point to each corner and edge
// midpoint, the distorted point must move outward (strictly) and stay finite.
void CheckInvertibleDistortion(const Camera& camera, std::string_view where) {
  constexpr int kSteps = 512;
  const double w = camera.width, h = camera.height;
  for (const glm::dvec2 edge :
       {glm::dvec2(0, 0), glm::dvec2(w, 0), glm::dvec2(0, h), glm::dvec2(w, h),
        glm::dvec2(w / 2, 0), glm::dvec2(w / 2, h), glm::dvec2(0, h / 2), glm::dvec2(w, h / 2)}) {
    const glm::dvec2 end((edge.x - camera.cx()) / camera.fx(),
                         (edge.y - camera.cy()) / camera.fy());
    const double length = glm::length(end);
    if (!(length > 0)) continue;
    const glm::dvec2 dir = end / length;
    double previous = 0;
    for (int i = 1; i <= kSteps; ++i) {
      const glm::dvec2 d = camera.Distort(end * (static_cast<double>(i) / kSteps));
      const double radial = glm::dot(d, dir);
      if (!std::isfinite(d.x) || !std::isfinite(d.y) || !(radial > previous)) {
        core::ThrowInputError(
            where,
            "{} distortion ({}) folds over within the image (towards pixel ({}, {})): "
            "it cannot be undistorted",
            CameraModelName(camera.model), fmt::join(camera.params, ", "), edge.x, edge.y);
      }
      previous = radial;
    }
  }
}

}  // namespace

void Camera::Check(std::string_view where) const {
  const int n = CameraModelParamCount(model);
  if (static_cast<int>(params.size()) != n) {
    core::ThrowInputError(where, "camera model {} needs {} parameters ({}), got {}",
                          CameraModelName(model), n, CameraModelParamOrder(model), params.size());
  }
  // Only the sides are bounded here (by the largest image ibr reads): a
  // camera's pixel count is bounded where its images are allocated, by the
  // memory budget (core::CheckMemory), and where they become textures or
  // frames, by the GL limits (render::CheckFrameSize), each naming its reason.
  if (width <= 0 || height <= 0) {
    core::ThrowInputError(where, "camera size {}x{} is empty", width, height);
  }
  if (width > core::kMaxImageSide || height > core::kMaxImageSide) {
    core::ThrowInputError(where,
                          "camera size {}x{}: a side above {} pixels, the largest image ibr "
                          "reads (the GL_MAX_TEXTURE_SIZE of Mesa and most GPUs)",
                          width, height, core::kMaxImageSide);
  }
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) {
      core::ThrowInputError(where, "camera parameter {} ({}) is not finite", i,
                            CameraModelParamOrder(model));
    }
  }
  if (!(fx() > 0) || !(fy() > 0)) {
    core::ThrowInputError(where, "camera focal length / scale must be positive (fx {}, fy {})",
                          fx(), fy());
  }
  // What the image spans at unit depth (perspective: 2 tan(fov/2)) or in
  // scene units (orthographic); outside these ranges the projection matrices
  // lose float precision.
  const double min_span = kCameraLimits.min_span;
  const double max_span =
      orthographic() ? kCameraLimits.max_orthographic_span : kCameraLimits.max_perspective_span;
  for (const auto& [axis, pixels, focal] :
       {std::tuple{"x", width, fx()}, std::tuple{"y", height, fy()}}) {
    const double span = pixels / focal;
    if (!(span >= min_span && span <= max_span)) {
      core::ThrowInputError(
          where, "{} {} {} gives an image span of {:.3g} {} along {}; allowed {:.3g}..{:.3g}",
          orthographic() ? "scale" : "focal length", axis == std::string_view("x") ? "fx" : "fy",
          focal, span, orthographic() ? "scene units" : "(2 tan(fov/2))", axis, min_span, max_span);
    }
  }
  const double max_offset = kCameraLimits.max_principal_offset;
  if (std::abs(cx() - 0.5 * width) > max_offset * width ||
      std::abs(cy() - 0.5 * height) > max_offset * height) {
    core::ThrowInputError(
        where, "principal point ({}, {}) is more than {} image sizes from the centre of {}x{}",
        cx(), cy(), max_offset, width, height);
  }
  if (distorted()) CheckInvertibleDistortion(*this, where);
}

bool Camera::distorted() const {
  return model != CameraModel::kSimplePinhole && model != CameraModel::kPinhole &&
         model != CameraModel::kOrthographic;
}

double Camera::fx() const { return params.at(0); }
double Camera::fy() const { return SingleFocal(model) ? params.at(0) : params.at(1); }
double Camera::cx() const { return SingleFocal(model) ? params.at(1) : params.at(2); }
double Camera::cy() const { return SingleFocal(model) ? params.at(2) : params.at(3); }

glm::dvec2 Camera::Project(const glm::dvec3& p) const {
  if (orthographic()) return {fx() * p.x + cx(), fy() * p.y + cy()};
  return {fx() * p.x / p.z + cx(), fy() * p.y / p.z + cy()};
}

glm::dvec3 Camera::Unproject(const glm::dvec2& uv, double depth) const {
  const double x = (uv.x - cx()) / fx();
  const double y = (uv.y - cy()) / fy();
  if (orthographic()) return {x, y, depth};
  return {x * depth, y * depth, depth};
}

glm::dvec2 Camera::Distort(const glm::dvec2& n) const {
  const double u = n.x, v = n.y;
  const auto& p = params;
  const double r2 = u * u + v * v;
  const double r = std::sqrt(r2);
  constexpr double kEps = 1e-12;
  switch (model) {
    case CameraModel::kSimplePinhole:
    case CameraModel::kPinhole:
    case CameraModel::kOrthographic:
      return n;
    case CameraModel::kSimpleRadial:
      return n * (1 + p[3] * r2);
    case CameraModel::kRadial:
      return n * (1 + p[3] * r2 + p[4] * r2 * r2);
    case CameraModel::kOpenCv: {
      const double radial = 1 + p[4] * r2 + p[5] * r2 * r2;
      return {u * radial + 2 * p[6] * u * v + p[7] * (r2 + 2 * u * u),
              v * radial + 2 * p[7] * u * v + p[6] * (r2 + 2 * v * v)};
    }
    case CameraModel::kFullOpenCv: {
      const double r4 = r2 * r2, r6 = r4 * r2;
      const double radial =
          (1 + p[4] * r2 + p[5] * r4 + p[8] * r6) / (1 + p[9] * r2 + p[10] * r4 + p[11] * r6);
      return {u * radial + 2 * p[6] * u * v + p[7] * (r2 + 2 * u * u),
              v * radial + 2 * p[7] * u * v + p[6] * (r2 + 2 * v * v)};
    }
    case CameraModel::kOpenCvFisheye:
    case CameraModel::kSimpleRadialFisheye:
    case CameraModel::kRadialFisheye: {
      if (r < kEps) return n;
      const double t = std::atan(r), t2 = t * t;
      double poly = 1;
      if (model == CameraModel::kOpenCvFisheye) {
        poly += t2 * (p[4] + t2 * (p[5] + t2 * (p[6] + t2 * p[7])));
      } else if (model == CameraModel::kSimpleRadialFisheye) {
        poly += p[3] * t2;
      } else {
        poly += t2 * (p[3] + t2 * p[4]);
      }
      return n * (t * poly / r);
    }
    case CameraModel::kFov: {
      const double omega = p[4];
      if (std::abs(omega) < kEps || r < kEps) return n;
      return n * (std::atan(2 * r * std::tan(omega / 2)) / (r * omega));
    }
    case CameraModel::kThinPrismFisheye: {
      glm::dvec2 f = n;  // equidistant fisheye mapping first
      if (r > kEps) f = n * (std::atan(r) / r);
      const double fu = f.x, fv = f.y;
      const double q2 = fu * fu + fv * fv, q4 = q2 * q2, q6 = q4 * q2, q8 = q4 * q4;
      const double radial = p[4] * q2 + p[5] * q4 + p[8] * q6 + p[9] * q8;
      return {fu + fu * radial + 2 * p[6] * fu * fv + p[7] * (q2 + 2 * fu * fu) + p[10] * q2,
              fv + fv * radial + 2 * p[7] * fu * fv + p[6] * (q2 + 2 * fv * fv) + p[11] * q2};
    }
  }
  IBR_CHECK(false && "unknown camera model");
  return n;
}

Camera DenseFromCamera(const Camera& camera) {
  IBR_CHECK(!camera.orthographic());
  Camera dense = camera;
  const int cx_index = SingleFocal(camera.model) ? 1 : 2;
  dense.params[cx_index] -= 0.5;
  dense.params[cx_index + 1] -= 0.5;
  return dense;
}

Camera CameraFromDense(const Camera& dense) {
  IBR_CHECK(!dense.orthographic());
  Camera camera = dense;
  const int cx_index = SingleFocal(dense.model) ? 1 : 2;
  camera.params[cx_index] += 0.5;
  camera.params[cx_index + 1] += 0.5;
  return camera;
}

Rigid3 Rigid3::Inverse() const {
  const glm::dmat3 rt = glm::transpose(rotation);
  return {rt, -(rt * translation)};
}

std::array<double, 4> Rigid3::Quaternion() const {
  glm::dquat q = glm::quat_cast(rotation);
  if (q.w < 0) q = -q;  // canonical sign, as COLMAP writes them
  return {q.w, q.x, q.y, q.z};
}

Rigid3 Rigid3::FromQuaternion(const std::array<double, 4>& q, const glm::dvec3& t) {
  const glm::dquat quat = glm::normalize(glm::dquat(q[0], q[1], q[2], q[3]));
  return {glm::mat3_cast(quat), t};
}

glm::mat4 Rigid3::ToMat4() const {
  glm::dmat4 m(rotation);
  m[3] = glm::dvec4(translation, 1.0);
  return glm::mat4(m);
}

Rigid3 Rigid3::FromMat4(const glm::dmat4& m) { return {glm::dmat3(m), glm::dvec3(m[3])}; }

void Rigid3::Check(std::string_view where, double tolerance) const {
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      if (!std::isfinite(rotation[c][r])) core::ThrowInputError(where, "rotation is not finite");
    }
    if (!std::isfinite(translation[c])) core::ThrowInputError(where, "translation is not finite");
  }
  const glm::dmat3 should_be_identity = glm::transpose(rotation) * rotation;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      const double err = std::abs(should_be_identity[c][r] - (c == r ? 1.0 : 0.0));
      if (err > tolerance) {
        core::ThrowInputError(where, "rotation is not orthonormal (R^T R off by {:.3g})", err);
      }
    }
  }
  if (glm::determinant(rotation) < 0)
    core::ThrowInputError(where, "rotation is a reflection (det < 0)");
}

glm::dmat3 NearestRotation(const glm::dmat3& m) {
  cv::Matx33d a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a(r, c) = m[c][r];
  const cv::SVD svd(cv::Mat(a), cv::SVD::FULL_UV);
  const cv::Mat nearest = svd.u * svd.vt;
  glm::dmat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[c][r] = nearest.at<double>(r, c);
  return out;
}

Rigid3 LookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up) {
  const glm::dmat4 m = core::CamFromWorldLookAtDouble(eye, target, up);
  return {glm::dmat3(m), glm::dvec3(m[3])};
}

Camera UndistortedCamera(const Camera& camera) {
  if (!camera.distorted()) return camera;
  return Camera::Pinhole(camera.width, camera.height, camera.fx(), camera.fy(), camera.cx(),
                         camera.cy());
}

namespace {

// OpenCV uses integer pixel centres: give it the dense-convention K.
cv::Matx33d DenseK(const Camera& camera) {
  return {camera.fx(), 0, camera.cx() - 0.5, 0, camera.fy(), camera.cy() - 0.5, 0, 0, 1};
}

// Maps in OpenCV's integer-centre coordinates (what cv::remap wants).
void OpenCvMaps(const Camera& camera, cv::Mat& map_x, cv::Mat& map_y) {
  const cv::Size size(camera.width, camera.height);
  const cv::Matx33d k = DenseK(camera);
  const auto& p = camera.params;
  std::vector<double> dist;
  bool fisheye = false;
  switch (camera.model) {
    case CameraModel::kSimpleRadial:
      dist = {p[3], 0, 0, 0};
      break;
    case CameraModel::kRadial:
      dist = {p[3], p[4], 0, 0};
      break;
    case CameraModel::kOpenCv:
      dist = {p[4], p[5], p[6], p[7]};
      break;
    case CameraModel::kFullOpenCv:
      dist = {p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11]};
      break;
    case CameraModel::kOpenCvFisheye:
      dist = {p[4], p[5], p[6], p[7]};
      fisheye = true;
      break;
    case CameraModel::kSimpleRadialFisheye:
      dist = {p[3], 0, 0, 0};
      fisheye = true;
      break;
    case CameraModel::kRadialFisheye:
      dist = {p[3], p[4], 0, 0};
      fisheye = true;
      break;
    default: {
      // FOV, THIN_PRISM_FISHEYE: OpenCV has no such model; map from Distort().
      map_x.create(size, CV_32FC1);
      map_y.create(size, CV_32FC1);
      for (int row = 0; row < camera.height; ++row) {
        for (int col = 0; col < camera.width; ++col) {
          const glm::dvec2 n((col + 0.5 - camera.cx()) / camera.fx(),
                             (row + 0.5 - camera.cy()) / camera.fy());
          const glm::dvec2 d = camera.Distort(n);
          map_x.at<float>(row, col) = static_cast<float>(camera.fx() * d.x + camera.cx() - 0.5);
          map_y.at<float>(row, col) = static_cast<float>(camera.fy() * d.y + camera.cy() - 0.5);
        }
      }
      return;
    }
  }
  if (fisheye) {
    cv::fisheye::initUndistortRectifyMap(k, dist, cv::Matx33d::eye(), k, size, CV_32FC1, map_x,
                                         map_y);
  } else {
    cv::initUndistortRectifyMap(k, dist, cv::Matx33d::eye(), k, size, CV_32FC1, map_x, map_y);
  }
}

}  // namespace

core::ImageF UndistortionMap(const Camera& camera) {
  core::ImageF map(camera.width, camera.height, 2);
  if (!camera.distorted()) {
    for (int row = 0; row < camera.height; ++row) {
      for (int col = 0; col < camera.width; ++col) {
        map.at(col, row, 0) = static_cast<float>(col + 0.5);
        map.at(col, row, 1) = static_cast<float>(row + 0.5);
      }
    }
    return map;
  }
  cv::Mat map_x, map_y;
  OpenCvMaps(camera, map_x, map_y);
  for (int row = 0; row < camera.height; ++row) {
    for (int col = 0; col < camera.width; ++col) {
      map.at(col, row, 0) = map_x.at<float>(row, col) + 0.5f;
      map.at(col, row, 1) = map_y.at<float>(row, col) + 0.5f;
    }
  }
  return map;
}

core::Image8 UndistortImage(const Camera& camera, const core::Image8& image) {
  IBR_CHECK_EQ(image.width(), camera.width);
  IBR_CHECK_EQ(image.height(), camera.height);
  if (!camera.distorted()) return image;
  cv::Mat map_x, map_y;
  OpenCvMaps(camera, map_x, map_y);
  const cv::Mat src(image.height(), image.width(), CV_8UC(image.channels()),
                    const_cast<uint8_t*>(image.data()));
  core::Image8 out(image.width(), image.height(), image.channels());
  cv::Mat dst(out.height(), out.width(), CV_8UC(out.channels()), out.data());
  cv::remap(src, dst, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

}  // namespace capture
