// Writes the seed corpora of the volume readers' fuzz targets: small valid
// QVis pairs (header, NUL, raw; see fuzz_qvis.cc), NRRD files (raw, gzip and
// bzip2, little and big endian, every voxel type, line and byte skips),
// detached NRRD headers over fuzz_nrrd_files.cc's data files (one file, LIST,
// %d pattern), NIfTI-1/2 files (plain, gzip, big endian, scaled), and
// transfer-function JSON files.
//   make_volume_seeds OUT_DIR
// Writes OUT_DIR/{qvis,nrrd,nrrd_files,nifti,transfer_function}/<seed>.
#include <bzlib.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/volume_io.h"
#include "tests/support/nifti_bytes.h"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc < 2) {
    std::cerr << "usage: make_volume_seeds OUT_DIR\n";
    return 2;
  }
  const fs::path root = argv[1];
  fs::create_directories(root / "qvis");
  fs::create_directories(root / "nrrd");
  int n = 0;
  for (core::ScalarType type :
       {core::ScalarType::kUint8, core::ScalarType::kUint16, core::ScalarType::kFloat32,
        core::ScalarType::kInt8, core::ScalarType::kInt16, core::ScalarType::kInt32,
        core::ScalarType::kUint32, core::ScalarType::kFloat64}) {
    core::Volume v = core::Volume::Zeros({3, 2, 4}, type, {1.0, 0.5, 2.0});
    for (int z = 0; z < 4; ++z)
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) v.SetValue(x, y, z, 7 * x + 5 * y + 3 * z);
    const std::string s = std::to_string(++n);
    // QVis holds uint8, uint16 and float32 only.
    if (type == core::ScalarType::kUint8 || type == core::ScalarType::kUint16 ||
        type == core::ScalarType::kFloat32) {
      std::ofstream out(root / "qvis" / s, std::ios::binary);
      core::WriteQVisHeader(out, v, "fuzz.raw");
      out.put('\0');
      core::WriteQVisRaw(out, v);
    }
    std::ofstream raw(root / "nrrd" / (s + "raw"), std::ios::binary);
    core::WriteNrrd(raw, v, core::NrrdEncoding::kRaw);
    std::ofstream gz(root / "nrrd" / (s + "gz"), std::ios::binary);
    core::WriteNrrd(gz, v, core::NrrdEncoding::kGzip);
  }
  std::ofstream big(root / "nrrd" / "big", std::ios::binary);
  big << "NRRD0005\n# comment\ntype: unsigned short\ndimension: 3\nsizes: 2 1 1\n"
         "space directions: (0,0.5,0) (3,4,0) (0,0,2)\nendian: big\nencoding: raw\nkey:=value\n\n";
  big.write("\x01\x02\x00\xff", 4);
  // Attached data after skips, and bzip2.
  const std::string head = "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 1\nencoding: ";
  const std::string voxels("\x00\xfc\xe8\x03\x01\x00\xff\x7f", 8);
  std::ofstream(root / "nrrd" / "lineskip", std::ios::binary)
      << head << "raw\nline skip: 2\n\nfirst line\nsecond\n"
      << voxels;
  std::ofstream(root / "nrrd" / "byteskip", std::ios::binary)
      << head << "raw\nbyte skip: 3\n\nxyz" << voxels;
  std::ofstream(root / "nrrd" / "byteskip-1", std::ios::binary)
      << head << "raw\nbyte skip: -1\n\nsome other header" << voxels;
  char bz[512];
  unsigned bz_size = sizeof bz;
  std::string bz_in = voxels;
  BZ2_bzBuffToBuffCompress(bz, &bz_size, bz_in.data(), 8, 9, 0, 0);
  std::ofstream(root / "nrrd" / "bzip2", std::ios::binary) << head << "bzip2\n\n"
                                                           << std::string(bz, bz_size);
  {
    core::Volume v = core::Volume::Zeros({2, 2, 1}, core::ScalarType::kInt16);
    std::memcpy(v.bytes.data(), voxels.data(), 8);
    std::ostringstream gz;
    core::WriteNrrd(gz, v, core::NrrdEncoding::kGzip);
    const std::string g = gz.str();
    std::ofstream(root / "nrrd" / "gz-byteskip-1", std::ios::binary)
        << head << "gzip\nbyte skip: -1\n\n"
        << g.substr(g.find("\n\n") + 2);
  }

  // Detached headers over fuzz_nrrd_files.cc's data files (8 bytes each:
  // d0..d3 raw, g0..g3 gzip, b0..b3 bzip2).
  fs::create_directories(root / "nrrd_files");
  const std::string files_head = "NRRD0004\ntype: uint8\ndimension: 3\n";
  const std::pair<const char*, std::string> detached[] = {
      {"one", files_head + "sizes: 2 4 1\nencoding: raw\ndata file: d0\n"},
      {"pattern", files_head + "sizes: 8 1 4\nencoding: raw\ndata file: d%d 0 3 1\n"},
      {"pattern-gz", files_head + "sizes: 8 1 2\nencoding: gzip\ndata file: g%01d 1 2 1 2\n"},
      {"pattern-down", files_head + "sizes: 8 1 4\nencoding: bzip2\ndata file: b%d 3 0 -1\n"},
      {"list", files_head + "sizes: 4 1 2\nencoding: raw\nbyte skip: 4\ndata file: LIST\nd1\nd2\n"},
      {"list-skip",
       files_head + "sizes: 1 1 2\nencoding: raw\nline skip: 1\ndata file: LIST 2\nd0\nd3\n"},
      {"skip-1", files_head + "sizes: 2 1 1\nencoding: gzip\nbyte skip: -1\ndata file: g2\n"},
  };
  for (const auto& [name, text] : detached)
    std::ofstream(root / "nrrd_files" / name, std::ios::binary) << text;

  // NIfTI: NIfTI-1 (348-byte header at nifti1.h offsets) and NIfTI-2 (540).
  fs::create_directories(root / "nifti");
  const auto nifti1 = [&](bool big_endian, float slope) {
    test_support::NiftiFields f;
    f.dims = {2, 2, 1};
    f.pixdim = {1.0, 1.0, 2.5};
    f.slope = slope;
    f.inter = -1024.0;
    f.big_endian = big_endian;
    return test_support::Nifti1Bytes(f, voxels);
  };
  std::ofstream(root / "nifti" / "n1", std::ios::binary) << nifti1(false, 1.0f);
  std::ofstream(root / "nifti" / "n1-big", std::ios::binary) << nifti1(true, 1.0f);
  std::ofstream(root / "nifti" / "n1-frac", std::ios::binary) << nifti1(false, 0.5f);
  {
    const std::string plain = nifti1(false, 1.0f);
    std::vector<unsigned char> gz(compressBound(static_cast<uLong>(plain.size())) + 64);
    z_stream z{};
    deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(plain.data()));
    z.avail_in = static_cast<uInt>(plain.size());
    z.next_out = gz.data();
    z.avail_out = static_cast<uInt>(gz.size());
    deflate(&z, Z_FINISH);
    std::ofstream(root / "nifti" / "n1-gz", std::ios::binary)
        .write(reinterpret_cast<const char*>(gz.data()), static_cast<std::streamsize>(z.total_out));
    deflateEnd(&z);
  }
  {
    test_support::NiftiFields f;
    f.dims = {2, 2, 1};
    f.inter = -1024.0;
    std::ofstream(root / "nifti" / "n2", std::ios::binary) << test_support::Nifti2Bytes(f, voxels);
  }
  fs::create_directories(root / "transfer_function");
  const char* transfer[] = {
      R"({"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 1]]})",
      R"({"points": [[0.2, 1, 0.5, 0, 0.1], [0.5, 0, 1, 0, 0.5], [0.9, 1, 1, 1, 0.9]]})",
      R"({"points": [[0.5, 0.1, 0.2, 0.3, 0.4]]})", R"({"points": [[0, "nan", 0, 0, 0]]})"};
  for (int i = 0; i < 4; ++i)
    std::ofstream(root / "transfer_function" / std::to_string(i), std::ios::binary) << transfer[i];
  std::cout << "make_volume_seeds: corpora in " << root.string() << "\n";
  return 0;
}
