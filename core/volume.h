// A CPU scalar volume: a regular grid of voxels, x fastest, then y, then z,
// with the physical spacing between voxel centres. Plain data: no GL, no files
// (core/volume_io.h reads and writes it; the volume pass uploads it as a 3D
// texture). Texture coordinates follow GL: voxel i of n has its centre at
// (i + 0.5) / n, and the box [0,1]^3 covers the voxels' cells.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <string_view>
#include <vector>

namespace core {

// The voxel types the readers accept: what CT, MRI and simulation files hold
// (CT is usually int16; 64-bit integers are refused by the readers: no
// scanner writes them and a double cannot hold them exactly).
enum class ScalarType { kUint8, kUint16, kFloat32, kInt8, kInt16, kInt32, kUint32, kFloat64 };

int BytesPerScalar(ScalarType type);
// "uint8", "uint16", "float32", "int8", "int16", "int32", "uint32", "float64"
std::string_view ScalarTypeName(ScalarType type);
// The type's default normalisation range: integers their full range, floats [0, 1].
glm::dvec2 TypeRange(ScalarType type);

// Largest volume the readers accept (bytes of voxel data); larger headers are
// refused as absurd before anything is allocated. 2 GiB: far above the
// shared volumes and any 3D texture llvmpipe takes (2048^3 texels max).
inline constexpr size_t kMaxVolumeBytes = size_t{1} << 31;
// Largest extent along one axis the readers accept (GL_MAX_3D_TEXTURE_SIZE
// on llvmpipe is 2048; a little headroom for CPU-only use).
inline constexpr int kMaxVolumeExtent = 8192;

// Bytes of voxel data for `dims` and `type`; InputError("where: ...") when an
// extent is outside [1, kMaxVolumeExtent] or the total exceeds kMaxVolumeBytes.
size_t CheckedVolumeBytes(std::string_view where, const glm::ivec3& dims, ScalarType type);

struct Volume {
  glm::ivec3 dims{0};       // voxels along x, y, z
  glm::dvec3 spacing{1.0};  // distance between voxel centres along x, y, z (file units, e.g. mm)
  ScalarType type = ScalarType::kUint8;
  std::vector<uint8_t> bytes;  // voxel_count() * BytesPerScalar(type), native (little) endian
  // The stored values that map to the normalised scalars 0 and 1 (what the
  // GPU texture holds and what presets and the shaders see; every value a
  // user types is in stored units and converted through this). lo == hi:
  // the type's range (TypeRange). The readers set it with FitNormalization.
  glm::dvec2 normalization{0.0};

  // A zero-filled volume; dims and type are checked like a file header.
  static Volume Zeros(const glm::ivec3& dims, ScalarType type,
                      const glm::dvec3& spacing = glm::dvec3(1.0));

  size_t voxel_count() const { return static_cast<size_t>(dims.x) * dims.y * dims.z; }
  size_t Index(int x, int y, int z) const;

  // The stored value (integers as they are, floats as they are).
  double Value(int x, int y, int z) const;
  void SetValue(int x, int y, int z, double value);  // rounds and clamps to the type's range
  // What the GPU texture of this volume holds: ToNormalized(Value(x, y, z)).
  double Normalized(int x, int y, int z) const;

  // [lo, hi] of `normalization`, or the type's range when it is unset.
  glm::dvec2 NormalizationRange() const;
  // value -> (value - lo) / (hi - lo), clamped to [0, 1]; NaN -> 0.
  double ToNormalized(double value) const;
  // The inverse (unclamped): lo + s (hi - lo).
  double FromNormalized(double s) const;
  // uint8 keeps its type range (the curated 8-bit volumes and their presets
  // keep their meaning), so do floats whose values lie in [0, 1]; every other
  // volume maps its finite data range [min, max] to [0, 1], so a 12-bit scan
  // in 16 bits or a CT in HU uses the whole transfer-function table (a type
  // range would squeeze it into a sliver).
  void FitNormalization();

  // Physical size of the box the texture covers: dims * spacing.
  glm::dvec3 Extent() const { return glm::dvec3(dims) * spacing; }

  // Same grid, type and bytes (the normalisation is derived, not compared).
  bool operator==(const Volume& other) const {
    return dims == other.dims && spacing == other.spacing && type == other.type &&
           bytes == other.bytes;
  }
};

// What `ibr info` prints and the default transfer function reads: the finite
// values' range and percentiles (stored units). Percentiles are exact for
// integer types whose range spans at most 2^20 values (one histogram bin per
// value); otherwise within (max - min) / 2^16 (a 2^16-bin histogram).
struct VolumeStats {
  double min = 0, max = 0;
  double p1 = 0, p50 = 0, p99 = 0;
  size_t finite = 0;      // voxels with a finite value
  size_t non_finite = 0;  // NaN or Inf voxels (floats only)
};
VolumeStats ComputeVolumeStats(const Volume& volume);

// Stored -> real values in place: v * slope + inter (NIfTI scl_slope /
// scl_inter, DICOM RescaleSlope / RescaleIntercept: HU for CT). Integral
// factors whose results over the data's range fit int16 or int32 give that
// type (a 12-bit CT in uint16 with intercept -1024 becomes int16); others
// float32.
// slope 0 (unset), non-finite factors or the identity change nothing.
void ApplyLinearScale(Volume& volume, double slope, double inter);

// CPU reference of GL's trilinear filter (GL_LINEAR, CLAMP_TO_EDGE) on the
// normalised values, in double: texture coordinate `tex` in [0,1]^3 (outside
// is clamped to the edge texels).
double SampleTrilinear(const Volume& volume, const glm::dvec3& tex);

// Central-difference gradient of the normalised values at voxel (x, y, z),
// per unit texture coordinate (one-sided at the faces).
glm::dvec3 GradientAtVoxel(const Volume& volume, int x, int y, int z);

}  // namespace core
