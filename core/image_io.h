// Image files through OpenImageIO: PNG/JPG (8/16 bit) and OpenEXR (float32,
// depth maps). Format follows the file extension. Reads validate that the file
// exists and decodes; writes are atomic (temp + rename).
#pragma once

#include <cstdint>
#include <filesystem>

#include "core/image.h"

namespace core {

// Limits every image read obeys (docs/guide/limits.md, "Images"), checked
// from the header before any pixel is decoded: 16384 is the GL texture size
// limit of Mesa and most GPUs. The pixel count is bounded by the memory budget
// (core/memory_budget.h), checked on the decoded size before decoding.
inline constexpr int kMaxImageSide = 16384;
inline constexpr int kMaxImageChannels = 4;

// Reads any image OpenImageIO understands (a .png/.jpg/.exr/.tif must hold
// that format; a JPEG must not be truncated; sizes within the limits above), converting to T:
//   uint8_t/uint16_t: integer files keep their values when the bit depth matches;
//   float: integer files are normalised to [0, 1] (OIIO convention), float
//          files (EXR) are returned exactly.
// `channels` > 0 requires exactly that many channels (InputError otherwise).
template <typename T>
Image<T> ReadImage(const std::filesystem::path& path, int channels = 0);

// Writes `image` to `path` atomically. EXR keeps float32 exactly; PNG takes
// uint8/uint16; floats written to PNG/JPG are clamped to [0,1] and quantised.
// Every file carries core::kFileMark as its `Software` attribute (a PNG text
// chunk, an EXR header attribute): what lets a later run replace it.
template <typename T>
void WriteImage(const std::filesystem::path& path, const Image<T>& image);

// Rewrites the image file `file` in place, in its own format and with the same
// pixels, adding the `Software` mark: for images a helper tool writes for ibr
// (gnuplot's plots). `file` is a staging file (core::AtomicWrite's).
void MarkImageFile(const std::filesystem::path& file);

// Image size and channel count without decoding the pixels.
struct ImageHeader {
  int width = 0;
  int height = 0;
  int channels = 0;
};
ImageHeader ReadImageHeader(const std::filesystem::path& path);

extern template Image<uint8_t> ReadImage(const std::filesystem::path&, int);
extern template Image<uint16_t> ReadImage(const std::filesystem::path&, int);
extern template Image<float> ReadImage(const std::filesystem::path&, int);
extern template void WriteImage(const std::filesystem::path&, const Image<uint8_t>&);
extern template void WriteImage(const std::filesystem::path&, const Image<uint16_t>&);
extern template void WriteImage(const std::filesystem::path&, const Image<float>&);

}  // namespace core
