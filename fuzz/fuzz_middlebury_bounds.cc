// libFuzzer target: the bounding box of a Middlebury README.txt
// (capture::ReadMiddleburyBounds). No writer: a clean rejection
// (core::InputError naming the file), no box, or a box that passes
// capture::CheckBounds.
#include <cstdio>
#include <cstdlib>

#include "capture/importers.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const std::optional<capture::Bounds> bounds = capture::ReadMiddleburyBounds(in, "fuzz");
    if (bounds) {
      try {
        capture::CheckBounds(*bounds, "fuzz");
      } catch (const core::InputError& e) {
        std::fprintf(stderr, "fuzz: accepted invalid bounds: %s\n", e.what());
        std::abort();
      }
    }
    return bounds;
  });
}
