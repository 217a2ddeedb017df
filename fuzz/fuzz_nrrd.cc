// libFuzzer target: NRRD volumes, attached raw or gzip data (see fuzz_reader.h).
#include "core/volume_io.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReader(
      data, size, [](std::istream& in) { return core::ReadNrrd(in, "fuzz"); },
      // Gzip when the input was gzip-encoded would need the encoding kept;
      // raw output is the canonical form the round trip compares.
      [](std::ostream& out, const core::Volume& value) {
        core::WriteNrrd(out, value, core::NrrdEncoding::kRaw);
      });
}
