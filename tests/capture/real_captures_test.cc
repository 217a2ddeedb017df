// Real third-party captures (../shared/data/tests-real/captures/README.md) through the
// importers: a COLMAP model of four photos of a facade (kapture's
// maupertuis sample) and one TUM RGB-D frame (Open3D's test data).
// - the COLMAP box is a percentile box: one stray point 1000 units away
//   leaves it within a small factor of the points' robust extent;
// - a sparse-only import says that nothing can be rendered yet and how to
//   add depth or masks; with --masks it renders as a visual hull;
// - the imported "up" is least along the cameras' x axes (from the
//   quaternions, parsed here), on the side of their -y axes;
// - the depth-scale check warns on the TUM frame read at 1000 units/m (and
//   names 5000), not at 5000; on the shared Redwood frames read at 5000 the
//   views disagree and 1000 is named;
// - cameras-only manifests (views without images) read for novel views.
#include "tests/support/real_captures.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "capture/colmap_dataset.h"
#include "capture/depth_scale.h"
#include "capture/importers.h"
#include "core/error.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"

namespace capture {
namespace {
namespace fs = std::filesystem;

const fs::path kReal = test_support::RealCapturesDir();

fs::path Fresh(const std::string& name) {
  const fs::path dir = test_support::TestOutputDir() / "real_captures" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

// The maupertuis model copied to `dir` (images + sparse/), optionally with a
// stray point appended to points3D.txt.
fs::path CopyMaupertuis(const fs::path& dir, bool stray_point) {
  fs::create_directories(dir);
  fs::copy(kReal / "maupertuis", dir, fs::copy_options::recursive);
  if (stray_point) {
    std::ofstream(dir / "sparse/points3D.txt", std::ios::app)
        << "1000000 1000 1000 1000 255 0 0 0.5 1 0\n";
  }
  return dir;
}

// Every sparse point of the original file, parsed here (not by colmap_io).
std::vector<glm::dvec3> MaupertuisPoints() {
  std::ifstream in(kReal / "maupertuis/sparse/points3D.txt");
  std::vector<glm::dvec3> points;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double id, x, y, z;
    s >> id >> x >> y >> z;
    points.emplace_back(x, y, z);
  }
  return points;
}

TEST(RealCaptures, ColmapBoxIgnoresAStrayPoint) {
  const fs::path src = CopyMaupertuis(Fresh("maupertuis_stray"), /*stray_point=*/true);
  std::vector<std::string> notes;
  const Dataset d = ImportColmap(src, Fresh("maupertuis_stray_out"), {}, {},
                                 [&](const std::string& n) { notes.push_back(n); });
  ASSERT_TRUE(d.bounds.has_value());
  const std::vector<glm::dvec3> points = MaupertuisPoints();
  ASSERT_EQ(points.size(), 1039u);
  // The points' robust extent, independently: the 5-95 % span per axis.
  for (int k = 0; k < 3; ++k) {
    std::vector<double> a;
    for (const glm::dvec3& p : points) a.push_back(p[k]);
    std::sort(a.begin(), a.end());
    const double span = a[a.size() * 95 / 100] - a[a.size() * 5 / 100];
    const double side = d.bounds->extent()[k];
    EXPECT_GT(side, span) << "axis " << k;
    EXPECT_LT(side, 3 * span) << "axis " << k << ": the box is not robust";
    // A min/max box would reach the stray point at 1000.
    EXPECT_LT(d.bounds->max[k], 100) << "axis " << k;
    std::printf("axis %d: box side %.3f, 5-95 %% span %.3f (ratio %.2f)\n", k, side, span,
                side / span);
  }
  // The box holds at least 97 % of the points (1-99 % per axis, plus margin).
  size_t inside = 0;
  for (const glm::dvec3& p : points) {
    inside += glm::all(glm::greaterThanEqual(p, d.bounds->min)) &&
              glm::all(glm::lessThanEqual(p, d.bounds->max));
  }
  EXPECT_GE(inside, points.size() * 97 / 100);
  std::printf("points inside the box: %zu of %zu\n", inside, points.size());
  // The note prints the box and how much larger every point's box is.
  std::string all;
  for (const std::string& n : notes) all += n + "\n";
  EXPECT_NE(all.find("bounds min ("), std::string::npos) << all;
  EXPECT_NE(all.find("of 1040 sparse points per axis"), std::string::npos) << all;
  EXPECT_NE(all.find("every point:"), std::string::npos) << all;
  std::printf("%s", all.c_str());
}

TEST(RealCaptures, SparseOnlyImportSaysWhatCanBeRendered) {
  const fs::path src = CopyMaupertuis(Fresh("maupertuis"), false);
  std::vector<std::string> notes;
  const Dataset d = ImportColmap(src, Fresh("maupertuis_out"), {}, {},
                                 [&](const std::string& n) { notes.push_back(n); });
  ASSERT_EQ(d.views.size(), 4u);
  for (const DatasetView& v : d.views) {
    EXPECT_TRUE(v.depth.empty());
    EXPECT_TRUE(v.mask.empty());
  }
  std::string all;
  for (const std::string& n : notes) all += n + "\n";
  EXPECT_NE(all.find("sparse model only"), std::string::npos) << all;
  EXPECT_NE(all.find("neither a depth object"), std::string::npos) << all;
  EXPECT_NE(all.find("COLMAP's dense steps"), std::string::npos) << all;
  EXPECT_NE(all.find("--masks DIR"), std::string::npos) << all;

  // With silhouettes (COLMAP's mask naming, NAME.png): masks, and the note
  // says a visual hull renders. The masks here are a centred rectangle.
  const fs::path masks = src / "masks";
  fs::create_directories(masks);
  for (const char* name : {"00.jpg", "01.jpg", "02.jpg", "03.jpg"}) {
    core::Image8 m(1919, 1079, 1);
    for (int y = 300; y < 800; ++y)
      for (int x = 500; x < 1400; ++x) m.at(x, y) = 255;
    core::WriteImage(masks / (std::string(name) + ".png"), m);
  }
  ColmapImportOptions options;
  options.masks = masks;
  notes.clear();
  const Dataset with_masks = ImportColmap(src, Fresh("maupertuis_masks_out"), options, {},
                                          [&](const std::string& n) { notes.push_back(n); });
  ASSERT_EQ(with_masks.views.size(), 4u);
  const core::Image8 mask = with_masks.LoadMask(0);
  EXPECT_EQ(mask.at(900, 500), 255);  // SIMPLE_PINHOLE: no undistortion moves it
  EXPECT_EQ(mask.at(100, 100), 0);
  all.clear();
  for (const std::string& n : notes) all += n + "\n";
  EXPECT_NE(all.find("renders as a visual hull"), std::string::npos) << all;
  // A photo without a mask is refused, naming what was looked for.
  fs::remove(masks / "02.jpg.png");
  try {
    ImportColmap(src, Fresh("maupertuis_masks_missing"), options);
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no mask for '02.jpg'"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(
      fs::exists(test_support::TestOutputDir() / "real_captures/maupertuis_masks_missing"));
}

// R(q) for COLMAP's (qw, qx, qy, qz), written out here (Hamilton, unit).
glm::dmat3 RotationRows(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n, x /= n, y /= n, z /= n;
  // glm is column-major: m[c][r].
  glm::dmat3 m;
  m[0][0] = 1 - 2 * (y * y + z * z), m[1][0] = 2 * (x * y - w * z), m[2][0] = 2 * (x * z + w * y);
  m[0][1] = 2 * (x * y + w * z), m[1][1] = 1 - 2 * (x * x + z * z), m[2][1] = 2 * (y * z - w * x);
  m[0][2] = 2 * (x * z - w * y), m[1][2] = 2 * (y * z + w * x), m[2][2] = 1 - 2 * (x * x + y * y);
  return m;
}

TEST(RealCaptures, ColmapUpIsLeastAlongTheCamerasXAxes) {
  const Dataset d =
      ImportColmap(CopyMaupertuis(Fresh("maupertuis_up"), false), Fresh("maupertuis_up_out"));
  ASSERT_TRUE(d.up.has_value());
  // From images.txt's quaternions: the camera's y axis in world is R's row 1.
  std::ifstream in(kReal / "maupertuis/sparse/images.txt");
  glm::dvec3 minus_y(0.0);
  glm::dmat3 xx(0.0);
  int images = 0;
  bool pose_line = true;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '#') continue;
    if (pose_line) {
      std::istringstream s(line);
      double id, w, x, y, z;
      s >> id >> w >> x >> y >> z;
      const glm::dmat3 r = RotationRows(w, x, y, z);
      const glm::dvec3 x_axis(r[0][0], r[1][0], r[2][0]);
      minus_y -= glm::dvec3(r[0][1], r[1][1], r[2][1]);
      xx += glm::outerProduct(x_axis, x_axis);
      ++images;
    }
    pose_line = !pose_line;
  }
  ASSERT_EQ(images, 4);
  const glm::dvec3 up = *d.up;
  // Least along the cameras' x axes: an eigenvector of sum x x^T (M up =
  // lambda up), no more along them than -(mean y), and on -(mean y)'s side.
  const double lambda = glm::dot(up, xx * up);
  EXPECT_LT(glm::length(xx * up - lambda * up), 1e-6);
  const glm::dvec3 mean_up = glm::normalize(minus_y);
  EXPECT_LE(lambda, glm::dot(mean_up, xx * mean_up) + 1e-12);
  std::printf("up (%.4f, %.4f, %.4f); -(mean y) (%.4f, %.4f, %.4f); sum (up.x)^2 %.2e\n", up.x,
              up.y, up.z, mean_up.x, mean_up.y, mean_up.z, lambda);
  // The photos are a drone's, circling the building and looking down at it
  // (images 00-03 show its roof from above): every camera holds x level
  // (within 2 degrees of across up), and looks down steeply, so -(mean y)
  // leans far from up and would tilt an orbit.
  for (const DatasetView& v : d.views) {
    const glm::dmat3& r = v.cam_from_world.rotation;
    const glm::dvec3 x(r[0][0], r[1][0], r[2][0]), z(r[0][2], r[1][2], r[2][2]);
    EXPECT_LT(std::abs(glm::dot(x, up)), std::sin(2 * M_PI / 180)) << v.name;
    const double down_deg = std::asin(-glm::dot(z, up)) * 180 / M_PI;
    std::printf("view %s: x.up %.4f, looks %.1f degrees below the horizon\n", v.name.c_str(),
                glm::dot(x, up), down_deg);
    EXPECT_GT(down_deg, 20) << v.name;
    EXPECT_GT(glm::dot(-glm::dvec3(r[0][1], r[1][1], r[2][1]), up), 0) << v.name;
  }
  EXPECT_LT(glm::dot(up, mean_up), std::cos(20 * M_PI / 180)) << "-(mean y) is 20+ degrees off";
  // The manifest keeps it.
  EXPECT_EQ(ReadDataset(d.root).up, d.up);
  EXPECT_EQ(DefaultUp(d).source, "dataset.json \"up\"");
}

TEST(RealCaptures, TumFrameDepthScaleWarnsOnlyAtTheWrongScale) {
  const fs::path src = test_support::WriteTumRedwoodLayout(Fresh("tum"));
  for (const double scale : {5000.0, 1000.0}) {
    std::vector<std::string> notes;
    RedwoodImportOptions options;
    options.depth_scale = scale;
    const Dataset d = ImportRedwood(src, Fresh(fmt::format("tum_{}", scale)), options, {},
                                    [&](const std::string& n) { notes.push_back(n); });
    const DepthScaleReport r = CheckDepthScale(d);
    std::string all;
    for (const std::string& n : notes) all += n + "\n";
    std::printf("scale %g: median %.3f m over %zu samples; %s", scale, r.median, r.samples,
                all.c_str());
    EXPECT_EQ(r.views, 1u);
    EXPECT_EQ(r.pairs, 0u) << "one frame: no baseline";
    if (scale == 5000) {
      EXPECT_TRUE(r.warning.empty()) << r.warning;
      EXPECT_EQ(all.find("warning"), std::string::npos) << all;
      EXPECT_GT(r.median, 0.3);
      EXPECT_LT(r.median, 5.0);
    } else {
      EXPECT_NE(r.warning.find("working range"), std::string::npos) << r.warning;
      EXPECT_EQ(r.suggested_factor, 0.2);
      EXPECT_NE(all.find("--depth-scale 5000 instead of 1000"), std::string::npos) << all;
    }
    // A y-down sensor at the identity pose: up is -y.
    ASSERT_TRUE(d.up.has_value());
    EXPECT_EQ(*d.up, glm::dvec3(0, -1, 0));
  }
}

// Several frames with a baseline: the wrong scale also shows as views that
// disagree (the shared Redwood frames, millimetres, read at TUM's 5000).
TEST(RealCaptures, RedwoodFramesDisagreeAtTheWrongScale) {
  const fs::path src = test_support::SharedData("rgbd/redwood5");
  if (src.empty()) GTEST_SKIP() << "../shared/data/rgbd/redwood5 is absent (IBR_SHARED_DATA)";
  for (const double scale : {1000.0, 5000.0}) {
    RedwoodImportOptions options;
    options.depth_scale = scale;
    const Dataset d = ImportRedwood(src, Fresh(fmt::format("redwood_{}", scale)), options);
    const DepthScaleReport r = CheckDepthScale(d);
    std::printf("scale %g: median %.3f m, %zu pairs, agreement %.3f, warning '%s'\n", scale,
                r.median, r.pairs, r.agreement, r.warning.c_str());
    ASSERT_GT(r.pairs, 0u) << "the frames have no baseline";
    if (scale == 1000) {
      EXPECT_TRUE(r.warning.empty()) << r.warning;
      EXPECT_GT(r.agreement, 0.5);
    } else {
      EXPECT_NE(r.warning.find("reprojected"), std::string::npos) << r.warning;
      EXPECT_EQ(r.suggested_factor, 5);
    }
  }
}

TEST(RealCaptures, CamerasOnlyManifestsReadAsNovelViews) {
  Dataset d;
  d.cameras.emplace(1, Camera::Pinhole(64, 48, 50, 50, 32, 24));
  DatasetView v;
  v.name = "novel";
  v.camera_id = 1;
  v.cam_from_world.translation = {0, 0, 3};
  d.views.push_back(v);
  std::stringstream s;
  WriteManifest(s, d);
  EXPECT_EQ(s.str().find("\"color\""), std::string::npos) << "no image named";
  const fs::path dir = Fresh("cameras_only");
  fs::create_directories(dir);
  std::ofstream(dir / "novel.json") << s.str();
  const Dataset read = ReadCameras(dir / "novel.json");
  ASSERT_EQ(read.views.size(), 1u);
  EXPECT_EQ(read.views[0].cam_from_world, v.cam_from_world);
  // As a dataset of images, the same file is refused: a view names no colour.
  std::stringstream again(s.str());
  EXPECT_THROW(ReadManifest(again, "novel.json"), core::InputError);
  // No "up" and an upright camera: the cameras' mean up, -y of the camera.
  EXPECT_EQ(DefaultUp(read).source, "the input cameras' mean up");
  EXPECT_EQ(DefaultUp(read).up, glm::dvec3(0, -1, 0));
}

TEST(RealCaptures, RobustBoundsDropsThePercentileTails) {
  std::vector<glm::dvec3> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(i, 2 * i, -i);
  points.emplace_back(1e5, 1e5, 1e5);
  // 101 points, 1 %: nearest rank floor(0.01 * 100) = 1 from each end.
  const Bounds b = RobustBounds(points, 1, 0);
  EXPECT_EQ(b.min, glm::dvec3(1, 2, -98));
  EXPECT_EQ(b.max, glm::dvec3(99, 198, 0));
}

}  // namespace
}  // namespace capture
