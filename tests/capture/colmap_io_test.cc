// COLMAP readers/writers through streams: bit-exact round trips, the exact
// byte layout of the dense maps, bad input giving InputError naming the file,
// and seeded random/mutated bytes never crashing a parser.
#include "capture/colmap_io.h"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <random>
#include <sstream>

#include "core/error.h"
#include "tests/capture/random_model.h"

namespace capture::colmap {
namespace {

template <typename Writer, typename Value>
std::string WriteToString(Writer writer, const Value& value) {
  std::ostringstream out(std::ios::binary);
  writer(out, value);
  return out.str();
}

template <typename Reader>
auto ReadFromString(Reader reader, const std::string& bytes, const std::string& name = "mem") {
  std::istringstream in(bytes, std::ios::binary);
  return reader(in, name);
}

TEST(ColmapText, RoundTripIsBitExactForEveryCameraModel) {
  const SparseModel model = test::RandomSparseModel(1);
  const auto cams = ReadFromString(ReadCamerasText, WriteToString(WriteCamerasText, model.cameras));
  const auto images = ReadFromString(ReadImagesText, WriteToString(WriteImagesText, model.images));
  const auto points =
      ReadFromString(ReadPoints3DText, WriteToString(WritePoints3DText, model.points3D));
  EXPECT_EQ(cams, model.cameras);  // operator== on doubles: bit-exact
  EXPECT_EQ(images, model.images);
  EXPECT_EQ(points, model.points3D);
  EXPECT_EQ(cams.size(), static_cast<size_t>(kNumColmapModels));
}

TEST(ColmapText, ParsesColmapsOwnLayout) {
  // As written by colmap model_converter (COLMAP-FORMATS.md), incl. an empty
  // POINTS2D line and a comment.
  const std::string cameras =
      "# Camera list\n1 PINHOLE 640 480 500 500 320 240\n2 SIMPLE_RADIAL 64 48 50 32 24 -0.01\n";
  const std::string images =
      "# Image list\n1 1 0 0 0 0.5 -0.25 3 1 a.png\n10 20 -1 30 40 5\n"
      "2 0.70710678118654757 0 0.70710678118654757 0 0 0 1 2 b.png\n\n";
  const std::string points = "7 0.5 0.25 1 255 0 10 0.75 1 0\n";
  const auto c = ReadFromString(ReadCamerasText, cameras);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.at(2).model, CameraModel::kSimpleRadial);
  EXPECT_EQ(c.at(2).params[3], -0.01);
  const auto im = ReadFromString(ReadImagesText, images);
  ASSERT_EQ(im.size(), 2u);
  EXPECT_EQ(im.at(1).name, "a.png");
  ASSERT_EQ(im.at(1).points2D.size(), 2u);
  EXPECT_EQ(im.at(1).points2D[0].point3D_id, kInvalidPoint3DId);
  EXPECT_EQ(im.at(1).points2D[1].point3D_id, 5u);
  EXPECT_EQ(im.at(1).points2D[1].x, 30.0);
  EXPECT_TRUE(im.at(2).points2D.empty());
  const auto pts = ReadFromString(ReadPoints3DText, points);
  ASSERT_EQ(pts.at(7).track.size(), 1u);
  EXPECT_EQ(pts.at(7).rgb[0], 255);
  SparseModel model{c, im, pts};
  // Point 7 names image 1, index 0: valid.
  EXPECT_NO_THROW(model.Check("t"));
}

TEST(ColmapBinary, RoundTripIsBitExactAndByteStable) {
  const SparseModel model = test::RandomSparseModel(2);
  const std::string cb = WriteToString(WriteCamerasBinary, model.cameras);
  const std::string ib = WriteToString(WriteImagesBinary, model.images);
  const std::string pb = WriteToString(WritePoints3DBinary, model.points3D);
  const auto cams = ReadFromString(ReadCamerasBinary, cb);
  const auto images = ReadFromString(ReadImagesBinary, ib);
  const auto points = ReadFromString(ReadPoints3DBinary, pb);
  EXPECT_EQ(cams, model.cameras);
  EXPECT_EQ(images, model.images);
  EXPECT_EQ(points, model.points3D);
  EXPECT_EQ(WriteToString(WriteCamerasBinary, cams), cb);
  EXPECT_EQ(WriteToString(WriteImagesBinary, images), ib);
  EXPECT_EQ(WriteToString(WritePoints3DBinary, points), pb);
  // Layout spot check: u64 count, then u32 id, i32 model id, u64 w, u64 h, f64 params.
  uint64_t n;
  std::memcpy(&n, cb.data(), 8);
  EXPECT_EQ(n, model.cameras.size());
  uint32_t id;
  int32_t model_id;
  uint64_t width;
  double f;
  std::memcpy(&id, cb.data() + 8, 4);
  std::memcpy(&model_id, cb.data() + 12, 4);
  std::memcpy(&width, cb.data() + 16, 8);
  std::memcpy(&f, cb.data() + 32, 8);
  EXPECT_EQ(id, 1u);
  EXPECT_EQ(model_id, 0);
  EXPECT_EQ(width, 320u);
  EXPECT_EQ(f, model.cameras.at(1).params[0]);
}

TEST(DenseMap, LayoutIsPlanarRowMajorAndRoundTripsExactly) {
  core::ImageF normal(3, 2, 3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c)
        normal.at(x, y, c) = static_cast<float>(100 * c + 10 * y + x) + 0.125f;
  const std::string bytes =
      WriteToString([](std::ostream& o, const core::ImageF& m) { WriteDenseMap(o, m); }, normal);
  const std::string header = "3&2&3&";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 18 * 4);
  // Element (row, col, channel) at channel*W*H + row*W + col.
  for (int c = 0; c < 3; ++c) {
    for (int y = 0; y < 2; ++y) {
      for (int x = 0; x < 3; ++x) {
        float v;
        std::memcpy(&v, bytes.data() + header.size() + 4 * (c * 6 + y * 3 + x), 4);
        EXPECT_EQ(v, normal.at(x, y, c));
      }
    }
  }
  const auto back = ReadFromString(
      [](std::istream& in, const std::string& n) { return ReadDenseMap(in, n); }, bytes);
  EXPECT_EQ(back, normal);
}

TEST(StereoConfigs, RoundTrip) {
  const std::vector<std::string> names = {"a.png", "b c.png", "view_002.png"};
  EXPECT_EQ(ReadFromString(ReadFusionConfig, WriteToString(WriteFusionConfig, names)), names);
  const std::vector<PatchMatchEntry> entries = {{"a.png", "__auto__, 20"},
                                                {"b.png", "a.png, c.png"}};
  EXPECT_EQ(ReadFromString(ReadPatchMatchConfig, WriteToString(WritePatchMatchConfig, entries)),
            entries);
}

// ---- bad input: every case must give InputError naming the file ----

struct BadCase {
  const char* what;
  std::function<void(const std::string& name)> read;
};

std::string ValidCamerasBin() {
  return WriteToString(WriteCamerasBinary, test::RandomSparseModel(3).cameras);
}
std::string ValidImagesBin() {
  return WriteToString(WriteImagesBinary, test::RandomSparseModel(3).images);
}
std::string ValidPointsBin() {
  return WriteToString(WritePoints3DBinary, test::RandomSparseModel(3).points3D);
}

template <typename Reader>
std::function<void(const std::string&)> Feed(Reader reader, std::string bytes) {
  return [reader, bytes](const std::string& name) {
    std::istringstream in(bytes, std::ios::binary);
    reader(in, name);
  };
}

std::string WithDouble(std::string bytes, size_t offset, double v) {
  std::memcpy(bytes.data() + offset, &v, 8);
  return bytes;
}

std::vector<BadCase> BadCases() {
  auto dense = [](std::istream& in, const std::string& n) { return ReadDenseMap(in, n); };
  const std::string cb = ValidCamerasBin(), ib = ValidImagesBin(), pb = ValidPointsBin();
  std::string model_id_99 = cb;
  const int32_t bad_model = 99;
  std::memcpy(model_id_99.data() + 12, &bad_model, 4);
  std::string huge_count = pb;
  const uint64_t big = UINT64_MAX / 2;
  std::memcpy(huge_count.data(), &big, 8);
  return {
      {"cameras.txt: unknown model", Feed(ReadCamerasText, "1 PINHOL 640 480 1 1 1 1\n")},
      {"cameras.txt: too few params", Feed(ReadCamerasText, "1 OPENCV 640 480 500 500 320 240\n")},
      {"cameras.txt: NaN param", Feed(ReadCamerasText, "1 PINHOLE 640 480 nan 500 320 240\n")},
      {"cameras.txt: non-numeric width",
       Feed(ReadCamerasText, "1 PINHOLE six 480 500 500 320 240\n")},
      {"cameras.txt: negative size", Feed(ReadCamerasText, "1 PINHOLE -640 480 500 500 320 240\n")},
      {"cameras.txt: zero focal", Feed(ReadCamerasText, "1 PINHOLE 640 480 0 500 320 240\n")},
      {"cameras.txt: duplicate id",
       Feed(ReadCamerasText, "1 PINHOLE 64 48 5 5 3 2\n1 PINHOLE 64 48 5 5 3 2\n")},
      {"cameras.txt: truncated line", Feed(ReadCamerasText, "1 PINHOLE 64\n")},
      {"images.txt: missing points line", Feed(ReadImagesText, "1 1 0 0 0 0 0 0 1 a.png")},
      {"images.txt: points not triples", Feed(ReadImagesText, "1 1 0 0 0 0 0 0 1 a.png\n1 2\n")},
      {"images.txt: NaN translation", Feed(ReadImagesText, "1 1 0 0 0 nan 0 0 1 a.png\n\n")},
      {"images.txt: zero quaternion", Feed(ReadImagesText, "1 0 0 0 0 0 0 0 1 a.png\n\n")},
      {"images.txt: too few fields", Feed(ReadImagesText, "1 1 0 0 0 0 0 0 1\n\n")},
      {"images.txt: POINT3D_ID -2", Feed(ReadImagesText, "1 1 0 0 0 0 0 0 1 a.png\n1 2 -2\n")},
      {"points3D.txt: colour 300", Feed(ReadPoints3DText, "1 0 0 0 300 0 0 0.5\n")},
      {"points3D.txt: odd track", Feed(ReadPoints3DText, "1 0 0 0 3 0 0 0.5 1\n")},
      {"points3D.txt: inf coordinate", Feed(ReadPoints3DText, "1 inf 0 0 3 0 0 0.5\n")},
      {"cameras.bin: empty", Feed(ReadCamerasBinary, "")},
      {"cameras.bin: truncated", Feed(ReadCamerasBinary, cb.substr(0, cb.size() - 5))},
      {"cameras.bin: unknown model id", Feed(ReadCamerasBinary, model_id_99)},
      {"cameras.bin: NaN param", Feed(ReadCamerasBinary, WithDouble(cb, 32, NAN))},
      {"cameras.bin: trailing bytes", Feed(ReadCamerasBinary, cb + "xyz")},
      {"images.bin: truncated inside name",
       Feed(ReadImagesBinary, ib.substr(0, 8 + 4 + 56 + 4 + 3))},
      {"images.bin: NaN quaternion", Feed(ReadImagesBinary, WithDouble(ib, 12, NAN))},
      {"images.bin: truncated points", Feed(ReadImagesBinary, ib.substr(0, ib.size() - 1))},
      {"points3D.bin: huge count", Feed(ReadPoints3DBinary, huge_count)},
      {"points3D.bin: NaN xyz", Feed(ReadPoints3DBinary, WithDouble(pb, 16, NAN))},
      {"depth.bin: no header", Feed(dense, "garbage")},
      {"depth.bin: truncated data", Feed(dense, std::string("4&4&1&") + std::string(60, '\0'))},
      {"depth.bin: trailing data", Feed(dense, std::string("1&1&1&") + std::string(8, '\0'))},
      {"depth.bin: zero width", Feed(dense, "0&4&1&")},
      {"depth.bin: 2 channels", Feed(dense, std::string("1&1&2&") + std::string(8, '\0'))},
      {"depth.bin: huge size", Feed(dense, "999999999&999999999&1&")},
      {"fusion.cfg: empty", Feed(ReadFusionConfig, "\n\n")},
      {"fusion.cfg: duplicate", Feed(ReadFusionConfig, "a.png\na.png\n")},
      {"patch-match.cfg: odd lines", Feed(ReadPatchMatchConfig, "a.png\n__auto__, 20\nb.png\n")},
  };
}

TEST(ColmapBadInput, EveryCaseThrowsInputErrorNamingTheFile) {
  const auto cases = BadCases();
  EXPECT_GE(cases.size(), 20u);
  for (const auto& c : cases) {
    const std::string name = std::string("/data/") + c.what;
    try {
      c.read(name);
      ADD_FAILURE() << c.what << ": no error";
    } catch (const core::InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(name), std::string::npos)
          << c.what << ": message does not name the file: " << msg;
      EXPECT_NE(msg.find("Read"), std::string::npos)
          << c.what << ": message does not name the function: " << msg;
    }
  }
}

TEST(ColmapBadInput, SparseModelWithDanglingReferences) {
  SparseModel model = test::RandomSparseModel(4);
  model.points3D.begin()->second.track[0].point2D_idx = 9999;
  EXPECT_THROW(model.Check("t"), core::InputError);
  model = test::RandomSparseModel(4);
  model.images.begin()->second.camera_id = 77;
  EXPECT_THROW(model.Check("t"), core::InputError);
}

// ---- robustness: seeded random and mutated inputs (the libFuzzer targets in
// fuzz/ do the same, open-ended, when built with clang) ----

template <typename Reader>
void Hammer(Reader reader, const std::string& seed_bytes, uint64_t seed, int iterations) {
  std::mt19937_64 rng(seed);
  int errors = 0, accepted = 0;
  for (int i = 0; i < iterations; ++i) {
    std::string bytes = seed_bytes;
    const int kind = static_cast<int>(rng() % 4);
    if (kind == 0) {  // random bytes
      bytes.resize(rng() % 200);
      for (char& ch : bytes) ch = static_cast<char>(rng());
    } else {  // flips, truncation, insertion of interesting bytes
      const int edits = 1 + static_cast<int>(rng() % 8);
      for (int e = 0; e < edits && !bytes.empty(); ++e) {
        const size_t at = rng() % bytes.size();
        switch (rng() % 4) {
          case 0:
            bytes[at] = static_cast<char>(rng());
            break;
          case 1:
            bytes.resize(at);
            break;
          case 2:
            bytes.insert(at, 1, "\0\xff -1&\n#e."[rng() % 11]);
            break;
          default:
            bytes[at] ^= static_cast<char>(1u << (rng() % 8));
            break;
        }
      }
    }
    std::istringstream in(bytes, std::ios::binary);
    try {
      reader(in, "fuzz");
      ++accepted;
    } catch (const core::InputError&) {
      ++errors;
    }
  }
  EXPECT_EQ(errors + accepted, iterations);
  EXPECT_GT(errors, 0) << "mutations never produced an error: the hammer is not hitting the parser";
}

TEST(ColmapFuzz, TextParsersOnlyEverThrowInputError) {
  const SparseModel model = test::RandomSparseModel(5, 4, 10);
  Hammer(ReadCamerasText, WriteToString(WriteCamerasText, model.cameras), 11, 3000);
  Hammer(ReadImagesText, WriteToString(WriteImagesText, model.images), 12, 3000);
  Hammer(ReadPoints3DText, WriteToString(WritePoints3DText, model.points3D), 13, 3000);
  Hammer(ReadFusionConfig, "a.png\nb.png\n", 14, 2000);
  Hammer(ReadPatchMatchConfig, "a.png\n__auto__, 20\n", 15, 2000);
}

TEST(ColmapFuzz, BinaryParsersOnlyEverThrowInputError) {
  const SparseModel model = test::RandomSparseModel(6, 4, 10);
  Hammer(ReadCamerasBinary, WriteToString(WriteCamerasBinary, model.cameras), 21, 3000);
  Hammer(ReadImagesBinary, WriteToString(WriteImagesBinary, model.images), 22, 3000);
  Hammer(ReadPoints3DBinary, WriteToString(WritePoints3DBinary, model.points3D), 23, 3000);
  core::ImageF map(5, 4, 3, 0.5f);
  Hammer([](std::istream& in, const std::string& n) { return ReadDenseMap(in, n); },
         WriteToString([](std::ostream& o, const core::ImageF& m) { WriteDenseMap(o, m); }, map),
         24, 3000);
}

}  // namespace
}  // namespace capture::colmap
