// A seeded random COLMAP sparse model with every camera model, for round
// trips (ours and the real colmap binary's).
#pragma once

#include <random>

#include "capture/colmap_io.h"

namespace capture::test {

inline colmap::SparseModel RandomSparseModel(uint32_t seed, int num_images = 6,
                                             int num_points = 40) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  colmap::SparseModel model;
  for (int id = 0; id < kNumColmapModels; ++id) {
    const CameraModel m = *CameraModelFromColmapId(id);
    Camera c{m, 320 + id, 240 + 2 * id, {}};
    const int n = CameraModelParamCount(m);
    for (int k = 0; k < n; ++k)
      c.params.push_back(k == 0 ? 300 + 50 * u(rng) : (k < 4 ? 160 + 10 * u(rng) : 0.05 * u(rng)));
    if (m == CameraModel::kPinhole || m == CameraModel::kOpenCv ||
        m == CameraModel::kOpenCvFisheye || m == CameraModel::kFullOpenCv ||
        m == CameraModel::kFov || m == CameraModel::kThinPrismFisheye) {
      c.params[1] = 300 + 50 * u(rng);  // fy
    }
    model.cameras.emplace(static_cast<uint32_t>(id + 1), c);
  }
  for (int i = 0; i < num_images; ++i) {
    colmap::Image im;
    im.image_id = static_cast<uint32_t>(i + 1);
    std::array<double, 4> q{u(rng), u(rng), u(rng), u(rng)};
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& v : q) v /= (q[0] < 0 ? -n : n);
    im.qvec = q;
    im.tvec = {u(rng), u(rng), 3 + u(rng)};
    im.camera_id = static_cast<uint32_t>(1 + i % kNumColmapModels);
    im.name = "view_" + std::to_string(i) + ".png";
    model.images.emplace(im.image_id, im);
  }
  for (int p = 0; p < num_points; ++p) {
    colmap::Point3D pt;
    pt.point3D_id = static_cast<uint64_t>(p + 1);
    pt.xyz = {u(rng), u(rng), u(rng)};
    pt.rgb = {static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng()),
              static_cast<uint8_t>(rng())};
    pt.error = 0.5 + 0.5 * u(rng);
    // Two or three observations in distinct images.
    const int len = 2 + static_cast<int>(rng() % 2);
    const uint32_t first = static_cast<uint32_t>(rng() % num_images);
    for (int k = 0; k < len; ++k) {
      auto& im = model.images.at(1 + (first + k) % num_images);
      pt.track.push_back({im.image_id, static_cast<uint32_t>(im.points2D.size())});
      im.points2D.push_back({100 + 100 * u(rng), 100 + 100 * u(rng), pt.point3D_id});
    }
    model.points3D.emplace(pt.point3D_id, pt);
  }
  // Some untriangulated keypoints too.
  for (auto& [id, im] : model.images)
    im.points2D.push_back({12.25, 7.5, colmap::kInvalidPoint3DId});
  return model;
}

}  // namespace capture::test
