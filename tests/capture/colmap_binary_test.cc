// Against the real colmap binary (Debian colmap 3.8, CPU): model_converter
// reads our text and binary models and writes back the same numbers;
// stereo_fusion on an exported synthetic sphere workspace fuses points on the
// true surface; the workspace imports back to the same depth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "capture/colmap_dataset.h"
#include "capture/synthetic.h"
#include "tests/capture/random_model.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace capture {
namespace {
namespace fs = std::filesystem;

bool HaveColmap() { return std::system("command -v colmap > /dev/null 2>&1") == 0; }

void ExpectSameModel(const colmap::SparseModel& a, const colmap::SparseModel& b) {
  EXPECT_EQ(a.cameras, b.cameras);  // parameters bit-exact
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [id, im] : a.images) {
    const colmap::Image& other = b.images.at(id);
    // COLMAP re-normalises quaternions on read: last-digit differences.
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(im.qvec[k], other.qvec[k], 1e-15);
    EXPECT_EQ(im.tvec, other.tvec);
    EXPECT_EQ(im.camera_id, other.camera_id);
    EXPECT_EQ(im.name, other.name);
    EXPECT_EQ(im.points2D, other.points2D);
  }
  EXPECT_EQ(a.points3D, b.points3D);
}

TEST(ColmapBinary, ModelConverterReadsOurTextAndBinaryModels) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap is not installed";
  const fs::path root = test_support::TestOutputDir();
  const colmap::SparseModel model = test::RandomSparseModel(42);
  for (const auto& [in_format, out_type] : {std::pair{colmap::ModelFormat::kText, "BIN"},
                                            std::pair{colmap::ModelFormat::kBinary, "TXT"}}) {
    const fs::path in = root / (std::string("in_") + out_type),
                   out = root / (std::string("out_") + out_type);
    fs::create_directories(in);
    fs::create_directories(out);
    colmap::WriteSparseModel(in, model, in_format);
    const auto result =
        test_support::RunCommand("colmap model_converter --input_path " + in.string() +
                                 " --output_path " + out.string() + " --output_type " + out_type);
    ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
    ExpectSameModel(colmap::ReadSparseModel(out), model);
  }
}

struct PlyPoints {
  std::vector<glm::dvec3> xyz;
};

PlyPoints ReadFusedPly(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  size_t n = 0;
  while (std::getline(in, line)) {
    if (line.rfind("element vertex", 0) == 0) n = std::stoul(line.substr(15));
    if (line == "end_header") break;
  }
  PlyPoints ply;
  for (size_t i = 0; i < n; ++i) {
    float v[6];
    uint8_t rgb[3];
    in.read(reinterpret_cast<char*>(v), sizeof v);
    in.read(reinterpret_cast<char*>(rgb), sizeof rgb);
    if (!in) break;
    ply.xyz.emplace_back(v[0], v[1], v[2]);
  }
  return ply;
}

class ColmapFusionTest : public test_support::GlTest {};

// A box: fusion averages consistent pixels, which on a curved surface pulls
// points off it by the curvature over the cluster (measured on the unit sphere
// at 160 px: mean 4e-4, max 7e-3 of the scene size); on planes it cannot, so
// the box isolates what this test checks: our depth maps, normals, cameras and
// pixel convention are exactly what colmap reads.
TEST_F(ColmapFusionTest, StereoFusionOfExportedBoxLiesOnTheBox) {
  if (!HaveColmap()) GTEST_SKIP() << "colmap is not installed";
  const fs::path root = test_support::TestOutputDir();
  CaptureOptions options;
  options.size = 160;
  options.rig = "sphere:10";
  const Dataset captured = CaptureDataset(programs(), MakeShapeScene("box"), options, root / "ds");
  const Dataset dataset = ReadDataset(root / "ds");
  ExportColmapWorkspace(dataset, root / "ws");
  const auto result = test_support::RunCommand(
      "colmap stereo_fusion --workspace_path " + (root / "ws").string() + " --output_path " +
      (root / "ws/fused.ply").string() +
      " --input_type geometric --StereoFusion.num_threads 1 --StereoFusion.min_num_pixels 3");
  ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  const PlyPoints ply = ReadFusedPly(root / "ws/fused.ply");
  ASSERT_GT(ply.xyz.size(), 5000u) << "fusion found too few consistent points";
  double max_err = 0, sum = 0;
  for (const auto& p : ply.xyz) {
    const glm::dvec3 q = glm::abs(p) - glm::dvec3(1.0, 0.7, 0.5);
    const double e =
        std::abs(glm::length(glm::max(q, 0.0)) + std::min(std::max({q.x, q.y, q.z}), 0.0));
    max_err = std::max(max_err, e);
    sum += e;
  }
  const double scene_size = 2.0;  // largest box extent
  std::printf("stereo_fusion: %zu points, mean error %.3g, max error %.3g of the scene size\n",
              ply.xyz.size(), sum / ply.xyz.size() / scene_size, max_err / scene_size);
  // The bar: within 1e-4 of the scene size (measured here: ~3e-7).
  EXPECT_LT(max_err / scene_size, 1e-4);

  // And back: the dense workspace imports to the same cameras and depth.
  const Dataset back = ImportColmap(root / "ws", root / "back");
  ASSERT_EQ(back.views.size(), dataset.views.size());
  for (size_t i = 0; i < back.views.size(); ++i) {
    EXPECT_EQ(back.camera(back.views[i]), dataset.camera(dataset.views[i]));
    const Rigid3& a = back.views[i].cam_from_world;
    const Rigid3& b = dataset.views[i].cam_from_world;
    EXPECT_NEAR(glm::length(a.translation - b.translation), 0, 1e-12);
    EXPECT_EQ(back.LoadDepth(i), dataset.LoadDepth(i));
    const core::ImageF n0 = back.LoadNormal(i), n1 = dataset.LoadNormal(i);
    double max_normal = 0;
    for (size_t p = 0; p < n0.values().size(); ++p)
      max_normal = std::max<double>(max_normal, std::abs(n0.values()[p] - n1.values()[p]));
    EXPECT_LT(max_normal, 1e-5);
  }
}

}  // namespace
}  // namespace capture
