// libFuzzer target: COLMAP points3D.bin (see fuzz_reader.h).
#include "capture/colmap_io.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReader(
      data, size, [](std::istream& in) { return capture::colmap::ReadPoints3DBinary(in, "fuzz"); },
      [](std::ostream& out, const auto& value) {
        capture::colmap::WritePoints3DBinary(out, value);
      });
}
