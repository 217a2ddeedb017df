// libFuzzer target: the QVis pair (.dat header + .raw voxels) as one input,
// the header, a NUL byte, then the raw bytes (see fuzz_reader.h).
#include <string>

#include "core/volume_io.h"
#include "fuzz/fuzz_reader.h"

namespace {

core::Volume ReadPair(std::istream& in) {
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t nul = all.find('\0');
  std::istringstream dat(all.substr(0, nul));
  std::istringstream raw(nul == std::string::npos ? std::string() : all.substr(nul + 1));
  const core::QVisHeader header = core::ReadQVisHeader(dat, "fuzz.dat");
  return core::ReadQVisRaw(raw, header, "fuzz.raw");
}

void WritePair(std::ostream& out, const core::Volume& volume) {
  core::WriteQVisHeader(out, volume, "fuzz.raw");
  out.put('\0');
  core::WriteQVisRaw(out, volume);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReader(data, size, ReadPair, WritePair);
}
