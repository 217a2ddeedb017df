// Writes the fuzz targets' seed corpora: small valid files made by our own
// writers (a seeded random sparse model with all 11 camera models, dense maps,
// a manifest, configs) plus hand-written Redwood/Middlebury lines, and copies
// of the real files in ../shared/data when the folder is given.
//   make_seeds OUT_DIR [SHARED_DATA_DIR]
// Writes OUT_DIR/<target>/<seed>, one folder per fuzz target.
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "capture/colmap_io.h"
#include "capture/dataset.h"
#include "tests/capture/random_model.h"

namespace {
namespace fs = std::filesystem;

void Seed(const fs::path& root, const std::string& target, const std::string& name,
          const std::function<void(std::ostream&)>& write) {
  fs::create_directories(root / target);
  std::ofstream out(root / target / name, std::ios::binary);
  write(out);
}

void CopyIfExists(const fs::path& from, const fs::path& root, const std::string& target) {
  if (!fs::is_regular_file(from)) return;
  fs::create_directories(root / target);
  fs::copy_file(from, root / target / from.filename(), fs::copy_options::overwrite_existing);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: make_seeds OUT_DIR [SHARED_DATA_DIR]\n";
    return 2;
  }
  const fs::path root = argv[1];
  namespace colmap = capture::colmap;
  for (uint32_t seed : {1u, 2u}) {
    // Small models: libFuzzer mutates small inputs faster.
    const colmap::SparseModel m = capture::test::RandomSparseModel(seed, 2, 3);
    const std::string s = std::to_string(seed);
    Seed(root, "colmap_cameras_text", s,
         [&](std::ostream& o) { colmap::WriteCamerasText(o, m.cameras); });
    Seed(root, "colmap_images_text", s,
         [&](std::ostream& o) { colmap::WriteImagesText(o, m.images); });
    Seed(root, "colmap_points3d_text", s,
         [&](std::ostream& o) { colmap::WritePoints3DText(o, m.points3D); });
    Seed(root, "colmap_cameras_bin", s,
         [&](std::ostream& o) { colmap::WriteCamerasBinary(o, m.cameras); });
    Seed(root, "colmap_images_bin", s,
         [&](std::ostream& o) { colmap::WriteImagesBinary(o, m.images); });
    Seed(root, "colmap_points3d_bin", s,
         [&](std::ostream& o) { colmap::WritePoints3DBinary(o, m.points3D); });
  }
  for (int channels : {1, 3}) {
    core::ImageF map(3, 2, channels);
    for (size_t i = 0; i < map.values().size(); ++i) map.data()[i] = 0.25f * static_cast<float>(i);
    Seed(root, "dense_map", std::to_string(channels),
         [&](std::ostream& o) { colmap::WriteDenseMap(o, map); });
  }
  Seed(root, "fusion_cfg", "1", [](std::ostream& o) {
    colmap::WriteFusionConfig(o, {"a.png", "b/c.png"});
  });
  Seed(root, "patch_match_cfg", "1", [](std::ostream& o) {
    colmap::WritePatchMatchConfig(o, {{"a.png", "__auto__, 20"}, {"b.png", "a.png, c.png"}});
  });
  capture::Dataset d;
  d.cameras.emplace(1, capture::Camera::Pinhole(8, 6, 10.5, 10.25, 4, 3));
  d.cameras.emplace(2, capture::Camera::Orthographic(8, 6, 2, 2, 4, 3));
  d.views.push_back({"a", 1, capture::LookAt({0, -3, 0.5}, {0, 0, 0}, {0, 0, 1}), "color/a.png",
                     "depth/a.exr", "mask/a.png", "normal/a.exr"});
  d.views.push_back(
      {"b", 2, capture::LookAt({3, 0, 0}, {0, 0, 0}, {0, 0, 1}), "color/b.png", "", "", ""});
  d.bounds = capture::Bounds{{-1, -1, -1}, {1, 1, 1}};
  d.depth_units = "m";
  Seed(root, "manifest", "1", [&](std::ostream& o) { capture::WriteManifest(o, d); });
  d.depth_noise = capture::ParseSensorModel("sigma=0.3%,model=quadratic,holes=0.02,edge=1", 2, 3);
  Seed(root, "manifest", "2", [&](std::ostream& o) { capture::WriteManifest(o, d); });
  Seed(root, "sensor_model", "1", [](std::ostream& o) {
    o << "sigma=0.3%,model=quadratic,quantize=0.001,edge=1,grazing=75,holes=0.02,hole-radius=3,"
         "flying=0.5,outliers=0.001,mask=depth,seed=7";
  });
  Seed(root, "nerf_frame", "1", [](std::ostream& o) {
    o << R"({"camera_angle_x": 0.69, "frames": [{"file_path": "./train/r_0", "transform_matrix": )"
         R"([[1, 0, 0, 0], [0, 0, -1, -4], [0, 1, 0, 0.5], [0, 0, 0, 1]]}]})";
  });
  Seed(root, "nerf_frame", "2", [](std::ostream& o) {
    o << R"({"fl_x": 500, "fl_y": 501, "cx": 32, "cy": 24, "w": 64, "h": 48, "k1": 0.01, )"
         R"("frames": [{"file_path": "a.png", "transform_matrix": )"
         R"([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1]]}]})";
  });
  Seed(root, "tum_list", "1", [](std::ostream& o) {
    o << "# color images\n# timestamp filename\n1305031102.175304 rgb/1305031102.175304.png\n"
         "1305031102.211214 rgb/1305031102.211214.png\n";
  });
  Seed(root, "tum_trajectory", "1", [](std::ostream& o) {
    o << "# timestamp tx ty tz qx qy qz qw\n1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 "
         "-0.3311 -0.3986\n1305031098.6758 1.3543 0.6326 1.6360 0.6130 0.5972 -0.3301 -0.3979\n";
  });
  Seed(root, "redwood_log", "1", [](std::ostream& o) {
    o << "0 0 1\n0 -1 0 1\n1 0 0 2\n0 0 1 3\n0 0 0 1\n1 1 2\n1 0 0 0\n0 1 0 0\n0 0 1 -5\n0 0 0 1\n";
  });
  Seed(root, "middlebury_par", "1", [](std::ostream& o) {
    o << "2\na.png 1500 0 300.5 0 1510 240.25 0 0 1 0 1 0 1 0 0 0 0 -1 0.1 0.2 0.6\n"
         "b.png 1500 0 300.5 0 1510 240.25 0 0 1 1 0 0 0 1 0 0 0 1 0 0 0.6\n";
  });
  Seed(root, "scene", "1", [](std::ostream& o) {
    o << R"({"version": 1, "cameras": {"orbit": {"count": 2}}, "lights": [{"type": "head"}], "objects": [)"
         R"({"type": "depth-object", "images": {"capture": {"shape": "cup"}}, "slices": 64},)"
         R"({"type": "displaced-mesh", "transform": {"translate": [1, 0, 0], "scale": 0.5}, "mesh": {"shape": "torus"},)"
         R"("height": {"generator": "bumps"}, "method": "ncs"}]})";
  });
  Seed(root, "scene", "2", [](std::ostream& o) {
    o << R"({"version": 1, "cameras": {"list": [{"name": "a", "width": 4, "height": 4, "fx": 1, "fy": 1, "cx": 2,)"
         R"("cy": 2, "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3]]}]},)"
         R"("objects": [{"type": "mesh", "mesh": {"file": "m.obj"}, "transform": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}}]})";
  });
  Seed(root, "redwood_intrinsics", "1", [](std::ostream& o) {
    o << R"({"width": 640, "height": 480, "intrinsic_matrix": [525, 0, 0, 0, 525, 0, 319.5, 239.5, 1]})";
  });
  Seed(root, "middlebury_bounds", "1", [](std::ostream& o) {
    o << "The bounding box of the object is\n(-0.023121 -0.038009 -0.091940)\n"
         "(0.078626 0.121636 -0.017395)\n";
  });
  if (argc > 2) {
    const fs::path shared = argv[2];
    CopyIfExists(shared / "rgbd/redwood5/camera_primesense.json", root, "redwood_intrinsics");
    CopyIfExists(shared / "photos/templeSparseRing/README.txt", root, "middlebury_bounds");
    CopyIfExists(shared / "photos/dinoSparseRing/README.txt", root, "middlebury_bounds");
    CopyIfExists(shared / "rgbd/redwood5/trajectory.log", root, "redwood_log");
    CopyIfExists(shared / "rgbd/redwood5/odometry.log", root, "redwood_log");
    CopyIfExists(shared / "photos/templeSparseRing/templeSR_par.txt", root, "middlebury_par");
    CopyIfExists(shared / "photos/dinoSparseRing/dinoSR_par.txt", root, "middlebury_par");
    CopyIfExists(shared / "real-captures/tum_fr3_cabinet/rgb.txt", root, "tum_list");
    CopyIfExists(shared / "real-captures/tum_fr3_cabinet/depth.txt", root, "tum_list");
    CopyIfExists(shared / "real-captures/tum_fr3_cabinet/groundtruth.txt", root, "tum_trajectory");
  }
  std::cout << "make_seeds: corpora in " << root.string() << "\n";
  return 0;
}
