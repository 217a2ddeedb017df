#include "core/volume_io.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/transfer_function.h"
#include "tests/support/gl_test.h"
#include "tests/support/nifti_bytes.h"

namespace core {
namespace {
namespace fs = std::filesystem;

Volume RandomVolume(const glm::ivec3& dims, ScalarType type, const glm::dvec3& spacing,
                    uint32_t seed) {
  Volume v = Volume::Zeros(dims, type, spacing);
  std::mt19937 rng(seed);
  if (type == ScalarType::kFloat32 || type == ScalarType::kFloat64) {
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
  // uint16 is normalised over its data range [0x00ff, 0x0201], not 0..65535.
  EXPECT_EQ(v.NormalizationRange(), glm::dvec2(0x00ff, 0x0201));
  EXPECT_DOUBLE_EQ(v.Normalized(1, 0, 0), 0.0);
  EXPECT_DOUBLE_EQ(v.Normalized(0, 0, 0), 1.0);
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
      {"NRRD0004\ntype: int64\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n", "type 'int64'"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nencoding: hex\n\n", "encoding 'hex'"},
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

// ---- every voxel type, NRRD's detached forms, NIfTI, DICOM, real files ----

const ScalarType kAllTypes[] = {ScalarType::kUint8,  ScalarType::kUint16, ScalarType::kFloat32,
                                ScalarType::kInt8,   ScalarType::kInt16,  ScalarType::kInt32,
                                ScalarType::kUint32, ScalarType::kFloat64};

fs::path RealVolumes() { return fs::path(IBR_REAL_DATA_DIR) / "volumes"; }

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string VolumeBytes(const Volume& v) { return {v.bytes.begin(), v.bytes.end()}; }

// `bytes` with every `width`-byte word reversed (the other endianness).
std::string Swapped(std::string bytes, int width) {
  for (size_t i = 0; i + width <= bytes.size(); i += width)
    std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(i),
                 bytes.begin() + static_cast<std::ptrdiff_t>(i + width));
  return bytes;
}

TEST(VolumeIo, EveryVoxelTypeRoundTripsThroughNrrdInBothByteOrders) {
  uint32_t seed = 40;
  for (ScalarType type : kAllTypes) {
    const Volume v = RandomVolume({5, 3, 4}, type, {0.5, 1.0, 2.0}, seed++);
    for (NrrdEncoding encoding : {NrrdEncoding::kRaw, NrrdEncoding::kGzip}) {
      std::stringstream s;
      WriteNrrd(s, v, encoding);
      const Volume back = ReadNrrd(s, "mem.nrrd");
      EXPECT_EQ(back, v) << ScalarTypeName(type);
    }
    // Big endian: the same values from byte-reversed words.
    std::istringstream big(
        fmt::format(
            "NRRD0004\ntype: {}\ndimension: 3\nsizes: 5 3 4\nendian: big\nencoding: raw\n\n",
            type == ScalarType::kFloat32   ? "float"
            : type == ScalarType::kFloat64 ? "double"
                                           : std::string(ScalarTypeName(type))) +
        Swapped(VolumeBytes(v), BytesPerScalar(type)));
    const Volume b = ReadNrrd(big, "big.nrrd");
    EXPECT_EQ(b.bytes, v.bytes) << ScalarTypeName(type);
    // Stored values come back as the type holds them (signed stays signed).
    EXPECT_EQ(b.Value(4, 2, 3), v.Value(4, 2, 3));
  }
  // A signed 16-bit CT value and the spec's type aliases.
  std::istringstream ct(std::string("NRRD0004\ntype: signed short int\ndimension: 3\nsizes: 2 1 1\n"
                                    "encoding: raw\nendian: little\n\n") +
                        std::string("\x00\xfc\xe8\x03", 4));  // -1024, 1000
  const Volume c = ReadNrrd(ct, "ct.nrrd");
  EXPECT_EQ(c.type, ScalarType::kInt16);
  EXPECT_EQ(c.Value(0, 0, 0), -1024);
  EXPECT_EQ(c.Value(1, 0, 0), 1000);
  // Normalised over the data range: -1024 -> 0, 1000 -> 1.
  EXPECT_EQ(c.NormalizationRange(), glm::dvec2(-1024, 1000));
  EXPECT_DOUBLE_EQ(c.ToNormalized(-12), 0.5);
}

TEST(Volume, StatsPercentilesAreTheSmallestValueWithThatShareAtOrBelow) {
  Volume v = Volume::Zeros({10, 10, 1}, ScalarType::kInt16);
  for (int i = 0; i < 100; ++i) v.SetValue(i % 10, i / 10, 0, i - 50);  // -50..49
  const VolumeStats st = ComputeVolumeStats(v);
  EXPECT_EQ(st.min, -50);
  EXPECT_EQ(st.max, 49);
  EXPECT_EQ(st.p1, -50);  // 1 of 100 at or below
  EXPECT_EQ(st.p50, -1);  // 50 of 100
  EXPECT_EQ(st.p99, 48);  // 99 of 100
  EXPECT_EQ(st.finite, 100u);
  // Floats: NaN counted apart; percentiles within (max - min) / 2^16.
  Volume f = Volume::Zeros({101, 1, 1}, ScalarType::kFloat64);
  for (int i = 0; i <= 100; ++i) f.SetValue(i, 0, 0, i * 0.5);
  f.SetValue(7, 0, 0, std::nan(""));
  const VolumeStats fs = ComputeVolumeStats(f);
  EXPECT_EQ(fs.non_finite, 1u);
  EXPECT_EQ(fs.finite, 100u);
  EXPECT_NEAR(fs.p50, 25.0, 50.0 / 65536 + 0.5);
  EXPECT_EQ(fs.max, 50.0);
  f.FitNormalization();
  EXPECT_EQ(f.NormalizationRange(), glm::dvec2(0.0, 50.0));
  EXPECT_EQ(f.Normalized(7, 0, 0), 0.0);  // NaN -> 0, never NaN on the GPU
}

TEST(Volume, LinearScaleKeepsIntegersWhereTheyFitElseFloat) {
  Volume v = Volume::Zeros({3, 1, 1}, ScalarType::kUint16);
  v.SetValue(0, 0, 0, 0);
  v.SetValue(1, 0, 0, 1024);
  v.SetValue(2, 0, 0, 4095);
  Volume hu = v;
  ApplyLinearScale(hu, 1, -1024);          // the usual CT rescale: stored 0..4095 -> HU
  EXPECT_EQ(hu.type, ScalarType::kInt16);  // the data's range -1024..3071 fits int16
  Volume wide = v;
  wide.SetValue(2, 0, 0, 65535);
  ApplyLinearScale(wide, 1, -1024);  // 65535 - 1024 does not
  EXPECT_EQ(wide.type, ScalarType::kInt32);
  EXPECT_EQ(wide.Value(2, 0, 0), 64511);
  EXPECT_EQ(hu.Value(0, 0, 0), -1024);
  EXPECT_EQ(hu.Value(2, 0, 0), 3071);
  Volume half = v;
  ApplyLinearScale(half, 0.5, 0.25);
  EXPECT_EQ(half.type, ScalarType::kFloat32);
  EXPECT_EQ(half.Value(1, 0, 0), 512.25);
  Volume same = v;
  ApplyLinearScale(same, 0, 7);  // slope 0: unset in NIfTI
  EXPECT_EQ(same, v);
}

// The ball of pynrrd's test data in seven NRRD forms (detached raw, byte
// skip -1 over the raw and over a gzipped NIfTI, attached gzip, gzip with
// line skip, gzip with byte skip -1, bzip2): each reads voxel for voxel as
// nibabel reads the NIfTI copy of it (python3-nibabel: 30^3 int16, 14328
// voxels at 257, the rest 0, sum 3682296).
TEST(VolumeIo, RealNrrdFilesOfPynrrdReadAsNibabelReadsTheirNiftiCopy) {
  const fs::path dir = RealVolumes() / "pynrrd";
  const Volume nifti = ReadVolume(dir / "BallBinary30x30x30.nii.gz");
  ASSERT_EQ(nifti.dims, glm::ivec3(30));
  ASSERT_EQ(nifti.type, ScalarType::kInt16);
  int64_t sum = 0, at257 = 0;
  for (int z = 0; z < 30; ++z)
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 30; ++x) {
        const double value = nifti.Value(x, y, z);
        sum += static_cast<int64_t>(value);
        at257 += value == 257;
      }
  EXPECT_EQ(sum, 3682296);
  EXPECT_EQ(at257, 14328);
  EXPECT_EQ(nifti.Value(15, 15, 15), 257);
  for (const char* name :
       {"BallBinary30x30x30.nhdr", "BallBinary30x30x30_byteskip_minus_one.nhdr",
        "BallBinary30x30x30_byteskip_minus_one_nifti.nhdr", "BallBinary30x30x30_gz.nrrd",
        "BallBinary30x30x30_gz_lineskip.nrrd", "BallBinary30x30x30_gz_byteskip_minus_one.nrrd",
        "BallBinary30x30x30_bz2.nrrd"}) {
    const Volume v = ReadVolume(dir / name);
    EXPECT_EQ(v, nifti) << name;
    EXPECT_EQ(v.spacing, glm::dvec3(1.0)) << name;  // space directions (1,0,0) (0,1,0) (0,0,1)
  }
}

// A real CT (TotalSegmentator's example, int16 HU, 3 mm voxels) as .nii.gz,
// against nibabel's reading of it; then the same voxels split into one
// gzip NRRD file per slice, named by a %03d pattern and by a LIST.
TEST(VolumeIo, RealCtNiftiAndItsSlicePerFileNrrdMatchNibabel) {
  const Volume ct = ReadVolume(RealVolumes() / "ct_totalseg_example_ct_sm.nii.gz");
  EXPECT_EQ(ct.type, ScalarType::kInt16);
  EXPECT_EQ(ct.dims, glm::ivec3(122, 101, 30));
  EXPECT_EQ(ct.spacing, glm::dvec3(3.0));
  // nibabel: sum -130894872, range -1100..1207, d[10,20,5] = -985,
  // d[121,100,29] = -997, percentiles (inverted CDF) 1/50/99: -1013 / -91 / 188.
  int64_t sum = 0;
  for (int z = 0; z < 30; ++z)
    for (int y = 0; y < 101; ++y)
      for (int x = 0; x < 122; ++x) sum += static_cast<int64_t>(ct.Value(x, y, z));
  EXPECT_EQ(sum, -130894872);
  EXPECT_EQ(ct.Value(0, 0, 0), -1024);
  EXPECT_EQ(ct.Value(10, 20, 5), -985);
  EXPECT_EQ(ct.Value(121, 100, 29), -997);
  const VolumeStats st = ComputeVolumeStats(ct);
  EXPECT_EQ(st.min, -1100);
  EXPECT_EQ(st.max, 1207);
  EXPECT_EQ(st.p1, -1013);
  EXPECT_EQ(st.p50, -91);
  EXPECT_EQ(st.p99, 188);
  for (const char* header : {"ct_slices_pattern.nhdr", "ct_slices_list.nhdr"}) {
    const Volume slices = ReadVolume(fs::path(IBR_GENERATED_DATA_DIR) / "volumes" / header);
    EXPECT_EQ(slices, ct) << header;
  }
}

// pyradiomics' breast MRI: int16, gzip, non-cubic voxels from its space
// directions (0.664062 x 0.664062 x 2.1 mm); values as Python's zlib and
// numpy decode them (sum 7187342, range 6..248).
TEST(VolumeIo, RealNonCubicMriKeepsItsSpacingAndExtent) {
  const Volume v = ReadVolume(RealVolumes() / "mri_pyradiomics_breast1.nrrd");
  EXPECT_EQ(v.type, ScalarType::kInt16);
  EXPECT_EQ(v.dims, glm::ivec3(45, 120, 21));
  EXPECT_NEAR(v.spacing.x, 0.664062, 1e-12);
  EXPECT_NEAR(v.spacing.y, 0.664062, 1e-12);
  EXPECT_NEAR(v.spacing.z, 2.1, 1e-12);
  // The box the renderer draws: dims * spacing, 3.2 times as deep per voxel.
  EXPECT_NEAR(v.Extent().z, 21 * 2.1, 1e-9);
  EXPECT_NEAR(v.Extent().x, 45 * 0.664062, 1e-9);
  int64_t sum = 0;
  for (int z = 0; z < 21; ++z)
    for (int y = 0; y < 120; ++y)
      for (int x = 0; x < 45; ++x) sum += static_cast<int64_t>(v.Value(x, y, z));
  EXPECT_EQ(sum, 7187342);
  EXPECT_EQ(v.Value(0, 0, 0), 86);
  EXPECT_EQ(v.Value(22, 60, 10), 61);
  EXPECT_EQ(v.Value(44, 119, 20), 49);
}

// NIfTI-1 / NIfTI-2 files of `dims` voxels (int16 unless told), scaled by
// slope/inter; NIfTI-1 with a flipped y spacing (|pixdim| is kept).
std::string Nifti1(const glm::ivec3& dims, float slope, float inter, const std::string& data,
                   int16_t datatype = 4, int16_t bitpix = 16, int16_t rank = 3) {
  test_support::NiftiFields f;
  f.dims = {dims.x, dims.y, dims.z};
  f.rank = rank;
  f.datatype = datatype;
  f.bitpix = bitpix;
  f.pixdim = {0.5, -0.75, 2.0};
  f.slope = slope;
  f.inter = inter;
  return test_support::Nifti1Bytes(f, data);
}

std::string Nifti2(const glm::ivec3& dims, double slope, double inter, const std::string& data) {
  test_support::NiftiFields f;
  f.dims = {dims.x, dims.y, dims.z};
  f.pixdim = {0.5, 0.75, 2.0};
  f.slope = slope;
  f.inter = inter;
  return test_support::Nifti2Bytes(f, data);
}

// A real CT series (TotalSegmentator's example DICOM: 20 JPEG 2000 slices,
// 12 bits stored, RescaleIntercept -1024). Geometry as dcm2niix wrote it
// into TotalSegmentator's example_seg_dicom.nii.gz (512 x 512 x 20, 0.9765625
// x 0.9765625 x 2 mm); values as Pillow's OpenJPEG decodes the codestreams
// with the slices ordered by their Image Position z and the intercept added
// (sum -3272217339, range -1024..1839).
TEST(VolumeIo, RealDicomCtSeriesInHuMatchesAnIndependentDecode) {
  const Volume v = ReadVolume(RealVolumes() / "ct_dicom_totalseg");
  EXPECT_EQ(v.dims, glm::ivec3(512, 512, 20));
  EXPECT_EQ(v.spacing, glm::dvec3(0.9765625, 0.9765625, 2.0));
  EXPECT_EQ(v.type, ScalarType::kInt16);  // 12-bit + intercept fits int16
  int64_t sum = 0;
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 512; ++y)
      for (int x = 0; x < 512; ++x) sum += static_cast<int64_t>(v.Value(x, y, z));
  EXPECT_EQ(sum, -3272217339);
  EXPECT_EQ(v.Value(256, 256, 0), 86);
  EXPECT_EQ(v.Value(300, 100, 19), -994);
  EXPECT_EQ(v.Value(50, 400, 10), 37);
  const VolumeStats st = ComputeVolumeStats(v);
  EXPECT_EQ(st.min, -1024);
  EXPECT_EQ(st.max, 1839);
  EXPECT_EQ(st.p50, -981);
  EXPECT_EQ(st.p99, 405);
  // A folder with one slice missing its pixel data's tail: refused naming it.
  const auto dir = test_support::TestOutputDir() / "dicom_cut";
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(RealVolumes() / "ct_dicom_totalseg"))
    fs::copy_file(e.path(), dir / e.path().filename(), fs::copy_options::overwrite_existing);
  const fs::path victim = dir / "CT.1.3.12.2.1107.5.1.4.60064.30000022120808113428000016580";
  const std::vector<uint8_t> bytes = FileBytes(victim);
  WriteBytes(victim, std::string(bytes.begin(), bytes.begin() + 100000));
  const std::string e = ErrorOf([&] { ReadVolume(dir); });
  EXPECT_NE(e.find("dicom_cut"), std::string::npos) << e;
}

TEST(VolumeIo, NiftiScalesToRealUnitsInEitherVersionAndByteOrder) {
  // Stored 0, 1000, 2000, 3000 (int16), scl_slope 1, scl_inter -1024: HU.
  const std::string data("\x00\x00\xe8\x03\xd0\x07\xb8\x0b", 8);
  std::istringstream one(Nifti1({4, 1, 1}, 1, -1024, data));
  const Volume v = ReadNifti(one, "ct.nii");
  EXPECT_EQ(v.type, ScalarType::kInt16);
  EXPECT_EQ(v.Value(0, 0, 0), -1024);
  EXPECT_EQ(v.Value(3, 0, 0), 1976);
  EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.75, 2));
  std::istringstream two(Nifti2({4, 1, 1}, 1, -1024, data));
  EXPECT_EQ(ReadNifti(two, "ct2.nii"), v);
  // Big endian: every header field and voxel byte-reversed.
  std::string big = Nifti1({4, 1, 1}, 1, -1024, "");
  const auto swap_at = [&](size_t offset, int width) {
    std::reverse(big.begin() + static_cast<std::ptrdiff_t>(offset),
                 big.begin() + static_cast<std::ptrdiff_t>(offset + width));
  };
  swap_at(0, 4);
  for (int i = 0; i < 8; ++i) swap_at(40 + 2 * i, 2);
  swap_at(70, 2);
  swap_at(72, 2);
  for (int i = 0; i < 8; ++i) swap_at(76 + 4 * i, 4);
  for (size_t o : {108, 112, 116}) swap_at(o, 4);
  std::istringstream big_in(big + Swapped(data, 2));
  EXPECT_EQ(ReadNifti(big_in, "big.nii"), v);
  // A fractional slope gives float32 real values.
  std::istringstream frac(Nifti1({4, 1, 1}, 0.5f, 0, data));
  const Volume f = ReadNifti(frac, "f.nii");
  EXPECT_EQ(f.type, ScalarType::kFloat32);
  EXPECT_EQ(f.Value(1, 0, 0), 500);
}

TEST(VolumeIo, BadNiftiNrrdAndDicomInputIsOneErrorNamingTheFile) {
  const auto dir = test_support::TestOutputDir();
  const std::string data("\x00\x00\xe8\x03\xd0\x07\xb8\x0b", 8);
  struct Case {
    std::string bytes, expect;
  };
  const Case nifti_cases[] = {
      {"", "too short"},
      {std::string(348, 'x'), "not a NIfTI file"},
      {Nifti1({4, 1, 1}, 1, 0, data.substr(0, 5)), "short data: 5 bytes, the header says 8"},
      {Nifti1({4, 1, 1}, 1, 0, data, /*datatype=*/128, 24), "datatype 128"},  // RGB
      {Nifti1({4, 1, 1}, 1, 0, data, 4, /*bitpix=*/8), "bitpix 8"},
      {Nifti1({0, 1, 1}, 1, 0, data), "each extent must be in"},
      {Nifti1({4, 1, 1}, 1, 0, data).substr(0, 200), "truncated NIfTI header"},
  };
  for (const Case& c : nifti_cases) {
    WriteBytes(dir / "bad.nii", c.bytes);
    const std::string e = ErrorOf([&] { ReadVolume(dir / "bad.nii"); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.expect << " -> " << e;
    EXPECT_NE(e.find("bad.nii"), std::string::npos) << e;
  }
  // 4D with 2 volumes.
  std::string four = Nifti1({4, 1, 1}, 1, 0, data + data, 4, 16, /*rank=*/4);
  const int16_t two = 2;
  std::memcpy(four.data() + 48, &two, 2);
  WriteBytes(dir / "four.nii", four);
  EXPECT_NE(ErrorOf([&] { ReadVolume(dir / "four.nii"); }).find("only 3D volumes"),
            std::string::npos);
  // Every prefix of a real .nii.gz past its gzip header is an error, never
  // a crash or a partial volume (sampled: the file is 483 kB).
  const std::vector<uint8_t> gz = FileBytes(RealVolumes() / "ct_totalseg_example_ct_sm.nii.gz");
  ASSERT_GT(gz.size(), 1000u);
  for (size_t cut = 0; cut < gz.size(); cut += gz.size() / 37 + 1) {
    std::istringstream in(std::string(gz.begin(), gz.begin() + static_cast<std::ptrdiff_t>(cut)));
    EXPECT_THROW(ReadNifti(in, "cut.nii.gz"), InputError) << cut;
  }

  // NRRD slice files: a missing slice, a short slice, too few files, a bad
  // pattern, skips past the end.
  const fs::path slices = dir / "slices";
  fs::create_directories(slices);
  for (int k = 0; k < 3; ++k) WriteBytes(slices / fmt::format("s{:02d}.raw", k), "abcd");
  const std::string head = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 3\nencoding: raw\n";
  const Case nrrd_cases[] = {
      {head + "data file: slices/s%02d.raw 0 2 1\n", ""},  // valid
      {head + "data file: slices/s%02d.raw 0 3 1\n", "4 data files"},
      {head + "data file: slices/s%02d.raw 1 3 1\n", "s03.raw': no such file"},
      {head + "data file: slices/s%s.raw 0 2 1\n", "one %d conversion"},
      {head + "data file: slices/s%02d.raw 0 2 0\n", "not a range"},
      {head + "data file: LIST\nslices/s00.raw\nslices/s01.raw\n", "2 data files"},
      {head + "data file: LIST\nslices/s00.raw\nslices/s01.raw\nslices/s09.raw\n",
       "s09.raw': no such file"},
      {head + "line skip: 3\ndata file: slices/s%02d.raw 0 2 1\n", "line skip 3 is past"},
      {head + "byte skip: 9\ndata file: slices/s%02d.raw 0 2 1\n", "byte skip 9 is past"},
      {head + "byte skip: -2\ndata file: slices/s%02d.raw 0 2 1\n", "byte skip -2"},
      {head + "data file: slices/s%02d.raw 0 2 1 3\n", "make 1 parts"},
  };
  WriteBytes(slices / "s01short.raw", "abc");
  for (const Case& c : nrrd_cases) {
    WriteBytes(dir / "bad.nhdr", c.bytes);
    if (c.expect.empty()) {
      const Volume v = ReadVolume(dir / "bad.nhdr");
      EXPECT_EQ(VolumeBytes(v), "abcdabcdabcd");
      continue;
    }
    const std::string e = ErrorOf([&] { ReadVolume(dir / "bad.nhdr"); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.bytes << " -> " << e;
  }
  WriteBytes(dir / "short.nhdr",
             head + "data file: LIST\nslices/s00.raw\nslices/s01short.raw\nslices/s02.raw\n");
  const std::string e = ErrorOf([&] { ReadVolume(dir / "short.nhdr"); });
  EXPECT_NE(e.find("s01short.raw': short data: 3 bytes, the header says 4"), std::string::npos)
      << e;
  // Every prefix of the real bzip2 file is an error; so is a flipped byte.
  const std::vector<uint8_t> bz = FileBytes(RealVolumes() / "pynrrd/BallBinary30x30x30_bz2.nrrd");
  const std::string bzs(bz.begin(), bz.end());
  const size_t data_start = bzs.find("\n\n") + 2;
  for (size_t cut = data_start; cut < bzs.size(); cut += 7) {
    std::istringstream in(bzs.substr(0, cut));
    EXPECT_THROW(ReadNrrd(in, "cut.nrrd"), InputError) << cut;
  }
  std::string flipped = bzs;
  flipped[data_start + 40] = static_cast<char>(flipped[data_start + 40] ^ 0x55);
  std::istringstream flipped_in(flipped);
  EXPECT_THROW(ReadNrrd(flipped_in, "flipped.nrrd"), InputError);
  // A detached list cannot be read from a stream.
  std::istringstream list_in(head + "data file: LIST\nslices/s00.raw\n");
  EXPECT_NE(ErrorOf([&] { ReadNrrd(list_in, "list.nhdr"); }).find("cannot be read from a stream"),
            std::string::npos);

  // DICOM: an empty folder, a folder of non-DICOM files.
  const fs::path empty = dir / "dicom_empty";
  fs::create_directories(empty);
  EXPECT_NE(ErrorOf([&] { ReadVolume(empty); }).find("no DICOM slice"), std::string::npos);
  const fs::path junk = dir / "dicom_junk";
  fs::create_directories(junk);
  WriteBytes(junk / "a.dcm", std::string(300, 'x'));
  const std::string je = ErrorOf([&] { ReadVolume(junk); });
  EXPECT_NE(je.find("dicom_junk"), std::string::npos) << je;
}

TEST(TransferFunction, DataUnitsConvertExactlyAndPresetsStayAsTheyWere) {
  // A CT-like range: stored -1024..3071 map to 0..1.
  const glm::dvec2 range(-1024, 3071);
  TransferFunction bone;
  bone.units = TransferUnits::kData;
  bone.points = {
      {-2000, {0, 0, 0, 0}}, {200, {0, 0, 0, 0}}, {400, {1, 0.9, 0.8, 0.6}}, {5000, {1, 1, 1, 1}}};
  bone.Check("test");
  const TransferFunction n = NormalizedTransfer(bone, range);
  n.Check("test");
  EXPECT_EQ(n.units, TransferUnits::kNormalized);
  for (double value = -1024; value <= 3071; value += 7.5) {
    const double s = (value - range.x) / (range.y - range.x);
    const glm::dvec4 a = bone.Evaluate(value), b = n.Evaluate(s);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(a[c], b[c], 1e-12) << value;
  }
  // Presets are normalised: unchanged, and the curated 8-bit volumes keep
  // their type range (value / 255) after reading.
  const TransferFunction tooth = TransferPreset("tooth");
  EXPECT_EQ(NormalizedTransfer(tooth, range).points.size(), tooth.points.size());
  Volume u8 = Volume::Zeros({2, 1, 1}, ScalarType::kUint8);
  u8.SetValue(0, 0, 0, 51);
  u8.SetValue(1, 0, 0, 102);
  u8.FitNormalization();
  EXPECT_DOUBLE_EQ(u8.Normalized(0, 0, 0), 51.0 / 255.0);
  // JSON with units.
  std::istringstream json(
      R"({"units": "data", "points": [[-100, 0, 0, 0, 0], [300, 1, 1, 1, 1]]})");
  EXPECT_EQ(ReadTransferFunction(json, "hu.json").units, TransferUnits::kData);
  std::istringstream bad_units(R"({"units": "hu", "points": [[0, 0, 0, 0, 0]]})");
  EXPECT_THROW(ReadTransferFunction(bad_units, "bad.json"), InputError);
  std::istringstream normalized_out(R"({"points": [[-100, 0, 0, 0, 0]]})");
  EXPECT_THROW(ReadTransferFunction(normalized_out, "out.json"), InputError);
  // An unknown preset names the valid ones.
  const std::string e = ErrorOf([] { TransferFromPresetOrFile("bone"); });
  EXPECT_NE(e.find("'bone' is neither a preset (tooth, neghip, bucky, ramp, empty)"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace core
