// Cameras against their definitions: COLMAP's model table, projection /
// back-projection, the two pixel-centre conventions, poses, and OpenCV's
// undistortion maps against COLMAP's forward distortion formulas.
#include "capture/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.h"

namespace capture {
namespace {

TEST(CameraModels, ColmapIdsNamesAndParamCountsMatchTheFormatTable) {
  // COLMAP-FORMATS.md, verified against colmap's model_converter.
  const std::pair<const char*, int> table[] = {{"SIMPLE_PINHOLE", 3},
                                               {"PINHOLE", 4},
                                               {"SIMPLE_RADIAL", 4},
                                               {"RADIAL", 5},
                                               {"OPENCV", 8},
                                               {"OPENCV_FISHEYE", 8},
                                               {"FULL_OPENCV", 12},
                                               {"FOV", 5},
                                               {"SIMPLE_RADIAL_FISHEYE", 4},
                                               {"RADIAL_FISHEYE", 5},
                                               {"THIN_PRISM_FISHEYE", 12}};
  for (int id = 0; id < kNumColmapModels; ++id) {
    const auto model = CameraModelFromColmapId(id);
    ASSERT_TRUE(model);
    EXPECT_EQ(CameraModelName(*model), table[id].first);
    EXPECT_EQ(CameraModelParamCount(*model), table[id].second);
    EXPECT_EQ(CameraModelFromName(table[id].first), model);
  }
  EXPECT_FALSE(CameraModelFromColmapId(11));
  EXPECT_FALSE(CameraModelFromColmapId(-1));
  EXPECT_FALSE(CameraModelFromName("pinhole"));
}

TEST(Camera, PinholeProjectionUsesPixelCornerOrigin) {
  const Camera cam = Camera::Pinhole(640, 480, 500, 510, 320, 240);
  // The principal ray hits the corner shared by pixels (319..320, 239..240).
  const glm::dvec2 uv = cam.Project({0, 0, 2});
  EXPECT_EQ(uv, glm::dvec2(320, 240));
  // Pixel (0,0)'s centre is (0.5, 0.5).
  const glm::dvec3 p = cam.UnprojectPixel(0, 0, 3.0);
  EXPECT_DOUBLE_EQ(p.z, 3.0);
  EXPECT_DOUBLE_EQ(p.x, (0.5 - 320) / 500 * 3);
  EXPECT_DOUBLE_EQ(p.y, (0.5 - 240) / 510 * 3);
  const glm::dvec2 back = cam.Project(p);
  EXPECT_NEAR(back.x, 0.5, 1e-12);
  EXPECT_NEAR(back.y, 0.5, 1e-12);
}

TEST(Camera, OrthographicDepthIsDistanceFromImagePlane) {
  const Camera cam = Camera::Orthographic(100, 50, 40, 40, 50, 25);
  const glm::dvec3 p = cam.UnprojectPixel(10, 20, 1.25);
  EXPECT_DOUBLE_EQ(p.z, 1.25);
  EXPECT_DOUBLE_EQ(p.x, (10.5 - 50) / 40);
  const glm::dvec2 uv = cam.Project({p.x, p.y, 7.0});  // independent of z
  EXPECT_NEAR(uv.x, 10.5, 1e-12);
  EXPECT_NEAR(uv.y, 20.5, 1e-12);
}

TEST(Camera, DenseConventionShiftsThePrincipalPointByHalfAPixel) {
  const Camera cam = Camera::Pinhole(64, 48, 50, 50, 32, 24);
  const Camera dense = DenseFromCamera(cam);
  EXPECT_EQ(dense.cx(), 31.5);
  EXPECT_EQ(dense.cy(), 23.5);
  // The dense map element (col, row) lies on the ray K_dense^-1 (col, row, 1),
  // the same ray as our pixel centre (col + 0.5, row + 0.5).
  const glm::dvec3 ours = cam.UnprojectPixel(5, 7, 2.0);
  const glm::dvec3 theirs = dense.Unproject({5, 7}, 2.0);
  EXPECT_NEAR(glm::length(ours - theirs), 0.0, 1e-15);
  EXPECT_EQ(CameraFromDense(dense), cam);
  const Camera simple{CameraModel::kSimpleRadial, 64, 48, {50, 32, 24, 0.1}};
  EXPECT_EQ(DenseFromCamera(simple).params, (std::vector<double>{50, 31.5, 23.5, 0.1}));
}

TEST(Camera, CheckRejectsBadCameras) {
  EXPECT_THROW(Camera::Pinhole(0, 10, 1, 1, 0, 0).Check("t"), core::InputError);
  EXPECT_THROW(Camera::Pinhole(10, 10, -1, 1, 0, 0).Check("t"), core::InputError);
  EXPECT_THROW(Camera::Pinhole(10, 10, NAN, 1, 0, 0).Check("t"), core::InputError);
  EXPECT_THROW((Camera{CameraModel::kOpenCv, 10, 10, {1, 1, 1}}.Check("t")), core::InputError);
  EXPECT_NO_THROW(Camera::Pinhole(10, 10, 1, 1, 5, 5).Check("t"));
}

TEST(Rigid3, QuaternionRoundTripAndLookAt) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int i = 0; i < 100; ++i) {
    std::array<double, 4> q{g(rng), g(rng), g(rng), g(rng)};
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& v : q) v /= (q[0] < 0 ? -n : n);
    const Rigid3 pose = Rigid3::FromQuaternion(q, {g(rng), g(rng), g(rng)});
    EXPECT_NO_THROW(pose.Check("t", 1e-12));
    const auto back = pose.Quaternion();
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(back[k], q[k], 1e-12);
    const glm::dvec3 p(g(rng), g(rng), g(rng));
    EXPECT_NEAR(glm::length(pose.Inverse() * (pose * p) - p), 0, 1e-12);
  }
  const Rigid3 look = LookAt({0, -3, 1}, {0, 0, 1}, {0, 0, 1});
  const glm::dvec3 target_in_cam = look * glm::dvec3(0, 0, 1);
  EXPECT_NEAR(target_in_cam.x, 0, 1e-12);
  EXPECT_NEAR(target_in_cam.y, 0, 1e-12);
  EXPECT_NEAR(target_in_cam.z, 3, 1e-12);
  // World up (+z) points to image up (-y).
  const glm::dvec3 up_in_cam = look.rotation * glm::dvec3(0, 0, 1);
  EXPECT_NEAR(up_in_cam.y, -1, 1e-12);
  EXPECT_NEAR(glm::length(look.Centre() - glm::dvec3(0, -3, 1)), 0, 1e-12);
  Rigid3 bad = look;
  bad.rotation[0][0] = 2;
  EXPECT_THROW(bad.Check("t"), core::InputError);
}

// OpenCV's undistortion maps (cv::initUndistortRectifyMap and its fisheye
// twin) against COLMAP's distortion formulas: for every output pixel the map
// must point where Distort() sends the undistorted ray.
TEST(Undistortion, OpenCvMapsAgreeWithColmapDistortionForEveryModel) {
  const int w = 160, h = 120;
  const std::vector<Camera> cameras = {
      {CameraModel::kSimpleRadial, w, h, {150, 80, 60, -0.08}},
      {CameraModel::kRadial, w, h, {150, 80.5, 59, -0.1, 0.02}},
      {CameraModel::kOpenCv, w, h, {150, 152, 81, 60, -0.1, 0.01, 0.001, -0.002}},
      {CameraModel::kFullOpenCv,
       w,
       h,
       {150, 152, 81, 60, -0.1, 0.01, 0.001, -0.002, 0.001, 0.01, 0.002, 0.0005}},
      {CameraModel::kOpenCvFisheye, w, h, {150, 152, 81, 60, 0.05, -0.01, 0.002, -0.001}},
      {CameraModel::kSimpleRadialFisheye, w, h, {150, 80, 60, 0.04}},
      {CameraModel::kRadialFisheye, w, h, {150, 80, 60, 0.04, -0.01}},
      {CameraModel::kFov, w, h, {150, 152, 80, 60, 0.9}},
      {CameraModel::kThinPrismFisheye,
       w,
       h,
       {150, 152, 81, 60, 0.05, -0.01, 0.001, 0.001, 0.002, -0.001, 0.001, -0.001}},
  };
  for (const Camera& cam : cameras) {
    SCOPED_TRACE(std::string(CameraModelName(cam.model)));
    ASSERT_TRUE(cam.distorted());
    const core::ImageF map = UndistortionMap(cam);
    double max_err = 0;
    for (int row = 0; row < h; row += 7) {
      for (int col = 0; col < w; col += 7) {
        const glm::dvec2 n((col + 0.5 - cam.cx()) / cam.fx(), (row + 0.5 - cam.cy()) / cam.fy());
        const glm::dvec2 d = cam.Distort(n);
        const glm::dvec2 expected(cam.fx() * d.x + cam.cx(), cam.fy() * d.y + cam.cy());
        max_err = std::max(max_err, std::abs(map.at(col, row, 0) - expected.x));
        max_err = std::max(max_err, std::abs(map.at(col, row, 1) - expected.y));
      }
    }
    // Float maps over a 160 px image: float rounding ~1e-5 px.
    EXPECT_LT(max_err, 2e-3) << "OpenCV's map and COLMAP's formula disagree";
    // The distortion is real (the test is not vacuous): corners move.
    EXPECT_GT(std::abs(map.at(0, 0, 0) - 0.5), 0.2);
    const Camera pinhole = UndistortedCamera(cam);
    EXPECT_EQ(pinhole.model, CameraModel::kPinhole);
    EXPECT_EQ(pinhole.cx(), cam.cx());
  }
}

TEST(Undistortion, RemapsAnImageWithOpenCv) {
  // A checkerboard "photographed" through a radial lens, then undistorted:
  // the pixel at the image centre is unchanged, corners are pulled inwards.
  const Camera cam{CameraModel::kSimpleRadial, 64, 64, {60, 32, 32, -0.2}};
  core::Image8 img(64, 64, 1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) img.at(x, y) = static_cast<uint8_t>(4 * x);
  const core::Image8 out = UndistortImage(cam, img);
  EXPECT_NEAR(out.at(32, 32), img.at(32, 32), 1);
  const core::ImageF map = UndistortionMap(cam);
  // Barrel distortion (k < 0): the output's left border samples inside the source.
  EXPECT_GT(map.at(0, 32, 0), 0.5f);
  EXPECT_NEAR(out.at(2, 32), 4 * (map.at(2, 32, 0) - 0.5), 2.5);
}

}  // namespace
}  // namespace capture
