// Writes the seed corpora of the volume readers' fuzz targets: small valid
// QVis pairs (header, NUL, raw; see fuzz_qvis.cc) and NRRD files (raw and
// gzip, little and big endian, every voxel type), made by our own writers,
// and transfer-function JSON files.
//   make_volume_seeds OUT_DIR
// Writes OUT_DIR/qvis/<seed>, OUT_DIR/nrrd/<seed> and OUT_DIR/transfer_function/<seed>.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "core/volume_io.h"

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
       {core::ScalarType::kUint8, core::ScalarType::kUint16, core::ScalarType::kFloat32}) {
    core::Volume v = core::Volume::Zeros({3, 2, 4}, type, {1.0, 0.5, 2.0});
    for (int z = 0; z < 4; ++z)
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) v.SetValue(x, y, z, 7 * x + 5 * y + 3 * z);
    const std::string s = std::to_string(++n);
    {
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
