#include "core/image_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "core/error.h"
#include "tests/support/gl_test.h"

namespace core {
namespace {
namespace fs = std::filesystem;

template <typename T>
Image<T> RandomImage(int w, int h, int c, uint32_t seed) {
  std::mt19937 rng(seed);
  Image<T> image(w, h, c);
  for (auto& v : image.values()) {
    if constexpr (std::is_floating_point_v<T>) {
      v = std::uniform_real_distribution<float>(-1e4f, 1e4f)(rng);
    } else {
      v = static_cast<T>(rng());
    }
  }
  return image;
}

TEST(ImageIo, PngUint8RoundTripIsExact) {
  const auto dir = test_support::TestOutputDir();
  for (int channels : {1, 3, 4}) {
    const auto image = RandomImage<uint8_t>(37, 23, channels, 1);
    WriteImage(dir / "a.png", image);
    EXPECT_EQ(ReadImage<uint8_t>(dir / "a.png"), image) << channels << " channels";
  }
}

TEST(ImageIo, PngUint16RoundTripIsExact) {
  const auto dir = test_support::TestOutputDir();
  const auto image = RandomImage<uint16_t>(31, 17, 1, 2);
  WriteImage(dir / "d.png", image);
  EXPECT_EQ(ReadImage<uint16_t>(dir / "d.png"), image);
}

TEST(ImageIo, ExrFloatRoundTripIsBitExact) {
  const auto dir = test_support::TestOutputDir();
  auto image = RandomImage<float>(41, 29, 1, 3);
  image.at(0, 0) = 0.0f;
  image.at(1, 0) = 1e-30f;   // tiny but representable in float32
  image.at(2, 0) = 3.4e38f;  // near float max
  image.at(3, 0) = std::nextafter(1.0f, 2.0f);
  WriteImage(dir / "depth.exr", image);
  const auto back = ReadImage<float>(dir / "depth.exr");
  ASSERT_EQ(back.width(), image.width());
  ASSERT_EQ(back.height(), image.height());
  ASSERT_EQ(back.channels(), 1);
  EXPECT_EQ(std::memcmp(back.data(), image.data(), image.values().size() * sizeof(float)), 0);
}

TEST(ImageIo, RowZeroIsTheTopOfTheFile) {
  const auto dir = test_support::TestOutputDir();
  Image8 image(4, 3, 1, 0);
  image.at(0, 0) = 200;  // top-left
  WriteImage(dir / "corner.png", image);
  const auto header = ReadImageHeader(dir / "corner.png");
  EXPECT_EQ(header.width, 4);
  EXPECT_EQ(header.height, 3);
  EXPECT_EQ(ReadImage<uint8_t>(dir / "corner.png").at(0, 0), 200);
}

TEST(ImageIo, MissingFileNamesTheFile) {
  try {
    ReadImage<uint8_t>("/nonexistent/dir/missing.png");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(ImageIo, CorruptAndTruncatedFilesAreRejected) {
  const auto dir = test_support::TestOutputDir();
  { std::ofstream(dir / "garbage.png") << "this is not a png at all"; }
  EXPECT_THROW(ReadImage<uint8_t>(dir / "garbage.png"), InputError);
  // A real PNG cut in half.
  WriteImage(dir / "full.png", RandomImage<uint8_t>(64, 64, 3, 4));
  std::ifstream in(dir / "full.png", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(dir / "half.png", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_THROW(ReadImage<uint8_t>(dir / "half.png"), InputError);
}

TEST(ImageIo, WrongChannelCountIsRejected) {
  const auto dir = test_support::TestOutputDir();
  WriteImage(dir / "rgb.png", RandomImage<uint8_t>(8, 8, 3, 5));
  EXPECT_THROW(ReadImage<uint8_t>(dir / "rgb.png", 1), InputError);
}

TEST(ImageIo, FailedWriteLeavesNothingBehind) {
  const auto dir = test_support::TestOutputDir() / "nowrite";
  fs::create_directories(dir);
  EXPECT_THROW(WriteImage(dir / "x.unknownformat", RandomImage<uint8_t>(4, 4, 1, 6)), InputError);
  EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
}  // namespace core
