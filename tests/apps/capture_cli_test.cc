// `ibr capture`, `ibr info DIR`, `ibr export colmap`, `ibr import ...` as a
// user runs them: a cube capture of the unit sphere has the analytic depth and
// `info` summarises its six views; a ring capture exported to a COLMAP
// workspace imports back to the same cameras and poses (dense and sparse-only);
// bad inputs give one `ibr: error:` line naming the file or option, a non-zero
// exit and no output directory.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/colmap_io.h"
#include "capture/dataset.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
void ExpectSamePose(const capture::Rigid3& a, const capture::Rigid3& b, double tolerance,
                    const std::string& what);
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::Quote;
using test_support::RunCommand;
using test_support::Scratch;

TEST(CaptureCli, CubeCaptureOfSphereThenInfoSummarisesSixViews) {
  const fs::path dir = Scratch("cube_info");
  const fs::path ds = dir / "D";
  const auto r =
      RunCommand(IbrBinary() + " capture --shape sphere --rig cube --size 64 --out " + Quote(ds));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("6 views of shape:sphere at 64x64 px"), std::string::npos) << r.out;

  // The files on disk, against analytic truth: each orthographic face looks
  // at the unit sphere from 1.05 (bounding cube half size with the 5 % margin),
  // so the depth at pixel (col, row) is 1.05 - sqrt(1 - x^2 - y^2), with
  // x, y the pixel centre's offset from the image centre in scene units.
  const capture::Dataset d = capture::ReadDataset(ds, /*check_pixels=*/true);
  ASSERT_EQ(d.views.size(), 6u);
  const double half = 1.05, units_per_px = 2 * half / 64;
  for (size_t v = 0; v < d.views.size(); ++v) {
    EXPECT_TRUE(d.camera(d.views[v]).orthographic());
    EXPECT_NEAR(glm::length(d.views[v].cam_from_world.Centre()), half, 1e-9);
    const core::ImageF depth = d.LoadDepth(v);
    double max_err = 0;
    int covered = 0;
    for (int row = 0; row < 64; ++row) {
      for (int col = 0; col < 64; ++col) {
        const double x = (col + 0.5 - 32) * units_per_px, y = (row + 0.5 - 32) * units_per_px;
        const double r2 = x * x + y * y;
        if (r2 > 0.98) continue;  // leave the silhouette's edge pixels alone
        ++covered;
        max_err = std::max(max_err, std::abs(depth.at(col, row) - (half - std::sqrt(1 - r2))));
      }
    }
    EXPECT_GT(covered, 2000);
    // Tessellation sag (256 x 512 sphere) plus float depth: well under 1e-3.
    EXPECT_LT(max_err, 1e-3) << d.views[v].name;
  }

  const auto info = RunCommand(IbrBinary() + " info " + Quote(ds));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("views     6 (depth 6, mask 6, normals 6)"), std::string::npos)
      << info.out;
  EXPECT_NE(info.out.find("6 x ORTHOGRAPHIC 64x64"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("bounds    min (-1, -1, -1)  max (1, 1, 1)"), std::string::npos)
      << info.out;
  for (const char* face : {"cube_px", "cube_nx", "cube_py", "cube_ny", "cube_pz", "cube_nz"}) {
    EXPECT_NE(info.out.find(face), std::string::npos) << face << "\n" << info.out;
  }
}

// --noise: the same rig through a sensor model. Colour and mask stay those
// of the exact capture; the depth differs from it by noise of the stated
// deviation (a percent of the object's diagonal) and misses the stated
// fraction in holes plus the silhouette's edge; dataset.json records the
// model and `ibr info` states it.
TEST(CaptureCli, NoiseAppliesTheSensorModelAndRecordsIt) {
  const fs::path dir = Scratch("noise");
  const std::string capture = IbrBinary() + " capture --shape sphere --rig sphere:4 --size 96";
  const auto clean = RunCommand(capture + " --out " + Quote(dir / "clean"));
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  const auto noisy = RunCommand(capture + " --noise sigma=0.5%,holes=0.03,edge=1,seed=5 --out " +
                                Quote(dir / "noisy"));
  ASSERT_EQ(noisy.exit_code, 0) << noisy.err;
  EXPECT_NE(noisy.err.find("sensor model"), std::string::npos) << noisy.err;
  const capture::Dataset a = capture::ReadDataset(dir / "clean", true);
  const capture::Dataset b = capture::ReadDataset(dir / "noisy", true);
  EXPECT_FALSE(a.depth_noise);
  ASSERT_TRUE(b.depth_noise);
  const double sigma = 0.005 * 2 * std::sqrt(3.0);  // the unit sphere's box: diagonal 2 sqrt 3
  EXPECT_NEAR(b.depth_noise->sigma, sigma, 1e-9);
  ASSERT_EQ(a.views.size(), b.views.size());
  for (size_t v = 0; v < a.views.size(); ++v) {
    EXPECT_EQ(a.LoadColor(v), b.LoadColor(v));
    EXPECT_EQ(a.LoadMask(v), b.LoadMask(v));
    const core::ImageF za = a.LoadDepth(v), zb = b.LoadDepth(v);
    double sum2 = 0;
    int both = 0, object = 0, missing = 0;
    for (size_t p = 0; p < za.pixel_count(); ++p) {
      if (!(za.data()[p] > 0)) continue;
      ++object;
      if (!(zb.data()[p] > 0)) {
        ++missing;
        continue;
      }
      const double d = zb.data()[p] - za.data()[p];
      sum2 += d * d;
      ++both;
    }
    ASSERT_GT(both, 1000);
    std::printf(
        "%s: residual sd %.5f (sigma %.5f) over %d pixels, %d of %d object pixels "
        "without depth\n",
        a.views[v].name.c_str(), std::sqrt(sum2 / both), sigma, both, missing, object);
    EXPECT_NEAR(std::sqrt(sum2 / both), sigma, 0.1 * sigma) << a.views[v].name;
    // 3 % in holes, and the rim's ring of pixels on top.
    EXPECT_GT(missing, 0.03 * object) << a.views[v].name;
    EXPECT_LT(missing, 0.15 * object) << a.views[v].name;
  }
  const auto info = RunCommand(IbrBinary() + " info " + Quote(dir / "noisy"));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("noise     depth noise 0.01732"), std::string::npos) << info.out;
  // The noise as the views' agreement measures it, from the maps alone:
  // the stated sigma on the noisy capture, next to nothing on the clean one.
  const auto measured = [&](const std::string& out) {
    const std::string key = "agree to a depth deviation of ";
    const size_t at = out.find(key);
    return at == std::string::npos ? -1.0 : std::stod(out.substr(at + key.size()));
  };
  const double noisy_sigma = measured(info.out);
  const auto clean_info = RunCommand(IbrBinary() + " info " + Quote(dir / "clean"));
  const double clean_sigma = measured(clean_info.out);
  std::printf("views agree to: noisy %.5f (stated %.5f), clean %.5f\n", noisy_sigma, sigma,
              clean_sigma);
  EXPECT_NEAR(noisy_sigma, sigma, 0.15 * sigma) << info.out;
  EXPECT_GE(clean_sigma, 0) << clean_info.out;
  EXPECT_LT(clean_sigma, 0.2 * sigma) << clean_info.out;
  const auto bad = RunCommand(capture + " --noise sigma=1%,hoels=0.1 --out " + Quote(dir / "bad"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("unknown key 'hoels'"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

// Partial and photometric-only COLMAP workspaces, and choosing views: a
// workspace without geometric maps imports its photometric ones with a
// warning (and --input-type geometric says which to use); a photo whose
// image is missing is left out with a warning; --views and --hold-out take
// and leave out photos by name, and an unknown name is one error line.
TEST(CaptureCli, PartialAndPhotometricWorkspacesImportAndViewsAreChosen) {
  const fs::path dir = Scratch("colmap_partial");
  ASSERT_EQ(RunCommand(IbrBinary() + " capture --shape sphere --rig ring:4 --size 64 --out " +
                       Quote(dir / "D"))
                .exit_code,
            0);
  const fs::path ws = dir / "WS";
  ASSERT_EQ(RunCommand(IbrBinary() + " export colmap " + Quote(dir / "D") + " --out " + Quote(ws))
                .exit_code,
            0);
  const capture::Dataset original = capture::ReadDataset(dir / "D");
  for (const auto& e : fs::directory_iterator(ws / "stereo/depth_maps")) {
    if (e.path().string().find(".geometric.") != std::string::npos) fs::remove(e.path());
  }
  const auto photometric =
      RunCommand(IbrBinary() + " import colmap " + Quote(ws) + " --out " + Quote(dir / "P"));
  ASSERT_EQ(photometric.exit_code, 0) << photometric.err;
  EXPECT_NE(photometric.out.find("photometric depth maps only"), std::string::npos)
      << photometric.out;
  const capture::Dataset p = capture::ReadDataset(dir / "P");
  ASSERT_EQ(p.views.size(), 4u);
  EXPECT_EQ(p.LoadDepth(1), original.LoadDepth(1));  // ibr wrote the same maps under both names
  const auto geometric = RunCommand(IbrBinary() + " import colmap " + Quote(ws) +
                                    " --input-type geometric --out " + Quote(dir / "G"));
  EXPECT_NE(geometric.exit_code, 0);
  EXPECT_EQ(CountLines(geometric.err), 1) << geometric.err;
  EXPECT_NE(geometric.err.find("--input-type photometric"), std::string::npos) << geometric.err;
  EXPECT_FALSE(fs::exists(dir / "G"));

  const std::string name = original.views[2].name;  // ring_002
  fs::remove(ws / "images" / (name + ".png"));
  const auto partial =
      RunCommand(IbrBinary() + " import colmap " + Quote(ws) + " --out " + Quote(dir / "M"));
  ASSERT_EQ(partial.exit_code, 0) << partial.err;
  EXPECT_NE(partial.out.find("1 of 4 photos left out"), std::string::npos) << partial.out;
  EXPECT_NE(partial.out.find(name + ".png"), std::string::npos) << partial.out;
  EXPECT_EQ(capture::ReadDataset(dir / "M").views.size(), 3u);

  const std::string first = original.views[0].name, last = original.views[3].name;
  const auto held = RunCommand(IbrBinary() + " import colmap " + Quote(ws) + " --hold-out " +
                               first + " --out " + Quote(dir / "H"));
  ASSERT_EQ(held.exit_code, 0) << held.err;
  const capture::Dataset h = capture::ReadDataset(dir / "H");
  ASSERT_EQ(h.views.size(), 2u);  // ring_002's image is gone, ring_000 held out
  EXPECT_EQ(h.views[1].name, last);
  const auto only = RunCommand(IbrBinary() + " import colmap " + Quote(ws) + " --views " + first +
                               "," + last + ".png --out " + Quote(dir / "V"));
  ASSERT_EQ(only.exit_code, 0) << only.err;
  const capture::Dataset v = capture::ReadDataset(dir / "V");
  ASSERT_EQ(v.views.size(), 2u);
  EXPECT_EQ(v.views[0].name, first);
  EXPECT_NEAR(
      glm::length(v.views[0].cam_from_world.Centre() - original.views[0].cam_from_world.Centre()),
      0, 1e-12);
  const auto unknown = RunCommand(IbrBinary() + " import colmap " + Quote(ws) +
                                  " --views nosuch --out " + Quote(dir / "U"));
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_EQ(CountLines(unknown.err), 1) << unknown.err;
  EXPECT_NE(unknown.err.find("no photo named 'nosuch'"), std::string::npos) << unknown.err;
  EXPECT_FALSE(fs::exists(dir / "U"));
}

// A NeRF transforms.json as the Blender synthetic scenes write it: RGBA
// PNGs whose alpha is the object, `camera_angle_x`, camera-to-world
// matrices of OpenGL cameras (y up, looking down -z), file paths without
// their extension. Written here from a capture (the conversion done in this
// test, independently of the importer), imported back: the same cameras,
// poses and masks, a box round the unit sphere from the masks' hull.
TEST(CaptureCli, NerfTransformsImportToTheCapturedCamerasAndMasks) {
  const fs::path dir = Scratch("nerf");
  ASSERT_EQ(RunCommand(IbrBinary() + " capture --shape sphere --rig sphere:8 --size 64 --out " +
                       Quote(dir / "D"))
                .exit_code,
            0);
  const capture::Dataset d = capture::ReadDataset(dir / "D");
  fs::create_directories(dir / "N" / "train");
  nlohmann::json frames = nlohmann::json::array();
  const capture::Camera& cam = d.camera(d.views[0]);
  for (size_t i = 0; i < d.views.size(); ++i) {
    const core::Image8 color = d.LoadColor(i), mask = d.LoadMask(i);
    core::Image8 rgba(color.width(), color.height(), 4);
    for (int y = 0; y < color.height(); ++y) {
      for (int x = 0; x < color.width(); ++x) {
        for (int c = 0; c < 3; ++c) rgba.at(x, y, c) = color.at(x, y, c);
        rgba.at(x, y, 3) = mask.at(x, y);
      }
    }
    core::WriteImage(dir / "N" / "train" / fmt::format("r_{}.png", i), rgba);
    // c2w (OpenGL) = world_from_cam (ours) with its y and z axes negated.
    const capture::Rigid3 w = d.views[i].cam_from_world.Inverse();
    nlohmann::json m = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) {
      m.push_back({w.rotation[0][r], -w.rotation[1][r], -w.rotation[2][r], w.translation[r]});
    }
    m.push_back({0, 0, 0, 1});
    frames.push_back({{"file_path", fmt::format("./train/r_{}", i)}, {"transform_matrix", m}});
  }
  std::ofstream(dir / "N" / "transforms_train.json") << nlohmann::json{
      {"camera_angle_x", 2 * std::atan(0.5 * cam.width / cam.fx())},
      {"frames", frames}}.dump(2);
  const auto r = RunCommand(IbrBinary() + " import nerf " + Quote(dir / "N") +
                            " --hold-out r_7 --out " + Quote(dir / "B"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("transforms_train.json"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("from the masks' coarse visual hull"), std::string::npos) << r.out;
  const capture::Dataset b = capture::ReadDataset(dir / "B", true);
  ASSERT_EQ(b.views.size(), d.views.size() - 1);
  for (size_t i = 0; i < b.views.size(); ++i) {
    EXPECT_EQ(b.views[i].name, fmt::format("r_{}", i));
    const capture::Camera& c = b.camera(b.views[i]);
    EXPECT_NEAR(c.fx(), cam.fx(), 1e-9);
    EXPECT_NEAR(c.cx(), cam.cx(), 1e-12);
    EXPECT_NEAR(c.cy(), cam.cy(), 1e-12);
    ExpectSamePose(b.views[i].cam_from_world, d.views[i].cam_from_world, 1e-9, b.views[i].name);
    EXPECT_EQ(b.LoadMask(i), d.LoadMask(i)) << b.views[i].name;
  }
  ASSERT_TRUE(b.bounds);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(b.bounds->min[a], -1.0) << a;
    EXPECT_GE(b.bounds->max[a], 1.0) << a;
    EXPECT_GT(b.bounds->min[a], -1.5) << a;  // the hull of 8 views, not the cameras' reach
    EXPECT_LT(b.bounds->max[a], 1.5) << a;
  }
  // The dataset renders: a depth object needs depth, a visual hull masks.
  const auto hull =
      RunCommand(IbrBinary() + " render " + Quote(dir / "B") +
                 " --method visual-hull --orbit 1 --size 48 --out " + Quote(dir / "H"));
  EXPECT_EQ(hull.exit_code, 0) << hull.err;
}

// --up z for a z-up mesh (the cup opens to +z): the rigs stand upright
// about z (every camera's image up, -y, rises along z; the cube's side
// faces look level with z straight up the image), the dataset records z,
// and an orbit of it keeps the cup's top at the top of the image.
TEST(CaptureCli, UpZCapturesAZUpMeshUprightAndRecordsIt) {
  const fs::path dir = Scratch("up_z");
  for (const char* rig : {"ring:4", "cube"}) {
    const fs::path ds = dir / (std::string(rig) == "cube" ? "cube" : "ring");
    const auto r = RunCommand(IbrBinary() + " capture --shape cup --up z --rig " + rig +
                              " --size 48 --out " + Quote(ds));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const capture::Dataset d = capture::ReadDataset(ds);
    ASSERT_TRUE(d.up);
    EXPECT_NEAR(glm::length(*d.up - glm::dvec3(0, 0, 1)), 0, 1e-12) << rig;
    for (const capture::DatasetView& v : d.views) {
      const glm::dvec3 image_up = glm::transpose(v.cam_from_world.rotation) * glm::dvec3(0, -1, 0);
      const glm::dvec3 forward = glm::transpose(v.cam_from_world.rotation) * glm::dvec3(0, 0, 1);
      if (std::abs(forward.z) > 0.99) continue;  // the cube's top and bottom faces
      EXPECT_GT(image_up.z, 0.9) << rig << " " << v.name;
    }
  }
  const auto info = RunCommand(IbrBinary() + " info " + Quote(dir / "ring"));
  EXPECT_NE(info.out.find("up        (0.000, 0.000, 1.000) from dataset.json"), std::string::npos)
      << info.out;
  const auto orbit = RunCommand(IbrBinary() + " render " + Quote(dir / "ring") +
                                " --orbit 3 --size 48 --out " + Quote(dir / "orbit"));
  ASSERT_EQ(orbit.exit_code, 0) << orbit.err;
  const capture::Dataset o = capture::ReadDataset(dir / "orbit");
  for (const capture::DatasetView& v : o.views) {
    const capture::Camera& c = o.camera(v);
    // The cup's rim (z = 1.2) above its foot (z = 0) in every orbit image.
    EXPECT_LT(c.Project(v.cam_from_world * glm::dvec3(0, 0, 1.2)).y,
              c.Project(v.cam_from_world * glm::dvec3(0, 0, 0)).y)
        << v.name;
  }
  const auto bad =
      RunCommand(IbrBinary() + " capture --shape cup --up w --out " + Quote(dir / "bad"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

// Poses agree when rotations and translations agree to `tolerance`.
void ExpectSamePose(const capture::Rigid3& a, const capture::Rigid3& b, double tolerance,
                    const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(a.rotation[c][r], b.rotation[c][r], tolerance) << what;
    EXPECT_NEAR(a.translation[c], b.translation[c], tolerance) << what;
  }
}

TEST(CaptureCli, ColmapExportThenImportRoundTripsCamerasAndPoses) {
  const fs::path dir = Scratch("colmap_round_trip");
  const auto cap = RunCommand(IbrBinary() + " capture --shape torus --rig ring:5 --size 96 --out " +
                              Quote(dir / "D"));
  ASSERT_EQ(cap.exit_code, 0) << cap.err;
  const capture::Dataset original = capture::ReadDataset(dir / "D");
  ASSERT_EQ(original.views.size(), 5u);

  for (const bool text : {false, true}) {
    const std::string tag = text ? "text" : "binary";
    const fs::path ws = dir / ("WS_" + tag);
    const auto exp = RunCommand(IbrBinary() + " export colmap " + Quote(dir / "D") + " --out " +
                                Quote(ws) + (text ? " --text" : ""));
    ASSERT_EQ(exp.exit_code, 0) << exp.err;
    EXPECT_NE(exp.out.find("export colmap: 5 views"), std::string::npos) << exp.out;
    EXPECT_TRUE(fs::exists(ws / "sparse" / (text ? "cameras.txt" : "cameras.bin"))) << tag;

    // The workspace's own cameras use COLMAP's dense convention (integer
    // pixel centres): cx, cy are ours minus half a pixel.
    const capture::colmap::SparseModel model = capture::colmap::ReadSparseModel(ws / "sparse");
    ASSERT_EQ(model.images.size(), 5u);
    for (const auto& [id, cam] : model.cameras) {
      EXPECT_EQ(cam.model, capture::CameraModel::kPinhole);
      EXPECT_DOUBLE_EQ(cam.cx(), 48.0 - 0.5);
      EXPECT_DOUBLE_EQ(cam.cy(), 48.0 - 0.5);
    }
    EXPECT_FALSE(model.points3D.empty()) << "stereo_fusion needs sparse points with tracks";

    // Dense import: same cameras (bit-exact after the +-0.5 shift), same poses.
    const auto imp = RunCommand(IbrBinary() + " import colmap " + Quote(ws) + " --out " +
                                Quote(dir / ("B_" + tag)));
    ASSERT_EQ(imp.exit_code, 0) << imp.err;
    EXPECT_NE(imp.out.find("import colmap: 5 views"), std::string::npos) << imp.out;
    const capture::Dataset back = capture::ReadDataset(dir / ("B_" + tag));
    ASSERT_EQ(back.views.size(), original.views.size());
    for (size_t i = 0; i < back.views.size(); ++i) {
      EXPECT_EQ(back.views[i].name, original.views[i].name);
      EXPECT_EQ(back.camera(back.views[i]), original.camera(original.views[i])) << tag << " " << i;
      // Quaternion round trip through 17 significant digits.
      ExpectSamePose(back.views[i].cam_from_world, original.views[i].cam_from_world, 1e-12, tag);
      EXPECT_EQ(back.LoadDepth(i), original.LoadDepth(i)) << tag << " " << i;
    }
  }

  // Sparse-only import: the same workspace without stereo/ gives poses and
  // colour, no depth.
  fs::create_directories(dir / "SP");
  fs::copy(dir / "WS_binary" / "sparse", dir / "SP" / "sparse", fs::copy_options::recursive);
  fs::copy(dir / "WS_binary" / "images", dir / "SP" / "images", fs::copy_options::recursive);
  const auto sp = RunCommand(IbrBinary() + " import colmap " + Quote(dir / "SP") + " --out " +
                             Quote(dir / "S"));
  ASSERT_EQ(sp.exit_code, 0) << sp.err;
  const capture::Dataset sparse = capture::ReadDataset(dir / "S");
  ASSERT_EQ(sparse.views.size(), original.views.size());
  for (size_t i = 0; i < sparse.views.size(); ++i) {
    EXPECT_TRUE(sparse.views[i].depth.empty());
    const capture::Camera& c = sparse.camera(sparse.views[i]);
    // Sparse import keeps COLMAP's cameras as they are (our pixel convention):
    // the export wrote dense cameras, so these sit half a pixel off ours.
    EXPECT_DOUBLE_EQ(c.cx(), original.camera(original.views[i]).cx() - 0.5);
    EXPECT_DOUBLE_EQ(c.fx(), original.camera(original.views[i]).fx());
    ExpectSamePose(sparse.views[i].cam_from_world, original.views[i].cam_from_world, 1e-12,
                   "sparse");
    EXPECT_EQ(sparse.LoadColor(i), original.LoadColor(i));
  }
}

struct BadCase {
  std::string name;
  std::string args;      // after the binary; OUT is replaced by the output path
  std::string expected;  // must appear in the error line (file or option)
};

TEST(CaptureCli, BadInputsGiveOneErrorLineAndNoOutput) {
  const fs::path dir = Scratch("bad_inputs");
  // A corrupt manifest (not JSON), a manifest with an impossible camera, a
  // dataset whose manifest names a missing image, and a valid cube capture
  // (orthographic: COLMAP has no such camera model).
  fs::create_directories(dir / "corrupt");
  std::ofstream(dir / "corrupt" / "dataset.json")
      << "{\"format\": \"ibr-dataset\", \"version\": 1, \"cameras\": [";
  fs::create_directories(dir / "badcam");
  std::ofstream(dir / "badcam" / "dataset.json")
      << R"({"format": "ibr-dataset", "version": 1, "depth": {"kind": "camera_z", "units": "m"},
            "cameras": [{"id": 1, "model": "PINHOLE", "width": -640, "height": 480, "params": [500, 500, 320, 240]}],
            "views": []})";
  ASSERT_EQ(RunCommand(IbrBinary() + " capture --shape box --rig ring:2 --size 32 --out " +
                       Quote(dir / "nofile"))
                .exit_code,
            0);
  fs::remove(dir / "nofile" / "color" / "ring_001.png");
  ASSERT_EQ(RunCommand(IbrBinary() + " capture --shape box --rig cube --size 32 --out " +
                       Quote(dir / "cube"))
                .exit_code,
            0);
  fs::create_directories(dir / "empty");

  const std::string missing = (dir / "no-such-dir").string();
  const std::vector<BadCase> cases = {
      {"info of a missing dir", "info " + missing, "no-such-dir"},
      {"info of a dir without manifest", "info " + (dir / "empty").string(), "dataset.json"},
      {"info of a corrupt manifest", "info " + (dir / "corrupt").string(), "corrupt/dataset.json"},
      {"info of an impossible camera", "info " + (dir / "badcam").string(), "badcam/dataset.json"},
      {"info of a missing image", "info " + (dir / "nofile").string(), "ring_001.png"},
      {"export of a missing dir", "export colmap " + missing + " --out OUT", "no-such-dir"},
      {"export of a corrupt manifest", "export colmap " + (dir / "corrupt").string() + " --out OUT",
       "corrupt/dataset.json"},
      {"export of a cube rig", "export colmap " + (dir / "cube").string() + " --out OUT",
       "orthographic"},
      {"import colmap of a missing dir", "import colmap " + missing + " --out OUT", "no-such-dir"},
      {"import colmap of an empty dir", "import colmap " + (dir / "empty").string() + " --out OUT",
       "empty"},
      {"import redwood of a missing dir", "import redwood " + missing + " --out OUT",
       "no-such-dir"},
      {"import redwood without intrinsics",
       "import redwood " + (dir / "empty").string() + " --out OUT", "camera_primesense.json"},
      {"import middlebury of a missing dir", "import middlebury " + missing + " --out OUT",
       "no-such-dir"},
      {"import middlebury without _par.txt",
       "import middlebury " + (dir / "empty").string() + " --out OUT", "_par.txt"},
      {"capture of a missing mesh", "capture --mesh " + missing + ".obj --out OUT",
       "no-such-dir.obj"},
      {"capture with a tiny size", "capture --shape sphere --size 3 --out OUT", "--size"},
      {"capture with an absurd size", "capture --shape sphere --size 1000000 --out OUT", "--size"},
      {"capture with an unknown rig",
       "capture --shape sphere --rig dodecahedron --size 32 --out OUT", "dodecahedron"},
      {"capture with an empty ring", "capture --shape sphere --rig ring:0 --size 32 --out OUT",
       "ring:0"},
      {"capture of an unknown shape", "capture --shape teapot --size 32 --out OUT", "teapot"},
      {"capture with a bad fov", "capture --shape sphere --rig ring:3 --fov 0 --size 32 --out OUT",
       "fov"},
  };
  for (const BadCase& c : cases) {
    const fs::path out = dir / "never";
    std::string args = c.args;
    if (const auto at = args.find("OUT"); at != std::string::npos)
      args.replace(at, 3, out.string());
    const auto r = RunCommand(IbrBinary() + " " + args);
    EXPECT_NE(r.exit_code, 0) << c.name;
    EXPECT_EQ(CountLines(r.err), 1) << c.name << ":\n" << r.err;
    EXPECT_EQ(r.err.rfind("ibr: error: ", 0), 0u) << c.name << ":\n" << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos)
        << c.name << ": expected '" << c.expected << "' in\n"
        << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.name;
    // Nothing staged beside it either (DatasetWriter's temporary directories).
    for (const auto& e : fs::directory_iterator(dir)) {
      EXPECT_EQ(e.path().filename().string().find("never"), std::string::npos)
          << c.name << ": left " << e.path();
    }
  }
}

TEST(CaptureCli, BuiltinSceneCapturesWithItsRig) {
  const fs::path out = test_support::TestOutputDir() / "scene";
  const auto r = RunCommand(IbrBinary() + " capture --scene torus-ring12 --size 32 --out '" +
                            out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const capture::Dataset d = capture::ReadDataset(out);
  EXPECT_EQ(d.views.size(), 12u);             // the scene's ring:12
  EXPECT_EQ(d.camera(d.views[0]).width, 32);  // --size wins over the scene's 256
  const auto bad = RunCommand(IbrBinary() + " capture --scene no-such-scene --out '" +
                              (out.string() + "2") + "'");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("no-such-scene"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(out.string() + "2"));
}

}  // namespace
