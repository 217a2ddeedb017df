#include "core/volume.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/check.h"
#include "core/error.h"

namespace core {

int BytesPerScalar(ScalarType type) {
  switch (type) {
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kFloat32:
      return 4;
  }
  IBR_CHECK(false);
  return 0;
}

std::string_view ScalarTypeName(ScalarType type) {
  switch (type) {
    case ScalarType::kUint8:
      return "uint8";
    case ScalarType::kUint16:
      return "uint16";
    case ScalarType::kFloat32:
      return "float32";
  }
  IBR_CHECK(false);
  return "";
}

size_t CheckedVolumeBytes(std::string_view where, const glm::ivec3& dims, ScalarType type) {
  for (int axis = 0; axis < 3; ++axis) {
    if (dims[axis] < 1 || dims[axis] > kMaxVolumeExtent) {
      ThrowInputError(where, "volume size {} x {} x {}: each extent must be in [1, {}]", dims.x,
                      dims.y, dims.z, kMaxVolumeExtent);
    }
  }
  // Each factor is <= 2^13, so the product of three fits in 64 bits.
  const size_t bytes = static_cast<size_t>(dims.x) * static_cast<size_t>(dims.y) *
                       static_cast<size_t>(dims.z) * static_cast<size_t>(BytesPerScalar(type));
  if (bytes > kMaxVolumeBytes) {
    ThrowInputError(where, "volume size {} x {} x {} {} is {} bytes, more than the {} accepted",
                    dims.x, dims.y, dims.z, ScalarTypeName(type), bytes, kMaxVolumeBytes);
  }
  return bytes;
}

Volume Volume::Zeros(const glm::ivec3& dims, ScalarType type, const glm::dvec3& spacing) {
  Volume v;
  v.dims = dims;
  v.spacing = spacing;
  v.type = type;
  v.bytes.assign(CheckedVolumeBytes("Volume::Zeros", dims, type), 0);
  return v;
}

size_t Volume::Index(int x, int y, int z) const {
  IBR_CHECK(x >= 0 && x < dims.x && y >= 0 && y < dims.y && z >= 0 && z < dims.z);
  return (static_cast<size_t>(z) * dims.y + y) * dims.x + x;
}

double Volume::Value(int x, int y, int z) const {
  const size_t i = Index(x, y, z);
  switch (type) {
    case ScalarType::kUint8:
      return bytes[i];
    case ScalarType::kUint16: {
      uint16_t v;
      std::memcpy(&v, bytes.data() + 2 * i, 2);
      return v;
    }
    case ScalarType::kFloat32: {
      float v;
      std::memcpy(&v, bytes.data() + 4 * i, 4);
      return v;
    }
  }
  IBR_CHECK(false);
  return 0;
}

void Volume::SetValue(int x, int y, int z, double value) {
  const size_t i = Index(x, y, z);
  switch (type) {
    case ScalarType::kUint8:
      bytes[i] = static_cast<uint8_t>(std::clamp(std::lround(value), 0l, 255l));
      return;
    case ScalarType::kUint16: {
      const auto v = static_cast<uint16_t>(std::clamp(std::lround(value), 0l, 65535l));
      std::memcpy(bytes.data() + 2 * i, &v, 2);
      return;
    }
    case ScalarType::kFloat32: {
      const auto v = static_cast<float>(value);
      std::memcpy(bytes.data() + 4 * i, &v, 4);
      return;
    }
  }
}

double Volume::Normalized(int x, int y, int z) const {
  const double v = Value(x, y, z);
  switch (type) {
    case ScalarType::kUint8:
      return v / 255.0;
    case ScalarType::kUint16:
      return v / 65535.0;
    case ScalarType::kFloat32:
      return v;
  }
  return v;
}

double SampleTrilinear(const Volume& volume, const glm::dvec3& tex) {
  IBR_CHECK(!volume.bytes.empty());
  int i0[3], i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const int n = volume.dims[a];
    // GL: texel coordinate u = tex * n - 0.5, clamped to the edge texels.
    const double u = std::clamp(tex[a] * n - 0.5, 0.0, static_cast<double>(n - 1));
    const double fl = std::floor(u);
    i0[a] = static_cast<int>(fl);
    i1[a] = std::min(i0[a] + 1, n - 1);
    f[a] = u - fl;
  }
  double result = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int cx = corner & 1, cy = (corner >> 1) & 1, cz = (corner >> 2) & 1;
    const double w = (cx ? f[0] : 1 - f[0]) * (cy ? f[1] : 1 - f[1]) * (cz ? f[2] : 1 - f[2]);
    if (w == 0.0) continue;
    result += w * volume.Normalized(cx ? i1[0] : i0[0], cy ? i1[1] : i0[1], cz ? i1[2] : i0[2]);
  }
  return result;
}

glm::dvec3 GradientAtVoxel(const Volume& volume, int x, int y, int z) {
  const glm::ivec3 p(x, y, z);
  glm::dvec3 g(0.0);
  for (int a = 0; a < 3; ++a) {
    glm::ivec3 lo = p, hi = p;
    lo[a] = std::max(p[a] - 1, 0);
    hi[a] = std::min(p[a] + 1, volume.dims[a] - 1);
    if (lo[a] == hi[a]) continue;  // one voxel thick along this axis: no variation
    const double dv = volume.Normalized(hi.x, hi.y, hi.z) - volume.Normalized(lo.x, lo.y, lo.z);
    g[a] = dv / (static_cast<double>(hi[a] - lo[a]) / volume.dims[a]);
  }
  return g;
}

}  // namespace core
