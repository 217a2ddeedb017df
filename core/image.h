// A CPU image: row-major, interleaved channels, row 0 at the TOP (image
// convention, as in OpenImageIO/OpenCV/COLMAP). GL readback flips on the way
// in so that every CPU image in the project shares this convention.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/check.h"

namespace core {

template <typename T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels, T fill = T{})
      : width_(width),
        height_(height),
        channels_(channels),
        data_(static_cast<size_t>(width) * height * channels, fill) {
    IBR_CHECK_GE(width, 0);
    IBR_CHECK_GE(height, 0);
    IBR_CHECK_GT(channels, 0);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  size_t pixel_count() const { return static_cast<size_t>(width_) * height_; }
  bool empty() const { return data_.empty(); }

  T& at(int x, int y, int c = 0) { return data_[Index(x, y, c)]; }
  const T& at(int x, int y, int c = 0) const { return data_[Index(x, y, c)]; }

  std::span<T> row(int y) {
    return {data_.data() + static_cast<size_t>(y) * width_ * channels_,
            static_cast<size_t>(width_) * channels_};
  }
  std::span<const T> row(int y) const {
    return {data_.data() + static_cast<size_t>(y) * width_ * channels_,
            static_cast<size_t>(width_) * channels_};
  }

  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& values() { return data_; }
  const std::vector<T>& values() const { return data_; }

  bool operator==(const Image& other) const = default;

 private:
  size_t Index(int x, int y, int c) const {
    IBR_CHECK(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return (static_cast<size_t>(y) * width_ + x) * channels_ + c;
  }

  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<T> data_;
};

using Image8 = Image<uint8_t>;
using ImageF = Image<float>;

}  // namespace core
