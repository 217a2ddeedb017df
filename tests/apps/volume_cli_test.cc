// `ibr volume` end to end: QVis and NRRD volumes with each effect, DVR and
// iso, written as PNG; real CT / MRI files (../shared/data/tests-real/volumes) in their
// own units; bad input (short raw file, absurd header sizes, NaN in
// a transfer function, unknown effect, ...) gives one error line, a non-zero
// exit and no output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/deformation.h"
#include "core/image_io.h"
#include "core/volume_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {

namespace fs = std::filesystem;

class VolumeCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_support::TestOutputDir().parent_path() / "volume_cli";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A ball of density falling off from the centre (uint8, 24^3, slab
    // spacing 1.5 along z).
    const int n = 24;
    core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kUint8);
    v.spacing = {1.0, 1.0, 1.5};
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const double r = std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0, z + 0.5 - n / 2.0);
          v.SetValue(x, y, z, std::clamp(255 * (1 - r / (0.45 * n)), 0.0, 255.0));
        }
    core::WriteQVis(dir_ / "ball.dat", v);
    core::WriteNrrd(dir_ / "ball.nrrd", v, core::NrrdEncoding::kGzip);
  }
  // Progress logging off (--log-level error), as the bad-input corpus runs:
  // stderr then holds only the error line.
  static test_support::CommandResult Volume(const std::string& args) {
    return test_support::RunCommand(test_support::IbrBinary() + " --log-level error volume " +
                                    args);
  }
  static fs::path dir_;
};
fs::path VolumeCliTest::dir_;

// Pixels that differ from the background of the first pixel (the corner is empty).
int Covered(const core::Image8& image) {
  int covered = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(image.at(x, y, c) - image.at(0, 0, c));
      covered += diff > 6;
    }
  return covered;
}

// --cameras takes a cameras-only manifest (no images: what `ibr view
// --camera-out` writes) and renders one PNG per view, named after it. A view
// placed where the orbit puts its eye (--azimuth 0 --elevation 0: on +x,
// z up; OrbitCameraView) renders the orbit's image: both are one camera
// through the same scene.
TEST_F(VolumeCliTest, DatasetCamerasRenderWhatTheOrbitShows) {
  const std::string dat = (dir_ / "ball.dat").string();
  const fs::path orbit = dir_ / "orbit.png", cams = dir_ / "cams", out = dir_ / "cams_out";
  fs::remove_all(cams), fs::remove_all(out), fs::create_directories(cams);
  const double f = 32.0 / std::tan(20.0 * M_PI / 180.0);  // 64 px, 40 degrees
  char params[128];
  std::snprintf(params, sizeof params, "[%.17g, %.17g, 32, 32]", f, f);
  std::ofstream(cams / "dataset.json") << R"({"format": "ibr-dataset", "version": 1,
  "cameras": [{"id": 1, "model": "PINHOLE", "width": 64, "height": 64, "params": )"
                                       << params << R"(}],
  "views": [{"name": "front", "camera": 1, "cam_from_world": [[0,1,0,0],[0,0,-1,0],[-1,0,0,100]]},
            {"name": "back", "camera": 1, "cam_from_world": [[0,-1,0,0],[0,0,-1,0],[1,0,0,100]]}]}
)";
  auto r = Volume(dat + " --transfer ramp --azimuth 0 --elevation 0 --distance 100 --fov 40 " +
                  "--size 64 --out " + orbit.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = Volume(dat + " --transfer ramp --cameras " + cams.string() + " --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(out / "front.png") && fs::exists(out / "back.png"));
  const core::Image8 a = core::ReadImage<uint8_t>(orbit);
  const core::Image8 b = core::ReadImage<uint8_t>(out / "front.png");
  ASSERT_EQ(b.width(), 64);
  EXPECT_GT(Covered(a), 200);
  EXPECT_GT(Covered(core::ReadImage<uint8_t>(out / "back.png")), 200);
  int worst = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.at(x, y, c) - b.at(x, y, c)));
  EXPECT_LE(worst, 1) << "the view at the orbit's eye renders the orbit's image";
}

TEST_F(VolumeCliTest, RendersEveryEffectAndMode) {
  const std::string dat = (dir_ / "ball.dat").string(), nrrd = (dir_ / "ball.nrrd").string();
  for (const std::string& args : std::vector<std::string>{
           dat + " --effect none --transfer ramp",
           dat + " --effect peel --amount 2.1 --displacement-bits 16",
           dat + " --effect peel --brick-texels 0",
           dat + " --effect seam --brick-texels 2 --no-support-skip",
           dat + " --effect slices --displacement-bits 8 --lighting transformed",
           dat + " --effect seam --mode iso:76 --lighting blended",  // stored units (uint8)
           nrrd + " --effect pull --map-size 32 --spacing 0.5",
           nrrd + " --effect wave --displacement-bits 32 --placement 0.1,0.1,0,0,0,0,0.8",
       }) {
    const fs::path out = dir_ / "out.png";
    fs::remove(out);
    const auto r = Volume(args + " --size 64 --azimuth 40 --elevation 25 --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    EXPECT_NE(r.out.find("volume: "), std::string::npos) << r.out;
    EXPECT_EQ(test_support::CountLines(r.out), 1) << r.out;
    const core::Image8 image = core::ReadImage<uint8_t>(out);
    EXPECT_EQ(image.width(), 64);
    EXPECT_EQ(image.height(), 64);
    // The ball covers a disc of radius ~0.45 of the volume at 64 px.
    EXPECT_GT(Covered(image), 200) << args;
  }
}

// Pixels whose colour differs by more than a rounding step.
int Differing(const core::Image8& a, const core::Image8& b) {
  int n = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(a.at(x, y, c) - b.at(x, y, c));
      n += diff > 24;
    }
  return n;
}

// The cut-aways the mesh deformations share (--deformation clip|cutaway|
// wedge) each remove part of the ball; a clip above the map (height 1)
// removes nothing.
TEST_F(VolumeCliTest, CutAwaysChangeThePictureAndAClipAboveRemovesNothing) {
  const std::string dat = (dir_ / "ball.dat").string();
  const auto render = [&](const std::string& args, const std::string& name) {
    const fs::path out = dir_ / name;
    const auto r = Volume(dat + " --mode iso:100 " + args +
                          " --size 128 --azimuth 30 --elevation 25 --out " + out.string());
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    return core::ReadImage<uint8_t>(out);
  };
  const core::Image8 none = render("--deformation none", "cut_none.png");
  const int ball = Covered(none);
  ASSERT_GT(ball, 500);
  for (const std::string cut : {"clip", "cutaway", "wedge"}) {
    const core::Image8 image = render("--deformation " + cut, "cut_" + cut + ".png");
    const int changed = Differing(image, none);
    std::printf("%s: %d of the ball's %d pixels changed\n", cut.c_str(), changed, ball);
    EXPECT_GT(changed, ball / 20) << cut;
  }
  const core::Image8 above = render("--deformation clip --amount 1", "cut_above.png");
  EXPECT_LE(Differing(above, none), ball / 100);
}

// Every deformation of the one vocabulary (core::kDeformationTable, the
// names `ibr deform` takes) renders on a volume, by DVR and as an iso
// surface, with its default amount and width: the picture is not empty and
// differs from the undeformed ball's. The wave gets a larger amplitude and
// the pull a wider Gaussian (their defaults are small or narrow on a ball),
// the twist's box is moved off the ball's axis (a ball turned about its own
// axis looks the same).
TEST_F(VolumeCliTest, EveryDeformationNameRendersAndChangesThePicture) {
  const std::string dat = (dir_ / "ball.dat").string();
  for (const std::string mode : {"dvr", "iso:100"}) {
    const auto render = [&](const std::string& args, const std::string& name) {
      const fs::path out = dir_ / name;
      fs::remove(out);
      const auto r = Volume(dat + " --mode " + mode + " " + args +
                            " --size 96 --azimuth 30 --elevation 25 --out " + out.string());
      EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
      return r.exit_code == 0 ? core::ReadImage<uint8_t>(out) : core::Image8(96, 96, 4);
    };
    const core::Image8 none = render("--deformation none", "every_none.png");
    const int ball = Covered(none);
    ASSERT_GT(ball, 400) << mode;
    for (const core::DeformationInfo& info : core::kDeformationTable) {
      const std::string name = core::DeformationKindName(info.kind);
      std::string args = "--deformation " + name;
      if (name == "wave") args += " --amount 0.2 --width 0.5";
      if (name == "twist") args += " --placement 0.3,0,0";  // off the ball's axis of symmetry
      if (name == "pull") args += " --width 0.15";
      const core::Image8 image = render(args, "every_" + name + ".png");
      const int changed = Differing(image, none);
      std::printf("volume %s %s: %d of the ball's %d pixels changed, %d covered\n", mode.c_str(),
                  name.c_str(), changed, ball, Covered(image));
      EXPECT_GT(Covered(image), ball / 4) << mode << " " << name;
      EXPECT_GT(changed, ball / 50) << mode << " " << name;
    }
  }
}

TEST_F(VolumeCliTest, BadInputGivesOneErrorLineAndNoOutput) {
  // Broken inputs.
  const fs::path short_dat = dir_ / "short.dat";
  std::ofstream(short_dat) << "ObjectFileName: short.raw\nResolution: 24 24 24\n"
                              "SliceThickness: 1 1 1\nFormat: UCHAR\n";
  std::ofstream(dir_ / "short.raw") << std::string(24 * 24 * 23, 'x');  // one slice short
  const fs::path huge_dat = dir_ / "huge.dat";
  std::ofstream(huge_dat) << "ObjectFileName: huge.raw\nResolution: 100000 100000 100000\n"
                             "SliceThickness: 1 1 1\nFormat: UCHAR\n";
  std::ofstream(dir_ / "huge.raw") << std::string(64, 'x');
  const fs::path zero_dat = dir_ / "zero.dat";
  std::ofstream(zero_dat) << "ObjectFileName: zero.raw\nResolution: 0 24 24\n"
                             "SliceThickness: 1 1 1\nFormat: UCHAR\n";
  std::ofstream(dir_ / "zero.raw") << "";
  const fs::path nan_tf = dir_ / "nan_tf.json";
  std::ofstream(nan_tf) << R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, "nan"]]})";
  const fs::path unsorted_tf = dir_ / "unsorted_tf.json";
  std::ofstream(unsorted_tf) << R"({"points": [[0.8, 0, 0, 0, 0], [0.2, 1, 1, 1, 1]]})";
  const std::string ball = (dir_ / "ball.dat").string();
  struct Case {
    std::string args;
    std::string expect;  // in the error line
  };
  const std::vector<Case> cases = {
      {short_dat.string(), "short.raw"},
      {huge_dat.string(), "huge.dat"},
      {zero_dat.string(), "zero.dat"},
      {(dir_ / "absent.dat").string(), "absent.dat"},
      {ball + " --transfer " + nan_tf.string(), "nan_tf.json"},
      {ball + " --transfer " + unsorted_tf.string(), "unsorted_tf.json"},
      {ball + " --transfer nosuchpreset", "neither a preset (tooth, neghip, bucky, ramp, empty)"},
      {ball + " --effect melt", "melt"},
      {ball + " --deformation wedge --amount 0", "wedge: angle"},
      {ball + " --deformation clip --amount 1.5", "clip: position"},
      {ball + " --mode iso:300", "iso value 300 is outside the data range [0, 235]"},
      {ball + " --mode iso:nan", "iso:nan"},
      {ball + " --mode fog", "fog"},
      {ball + " --lighting spot", "spot"},
      {ball + " --displacement-bits 12", "12"},
      {ball + " --effect peel --map-size 0", "0"},
      {ball + " --effect slices --amount 0.5 --width 0.25", "gap"},
      {ball + " --spacing 0", "0"},
      {ball + " --size 0", "size"},
      {ball + " --effect peel --placement 0,0,0,0,0,0,0", "placement"},
      {ball + " --deformation peel,pull --amount 1,2,3", "3 values for 2"},
      {ball + " --effect peel --brick-texels -1", "brick"},
      {ball + " --effect peel --brick-texels 5000", "brick"},
  };
  for (const Case& c : cases) {
    const fs::path out = dir_ / "bad.png";
    fs::remove(out);
    const auto r = Volume(c.args + " --size 32 --out " + out.string());
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_EQ(test_support::CountLines(r.err), 1) << c.args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("ibr: error: ", 0), 0u) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args << ": wrote output";
    // Nothing staged left beside it either.
    for (const auto& e : fs::directory_iterator(dir_))
      EXPECT_EQ(e.path().filename().string().find("bad.png"), std::string::npos)
          << c.args << ": left " << e.path();
  }
}

fs::path RealVolumes() { return fs::path(IBR_REAL_DATA_DIR) / "volumes"; }

core::Image8 RenderOk(const std::string& args, const fs::path& out) {
  fs::remove(out);
  const auto r =
      test_support::RunCommand(test_support::IbrBinary() + " --log-level error volume " + args +
                               " --size 96 --azimuth 30 --elevation 20 --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
  if (r.exit_code != 0) return core::Image8(1, 1, 4);
  return core::ReadImage<uint8_t>(out);
}

// Pixels the volume's box covers: the volume drawn with every value opaque
// white (a transfer function in data units with one point).
// Mean grey level (0..255) of the covered pixels.
double CoveredGrey(const core::Image8& image) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(image.at(x, y, c) - image.at(0, 0, c));
      if (diff <= 6) continue;
      sum += (image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2)) / 3.0;
      ++n;
    }
  return n ? sum / n : 0;
}

int Footprint(const std::string& volume, const fs::path& dir) {
  const fs::path opaque = dir / "opaque.json";
  std::ofstream(opaque) << R"({"units": "data", "points": [[0, 1, 1, 1, 1]]})";
  return Covered(RenderOk(volume + " --transfer " + opaque.string(), dir / "footprint.png"));
}

// A real signed 16-bit CT (HU): DVR with the default transfer function (a
// ramp over its 50th..99th percentile window, -91..188 HU) is not black, and
// iso surfaces at values in HU draw (skin at -300 wraps bone at 300); an iso
// value outside the data range is refused naming the range.
TEST_F(VolumeCliTest, RealCtRendersByDefaultDvrAndAsAnIsoSurfaceInHu) {
  const std::string ct = (RealVolumes() / "ct_totalseg_example_ct_sm.nii.gz").string();
  const int box = Footprint(ct, dir_);
  const core::Image8 dvr = RenderOk(ct, dir_ / "ct_dvr.png");
  const core::Image8 bone = RenderOk(ct + " --mode iso:300", dir_ / "ct_iso300.png");
  const core::Image8 skin = RenderOk(ct + " --mode iso:-300", dir_ / "ct_iso-300.png");
  const int dvr_covered = Covered(dvr), bone_covered = Covered(bone), skin_covered = Covered(skin);
  std::printf(
      "CT: box %d px; default DVR %d px (mean grey %.1f); iso 300 HU %d px; iso -300 HU %d px\n",
      box, dvr_covered, CoveredGrey(dvr), bone_covered, skin_covered);
  // The body fills most of the CT's box (the air around it is transparent
  // by default); before signed types and the data-range window, nothing.
  EXPECT_GT(dvr_covered, box / 2);
  EXPECT_GT(CoveredGrey(dvr), 64);  // a quarter of full white: not near-black
  EXPECT_GT(skin_covered, box / 2);
  // Bone (1 % of the voxels are above 188 HU) draws, inside the skin.
  EXPECT_GT(bone_covered, 0);
  EXPECT_LT(bone_covered, skin_covered);
  const auto r = Volume(ct + " --mode iso:5000 --size 32 --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("iso value 5000 is outside the data range [-1100, 1207]"), std::string::npos)
      << r.err;
  EXPECT_EQ(test_support::CountLines(r.err), 1) << r.err;
}

// A real DICOM CT series (20 slices, 12 bits stored + intercept -> HU,
// 0.98 x 0.98 x 2 mm) renders by DVR with the default transfer function and
// as a bone iso surface.
TEST_F(VolumeCliTest, RealDicomSeriesRendersInHu) {
  const std::string dicom = (RealVolumes() / "ct_dicom_totalseg").string();
  const int box = Footprint(dicom, dir_);
  const core::Image8 dvr = RenderOk(dicom, dir_ / "dicom_dvr.png");
  const core::Image8 bone = RenderOk(dicom + " --mode iso:300", dir_ / "dicom_iso.png");
  std::printf("DICOM CT: box %d px; default DVR %d px; iso 300 HU %d px\n", box, Covered(dvr),
              Covered(bone));
  // The body within the scanner's circular field of view: a good part of
  // the square slab.
  EXPECT_GT(Covered(dvr), box / 4);
  EXPECT_GT(Covered(bone), 0);
  EXPECT_LT(Covered(bone), Covered(dvr));
}

// The same CT split into one gzip NRRD file per slice (a %03d pattern and a
// LIST) renders the same image as the NIfTI it came from.
TEST_F(VolumeCliTest, SlicePerFileNrrdRendersLikeItsSource) {
  const core::Image8 nifti =
      RenderOk((RealVolumes() / "ct_totalseg_example_ct_sm.nii.gz").string() + " --mode iso:300",
               dir_ / "src.png");
  for (const char* header : {"ct_slices_pattern.nhdr", "ct_slices_list.nhdr"}) {
    const core::Image8 slices = RenderOk(
        (fs::path(IBR_GENERATED_DATA_DIR) / "volumes" / header).string() + " --mode iso:300",
        dir_ / "slices.png");
    EXPECT_GT(Covered(slices), 0) << header;
    EXPECT_TRUE(slices == nifti) << header << ": differs from the NIfTI render";
  }
}

// A 12-bit scan in 16 bits (values 0..4095 of 65535): with no transfer
// function named, the default window makes it visible.
TEST_F(VolumeCliTest, TwelveBitScanIsNotBlackByDefault) {
  const int n = 24;
  core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kUint16);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r = std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0, z + 0.5 - n / 2.0);
        v.SetValue(x, y, z, std::clamp(4095 * (1 - r / (0.45 * n)), 0.0, 4095.0));
      }
  core::WriteNrrd(dir_ / "scan12.nrrd", v, core::NrrdEncoding::kGzip);
  const std::string scan = (dir_ / "scan12.nrrd").string();
  const int box = Footprint(scan, dir_);
  const int covered = Covered(RenderOk(scan, dir_ / "scan12.png"));
  std::printf("12-bit ball, default transfer: %d px of its box's %d\n", covered, box);
  // The ball's disc is pi * 0.45^2 / 1 of the box's square face, about 60 %
  // (less from 20 degrees above, the box's top adds to its footprint).
  EXPECT_GT(covered, box / 3);
}

// Non-cubic voxels render at their true shape: pyradiomics' breast MRI
// (45 x 120 x 21 voxels of 0.664 x 0.664 x 2.1 mm) drawn opaque, seen along
// +x from the orbit's eye (azimuth 0, elevation 0: image right = y, up = z).
// The silhouette is the box's near face, y : z = 79.7 : 44.1 mm = 1.807
// (voxel counts alone would give 120 : 21 = 5.7).
TEST_F(VolumeCliTest, NonCubicVoxelsRenderAtTheirTrueShape) {
  const fs::path opaque = dir_ / "opaque.json";
  std::ofstream(opaque) << R"({"units": "data", "points": [[0, 1, 1, 1, 1]]})";
  const fs::path out = dir_ / "breast.png";
  const auto r =
      Volume((RealVolumes() / "mri_pyradiomics_breast1.nrrd").string() + " --transfer " +
             opaque.string() + " --azimuth 0 --elevation 0 --size 192 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const core::Image8 image = core::ReadImage<uint8_t>(out);
  int x0 = image.width(), x1 = -1, y0 = image.height(), y1 = -1;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(image.at(x, y, c) - image.at(0, 0, c));
      if (diff <= 6) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  ASSERT_GE(x1, x0);
  const double width = x1 - x0 + 1, height = y1 - y0 + 1;
  const double expected = (120 * 0.664062) / (21 * 2.1);
  std::printf("breast MRI silhouette %.0f x %.0f px: ratio %.3f, true shape %.3f\n", width, height,
              width / height, expected);
  // One pixel of rounding at each edge of a ~130 x 73 px silhouette.
  EXPECT_NEAR(width / height, expected, expected * (2 / width + 2 / height));
}

// The covered pixels' centroid and bounding box (pixels differing from the
// corner's background).
struct Footprint2d {
  int count = 0;
  double cx = 0, cy = 0;
  int x0 = 1 << 30, x1 = -1, y0 = 1 << 30, y1 = -1;
};
Footprint2d Measure(const core::Image8& image) {
  Footprint2d f;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(image.at(x, y, c) - image.at(0, 0, c));
      if (diff <= 6) continue;
      ++f.count;
      f.cx += x + 0.5, f.cy += y + 0.5;
      f.x0 = std::min(f.x0, x), f.x1 = std::max(f.x1, x), f.y0 = std::min(f.y0, y);
      f.y1 = std::max(f.y1, y);
    }
  if (f.count > 0) f.cx /= f.count, f.cy /= f.count;
  return f;
}

// --up, --distance, --fov (ibr::OrbitCameraView, shared with ibr displace).
// A 24^3 volume, empty but for an opaque blob at the top (+z) of its box,
// seen from azimuth 0, elevation 0: with --up z the blob is at the top of the
// image (above the centre row); with --up x the orbit's frame turns (h1 = y,
// h2 = z), the eye is on +y with x up, so +z is image right. And the box of
// a uniform volume seen face on from --distance 100 with --fov 30 is
// f * 24 / (100 - 12) px wide, f = 64 / tan(15 deg).
TEST_F(VolumeCliTest, UpDistanceAndFovPlaceTheViewAnalytically) {
  const int n = 24;
  core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kUint8);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r = std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0, z + 0.5 - 20.0);
        v.SetValue(x, y, z, r < 3.5 ? 255 : 0);
      }
  core::WriteNrrd(dir_ / "blob.nrrd", v, core::NrrdEncoding::kRaw);
  const fs::path opaque = dir_ / "blob_tf.json";
  std::ofstream(opaque) << R"({"units": "data", "points": [[100, 1, 1, 1, 0], [101, 1, 1, 1, 1]]})";
  const auto render = [&](const std::string& args) {
    const fs::path out = dir_ / "up.png";
    fs::remove(out);
    const auto r = Volume((dir_ / "blob.nrrd").string() + " --transfer " + opaque.string() +
                          " --azimuth 0 --elevation 0 --lighting none --size 128 " + args +
                          " --out " + out.string());
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    return r.exit_code == 0 ? Measure(core::ReadImage<uint8_t>(out)) : Footprint2d{};
  };
  const Footprint2d z_up = render("--up z"), x_up = render("--up x"), minus_z = render("--up -z");
  std::printf(
      "blob at +z: --up z centroid (%.1f, %.1f); --up x (%.1f, %.1f); --up -z (%.1f, %.1f)"
      " of a 128 px image\n",
      z_up.cx, z_up.cy, x_up.cx, x_up.cy, minus_z.cx, minus_z.cy);
  // The blob's centre is 8 voxels above the box centre: 8 / 24 of the box's
  // height, well off the image centre (64) on the side named.
  ASSERT_GT(z_up.count, 0);
  EXPECT_LT(z_up.cy, 64 - 10);
  EXPECT_NEAR(z_up.cx, 64, 1.5);
  ASSERT_GT(x_up.count, 0);
  EXPECT_GT(x_up.cx, 64 + 10);
  EXPECT_NEAR(x_up.cy, 64, 1.5);
  ASSERT_GT(minus_z.count, 0);
  EXPECT_GT(minus_z.cy, 64 + 10);  // upside down: the blob at the bottom
  // Distance and field of view: an opaque uniform cube.
  core::Volume cube = core::Volume::Zeros({n, n, n}, core::ScalarType::kUint8);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) cube.SetValue(x, y, z, 200);
  core::WriteNrrd(dir_ / "blob.nrrd", cube, core::NrrdEncoding::kRaw);
  const Footprint2d face = render("--distance 100 --fov 30");
  const double expected = 64 / std::tan(15 * M_PI / 180) * 24 / (100 - 12);
  std::printf("cube face from 100 units, fov 30: %d x %d px, expected %.1f\n",
              face.x1 - face.x0 + 1, face.y1 - face.y0 + 1, expected);
  EXPECT_NEAR(face.x1 - face.x0 + 1, expected, 1.5);  // a pixel of rounding at each edge
  EXPECT_NEAR(face.y1 - face.y0 + 1, expected, 1.5);
  for (const char* bad : {"--up w", "--up 0,0,1", "--fov 0", "--fov 180", "--distance -1"}) {
    const auto r = Volume((dir_ / "blob.nrrd").string() + " " + bad + " --size 32 --out " +
                          (dir_ / "bad_up.png").string());
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_EQ(test_support::CountLines(r.err), 1) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad_up.png")) << bad;
  }
}

// Window/level in HU on the real signed 16-bit CT (range -1100..1207,
// percentiles 1/50/99: -1013 / -91 / 188): the window is the white ramp over
// [L - W/2, L + W/2], so (a) the default's 50th..99th window typed as W 279
// L 48.5 gives the default image, (b) W 400 L 40 gives the image of the same
// ramp written as a data-unit transfer file, (c) a bone window (W 1000 L 700:
// 200..1200 HU) draws less than the soft-tissue one and something, (d) a
// window below the data minimum makes every voxel opaque (the box, with a
// warning) and (e) one above the maximum, or a width <= 0 or NaN, is refused.
TEST_F(VolumeCliTest, WindowLevelInHuOnARealCt) {
  const std::string ct = (RealVolumes() / "ct_totalseg_example_ct_sm.nii.gz").string();
  const core::Image8 by_default = RenderOk(ct, dir_ / "wl_default.png");
  const core::Image8 same_window = RenderOk(ct + " --window 279 --level 48.5", dir_ / "wl_a.png");
  EXPECT_TRUE(same_window == by_default) << "W 279 L 48.5 is the default window";
  const fs::path soft_tf = dir_ / "soft_tf.json";
  std::ofstream(soft_tf)
      << R"({"units": "data", "points": [[-160, 1, 1, 1, 0], [240, 1, 1, 1, 1]]})";
  const core::Image8 soft = RenderOk(ct + " --window 400 --level 40", dir_ / "wl_soft.png");
  const core::Image8 soft_file =
      RenderOk(ct + " --transfer " + soft_tf.string(), dir_ / "wl_b.png");
  EXPECT_TRUE(soft == soft_file) << "W 400 L 40 is the ramp over -160..240 HU";
  const core::Image8 bone = RenderOk(ct + " --window 1000 --level 700", dir_ / "wl_bone.png");
  const int box = Footprint(ct, dir_);
  const core::Image8 below = RenderOk(ct + " --window 100 --level -1200", dir_ / "wl_below.png");
  std::printf(
      "CT window/level: soft W400 L40 %d px (mean grey %.1f), bone W1000 L700 %d px (mean "
      "grey %.1f), below the minimum %d px, box %d px\n",
      Covered(soft), CoveredGrey(soft), Covered(bone), CoveredGrey(bone), Covered(below), box);
  EXPECT_GT(Covered(soft), box / 2);  // the body
  EXPECT_GT(Covered(bone), 0);
  EXPECT_LT(Covered(bone), Covered(soft));
  EXPECT_FALSE(bone == soft);
  EXPECT_EQ(Covered(below), box);
  const auto warned = test_support::RunCommand(test_support::IbrBinary() + " volume " + ct +
                                               " --window 100 --level -1200 --size 32 --out " +
                                               (dir_ / "wl_warn.png").string());
  EXPECT_EQ(warned.exit_code, 0) << warned.err;
  EXPECT_NE(warned.err.find("ends at or below the data minimum -1100: every voxel is opaque"),
            std::string::npos)
      << warned.err;
  struct Case {
    std::string args, expect;
  };
  for (const Case& c : std::vector<Case>{
           {"--window 100 --level 1300",
            "window [1250, 1350] starts at or above the data maximum 1207 (range [-1100, 1207]"},
           {"--window 0 --level 40", "the width must be finite and > 0"},
           {"--window -400 --level 40", "the width must be finite and > 0"},
           {"--window nan --level 40", "nan"},
           {"--window 400 --level nan", "nan"},
           {"--window 400", "--level"},
           {"--window 400 --level 40 --transfer ramp", "--transfer"},
       }) {
    const fs::path out = dir_ / "wl_bad.png";
    fs::remove(out);
    const auto r = Volume(ct + " " + c.args + " --size 32 --out " + out.string());
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_EQ(test_support::CountLines(r.err), 1) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

TEST_F(VolumeCliTest, InfoPrintsTypeSizeSpacingRangeAndPercentiles) {
  const auto r =
      test_support::RunCommand(test_support::IbrBinary() + " --log-level error info " +
                               (RealVolumes() / "ct_totalseg_example_ct_sm.nii.gz").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* expect :
       {"type      int16", "size      122 x 101 x 30 voxels", "spacing   3 x 3 x 3",
        "range     -1100 .. 1207", "percentiles 1 / 50 / 99: -1013 / -91 / 188"}) {
    EXPECT_NE(r.out.find(expect), std::string::npos) << expect << "\n" << r.out;
  }
  const auto mri =
      test_support::RunCommand(test_support::IbrBinary() + " --log-level error info " +
                               (RealVolumes() / "mri_pyradiomics_breast1.nrrd").string());
  ASSERT_EQ(mri.exit_code, 0) << mri.err;
  EXPECT_NE(mri.out.find("spacing   0.664062 x 0.664062 x 2.1"), std::string::npos) << mri.out;
}

}  // namespace
