// libFuzzer target: a detached NRRD header read from a file beside fixed data
// files (d0..d3 raw, g0..g3 gzip, b0..b3 bzip2, 8 bytes each decoded), so the
// paths that open data files run: one file, "data file: LIST" and the %d
// pattern, with line and byte skips per file. The header is the input.
#include <bzlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/volume_io.h"
#include "fuzz/fuzz_reader.h"

namespace {

namespace fs = std::filesystem;

// The data files, written once per process (the fuzzer's seed corpus has
// the matching compressed bytes: fuzz/make_volume_seeds.cc writes both).
fs::path DataDir() {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / ("ibr_fuzz_nrrd_files_" + std::to_string(getpid()));
    fs::create_directories(d);
    for (int i = 0; i < 4; ++i) {
      const std::string raw = "abcdefg\n" + std::string(1, static_cast<char>('0' + i));
      std::ofstream(d / ("d" + std::to_string(i)), std::ios::binary) << raw.substr(0, 8);
      // Compressed copies: NRRD gzip / bzip2 streams of the same 8 bytes.
      core::Volume v = core::Volume::Zeros({8, 1, 1}, core::ScalarType::kUint8);
      for (int k = 0; k < 8; ++k) v.SetValue(k, 0, 0, static_cast<uint8_t>(raw[k]));
      std::ostringstream gz;
      core::WriteNrrd(gz, v, core::NrrdEncoding::kGzip);
      const std::string g = gz.str();
      std::ofstream(d / ("g" + std::to_string(i)), std::ios::binary)
          << g.substr(g.find("\n\n") + 2);
      char bz[256];
      unsigned bz_size = sizeof bz;
      std::string in = raw.substr(0, 8);
      BZ2_bzBuffToBuffCompress(bz, &bz_size, in.data(), 8, 9, 0, 0);
      std::ofstream(d / ("b" + std::to_string(i)), std::ios::binary).write(bz, bz_size);
    }
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path header = DataDir() / "h.nhdr";
  std::ofstream(header, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    core::ReadNrrd(header);
  } catch (const core::InputError&) {
  }
  return 0;
}
