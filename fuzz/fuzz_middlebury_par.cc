// libFuzzer target: Middlebury *_par.txt (see fuzz_reader.h). Accepted views
// must have valid rotations (snapped to orthonormal) and finite cameras.
#include "capture/importers.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    for (const capture::MiddleburyView& view : capture::ReadMiddleburyPar(in, "fuzz")) {
      try {
        view.cam_from_world.Check("fuzz");  // the default 1e-6: after snapping
      } catch (const core::InputError& e) {
        std::fprintf(stderr, "fuzz: accepted an invalid pose: %s\n", e.what());
        std::abort();
      }
    }
  });
}
