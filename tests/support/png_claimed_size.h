// Test inputs whose image header lies about the image's size.
#pragma once

#include <cstdint>
#include <string>

namespace test_support {

// A PNG's IHDR patched to `width` x `height` (CRC recomputed): the header
// claims a huge image, the file is tiny.
inline std::string PngWithClaimedSize(const std::string& png, uint32_t width, uint32_t height) {
  std::string out = png;
  auto put32 = [&](size_t at, uint32_t v) {
    for (int k = 0; k < 4; ++k) out[at + k] = static_cast<char>((v >> (24 - 8 * k)) & 0xff);
  };
  put32(16, width);
  put32(20, height);
  uint32_t crc = 0xffffffffu;  // CRC-32 over chunk type + data (bytes 12..28)
  for (size_t i = 12; i < 29; ++i) {
    crc ^= static_cast<unsigned char>(out[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  put32(29, crc ^ 0xffffffffu);
  return out;
}

}  // namespace test_support
