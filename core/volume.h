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

enum class ScalarType { kUint8, kUint16, kFloat32 };

int BytesPerScalar(ScalarType type);
std::string_view ScalarTypeName(ScalarType type);  // "uint8", "uint16", "float32"

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

  // A zero-filled volume; dims and type are checked like a file header.
  static Volume Zeros(const glm::ivec3& dims, ScalarType type,
                      const glm::dvec3& spacing = glm::dvec3(1.0));

  size_t voxel_count() const { return static_cast<size_t>(dims.x) * dims.y * dims.z; }
  size_t Index(int x, int y, int z) const;

  // The stored value (integers as they are, floats as they are).
  double Value(int x, int y, int z) const;
  void SetValue(int x, int y, int z, double value);  // rounds and clamps to the type's range
  // What a GL texture of this volume returns: integers normalised to [0, 1]
  // (UNORM: value / (2^bits - 1)), floats unchanged.
  double Normalized(int x, int y, int z) const;

  // Physical size of the box the texture covers: dims * spacing.
  glm::dvec3 Extent() const { return glm::dvec3(dims) * spacing; }

  bool operator==(const Volume& other) const = default;
};

// CPU reference of GL's trilinear filter (GL_LINEAR, CLAMP_TO_EDGE) on the
// normalised values, in double: texture coordinate `tex` in [0,1]^3 (outside
// is clamped to the edge texels).
double SampleTrilinear(const Volume& volume, const glm::dvec3& tex);

// Central-difference gradient of the normalised values at voxel (x, y, z),
// per unit texture coordinate (one-sided at the faces).
glm::dvec3 GradientAtVoxel(const Volume& volume, int x, int y, int z);

}  // namespace core
