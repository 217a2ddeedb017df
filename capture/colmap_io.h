// COLMAP 3.8 files (../shared/COLMAP-FORMATS.md): the sparse model in text and
// binary, the dense workspace's depth/normal maps (.bin) and its fusion.cfg /
// patch-match.cfg. CPU-only, no GL. Readers take a stream plus the name used
// in messages; the path overloads only open the file. Every reader throws
// core::InputError naming the function, the file and the problem (line number
// for text) on any malformed input, and never crashes on arbitrary bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <istream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "capture/camera.h"
#include "core/image.h"

namespace capture::colmap {

inline constexpr uint64_t kInvalidPoint3DId = UINT64_MAX;  // 2^64-1; "-1" in text

struct Point2D {
  double x = 0, y = 0;  // sparse pixel convention (+0.5)
  uint64_t point3D_id = kInvalidPoint3DId;
  bool operator==(const Point2D&) const = default;
};

struct Image {
  uint32_t image_id = 0;
  std::array<double, 4> qvec{1, 0, 0, 0};  // cam_from_world rotation, (qw, qx, qy, qz)
  std::array<double, 3> tvec{0, 0, 0};     // cam_from_world translation
  uint32_t camera_id = 0;
  std::string name;
  std::vector<Point2D> points2D;

  Rigid3 cam_from_world() const {
    return Rigid3::FromQuaternion(qvec, {tvec[0], tvec[1], tvec[2]});
  }
  bool operator==(const Image&) const = default;
};

struct TrackElement {
  uint32_t image_id = 0;
  uint32_t point2D_idx = 0;  // 0-based index into that image's points2D
  bool operator==(const TrackElement&) const = default;
};

struct Point3D {
  uint64_t point3D_id = 0;
  std::array<double, 3> xyz{0, 0, 0};
  std::array<uint8_t, 3> rgb{0, 0, 0};
  double error = 0;  // mean reprojection error, pixels
  std::vector<TrackElement> track;
  bool operator==(const Point3D&) const = default;
};

// Cameras keyed by COLMAP camera id. Camera::model is one of the 11 COLMAP
// models (never ORTHOGRAPHIC).
struct SparseModel {
  std::map<uint32_t, Camera> cameras;
  std::map<uint32_t, Image> images;
  std::map<uint64_t, Point3D> points3D;
  bool operator==(const SparseModel&) const = default;
  // Throws InputError if an image names an unknown camera, a track names an
  // unknown image or an out-of-range point2D index.
  void Check(const std::string& where) const;
};

// ---- text ----
std::map<uint32_t, Camera> ReadCamerasText(std::istream& in, const std::string& name);
std::map<uint32_t, Image> ReadImagesText(std::istream& in, const std::string& name);
std::map<uint64_t, Point3D> ReadPoints3DText(std::istream& in, const std::string& name);
// Writes doubles in shortest round-trip form: text round trips are bit-exact.
void WriteCamerasText(std::ostream& out, const std::map<uint32_t, Camera>& cameras);
void WriteImagesText(std::ostream& out, const std::map<uint32_t, Image>& images);
void WritePoints3DText(std::ostream& out, const std::map<uint64_t, Point3D>& points);

// ---- binary (little-endian, packed) ----
std::map<uint32_t, Camera> ReadCamerasBinary(std::istream& in, const std::string& name);
std::map<uint32_t, Image> ReadImagesBinary(std::istream& in, const std::string& name);
std::map<uint64_t, Point3D> ReadPoints3DBinary(std::istream& in, const std::string& name);
void WriteCamerasBinary(std::ostream& out, const std::map<uint32_t, Camera>& cameras);
void WriteImagesBinary(std::ostream& out, const std::map<uint32_t, Image>& images);
void WritePoints3DBinary(std::ostream& out, const std::map<uint64_t, Point3D>& points);

// ---- a model directory ----
enum class ModelFormat { kText, kBinary };
// Prefers cameras.bin/images.bin/points3D.bin when cameras.bin exists, else the
// .txt files (as COLMAP's Reconstruction::Read). Checks the model.
SparseModel ReadSparseModel(const std::filesystem::path& dir);
// True if `dir` holds cameras.bin or cameras.txt.
bool IsSparseModelDir(const std::filesystem::path& dir);
// Writes the three files atomically each; `dir` must exist.
void WriteSparseModel(const std::filesystem::path& dir, const SparseModel& model,
                      ModelFormat format);

// ---- dense maps: "W&H&C&" + W*H*C float32, planar [C][H][W] ----
// Returns an interleaved core::ImageF (C channels).
core::ImageF ReadDenseMap(std::istream& in, const std::string& name);
core::ImageF ReadDenseMap(const std::filesystem::path& path);
void WriteDenseMap(std::ostream& out, const core::ImageF& map);
void WriteDenseMap(const std::filesystem::path& path, const core::ImageF& map);

// ---- stereo/fusion.cfg (one image name per line) ----
std::vector<std::string> ReadFusionConfig(std::istream& in, const std::string& name);
void WriteFusionConfig(std::ostream& out, const std::vector<std::string>& image_names);

// ---- stereo/patch-match.cfg: pairs of lines, name then sources ----
struct PatchMatchEntry {
  std::string image_name;
  std::string sources;  // "__auto__, 20", "__all__" or "a.png, b.png, ..."
  bool operator==(const PatchMatchEntry&) const = default;
};
std::vector<PatchMatchEntry> ReadPatchMatchConfig(std::istream& in, const std::string& name);
void WritePatchMatchConfig(std::ostream& out, const std::vector<PatchMatchEntry>& entries);

// Opens `path` and calls the stream reader; InputError if it cannot be opened.
template <typename Reader>
auto ReadFile(const std::filesystem::path& path, Reader reader);

}  // namespace capture::colmap

#include <fstream>

#include "core/error.h"

namespace capture::colmap {
template <typename Reader>
auto ReadFile(const std::filesystem::path& path, Reader reader) {
  std::ifstream in(path, std::ios::binary);
  if (!in) core::ThrowFileError("colmap::ReadFile", path, "cannot open file");
  return reader(in, path.string());
}
}  // namespace capture::colmap
