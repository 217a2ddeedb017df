// The real capture files under ../shared/data/tests-real/captures (README.md there),
// for the tests of targets that define IBR_REAL_DATA_DIR.
#pragma once

#include <filesystem>
#include <fstream>

namespace test_support {

inline std::filesystem::path RealCapturesDir() {
  return std::filesystem::path(IBR_REAL_DATA_DIR) / "captures";
}

// The TUM RGB-D frame in the Redwood layout `ibr import redwood` reads
// (README.md: PrimeSense default intrinsics, identity pose), written to a
// fresh `dir`.
inline std::filesystem::path WriteTumRedwoodLayout(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  fs::remove_all(dir);
  fs::create_directories(dir / "color");
  fs::create_directories(dir / "depth");
  fs::copy_file(RealCapturesDir() / "tum_frame/TUM_color.png", dir / "color/00000.png");
  fs::copy_file(RealCapturesDir() / "tum_frame/TUM_depth.png", dir / "depth/00000.png");
  std::ofstream(dir / "camera_primesense.json")
      << R"({"width": 640, "height": 480, "intrinsic_matrix": [525, 0, 0, 0, 525, 0, 319.5, 239.5, 1]})";
  std::ofstream(dir / "trajectory.log") << "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  return dir;
}

}  // namespace test_support
