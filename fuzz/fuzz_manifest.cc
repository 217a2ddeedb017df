// libFuzzer target: the dataset.json manifest (see fuzz_reader.h).
#include "capture/dataset.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReader(
      data, size, [](std::istream& in) { return capture::ReadManifest(in, "fuzz"); },
      [](std::ostream& out, const auto& value) { capture::WriteManifest(out, value); });
}
