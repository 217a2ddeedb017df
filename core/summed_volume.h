// Counts of flagged cells of a 3D grid over any axis-aligned box in constant
// time: a summed-volume table (the 3D summed-area table). Used to classify
// displacement-map bricks (core::ClassifyMapBricks) and to merge labelled
// cells into boxes (render::BoxTreeOfGrid).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace core {

class SummedVolume {
 public:
  // flags: one per cell of a dims grid, x fastest; non-zero cells count.
  SummedVolume(const glm::ivec3& dims, const std::vector<uint8_t>& flags);
  // Flagged cells in [lo, hi) (hi exclusive), 0 <= lo <= hi <= dims.
  int Count(const glm::ivec3& lo, const glm::ivec3& hi) const;

 private:
  size_t At(int x, int y, int z) const {
    return (static_cast<size_t>(z) * (dims_.y + 1) + y) * (dims_.x + 1) + x;
  }
  glm::ivec3 dims_;
  std::vector<int> sums_;  // (dims + 1)^3: sums_[At(x, y, z)] = flagged cells in [0, (x, y, z))
};

}  // namespace core
