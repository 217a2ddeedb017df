// libFuzzer target: Redwood trajectory .log (see fuzz_reader.h). Accepted
// poses must be valid rigid transforms.
#include "capture/importers.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    for (const capture::Rigid3& pose : capture::ReadRedwoodLog(in, "fuzz")) {
      try {
        pose.Check("fuzz", 1e-5);
      } catch (const core::InputError& e) {
        std::fprintf(stderr, "fuzz: accepted an invalid pose: %s\n", e.what());
        std::abort();
      }
    }
  });
}
