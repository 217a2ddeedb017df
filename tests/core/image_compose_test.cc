#include "core/image_compose.h"

#include <gtest/gtest.h>

namespace core {
namespace {

TEST(ImageCompose, ContactSheetPlacesImagesOnAGrid) {
  Image8 a(10, 8, 4, 0), b(6, 6, 4, 0);
  for (auto& v : a.values()) v = 255;  // opaque white
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 6; ++x) {
      b.at(x, y, 0) = 255;  // opaque red
      b.at(x, y, 3) = 255;
    }
  const Image8 sheet = ContactSheet({a, b, a}, 2, 2);
  EXPECT_EQ(sheet.width(), 2 + 2 * (10 + 2));
  EXPECT_EQ(sheet.height(), 2 + 2 * (8 + 2));
  EXPECT_EQ(sheet.at(2, 2, 1), 255);  // a, top-left
  EXPECT_EQ(sheet.at(14, 2, 1), 0);   // b is red: no green
  EXPECT_EQ(sheet.at(14, 2, 0), 255);
  EXPECT_EQ(sheet.at(14 + 7, 2, 0), 40);  // right of b, inside its cell: background
  EXPECT_EQ(sheet.at(0, 0, 0), 40);       // gap
}

TEST(ImageCompose, OverBackgroundIsPremultipliedOver) {
  Image8 frame(2, 1, 4, 0);
  frame.at(1, 0, 0) = 100;  // premultiplied red 100 at alpha 0.5
  frame.at(1, 0, 3) = 128;
  const Image8 out = OverBackground(frame, glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(out.at(0, 0, 1), 255);  // transparent: the background
  EXPECT_EQ(out.at(0, 0, 3), 255);
  EXPECT_EQ(out.at(1, 0, 0), 100);
  // 1 - 128/255 of the green background.
  EXPECT_EQ(out.at(1, 0, 1), static_cast<int>((1 - 128 / 255.0f) * 255.0f + 0.5f));
  EXPECT_EQ(out.at(1, 0, 3), 255);
}

}  // namespace
}  // namespace core
