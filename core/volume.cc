#include "core/volume.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include "core/check.h"
#include "core/error.h"
#include "core/memory_budget.h"

namespace core {

namespace {

// Calls f(T{}) with the C++ type stored for `type`.
template <class F>
decltype(auto) WithScalarType(ScalarType type, F&& f) {
  switch (type) {
    case ScalarType::kUint8:
      return f(uint8_t{});
    case ScalarType::kUint16:
      return f(uint16_t{});
    case ScalarType::kFloat32:
      return f(float{});
    case ScalarType::kInt8:
      return f(int8_t{});
    case ScalarType::kInt16:
      return f(int16_t{});
    case ScalarType::kInt32:
      return f(int32_t{});
    case ScalarType::kUint32:
      return f(uint32_t{});
    case ScalarType::kFloat64:
      return f(double{});
  }
  IBR_CHECK(false);
  return f(uint8_t{});
}

template <class T>
T Load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

}  // namespace

int BytesPerScalar(ScalarType type) {
  return WithScalarType(type, [](auto t) { return static_cast<int>(sizeof(t)); });
}

std::string_view ScalarTypeName(ScalarType type) {
  switch (type) {
    case ScalarType::kUint8:
      return "uint8";
    case ScalarType::kUint16:
      return "uint16";
    case ScalarType::kFloat32:
      return "float32";
    case ScalarType::kInt8:
      return "int8";
    case ScalarType::kInt16:
      return "int16";
    case ScalarType::kInt32:
      return "int32";
    case ScalarType::kUint32:
      return "uint32";
    case ScalarType::kFloat64:
      return "float64";
  }
  IBR_CHECK(false);
  return "";
}

glm::dvec2 TypeRange(ScalarType type) {
  return WithScalarType(type, [](auto t) {
    using T = decltype(t);
    if constexpr (std::is_floating_point_v<T>) {
      return glm::dvec2(0.0, 1.0);
    } else {
      return glm::dvec2(std::numeric_limits<T>::lowest(), std::numeric_limits<T>::max());
    }
  });
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
  CheckMemory(
      bytes, where,
      fmt::format("a {} x {} x {} {} volume", dims.x, dims.y, dims.z, ScalarTypeName(type)));
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
  const uint8_t* p = bytes.data() + Index(x, y, z) * BytesPerScalar(type);
  return WithScalarType(type, [p](auto t) { return static_cast<double>(Load<decltype(t)>(p)); });
}

void Volume::SetValue(int x, int y, int z, double value) {
  uint8_t* p = bytes.data() + Index(x, y, z) * BytesPerScalar(type);
  WithScalarType(type, [p, value](auto t) {
    using T = decltype(t);
    T v;
    if constexpr (std::is_floating_point_v<T>) {
      v = static_cast<T>(value);
    } else {
      const double r = std::isnan(value) ? 0.0 : std::round(value);
      v = static_cast<T>(std::clamp(r, static_cast<double>(std::numeric_limits<T>::lowest()),
                                    static_cast<double>(std::numeric_limits<T>::max())));
    }
    std::memcpy(p, &v, sizeof(T));
    return 0;
  });
}

glm::dvec2 Volume::NormalizationRange() const {
  return normalization.x == normalization.y ? TypeRange(type) : normalization;
}

double Volume::ToNormalized(double value) const {
  if (std::isnan(value)) return 0;
  const glm::dvec2 r = NormalizationRange();
  return std::clamp((value - r.x) / (r.y - r.x), 0.0, 1.0);
}

double Volume::FromNormalized(double s) const {
  const glm::dvec2 r = NormalizationRange();
  return r.x + s * (r.y - r.x);
}

double Volume::Normalized(int x, int y, int z) const { return ToNormalized(Value(x, y, z)); }

void Volume::FitNormalization() {
  normalization = glm::dvec2(0.0);
  if (type == ScalarType::kUint8) return;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  WithScalarType(type, [&](auto t) {
    using T = decltype(t);
    const size_t n = bytes.size() / sizeof(T);
    for (size_t i = 0; i < n; ++i) {
      const double v = Load<T>(bytes.data() + i * sizeof(T));
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    return 0;
  });
  if (!(lo <= hi)) return;  // no finite value: the type's range
  const bool is_float = type == ScalarType::kFloat32 || type == ScalarType::kFloat64;
  // Floats already in [0, 1] (densities, masks) keep their values as the
  // normalised scalar.
  if (is_float && lo >= 0 && hi <= 1) return;
  // A constant volume: a unit-wide range with the value at 0.
  normalization = glm::dvec2(lo, hi > lo ? hi : lo + 1);
}

VolumeStats ComputeVolumeStats(const Volume& volume) {
  VolumeStats st;
  st.min = std::numeric_limits<double>::infinity();
  st.max = -st.min;
  WithScalarType(volume.type, [&](auto t) {
    using T = decltype(t);
    const size_t n = volume.bytes.size() / sizeof(T);
    const auto value = [&](size_t i) {
      return static_cast<double>(Load<T>(volume.bytes.data() + i * sizeof(T)));
    };
    for (size_t i = 0; i < n; ++i) {
      const double v = value(i);
      if (!std::isfinite(v)) {
        ++st.non_finite;
        continue;
      }
      ++st.finite;
      st.min = std::min(st.min, v);
      st.max = std::max(st.max, v);
    }
    if (st.finite == 0) return 0;
    // One bin per value for narrow integer ranges (exact), else 2^16 bins.
    const bool exact = std::is_integral_v<T> && st.max - st.min < double(1 << 20);
    const size_t bins = exact ? static_cast<size_t>(st.max - st.min) + 1 : size_t{1} << 16;
    const double width = exact ? 1.0 : (st.max - st.min) / static_cast<double>(bins);
    std::vector<size_t> histogram(bins, 0);
    for (size_t i = 0; i < n; ++i) {
      const double v = value(i);
      if (!std::isfinite(v)) continue;
      const size_t b =
          width > 0 ? std::min(static_cast<size_t>((v - st.min) / width), bins - 1) : 0;
      ++histogram[b];
    }
    // The smallest value with at least q of the finite voxels at or below it.
    const auto percentile = [&](double q) {
      const double target = q * static_cast<double>(st.finite);
      size_t cumulative = 0;
      for (size_t b = 0; b < bins; ++b) {
        cumulative += histogram[b];
        if (static_cast<double>(cumulative) >= target)
          return std::min(st.min + static_cast<double>(b) * width, st.max);
      }
      return st.max;
    };
    st.p1 = percentile(0.01);
    st.p50 = percentile(0.5);
    st.p99 = percentile(0.99);
    return 0;
  });
  if (st.finite == 0) st.min = st.max = 0;
  return st;
}

void ApplyLinearScale(Volume& v, double slope, double inter) {
  if (!std::isfinite(slope) || !std::isfinite(inter) || slope == 0 || (slope == 1 && inter == 0)) {
    return;
  }
  const bool integer = v.type != ScalarType::kFloat32 && v.type != ScalarType::kFloat64;
  const bool integral = integer && slope == std::round(slope) && inter == std::round(inter);
  // The scaled data's range (not the type's: a 12-bit CT in uint16 with
  // intercept -1024 fits int16).
  const VolumeStats st = integral ? ComputeVolumeStats(v) : VolumeStats{};
  const double lo = std::min(st.min * slope + inter, st.max * slope + inter);
  const double hi = std::max(st.min * slope + inter, st.max * slope + inter);
  ScalarType out = ScalarType::kFloat32;
  if (integral && lo >= -32768 && hi <= 32767) {
    out = ScalarType::kInt16;
  } else if (integral && lo >= std::numeric_limits<int32_t>::lowest() &&
             hi <= std::numeric_limits<int32_t>::max()) {
    out = ScalarType::kInt32;
  }
  Volume scaled = Volume::Zeros(v.dims, out, v.spacing);
  for (int z = 0; z < v.dims.z; ++z)
    for (int y = 0; y < v.dims.y; ++y)
      for (int x = 0; x < v.dims.x; ++x) scaled.SetValue(x, y, z, v.Value(x, y, z) * slope + inter);
  v = std::move(scaled);
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
