// The report's gallery (bench/gallery.h): the volume entry is there when the
// shared volumes are, and its render agrees with its truth (the double DVR
// reference of verify/volume_reference.h) within the volume pass test's bound;
// the cut's entry covers what its truth (bench::TraceDeformReference, shared
// with `ibr bench deform`'s accuracy sweep) covers, give or take a silhouette.
#include "bench/gallery.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tests/support/gl_test.h"

namespace bench {
namespace {

using test_support::GlTest;

TEST_F(GlTest, GalleryVolumeEntryAgreesWithTheDoubleReference) {
  if (test_support::SharedData("volumes/tooth_103x94x161_uint8.dat").empty())
    GTEST_SKIP() << "../shared/data is absent";
  GalleryOptions o;
  o.size = 96;
  o.quick = true;
  o.families = {"volume"};
  const std::vector<GalleryEntry> entries = RenderGallery(programs(), o);
  ASSERT_EQ(entries.size(), 1u);
  const GalleryEntry& g = entries.front();
  std::printf("%s: %s\n", g.title.c_str(), g.caption.c_str());
  EXPECT_EQ(g.family, "volume");
  ASSERT_EQ(g.render.width(), o.size);
  ASSERT_EQ(g.truth.width(), o.size);
  ASSERT_EQ(g.heat.width(), o.size);
  test_support::WriteDebugImage("gallery-volume-render.png", g.render);
  test_support::WriteDebugImage("gallery-volume-truth.png", g.truth);
  test_support::WriteDebugImage("gallery-volume-heat.png", g.heat);
  // Something is drawn: pixels off the background (shown over one, opaque).
  int drawn = 0, worst = 0;
  for (int y = 0; y < o.size; ++y)
    for (int x = 0; x < o.size; ++x) {
      drawn += std::abs(g.render.at(x, y, 0) - g.render.at(0, 0, 0)) > 8;
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(g.render.at(x, y, c) - g.truth.at(x, y, c)));
    }
  EXPECT_GT(drawn, 500);
  // Over the background, 8-bit: the colour error (<= 2/255, the bound of
  // VolumeDvrAgreesWithTheDoubleReference) plus one rounding each side.
  EXPECT_LE(worst, 3);
  // The caption's largest error is the pass's bound against the double
  // reference (VolumeDvrAgreesWithTheDoubleReference: 2/255), and the heat
  // map saturates at it: its hottest pixel is white (the ramp's end), and
  // every pixel is on the ramp (dark grey where both are empty).
  const size_t at = g.caption.find("max colour error ");
  ASSERT_NE(at, std::string::npos) << g.caption;
  const double max_error = std::stod(g.caption.substr(at + 17));
  EXPECT_LE(max_error, 2.0);
  int white = 0;
  for (int y = 0; y < o.size; ++y)
    for (int x = 0; x < o.size; ++x) {
      const uint8_t r = g.heat.at(x, y, 0), gr = g.heat.at(x, y, 1), b = g.heat.at(x, y, 2);
      if (r == 40 && gr == 40 && b == 40) continue;
      white += r == 255 && gr == 255 && b == 255;
      EXPECT_TRUE(b == 0 || (r == 255 && gr == 255)) << x << "," << y;
      EXPECT_TRUE(gr == 0 || r == 255) << x << "," << y;
    }
  if (max_error >= 1e-3) {
    EXPECT_GE(white, 1);
  }
  EXPECT_NO_GL_ERROR();
}

TEST_F(GlTest, GalleryDeformEntryCoversWhatTheSphereTracerSees) {
  if (test_support::SharedData("meshes/spot.obj").empty())
    GTEST_SKIP() << "../shared/data is absent";
  GalleryOptions o;
  o.size = 96;
  o.quick = true;
  o.families = {"deform"};
  const std::vector<GalleryEntry> entries = RenderGallery(programs(), o);
  ASSERT_EQ(entries.size(), 1u);
  const GalleryEntry& g = entries.front();
  std::printf("%s: %s\n", g.title.c_str(), g.caption.c_str());
  EXPECT_EQ(g.family, "deform");
  ASSERT_EQ(g.render.width(), o.size);
  ASSERT_EQ(g.truth.width(), o.size);
  test_support::WriteDebugImage("gallery-deform-render.png", g.render);
  test_support::WriteDebugImage("gallery-deform-truth.png", g.truth);
  test_support::WriteDebugImage("gallery-deform-heat.png", g.heat);
  // Coverage (alpha 255): the truth sees Spot, and the pass's silhouette
  // matches it up to a thin rim (a 64^3 field at 96 px: a few percent).
  int truth = 0, both = 0, either = 0;
  for (int y = 0; y < o.size; ++y)
    for (int x = 0; x < o.size; ++x) {
      const bool a = g.render.at(x, y, 3) == 255, b = g.truth.at(x, y, 3) == 255;
      truth += b, both += a && b, either += a || b;
    }
  EXPECT_GT(truth, 500);
  EXPECT_GT(static_cast<double>(both) / either, 0.95);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
