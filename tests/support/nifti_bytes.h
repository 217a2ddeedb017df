// NIfTI-1 and NIfTI-2 files as bytes, header fields at the offsets of
// nifti1.h / nifti2.h, for the readers' tests and fuzz seeds. Written here
// rather than with nifticlib so that a test can also make the malformed and
// big-endian variants nifticlib would not write.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>

namespace test_support {

struct NiftiFields {
  std::array<int64_t, 3> dims{1, 1, 1};
  int rank = 3;          // dim[0]
  int16_t datatype = 4;  // DT_INT16
  int16_t bitpix = 16;
  std::array<double, 3> pixdim{1.0, 1.0, 1.0};
  double slope = 1.0;       // scl_slope
  double inter = 0.0;       // scl_inter
  bool big_endian = false;  // NIfTI-1 only: every header field and 16-bit voxel swapped
};

// A single-file NIfTI-1 (`n+1`, voxels at offset 352) holding `data` as given.
inline std::string Nifti1Bytes(const NiftiFields& f, std::string data) {
  std::string h(352, '\0');
  const auto put = [&](size_t offset, auto value) {
    std::memcpy(h.data() + offset, &value, sizeof value);
    if (f.big_endian) {
      std::reverse(h.begin() + static_cast<std::ptrdiff_t>(offset),
                   h.begin() + static_cast<std::ptrdiff_t>(offset + sizeof value));
    }
  };
  put(0, int32_t{348});
  const int16_t dim[8] = {static_cast<int16_t>(f.rank),
                          static_cast<int16_t>(f.dims[0]),
                          static_cast<int16_t>(f.dims[1]),
                          static_cast<int16_t>(f.dims[2]),
                          1,
                          1,
                          1,
                          1};
  for (int i = 0; i < 8; ++i) put(40 + 2 * i, dim[i]);
  put(70, f.datatype);
  put(72, f.bitpix);
  for (int i = 0; i < 8; ++i)
    put(76 + 4 * i, static_cast<float>(i >= 1 && i <= 3 ? f.pixdim[i - 1] : 1.0));
  put(108, 352.0f);
  put(112, static_cast<float>(f.slope));
  put(116, static_cast<float>(f.inter));
  std::memcpy(h.data() + 344, "n+1\0", 4);
  if (f.big_endian && f.bitpix == 16) {
    for (size_t i = 0; i + 1 < data.size(); i += 2) std::swap(data[i], data[i + 1]);
  }
  return h + data;
}

// A single-file NIfTI-2 (`n+2`, voxels at offset 544), little endian.
inline std::string Nifti2Bytes(const NiftiFields& f, const std::string& data) {
  std::string h(544, '\0');
  const auto put = [&](size_t offset, auto value) {
    std::memcpy(h.data() + offset, &value, sizeof value);
  };
  put(0, int32_t{540});
  std::memcpy(h.data() + 4, "n+2\0\r\n\032\n", 8);
  put(12, f.datatype);
  put(14, f.bitpix);
  const int64_t dim[8] = {f.rank, f.dims[0], f.dims[1], f.dims[2], 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i) put(16 + 8 * i, dim[i]);
  for (int i = 0; i < 8; ++i) put(104 + 8 * i, i >= 1 && i <= 3 ? f.pixdim[i - 1] : 1.0);
  put(168, int64_t{544});
  put(176, f.slope);
  put(184, f.inter);
  return h + data;
}

}  // namespace test_support
