// Depth objects and visual hulls on real data (issue 5, "Real data"):
// - the Middlebury temple and dino rings (16 calibrated photos each, masks by
//   the README's recipe, imported with capture::ImportMiddlebury): the visual
//   hull rendered from every input camera, reprojected, agrees with that
//   photo's mask;
// - the Redwood RGB-D frames (capture::ImportRedwood) as a robust depth
//   object: from a novel view finite, non-empty and inside the scene, and
//   from an input camera its depth agrees with that frame's sensor depth.
// Needs ../shared/data (IBR_SHARED_DATA); skips with the reason when absent.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "capture/importers.h"
#include "core/image_io.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/views.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

namespace fs = std::filesystem;

class RealDataTest : public test_support::GlTest {};

// ------------------------------------------------------------ Middlebury ----

struct MaskAgreement {
  int64_t hull = 0, photo = 0, both = 0;
  double iou() const {
    return hull + photo - both > 0 ? double(both) / double(hull + photo - both) : 1.0;
  }
  // Of the hull's pixels, the fraction inside the photo's mask.
  double precision() const { return hull > 0 ? double(both) / double(hull) : 1.0; }
  // Of the photo's mask, the fraction the hull covers.
  double recall() const { return photo > 0 ? double(both) / double(photo) : 1.0; }
};

// The views are rendered at 1/kDown of the photos' size (llvmpipe: a
// 640x480 hull of 16 maps at 256 slices takes ~30 s a view). Pixel (c, r) of
// the small view has its centre at photo coordinates (kDown c + kDown/2,
// kDown r + kDown/2): with kDown = 2 exactly the photo texel the hull test
// reads there, so each small pixel is compared with that texel.
constexpr int kDown = 2;

template <typename T>
core::Image<T> SampleLikeTheView(const core::Image<T>& photo) {
  core::Image<T> out(photo.width() / kDown, photo.height() / kDown, photo.channels());
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = 0; c < photo.channels(); ++c)
        out.at(x, y, c) = photo.at(kDown * x + kDown / 2, kDown * y + kDown / 2, c);
  return out;
}

// Counts inside the pixel rectangle [x0, x1) x [y0, y1) of the view.
MaskAgreement CompareMasks(const core::Image8& hull, const core::Image8& photo, int x0, int y0,
                           int x1, int y1) {
  MaskAgreement a;
  for (int y = std::max(y0, 0); y < std::min(y1, hull.height()); ++y) {
    for (int x = std::max(x0, 0); x < std::min(x1, hull.width()); ++x) {
      const bool h = hull.at(x, y) > 127, m = photo.at(x, y) > 127;
      a.hull += h;
      a.photo += m;
      a.both += h && m;
    }
  }
  return a;
}

// Hull pixels with no mask pixel of the full-size photo within one texel of
// the texel their centre falls on ((kDown c + 1, kDown r + 1); float rounding
// of the projection may pick a neighbour).
int64_t HullPixelsOutsideTheMask(const core::Image8& hull, const core::Image8& full_mask) {
  int64_t outside = 0;
  for (int y = 0; y < hull.height(); ++y) {
    for (int x = 0; x < hull.width(); ++x) {
      if (hull.at(x, y) <= 127) continue;
      bool near_mask = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int px = std::clamp(kDown * x + kDown / 2 + dx, 0, full_mask.width() - 1);
          const int py = std::clamp(kDown * y + kDown / 2 + dy, 0, full_mask.height() - 1);
          near_mask = near_mask || full_mask.at(px, py) > 127;
        }
      outside += !near_mask;
    }
  }
  return outside;
}

// Green = both, red = hull only, blue = photo mask only.
core::Image8 Overlay(const core::Image8& hull, const core::Image8& photo) {
  core::Image8 out(hull.width(), hull.height(), 3, 0);
  for (int y = 0; y < hull.height(); ++y) {
    for (int x = 0; x < hull.width(); ++x) {
      const bool h = hull.at(x, y) > 127, m = photo.at(x, y) > 127;
      out.at(x, y, 0) = h && !m ? 255 : 0;
      out.at(x, y, 1) = h && m ? 200 : 0;
      out.at(x, y, 2) = !h && m ? 255 : 0;
    }
  }
  return out;
}

struct RingCase {
  const char* folder;
  // Lower bounds on every view's IoU, on the whole image and inside the
  // README box's projection, a little below the measured worst view (see
  // the test for why they are not higher).
  double min_iou;
  double min_iou_in_box;
};

void PrintTo(const RingCase& ring, std::ostream* os) { *os << ring.folder; }

class MiddleburyHullTest : public RealDataTest, public ::testing::WithParamInterface<RingCase> {};

TEST_P(MiddleburyHullTest, HullReprojectedIntoEachPhotoAgreesWithItsMask) {
  const RingCase ring = GetParam();
  const fs::path src = test_support::SharedData(fmt::format("photos/{}", ring.folder));
  if (src.empty())
    GTEST_SKIP() << "../shared/data/photos/" << ring.folder << " is absent (IBR_SHARED_DATA)";
  const fs::path out = test_support::TestOutputDir() / ring.folder;
  fs::remove_all(out);
  capture::ImportMiddlebury(src, out / "dataset");  // the README's mask recipe (default options)
  const capture::Dataset dataset = capture::ReadDataset(out / "dataset");
  ASSERT_EQ(dataset.views.size(), 16u);

  DepthObjectRenderer renderer(programs(), MapsFromDataset(dataset));
  std::vector<ViewCamera> views = ViewsFromDataset(dataset);
  for (ViewCamera& v : views) v.camera = ResizeCamera(v.camera, v.camera.width / kDown);
  DepthObjectOptions o;
  o.method = Method::kVisualHull;
  o.slicing = Slicing::kScreen;
  // Screen slices are view planes, so from an input camera a silhouette
  // pixel's own cone is tested at its own texel on every slice; 128 slices
  // through the box (~0.2 scene units deep: < 2 mm apart) leave none of the
  // object's parts (columns ~5 mm, the dinosaur's legs) between two slices.
  o.slices = 128;
  o.texturing = Texturing::kNone;
  o.outside = OutsidePolicy::kPass;  // the default: the object is inside every photo anyway
  std::vector<double> ious;
  std::vector<core::Image8> sheet;
  for (size_t i = 0; i < views.size(); ++i) {
    core::Stopwatch watch;
    const render::Frame frame = renderer.RenderFrame(views[i], o);
    const double ms = watch.ElapsedMs();
    const core::Image8 hull_mask = render::CoverageMask(frame);
    const core::Image8 full_mask = dataset.LoadMask(i);
    const core::Image8 photo_mask = SampleLikeTheView(full_mask);
    const MaskAgreement a =
        CompareMasks(hull_mask, photo_mask, 0, 0, hull_mask.width(), hull_mask.height());
    // The same inside the README's tight box projected into the view (plus
    // 3 px): the mask recipe also admits lit clutter at the image borders
    // (parts of the gantry, threshold 0.19), which is no part of the object
    // and which no other photo's cone can contain.
    glm::dvec2 lo(1e30), hi(-1e30);
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 corner((c & 1 ? dataset.bounds->max : dataset.bounds->min).x,
                              (c & 2 ? dataset.bounds->max : dataset.bounds->min).y,
                              (c & 4 ? dataset.bounds->max : dataset.bounds->min).z);
      const glm::dvec3 q(views[i].cam_from_world * glm::dvec4(corner, 1.0));
      const glm::dvec2 uv(views[i].camera.fx * q.x / q.z + views[i].camera.cx,
                          views[i].camera.fy * q.y / q.z + views[i].camera.cy);
      lo = glm::min(lo, uv);
      hi = glm::max(hi, uv);
    }
    const MaskAgreement in_box =
        CompareMasks(hull_mask, photo_mask, static_cast<int>(lo.x) - 3, static_cast<int>(lo.y) - 3,
                     static_cast<int>(hi.x) + 4, static_cast<int>(hi.y) + 4);
    const int64_t outside = HullPixelsOutsideTheMask(hull_mask, full_mask);
    ious.push_back(a.iou());
    std::printf(
        "%s %s: hull %lld px, mask %lld px, IoU %.4f (precision %.4f, recall %.4f), in the README "
        "box "
        "IoU %.4f; %lld hull px off the mask; %.0f ms\n",
        ring.folder, dataset.views[i].name.c_str(), static_cast<long long>(a.hull),
        static_cast<long long>(a.photo), a.iou(), a.precision(), a.recall(), in_box.iou(),
        static_cast<long long>(outside), ms);
    // The hull is the intersection of every camera's silhouette cone, this
    // camera's included, and from this camera a fragment at a pixel centre
    // projects onto that same pixel of its own mask: the hull never leaves
    // the photo's mask (up to the texel next door, float rounding).
    EXPECT_EQ(outside, 0) << dataset.views[i].name;
    // The other 15 cones cut into the mask wherever the calibration (about a
    // pixel on this data) or the threshold-dilate-erode silhouettes (dark
    // parts and shadows on the base below the 0.19 threshold that the closing
    // does not fill, differently in each photo) disagree between photos:
    // a band along the outline. The bound on the whole image also pays for
    // the clutter the recipe picks up at the temple photos' borders (0.82
    // measured on templeSR0002); inside the box mostly the band remains
    // (0.92 on templeSR0002, where the clutter reaches into the box; 0.96
    // and more elsewhere; the dinosaur's photos are clean: 0.985 and more).
    EXPECT_GE(a.iou(), ring.min_iou) << dataset.views[i].name;
    EXPECT_GE(in_box.iou(), ring.min_iou_in_box) << dataset.views[i].name;
    const core::Image8 overlay = Overlay(hull_mask, photo_mask);
    if (i == 0)
      test_support::WriteDebugImage(
          fmt::format("{}_hull_{}.png", ring.folder, dataset.views[i].name), frame.color);
    sheet.push_back(overlay);
  }
  // All 16 overlays side by side for a look: green both, red hull only, blue mask only.
  core::Image8 montage(views[0].camera.width * 4, views[0].camera.height * 4, 3, 0);
  for (size_t i = 0; i < sheet.size(); ++i) {
    const int ox = static_cast<int>(i % 4) * views[0].camera.width,
              oy = static_cast<int>(i / 4) * views[0].camera.height;
    for (int y = 0; y < sheet[i].height(); ++y)
      for (int x = 0; x < sheet[i].width(); ++x)
        for (int c = 0; c < 3; ++c) montage.at(ox + x, oy + y, c) = sheet[i].at(x, y, c);
  }
  test_support::WriteDebugImage(fmt::format("{}_overlays.png", ring.folder), montage);
  const auto [lo, hi] = std::minmax_element(ious.begin(), ious.end());
  double mean = 0;
  for (double v : ious) mean += v / ious.size();
  std::printf("%s: mask IoU over 16 views: min %.4f mean %.4f max %.4f\n", ring.folder, *lo, mean,
              *hi);
  EXPECT_NO_GL_ERROR();
}

INSTANTIATE_TEST_SUITE_P(Rings, MiddleburyHullTest,
                         ::testing::Values(RingCase{"templeSparseRing", 0.80, 0.90},
                                           RingCase{"dinoSparseRing", 0.97, 0.97}),
                         [](const auto& param_info) {
                           return std::string(param_info.param.folder);
                         });

// --------------------------------------------------------------- Redwood ----

// The scene's extent: every valid sensor point of every frame, lifted into
// the world. (ImportRedwood writes no bounds and MapsFromDataset needs them.)
capture::Bounds PointBounds(const capture::Dataset& d) {
  capture::Bounds b{glm::dvec3(std::numeric_limits<double>::max()),
                    glm::dvec3(-std::numeric_limits<double>::max())};
  for (size_t v = 0; v < d.views.size(); ++v) {
    const core::ImageF depth = d.LoadDepth(v);
    const capture::Camera& cam = d.camera(d.views[v]);
    const capture::Rigid3 world_from_cam = d.views[v].cam_from_world.Inverse();
    for (int row = 0; row < depth.height(); ++row) {
      for (int col = 0; col < depth.width(); ++col) {
        const float z = depth.at(col, row);
        if (!(z > 0)) continue;
        const glm::dvec3 p = world_from_cam * cam.UnprojectPixel(col, row, z);
        b.min = glm::min(b.min, p);
        b.max = glm::max(b.max, p);
      }
    }
  }
  return b;
}

TEST_F(RealDataTest, RedwoodRobustDepthObject) {
  const fs::path src = test_support::SharedData("rgbd/redwood5");
  if (src.empty()) GTEST_SKIP() << "../shared/data/rgbd/redwood5 is absent (IBR_SHARED_DATA)";
  const fs::path out = test_support::TestOutputDir() / "redwood";
  fs::remove_all(out);
  capture::ImportRedwood(src, out / "dataset");
  capture::Dataset dataset = capture::ReadDataset(out / "dataset");
  ASSERT_EQ(dataset.views.size(), 5u);
  dataset.bounds = PointBounds(dataset);
  std::printf("redwood: scene bounds (%.3f %.3f %.3f) - (%.3f %.3f %.3f) m\n",
              dataset.bounds->min.x, dataset.bounds->min.y, dataset.bounds->min.z,
              dataset.bounds->max.x, dataset.bounds->max.y, dataset.bounds->max.z);
  MapSet maps = MapsFromDataset(dataset);
  // The importer's mask is "valid depth"; without it a sensor hole (depth 0)
  // is invalid depth inside the silhouette, which kNoConstraint lets carve
  // nothing, instead of carving its whole ray.
  for (ImageMap& m : maps.maps) m.mask = {};
  DepthObjectRenderer renderer(programs(), maps);

  DepthObjectOptions o;
  o.method = Method::kDepthObject;
  o.slicing = Slicing::kScreen;
  o.slices = 128;  // through a box ~4 m deep: ~3 cm apart
  o.robust_k = 1;  // keep what 4 of the 5 frames agree on: sensor noise and edges
  o.invalid_depth = InvalidDepthPolicy::kNoConstraint;
  o.outside = OutsidePolicy::kFail;
  o.texturing = Texturing::kViewDependent;
  o.Check();

  // (1) From each input camera: the rendered depth agrees with that frame's
  // sensor depth. Screen slices are camera-z planes, so the frame's own map
  // leaves the first kept slice within one spacing behind its surface; the
  // other frames can only carve further (where they disagree by more than
  // the robust vote tolerates).
  for (size_t i : {size_t{0}, size_t{2}, size_t{4}}) {
    const ImageMap& m = renderer.maps().maps[i];
    const ViewCamera view{ResizeCamera(m.camera, m.camera.width / kDown), m.cam_from_world};
    const core::ImageF sensor = SampleLikeTheView(m.depth);
    const FrameParams params = PrepareFrame(renderer.maps(), view, o);
    const render::Frame frame = renderer.RenderFrame(view, o);
    const double spacing = params.stack.spacing_world;
    // Tolerance: two slice spacings plus 2 % of the depth (the sensor's
    // quantisation and the frames' mutual disagreement, about 0.3 % median,
    // see capture/importers_test, with a margin for the edges of objects
    // where neighbouring texels of other frames see the background).
    int64_t valid = 0, agree = 0, covered = 0;
    for (int y = 0; y < frame.depth.height(); ++y) {
      for (int x = 0; x < frame.depth.width(); ++x) {
        const float got = frame.depth.at(x, y), want = sensor.at(x, y);
        ASSERT_TRUE(std::isfinite(got)) << x << "," << y;
        covered += got > 0;
        if (!(want > 0)) continue;
        ++valid;
        agree += got > 0 && std::abs(got - want) <= 2.0 * spacing + 0.02 * want;
      }
    }
    const double fraction = double(agree) / double(valid);
    std::printf(
        "redwood input camera %s: %lld valid sensor pixels, %lld rendered, %.4f agree within 2 "
        "spacings "
        "(%.4f m) + 2 %% of depth\n",
        m.name.c_str(), static_cast<long long>(valid), static_cast<long long>(covered), fraction,
        spacing);
    // Most of them (measured 0.97-0.99): the rest are the rims of objects
    // (the chair's tubes, curtain folds), where a neighbouring frame's texel
    // sees the background and carves in front, and pixels the other frames
    // do not see, which kFail carves.
    EXPECT_GE(fraction, 0.95) << m.name;
    test_support::WriteDebugImage(fmt::format("redwood_input_{}_color.png", m.name), frame.color);
  }

  // (2) A novel view: the middle frame's orientation at the mean of the five
  // camera centres, turned by 8 degrees about the camera's y axis.
  glm::dvec3 centre(0.0);
  for (const ImageMap& m : renderer.maps().maps) centre += CameraCentre(m.cam_from_world) / 5.0;
  const glm::dmat4& mid = renderer.maps().maps[2].cam_from_world;
  const glm::dmat3 rot_turn =
      glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(8.0), glm::dvec3(0, 1, 0)));
  const glm::dmat3 rotation = rot_turn * glm::dmat3(mid);
  glm::dmat4 novel_from_world(rotation);
  novel_from_world[3] = glm::dvec4(-(rotation * centre), 1.0);
  const ViewCamera novel{ResizeCamera(renderer.maps().maps[2].camera, 640 / kDown),
                         novel_from_world};
  const FrameParams params = PrepareFrame(renderer.maps(), novel, o);
  const double spacing = params.stack.spacing_world;
  const render::Frame frame = renderer.RenderFrame(novel, o);

  // What the sensor saw, seen from the novel view: every valid pixel of
  // every frame lifted to the world and splatted (nearest z per pixel).
  core::ImageF splat(novel.camera.width, novel.camera.height, 1, 0.0f);
  double scene_lo = std::numeric_limits<double>::max(), scene_hi = 0;
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    const core::ImageF depth = dataset.LoadDepth(v);
    const capture::Camera& cam = dataset.camera(dataset.views[v]);
    const capture::Rigid3 world_from_cam = dataset.views[v].cam_from_world.Inverse();
    for (int row = 0; row < depth.height(); ++row) {
      for (int col = 0; col < depth.width(); ++col) {
        if (!(depth.at(col, row) > 0)) continue;
        const glm::dvec3 p_in_world =
            world_from_cam * cam.UnprojectPixel(col, row, depth.at(col, row));
        const glm::dvec3 q = glm::dvec3(novel.cam_from_world * glm::dvec4(p_in_world, 1.0));
        if (q.z <= 0) continue;
        const double u = novel.camera.fx * q.x / q.z + novel.camera.cx,
                     w = novel.camera.fy * q.y / q.z + novel.camera.cy;
        if (!(u >= 0 && w >= 0 && u < novel.camera.width && w < novel.camera.height)) continue;
        scene_lo = std::min(scene_lo, q.z);
        scene_hi = std::max(scene_hi, q.z);
        float& z = splat.at(static_cast<int>(u), static_cast<int>(w));
        if (z == 0 || q.z < z) z = static_cast<float>(q.z);
      }
    }
  }
  int64_t covered = 0, out_of_range = 0, non_finite = 0, compared = 0, agree = 0;
  for (size_t p = 0; p < frame.depth.pixel_count(); ++p) {
    const float z = frame.depth.data()[p], s = splat.data()[p];
    if (!std::isfinite(z)) ++non_finite;
    if (!(z > 0)) continue;
    ++covered;
    out_of_range += z < scene_lo - 2 * spacing || z > scene_hi + 2 * spacing;
    if (s > 0) {
      ++compared;
      agree += std::abs(z - s) <= 2.0 * spacing + 0.02 * s;
    }
  }
  std::printf(
      "redwood novel view: %lld of %zu pixels covered; the sensor points seen from there span z "
      "%.3f..%.3f m, "
      "%lld rendered pixels outside that (+-2 spacings, %.4f m); %lld pixels with splatted points, "
      "%.4f agree within 2 spacings + 2 %%\n",
      static_cast<long long>(covered), frame.depth.pixel_count(), scene_lo, scene_hi,
      static_cast<long long>(out_of_range), spacing, static_cast<long long>(compared),
      double(agree) / double(std::max<int64_t>(compared, 1)));
  EXPECT_EQ(non_finite, 0);
  EXPECT_GT(covered, 0);
  // Nearly all rendered depth lies where the sensor saw the scene (measured
  // 1 % outside): the exceptions look through sensor holes (the window),
  // which carve nothing under kNoConstraint, so the object there ends where
  // the frames' frusta or the box end.
  EXPECT_LE(double(out_of_range) / double(covered), 0.03);
  // Where sensor points land, the novel view's surface is theirs (measured
  // 0.96): the splat is sparse at grazing surfaces and lets hidden points
  // through between splats, and rims disagree as above.
  EXPECT_GE(double(agree) / double(std::max<int64_t>(compared, 1)), 0.90);
  EXPECT_GE(covered, frame.depth.pixel_count() / 2);
  test_support::WriteDebugImage("redwood_novel_splat.exr", splat);
  test_support::WriteDebugImage("redwood_novel_color.png", frame.color);
  test_support::WriteDebugImage("redwood_novel_depth.exr", frame.depth);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
