// libFuzzer target: Redwood's camera_primesense.json reader
// (capture::ReadRedwoodIntrinsics). No writer: a clean rejection
// (core::InputError naming the file) or a camera that passes its own check.
#include <cstdio>
#include <cstdlib>

#include "capture/importers.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const capture::Camera camera = capture::ReadRedwoodIntrinsics(in, "fuzz");
    try {
      camera.Check("fuzz");
    } catch (const core::InputError& e) {
      std::fprintf(stderr, "fuzz: accepted an invalid camera: %s\n", e.what());
      std::abort();
    }
    return camera;
  });
}
