#include "core/volume_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/transfer_function.h"
#include "tests/support/gl_test.h"

namespace core {
namespace {
namespace fs = std::filesystem;

Volume RandomVolume(const glm::ivec3& dims, ScalarType type, const glm::dvec3& spacing,
                    uint32_t seed) {
  Volume v = Volume::Zeros(dims, type, spacing);
  std::mt19937 rng(seed);
  if (type == ScalarType::kFloat32) {
    std::uniform_real_distribution<double> u(-1e3, 1e3);
    for (int z = 0; z < dims.z; ++z)
      for (int y = 0; y < dims.y; ++y)
        for (int x = 0; x < dims.x; ++x) v.SetValue(x, y, z, u(rng));
  } else {
    for (auto& b : v.bytes) b = static_cast<uint8_t>(rng());
  }
  return v;
}

std::vector<uint8_t> FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The message of the InputError `f` throws ("" and a test failure if none).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

struct SharedVolume {
  const char* dat;
  glm::ivec3 dims;
};

TEST(VolumeIo, ReadsTheSharedQVisVolumesByteForByte) {
  const SharedVolume volumes[] = {{"volumes/tooth_103x94x161_uint8.dat", {103, 94, 161}},
                                  {"volumes/neghip_64x64x64_uint8.dat", {64, 64, 64}},
                                  {"volumes/Bucky_32x32x32_uint8.dat", {32, 32, 32}}};
  for (const auto& s : volumes) {
    const fs::path dat = test_support::SharedData(s.dat);
    if (dat.empty()) GTEST_SKIP() << "../shared/data is absent";
    const Volume v = ReadVolume(dat);
    EXPECT_EQ(v.dims, s.dims) << s.dat;
    EXPECT_EQ(v.type, ScalarType::kUint8);
    EXPECT_EQ(v.spacing, glm::dvec3(1.0));
    fs::path raw = dat;
    raw.replace_extension(".raw");
    // The raw file is the voxels, x fastest: the bytes are the file's.
    EXPECT_EQ(v.bytes, FileBytes(raw)) << s.dat;
    // Not an empty scan: some voxels above 1/4 of the range.
    size_t bright = 0;
    for (uint8_t b : v.bytes) bright += b > 64;
    EXPECT_GT(bright, v.voxel_count() / 100) << s.dat;
  }
}

TEST(VolumeIo, QVisRoundTripThroughStreamsAndFiles) {
  const auto dir = test_support::TestOutputDir();
  uint32_t seed = 1;
  for (ScalarType type : {ScalarType::kUint8, ScalarType::kUint16, ScalarType::kFloat32}) {
    const Volume v = RandomVolume({7, 3, 5}, type, {0.5, 1.25, 3.0 / 7.0}, seed++);
    std::stringstream dat, raw;
    WriteQVisHeader(dat, v, "x.raw");
    WriteQVisRaw(raw, v);
    const QVisHeader h = ReadQVisHeader(dat, "mem.dat");
    EXPECT_EQ(h.object_file, "x.raw");
    EXPECT_EQ(ReadQVisRaw(raw, h, "mem.raw"), v) << ScalarTypeName(type);
    WriteQVis(dir / "v.dat", v);
    EXPECT_EQ(ReadVolume(dir / "v.dat"), v) << ScalarTypeName(type);
    EXPECT_EQ(fs::file_size(dir / "v.raw"), v.voxel_count() * BytesPerScalar(type));
  }
}

TEST(VolumeIo, QVisSpacingFromSliceThicknessAndUshortIsLittleEndian) {
  std::istringstream dat(
      "ObjectFileName: a.raw\nTaggedFileName: ---\nResolution:  2 1 1\n"
      "SliceThickness: 0.5 0.25 2\nFormat:  USHORT\n\n\n");
  const QVisHeader h = ReadQVisHeader(dat, "a.dat");
  EXPECT_EQ(h.spacing, glm::dvec3(0.5, 0.25, 2.0));
  std::istringstream raw(std::string("\x01\x02\xff\x00", 4));
  const Volume v = ReadQVisRaw(raw, h, "a.raw");
  EXPECT_EQ(v.Value(0, 0, 0), 0x0201);
  EXPECT_EQ(v.Value(1, 0, 0), 0x00ff);
  EXPECT_DOUBLE_EQ(v.Normalized(1, 0, 0), 255.0 / 65535.0);
}

TEST(VolumeIo, NrrdRoundTripRawAndGzip) {
  const auto dir = test_support::TestOutputDir();
  uint32_t seed = 10;
  for (ScalarType type : {ScalarType::kUint8, ScalarType::kUint16, ScalarType::kFloat32}) {
    for (NrrdEncoding encoding : {NrrdEncoding::kRaw, NrrdEncoding::kGzip}) {
      const Volume v = RandomVolume({9, 4, 6}, type, {1.0, 0.3, 2.5}, seed++);
      std::stringstream s;
      WriteNrrd(s, v, encoding);
      EXPECT_EQ(ReadNrrd(s, "mem.nrrd"), v);
      WriteNrrd(dir / "v.nrrd", v, encoding);
      EXPECT_EQ(ReadVolume(dir / "v.nrrd"), v);
    }
  }
  // A smooth volume compresses: gzip is really deflating.
  Volume smooth = Volume::Zeros({32, 32, 32}, ScalarType::kUint8);
  std::stringstream raw, gz;
  WriteNrrd(raw, smooth, NrrdEncoding::kRaw);
  WriteNrrd(gz, smooth, NrrdEncoding::kGzip);
  EXPECT_LT(gz.str().size() * 20, raw.str().size());
}

TEST(VolumeIo, NrrdBigEndianSpaceDirectionsAndDetachedData) {
  std::istringstream in(
      std::string("NRRD0005\n# comment\ntype: unsigned short\ndimension: 3\n"
                  "space: right-anterior-superior\nsizes: 2 1 1\n"
                  "space directions: (0,0.5,0) (3,4,0) (0,0,2)\n"
                  "kinds: domain domain domain\nendian: big\nencoding: raw\nkey:=value\n\n") +
      std::string("\x01\x02\x00\xff", 4));
  const Volume v = ReadNrrd(in, "mem.nrrd");
  EXPECT_EQ(v.spacing, glm::dvec3(0.5, 5.0, 2.0));
  EXPECT_EQ(v.Value(0, 0, 0), 0x0102);
  EXPECT_EQ(v.Value(1, 0, 0), 0x00ff);

  const auto dir = test_support::TestOutputDir();
  {
    std::ofstream h(dir / "d.nhdr");
    h << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 1\nencoding: raw\ndata file: d.raw\n";
    std::ofstream r(dir / "d.raw", std::ios::binary);
    r << "abcd";
  }
  const Volume d = ReadVolume(dir / "d.nhdr");
  EXPECT_EQ(d.Value(1, 1, 0), 'd');
  std::ifstream again(dir / "d.nhdr");
  EXPECT_NE(ErrorOf([&] { ReadNrrd(again, "d.nhdr"); }).find("detached"), std::string::npos);
}

TEST(VolumeIo, BadInputIsOneClearErrorNamingTheFile) {
  const auto dir = test_support::TestOutputDir();
  const Volume v = RandomVolume({4, 4, 4}, ScalarType::kUint8, glm::dvec3(1.0), 3);
  WriteQVis(dir / "ok.dat", v);
  // Short and long raw files.
  {
    std::ofstream r(dir / "short.raw", std::ios::binary);
    r << std::string(63, 'x');
    std::ofstream d(dir / "short.dat");
    d << "ObjectFileName: short.raw\nResolution: 4 4 4\nFormat: UCHAR\n";
  }
  std::string e = ErrorOf([&] { ReadVolume(dir / "short.dat"); });
  EXPECT_NE(e.find("short.raw"), std::string::npos) << e;
  EXPECT_NE(e.find("short data: 63 bytes, the header says 64"), std::string::npos) << e;
  {
    std::ofstream r(dir / "long.raw", std::ios::binary);
    r << std::string(65, 'x');
    std::ofstream d(dir / "long.dat");
    d << "ObjectFileName: long.raw\nResolution: 4 4 4\nFormat: UCHAR\n";
  }
  e = ErrorOf([&] { ReadVolume(dir / "long.dat"); });
  EXPECT_NE(e.find("65 bytes of data, the header says 64"), std::string::npos) << e;

  struct Case {
    const char* header;
    const char* expect;
  };
  const Case qvis_cases[] = {
      {"Resolution: 4 4 4\nFormat: UCHAR\n", "no ObjectFileName"},
      {"ObjectFileName: ok.raw\nFormat: UCHAR\n", "no Resolution"},
      {"ObjectFileName: ok.raw\nResolution: 4 4\nFormat: UCHAR\n", "expected 3 sizes"},
      {"ObjectFileName: ok.raw\nResolution: 4 4 x\nFormat: UCHAR\n", "not an integer"},
      {"ObjectFileName: ok.raw\nResolution: 4 4 4\nFormat: DOUBLE\n", "not supported"},
      {"ObjectFileName: ok.raw\nResolution: 0 4 4\nFormat: UCHAR\n", "each extent must be in"},
      {"ObjectFileName: ok.raw\nResolution: 8000 8000 8000\nFormat: UCHAR\n", "more than the"},
      {"ObjectFileName: ok.raw\nResolution: 4 4 4\nSliceThickness: 1 nan 1\nFormat: UCHAR\n",
       "finite and > 0"},
      {"ObjectFileName: ok.raw\nResolution: 4 4 4\nSliceThickness: 1 -1 1\nFormat: UCHAR\n",
       "finite and > 0"},
      {"ObjectFileName: missing.raw\nResolution: 4 4 4\nFormat: UCHAR\n", "no such file"},
  };
  for (const auto& c : qvis_cases) {
    {
      std::ofstream d(dir / "bad.dat");
      d << c.header;
    }
    e = ErrorOf([&] { ReadVolume(dir / "bad.dat"); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.header << " -> " << e;
    EXPECT_TRUE(e.find("bad.dat") != std::string::npos ||
                e.find("missing.raw") != std::string::npos)
        << e;
  }

  const Case nrrd_cases[] = {
      {"NRRD0009\n", "not a NRRD file"},
      {"NRRD0004\ntype: uint8\ndimension: 2\nsizes: 4 4\nencoding: raw\n\n", "dimension 2"},
      {"NRRD0004\ntype: int32\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n", "type 'int32'"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nencoding: bzip2\n\n",
       "encoding 'bzip2'"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\n\n", "lacks a required field"},
      // A header claiming 1 GB over a few bytes: refused from the stream's
      // size before the volume is allocated.
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1000 1000 1000\nencoding: raw\n\nabc",
       "short data: 3 bytes"},
      {"NRRD0004\ntype: float\ndimension: 3\nsizes: 2048 2048 2048\nencoding: raw\n\n",
       "more than the"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1000 1000 1000\nencoding: gzip\n\nnot gzip",
       "gzip"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nspacings: 1 1 inf\nencoding: raw\n\n",
       "finite and > 0"},
  };
  for (const auto& c : nrrd_cases) {
    {
      std::ofstream d(dir / "bad.nrrd", std::ios::binary);
      d << c.header;
    }
    e = ErrorOf([&] { ReadVolume(dir / "bad.nrrd"); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.header << " -> " << e;
    EXPECT_NE(e.find("bad.nrrd"), std::string::npos) << e;
  }

  // Truncated gzip: every prefix of a valid gzip file is a clean error.
  std::stringstream gz;
  WriteNrrd(gz, v, NrrdEncoding::kGzip);
  const std::string full = gz.str();
  const size_t header_end = full.find("\n\n") + 2;
  for (size_t cut = header_end; cut < full.size() - 8; cut += 3) {
    std::istringstream in(full.substr(0, cut));
    EXPECT_THROW(ReadNrrd(in, "cut.nrrd"), InputError) << cut;
  }
  EXPECT_THROW(ReadVolume(dir / "x.vol"), InputError);
}

TEST(Volume, TrilinearMatchesTheVoxelsAtTheirCentresAndInterpolatesBetween) {
  const Volume v = RandomVolume({5, 4, 3}, ScalarType::kUint16, glm::dvec3(1.0), 7);
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 5; ++x) {
        const glm::dvec3 centre((x + 0.5) / 5, (y + 0.5) / 4, (z + 0.5) / 3);
        EXPECT_NEAR(SampleTrilinear(v, centre), v.Normalized(x, y, z), 1e-12);
      }
  // Halfway between (1,1,1) and (2,1,1): the mean.
  EXPECT_NEAR(SampleTrilinear(v, {2.0 / 5, 1.5 / 4, 1.5 / 3}),
              0.5 * (v.Normalized(1, 1, 1) + v.Normalized(2, 1, 1)), 1e-12);
  // Outside: clamped to the edge voxel.
  EXPECT_NEAR(SampleTrilinear(v, {-3, 0.5 / 4, 0.5 / 3}), v.Normalized(0, 0, 0), 1e-12);
}

TEST(TransferFunction, OpacityCorrectionComposesLikeTheSamplesItStandsFor) {
  const std::vector<glm::vec4> table = TransferPreset("tooth").Table(256);
  // Exponent 1: the table as is; colours are never touched.
  EXPECT_EQ(OpacityCorrectedTable(table, 1.0), table);
  for (const double e : {0.25, 0.5, 2.0, 3.7}) {
    const std::vector<glm::vec4> c = OpacityCorrectedTable(table, e);
    ASSERT_EQ(c.size(), table.size());
    for (size_t i = 0; i < table.size(); ++i) {
      EXPECT_EQ(glm::vec3(c[i]), glm::vec3(table[i]));
      // 1 - (1 - a)^e: n samples at spacing 1 / n composite to one at
      // spacing 1, whatever a is (transparent and opaque stay so). Inverted
      // here, the float rounding of a' grows by up to ~80x near a' = 1.
      const double a = table[i].a, ac = c[i].a;
      EXPECT_NEAR(1 - std::pow(1 - ac, 1 / e), a, 1e-5) << i << " exponent " << e;
      if (a == 0) {
        EXPECT_EQ(ac, 0.0f);
      }
      if (e > 1 && a > 0 && a < 1) {
        EXPECT_GT(ac, a);
      }
      if (e < 1 && a > 0 && a < 1) {
        EXPECT_LT(ac, a);
      }
    }
  }
  // Two half-spacing samples of the corrected opacity over-composite to one
  // full-spacing sample: (1 - a_half)^2 = 1 - a.
  const std::vector<glm::vec4> half = OpacityCorrectedTable(table, 0.5);
  for (size_t i = 0; i < table.size(); ++i) {
    const double t = 1 - half[i].a;
    EXPECT_NEAR(1 - t * t, table[i].a, 1e-6);
  }
}

}  // namespace
}  // namespace core
