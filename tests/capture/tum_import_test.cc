// The TUM RGB-D importer (capture/tum_import.h): the list and trajectory
// parsers, association by timestamp (associate.py's closest-first rule),
// pose interpolation, the published calibrations; then the real fr3/cabinet
// keyframes (../shared/data/real-captures/tum_fr3_cabinet, README.md there)
// imported in one call and checked against what the files say
// independently: every camera centre is its ground-truth position, and the
// cabinet's surveyed box (truth_objects.txt) lies where the imported depth
// maps see a surface, view after view.
#include "capture/tum_import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <sstream>

#include "core/error.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"

namespace capture {
namespace {
namespace fs = std::filesystem;

const fs::path kCabinet = fs::path(IBR_REAL_CAPTURES_DIR) / "tum_fr3_cabinet";

std::vector<TumStamped> List(const std::string& text) {
  std::istringstream in(text);
  return ReadTumList(in, "list.txt");
}

TEST(TumImport, ListsAndTrajectoriesParseAndBadLinesNameTheLine) {
  const auto list =
      List("# color images\n# timestamp filename\n1.5 rgb/1.5.png\n\n2.25 rgb/2.png\n");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_DOUBLE_EQ(list[1].time, 2.25);
  EXPECT_EQ(list[1].file, "rgb/2.png");
  for (const auto& [text, says] : std::vector<std::pair<std::string, std::string>>{
           {"1.5\n", "line 1: expected \"timestamp filename\""},
           {"# x\nabc rgb/a.png\n", "line 2: 'abc' is not a finite number"},
           {"1 a.png extra\n", "line 1"},
           {"# only comments\n", "no entries"}}) {
    try {
      List(text);
      ADD_FAILURE() << text;
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("'list.txt'"), std::string::npos) << e.what();
    }
  }
  std::istringstream gt(
      "# timestamp tx ty tz qx qy qz qw\n1 1 2 3 0 0 0 1\n2 1 2 3 0 0 0.7071068 0.7071068\n");
  const auto poses = ReadTumTrajectory(gt, "gt.txt");
  ASSERT_EQ(poses.size(), 2u);
  // world_from_cam's translation is the camera centre.
  EXPECT_NEAR(glm::length(poses[1].cam_from_world.Centre() - glm::dvec3(1, 2, 3)), 0, 1e-12);
  // 90 degrees about z: the camera's x axis is the world's y.
  const glm::dvec3 x_in_world =
      glm::transpose(poses[1].cam_from_world.rotation) * glm::dvec3(1, 0, 0);
  EXPECT_NEAR(glm::length(x_in_world - glm::dvec3(0, 1, 0)), 0, 1e-6);
  std::istringstream bad("1 0 0 0 0 0 0 2\n");
  EXPECT_THROW(ReadTumTrajectory(bad, "gt.txt"), core::InputError);
  std::istringstream backwards("2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_THROW(ReadTumTrajectory(backwards, "gt.txt"), core::InputError);
}

TEST(TumImport, AssociationTakesTheClosestPairsFirstEachOnce) {
  const auto rgb = List("1.000 a\n1.010 b\n2.000 c\n3.000 d\n");
  const auto depth = List("1.008 A\n2.050 C\n2.995 D\n");
  const auto pairs = AssociateTum(rgb, depth, 0.02);
  // A is nearest to a (0.008) but nearer still to b (0.002): b takes it and
  // a has no depth; c's nearest is beyond the bound; d pairs with D.
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], (std::pair<size_t, size_t>{1, 0}));
  EXPECT_EQ(pairs[1], (std::pair<size_t, size_t>{3, 2}));
  EXPECT_EQ(AssociateTum(rgb, depth, 0.001).size(), 0u);
}

TEST(TumImport, PosesInterpolateOnTheLineAndTheShortestArc) {
  std::vector<TumPose> t(2);
  t[0].time = 10;
  t[0].cam_from_world = Rigid3::FromQuaternion({1, 0, 0, 0}, {0, 0, 0}).Inverse();
  t[1].time = 10.05;
  // world_from_cam: 90 degrees about z, centre (1, 0, 0); the quaternion's
  // sign flipped, which the interpolation must not follow the long way.
  t[1].cam_from_world =
      Rigid3::FromQuaternion({-std::sqrt(0.5), 0, 0, -std::sqrt(0.5)}, {1, 0, 0}).Inverse();
  Rigid3 mid;
  ASSERT_TRUE(InterpolateTumPose(t, 10.025, 0.1, mid));
  EXPECT_NEAR(glm::length(mid.Centre() - glm::dvec3(0.5, 0, 0)), 0, 1e-9);
  const glm::dvec3 x_in_world = glm::transpose(mid.rotation) * glm::dvec3(1, 0, 0);
  EXPECT_NEAR(glm::length(x_in_world - glm::dvec3(std::sqrt(0.5), std::sqrt(0.5), 0)), 0, 1e-9);
  Rigid3 p;
  EXPECT_TRUE(InterpolateTumPose(t, 10, 0.1, p));
  EXPECT_FALSE(InterpolateTumPose(t, 9.9, 0.1, p));
  EXPECT_FALSE(InterpolateTumPose(t, 10.1, 0.1, p));
  EXPECT_FALSE(InterpolateTumPose(t, 10.025, 0.01, p));  // a gap in the ground truth
}

TEST(TumImport, CamerasAreTumsPublishedCalibrations) {
  const Camera fr3 = TumCamera("fr3", 640, 480);
  EXPECT_EQ(fr3.model, CameraModel::kPinhole);
  EXPECT_DOUBLE_EQ(fr3.fx(), 535.4);
  EXPECT_DOUBLE_EQ(fr3.cx(), 320.6);  // TUM's integer pixel centres, + 0.5
  const Camera fr1 = TumCamera("fr1", 640, 480);
  EXPECT_EQ(fr1.model, CameraModel::kFullOpenCv);
  EXPECT_TRUE(fr1.distorted());
  EXPECT_DOUBLE_EQ(fr1.params[8], 1.1633);
  EXPECT_DOUBLE_EQ(TumCamera("525,525,319.5,239.5", 640, 480).cy(), 240);
  EXPECT_THROW(TumCamera("fr4", 640, 480), core::InputError);
  EXPECT_THROW(TumCamera("525,525,319.5", 640, 480), core::InputError);
  EXPECT_THROW(TumCamera("525,x,319.5,239.5", 640, 480), core::InputError);
}

TEST(TumImport, RealCabinetSequenceImportsWithItsPosesAndTheCabinetWhereTheDepthSeesIt) {
  const fs::path out = test_support::TestOutputDir() / "cabinet";
  std::vector<std::string> notes;
  const Dataset d = ImportTum(kCabinet, out, {}, {}, [&](const std::string& n) {
    notes.push_back(n);
    std::printf("note: %s\n", n.c_str());
  });
  ASSERT_EQ(d.views.size(), 29u);
  std::string all;
  for (const auto& n : notes) all += n + "\n";
  EXPECT_NE(all.find("camera: TUM fr3 (from the sequence's name"), std::string::npos) << all;
  EXPECT_EQ(all.find("warning"), std::string::npos) << all;  // 5000 units per metre agree
  EXPECT_EQ(d.depth_units, "m");
  // Camera centres: the ground-truth positions, line for line.
  std::ifstream gt(kCabinet / "groundtruth.txt");
  const auto poses = ReadTumTrajectory(gt, "groundtruth.txt");
  ASSERT_EQ(poses.size(), d.views.size());
  for (size_t i = 0; i < d.views.size(); ++i) {
    EXPECT_NEAR(glm::length(d.views[i].cam_from_world.Centre() - poses[i].cam_from_world.Centre()),
                0, 1e-9)
        << d.views[i].name;
  }
  // The surveyed box: centre, yaw about z, half extents (truth_objects.txt).
  std::ifstream box_file(kCabinet / "truth_objects.txt");
  double cx, cy, cz, yaw, hx, hy, hz;
  ASSERT_TRUE(box_file >> cx >> cy >> cz >> yaw >> hx >> hy >> hz);
  const glm::dvec3 centre(cx, cy, cz);
  const glm::dmat3 rot = glm::dmat3(glm::rotate(glm::dmat4(1.0), yaw, glm::dvec3(0, 0, 1)));
  auto inside_box = [&](const glm::dvec3& p, double grow) {
    const glm::dvec3 local = glm::transpose(rot) * (p - centre);
    return std::abs(local.x) <= hx + grow && std::abs(local.y) <= hy + grow &&
           std::abs(local.z) <= hz + grow;
  };
  // In every view that sees the box centre, the depth pixels around its
  // projection are points on the cabinet: within 3 cm of its box (sensor
  // noise at 1-3 m, and the box's own survey) -- a wrong pose, intrinsics,
  // pixel convention or depth scale moves them off it.
  int views_seeing = 0;
  int64_t on_box = 0, samples = 0;
  for (size_t i = 0; i < d.views.size(); ++i) {
    const Camera& cam = d.camera(d.views[i]);
    const glm::dvec3 c_in_cam = d.views[i].cam_from_world * centre;
    if (c_in_cam.z <= 0) continue;
    const glm::dvec2 uv = cam.Project(c_in_cam);
    if (uv.x < 40 || uv.y < 40 || uv.x > cam.width - 40 || uv.y > cam.height - 40) continue;
    ++views_seeing;
    const core::ImageF depth = d.LoadDepth(i);
    const Rigid3 world_from_cam = d.views[i].cam_from_world.Inverse();
    for (int dy = -6; dy <= 6; dy += 3) {
      for (int dx = -6; dx <= 6; dx += 3) {
        const int col = static_cast<int>(uv.x) + dx, row = static_cast<int>(uv.y) + dy;
        const float z = depth.at(col, row);
        if (!(z > 0)) continue;
        ++samples;
        on_box += inside_box(world_from_cam * cam.UnprojectPixel(col, row, z), 0.03);
      }
    }
  }
  std::printf("%d views see the cabinet's centre; %lld of %lld depth samples there on its box\n",
              views_seeing, (long long)on_box, (long long)samples);
  EXPECT_GE(views_seeing, 20);
  EXPECT_GT(on_box, 0.95 * samples);
  // The dataset's box: around the cabinet (every corner of its surveyed box
  // inside), not the room the sensor also saw (about 10 x 9 m).
  ASSERT_TRUE(d.bounds);
  std::printf("bounds (%.3f, %.3f, %.3f)..(%.3f, %.3f, %.3f)\n", d.bounds->min.x, d.bounds->min.y,
              d.bounds->min.z, d.bounds->max.x, d.bounds->max.y, d.bounds->max.z);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 local((corner & 1 ? hx : -hx), (corner & 2 ? hy : -hy),
                           (corner & 4 ? hz : -hz));
    const glm::dvec3 p = centre + rot * local;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(p[a], d.bounds->min[a] - 0.02) << "corner " << corner << " axis " << a;
      EXPECT_LE(p[a], d.bounds->max[a] + 0.02) << "corner " << corner << " axis " << a;
    }
  }
  for (int a = 0; a < 3; ++a) EXPECT_LT(d.bounds->extent()[a], 2.5) << "axis " << a;
  EXPECT_NE(all.find("where at least"), std::string::npos) << all;
  // Given bounds win.
  TumImportOptions given;
  given.bounds = Bounds{{-2, 0, 0}, {-1, 1, 0.6}};
  given.every = 7;
  const Dataset g = ImportTum(kCabinet, test_support::TestOutputDir() / "given", given);
  EXPECT_EQ(g.bounds, given.bounds);
  EXPECT_EQ(g.views.size(), 5u);  // frames 0, 7, 14, 21, 28
}

// fr1 and fr2 images are distorted: the import resamples them into the
// pinhole camera, colour bilinearly, depth by its nearest sample (a blend of
// two depths across an edge would be a point on neither surface).
TEST(TumImport, DistortedSensorsAreUndistortedDepthByNearestSample) {
  const fs::path dir = test_support::TestOutputDir() / "fr1_seq";
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  core::Image8 color(640, 480, 3, 128);
  core::Image<uint16_t> depth(640, 480, 1, 0);
  for (int y = 40; y < 440; ++y)
    for (int x = 40; x < 600; ++x) depth.at(x, y) = x < 320 ? 5000 : 10000;  // 1 m | 2 m
  core::WriteImage(dir / "rgb" / "1.png", color);
  core::WriteImage(dir / "depth" / "1.png", depth);
  std::ofstream(dir / "rgb.txt") << "1.000 rgb/1.png\n";
  std::ofstream(dir / "depth.txt") << "1.005 depth/1.png\n";
  std::ofstream(dir / "groundtruth.txt") << "0.97 0 0 0 0 0 0 1\n1.03 0 0 0 0 0 0 1\n";
  TumImportOptions options;
  options.camera = "fr1";
  std::string notes;
  const Dataset d = ImportTum(dir, test_support::TestOutputDir() / "fr1_out", options, {},
                              [&](const std::string& n) { notes += n + "\n"; });
  EXPECT_NE(notes.find("undistorting FULL_OPENCV into PINHOLE"), std::string::npos) << notes;
  ASSERT_EQ(d.views.size(), 1u);
  EXPECT_EQ(d.camera(d.views[0]).model, CameraModel::kPinhole);
  const core::ImageF z = d.LoadDepth(0);
  int near = 0, far = 0;
  for (float v : z.values()) {
    EXPECT_TRUE(v == 0 || v == 1.0f || v == 2.0f) << v;
    near += v == 1.0f;
    far += v == 2.0f;
  }
  EXPECT_GT(near, 50000);
  EXPECT_GT(far, 50000);
}

TEST(TumImport, MissingFilesAndUnknownSensorsAreOneClearError) {
  const fs::path dir = test_support::TestOutputDir() / "seq";
  fs::create_directories(dir);
  std::ofstream(dir / "rgb.txt") << "1 rgb/1.png\n";
  std::ofstream(dir / "depth.txt") << "1 depth/1.png\n";
  try {
    ImportTum(dir, test_support::TestOutputDir() / "out");
    ADD_FAILURE();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("groundtruth.txt"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "groundtruth.txt") << "1 0 0 0 0 0 0 1\n";
  try {
    ImportTum(dir, test_support::TestOutputDir() / "out");
    ADD_FAILURE();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--camera fr1|fr2|fr3"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(test_support::TestOutputDir() / "out"));
}

}  // namespace
}  // namespace capture
