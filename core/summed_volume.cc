#include "core/summed_volume.h"

#include "core/check.h"

namespace core {

SummedVolume::SummedVolume(const glm::ivec3& dims, const std::vector<uint8_t>& flags)
    : dims_(dims), sums_(static_cast<size_t>(dims.x + 1) * (dims.y + 1) * (dims.z + 1), 0) {
  IBR_CHECK_EQ(flags.size(), static_cast<size_t>(dims.x) * dims.y * dims.z);
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const int flag = flags[(static_cast<size_t>(z) * dims.y + y) * dims.x + x] != 0;
        sums_[At(x + 1, y + 1, z + 1)] = flag + sums_[At(x, y + 1, z + 1)] +
                                         sums_[At(x + 1, y, z + 1)] + sums_[At(x + 1, y + 1, z)] -
                                         sums_[At(x, y, z + 1)] - sums_[At(x, y + 1, z)] -
                                         sums_[At(x + 1, y, z)] + sums_[At(x, y, z)];
      }
}

int SummedVolume::Count(const glm::ivec3& lo, const glm::ivec3& hi) const {
  IBR_CHECK(glm::all(glm::lessThanEqual(glm::ivec3(0), lo)) &&
            glm::all(glm::lessThanEqual(lo, hi)) && glm::all(glm::lessThanEqual(hi, dims_)));
  return sums_[At(hi.x, hi.y, hi.z)] - sums_[At(lo.x, hi.y, hi.z)] - sums_[At(hi.x, lo.y, hi.z)] -
         sums_[At(hi.x, hi.y, lo.z)] + sums_[At(lo.x, lo.y, hi.z)] + sums_[At(lo.x, hi.y, lo.z)] +
         sums_[At(hi.x, lo.y, lo.z)] - sums_[At(lo.x, lo.y, lo.z)];
}

}  // namespace core
