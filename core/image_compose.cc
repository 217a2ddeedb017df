#include "core/image_compose.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/check.h"

namespace core {

Image8 OverBackground(const Image8& premultiplied, const glm::vec3& background) {
  Image8 out(premultiplied.width(), premultiplied.height(), 4);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      const float a = premultiplied.at(x, y, 3) / 255.0f;
      for (int c = 0; c < 3; ++c) {
        const float v = premultiplied.at(x, y, c) / 255.0f + (1 - a) * background[c];
        out.at(x, y, c) = static_cast<uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
      }
      out.at(x, y, 3) = 255;
    }
  return out;
}

Image8 ContactSheet(const std::vector<Image8>& images, int columns, int gap_px) {
  IBR_CHECK(!images.empty() && columns >= 1 && gap_px >= 0);
  int cell_w = 0, cell_h = 0;
  for (const auto& im : images) {
    cell_w = std::max(cell_w, im.width());
    cell_h = std::max(cell_h, im.height());
  }
  const int cols = std::min<int>(columns, static_cast<int>(images.size()));
  const int rows = (static_cast<int>(images.size()) + cols - 1) / cols;
  Image8 sheet(gap_px + cols * (cell_w + gap_px), gap_px + rows * (cell_h + gap_px), 4, 0);
  for (int y = 0; y < sheet.height(); ++y) {
    for (int x = 0; x < sheet.width(); ++x) {
      for (int c = 0; c < 3; ++c) sheet.at(x, y, c) = 40;
      sheet.at(x, y, 3) = 255;
    }
  }
  for (size_t i = 0; i < images.size(); ++i) {
    const Image8& im = images[i];
    const int ox = gap_px + static_cast<int>(i % cols) * (cell_w + gap_px);
    const int oy = gap_px + static_cast<int>(i / cols) * (cell_h + gap_px);
    for (int y = 0; y < im.height(); ++y) {
      for (int x = 0; x < im.width(); ++x) {
        // Composite over a light grey so transparent backgrounds read as such.
        const float a = im.channels() == 4 ? im.at(x, y, 3) / 255.0f : 1.0f;
        for (int c = 0; c < 3; ++c) {
          const float v = im.at(x, y, std::min(c, im.channels() - 1));
          sheet.at(ox + x, oy + y, c) = static_cast<uint8_t>(std::lround(a * v + (1 - a) * 200));
        }
      }
    }
  }
  return sheet;
}

}  // namespace core
