// Structure from motion with the real colmap binary (Debian colmap 3.8, CPU):
// a ring capture of textured Spot in front of the noise backdrop, known
// PINHOLE intrinsics, feature_extractor + exhaustive_matcher + mapper; the
// model imported with our sparse importer registers every view, and after a
// similarity alignment (Umeyama on camera centres, cv::SVD) the poses match
// the true ones: rotation < 0.5 degree, centre < 1 % of the camera distance.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <opencv2/core.hpp>

#include "capture/colmap_dataset.h"
#include "capture/synthetic.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace capture {
namespace {
namespace fs = std::filesystem;

bool HaveColmap() { return std::system("command -v colmap > /dev/null 2>&1") == 0; }

// y ~ s R x + t in the least-squares sense (Umeyama 1991, eqs. 40-42).
struct Similarity {
  double scale = 1;
  glm::dmat3 rotation{1.0};
  glm::dvec3 translation{0.0};
  glm::dvec3 operator*(const glm::dvec3& x) const { return scale * (rotation * x) + translation; }
};

Similarity Umeyama(const std::vector<glm::dvec3>& x, const std::vector<glm::dvec3>& y) {
  const size_t n = x.size();
  glm::dvec3 mx(0.0), my(0.0);
  for (size_t i = 0; i < n; ++i) {
    mx += x[i] / double(n);
    my += y[i] / double(n);
  }
  cv::Matx33d sigma = cv::Matx33d::zeros();
  double var_x = 0;
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 dx = x[i] - mx, dy = y[i] - my;
    var_x += glm::dot(dx, dx) / double(n);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) sigma(r, c) += dy[r] * dx[c] / double(n);
  }
  const cv::SVD svd(cv::Mat(sigma), cv::SVD::FULL_UV);
  cv::Matx33d s = cv::Matx33d::eye();
  if (cv::determinant(svd.u) * cv::determinant(svd.vt) < 0) s(2, 2) = -1;
  const cv::Mat rot = svd.u * cv::Mat(s) * svd.vt;
  Similarity out;
  double trace_ds = 0;
  for (int k = 0; k < 3; ++k) trace_ds += svd.w.at<double>(k) * s(k, k);
  out.scale = trace_ds / var_x;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.rotation[c][r] = rot.at<double>(r, c);
  out.translation = my - out.scale * (out.rotation * mx);
  return out;
}

double AngleDeg(const glm::dmat3& r) {
  const double c = std::clamp((r[0][0] + r[1][1] + r[2][2] - 1) / 2, -1.0, 1.0);
  return std::acos(c) * 180 / std::numbers::pi;
}

TEST(Umeyama, RecoversAKnownSimilarity) {
  Similarity truth;
  truth.scale = 2.5;
  truth.rotation = LookAt({1, 2, 3}, {0, 0, 0}, {0, 0, 1}).rotation;
  truth.translation = {0.3, -4, 7};
  std::vector<glm::dvec3> x, y;
  for (int i = 0; i < 10; ++i) {
    x.emplace_back(std::sin(i * 1.3), std::cos(i * 0.7), 0.1 * i * i);
    y.push_back(truth * x.back());
  }
  const Similarity est = Umeyama(x, y);
  EXPECT_NEAR(est.scale, truth.scale, 1e-12);
  EXPECT_NEAR(AngleDeg(glm::transpose(est.rotation) * truth.rotation), 0, 1e-5);
  EXPECT_NEAR(glm::length(est.translation - truth.translation), 0, 1e-11);
}

class ColmapSfmTest : public test_support::GlTest {};

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

TEST_F(ColmapSfmTest, RingOfSpotRegistersEveryViewWithTruePoses) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap is not installed";
  const fs::path spot = test_support::SharedData("meshes/spot.obj");
  if (spot.empty()) GTEST_SKIP() << "../shared/data/meshes/spot.obj is absent (IBR_SHARED_DATA)";
  const fs::path root = test_support::TestOutputDir();
  fs::remove_all(root);
  fs::create_directories(root);

  auto start = std::chrono::steady_clock::now();
  CaptureOptions options;
  options.size = 512;
  options.rig = "ring:16";
  // Spot with its own texture gives SIFT ~80 features per view: too few. It
  // wears a noise texture on its UVs (features near the rotation centre:
  // parallax), in front of the noise backdrop (features all around).
  options.background = "noise";
  SceneMesh scene = LoadSceneMesh(spot);
  scene.texture = NoiseTexture(1024, 1024, 7);
  const Dataset truth = CaptureDataset(programs(), scene, options, root / "ds");
  ASSERT_EQ(truth.views.size(), 16u);
  std::printf("capture: %.1f s\n", Seconds(start));

  const Camera& cam = truth.cameras.begin()->second;
  // Our intrinsics are COLMAP's sparse ones (pixel centres at +0.5).
  const std::string params =
      fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}", cam.fx(), cam.fy(), cam.cx(), cam.cy());
  const std::string db = (root / "database.db").string(), images = (root / "ds" / "color").string();
  fs::create_directories(root / "sparse");
  const std::vector<std::pair<const char*, std::string>> steps = {
      {"feature_extractor", "colmap feature_extractor --database_path " + db + " --image_path " +
                                images +
                                " --ImageReader.single_camera 1 --ImageReader.camera_model PINHOLE"
                                " --ImageReader.camera_params " +
                                params + " --SiftExtraction.use_gpu 0"},
      {"exhaustive_matcher",
       "colmap exhaustive_matcher --database_path " + db + " --SiftMatching.use_gpu 0"},
      // The intrinsics are known: keep them fixed.
      {"mapper", "colmap mapper --database_path " + db + " --image_path " + images +
                     " --output_path " + (root / "sparse").string() +
                     " --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_principal_point 0"
                     " --Mapper.ba_refine_extra_params 0"},
  };
  for (const auto& [name, command] : steps) {
    start = std::chrono::steady_clock::now();
    const auto r = test_support::RunCommand(command);
    ASSERT_EQ(r.exit_code, 0) << name << ":\n" << r.out << r.err;
    std::printf("colmap %s: %.1f s\n", name, Seconds(start));
  }
  ASSERT_TRUE(fs::exists(root / "sparse" / "0" / "cameras.bin")) << "mapper wrote no model";
  ASSERT_FALSE(fs::exists(root / "sparse" / "1")) << "mapper split the ring into several models";

  ColmapImportOptions import;
  import.images = images;
  const Dataset sfm = ImportColmap(root / "sparse" / "0", root / "imported", import);
  ASSERT_EQ(sfm.views.size(), truth.views.size()) << "not every view registered";
  ASSERT_EQ(sfm.cameras.size(), 1u);
  EXPECT_EQ(sfm.cameras.begin()->second, cam) << "the fixed intrinsics came back changed";

  std::vector<glm::dvec3> true_centres, sfm_centres;
  for (size_t i = 0; i < sfm.views.size(); ++i) {
    ASSERT_EQ(sfm.views[i].name, truth.views[i].name);
    true_centres.push_back(truth.views[i].cam_from_world.Centre());
    sfm_centres.push_back(sfm.views[i].cam_from_world.Centre());
  }
  // sfm_world ~ s R true_world + t.
  const Similarity align = Umeyama(true_centres, sfm_centres);
  const glm::dvec3 object = truth.bounds->centre();
  double max_rot_deg = 0, max_centre = 0, sum_rot = 0, sum_centre = 0;
  for (size_t i = 0; i < sfm.views.size(); ++i) {
    // R_sfm R = R_true when the poses agree (cam_from_world composed with the alignment).
    const glm::dmat3 diff = sfm.views[i].cam_from_world.rotation * align.rotation *
                            glm::transpose(truth.views[i].cam_from_world.rotation);
    const double rot = AngleDeg(diff);
    const double distance = glm::length(true_centres[i] - object);
    const double centre =
        glm::length(align * true_centres[i] - sfm_centres[i]) / align.scale / distance;
    max_rot_deg = std::max(max_rot_deg, rot);
    max_centre = std::max(max_centre, centre);
    sum_rot += rot;
    sum_centre += centre;
  }
  const double n = static_cast<double>(sfm.views.size());
  std::printf(
      "sfm: %zu/%zu views registered; rotation error mean %.4f max %.4f deg; centre error mean "
      "%.2e max %.2e "
      "of the camera distance\n",
      sfm.views.size(), truth.views.size(), sum_rot / n, max_rot_deg, sum_centre / n, max_centre);
  EXPECT_LT(max_rot_deg, 0.5);
  EXPECT_LT(max_centre, 0.01);
}

}  // namespace
}  // namespace capture
