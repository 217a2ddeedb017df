// Putting rendered images together for a user to look at: a frame composited
// over a background, several frames on one sheet.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "core/image.h"

namespace core {

// Colour over an opaque background (premultiplied frame -> RGBA8 with alpha 255).
Image8 OverBackground(const Image8& premultiplied, const glm::vec3& background);

// Images (RGBA8, any sizes) placed on a grid of `columns`, each cell the size
// of the largest image, with a `gap_px` dark border, labels not drawn.
Image8 ContactSheet(const std::vector<Image8>& images, int columns, int gap_px = 4);

}  // namespace core
