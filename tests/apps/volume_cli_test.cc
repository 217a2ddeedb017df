// `ibr volume` end to end: QVis and NRRD volumes with each effect, DVR and
// iso, written as PNG; bad input (short raw file, absurd header sizes, NaN in
// a transfer function, unknown effect, ...) gives one error line, a non-zero
// exit and no output file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

TEST_F(VolumeCliTest, RendersEveryEffectAndMode) {
  const std::string dat = (dir_ / "ball.dat").string(), nrrd = (dir_ / "ball.nrrd").string();
  for (const std::string& args : std::vector<std::string>{
           dat + " --effect none --transfer ramp",
           dat + " --effect peel --peel-angle 120 --displacement-bits 16",
           dat + " --effect peel --brick-texels 0",
           dat + " --effect seam --brick-texels 2 --no-support-skip",
           dat + " --effect slices --displacement-bits 8 --lighting transformed",
           dat + " --effect seam --mode iso:0.3 --lighting blended",
           nrrd + " --effect pull --map-size 32 --spacing 0.5",
           nrrd + " --effect wave --displacement-bits 32 --placement 0.1 0.1 0 0.8 0.8 1",
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
      {ball + " --transfer nosuchpreset", "nosuchpreset"},
      {ball + " --effect melt", "melt"},
      {ball + " --mode iso:2", "iso:2"},
      {ball + " --mode fog", "fog"},
      {ball + " --lighting spot", "spot"},
      {ball + " --displacement-bits 12", "12"},
      {ball + " --effect peel --map-size 0", "0"},
      {ball + " --effect slices --slices-gap 0.5 --slices-period 0.25", "gap"},
      {ball + " --spacing 0", "0"},
      {ball + " --size 0", "size"},
      {ball + " --effect peel --placement 0 0 0 0 1 1", "placement"},
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

}  // namespace
