// libFuzzer target: a TUM RGB-D rgb.txt / depth.txt list (see fuzz_reader.h).
// Accepted entries have finite timestamps and a file name; association of a
// list with itself pairs every entry (distinct times) or fewer, never more.
#include <cmath>

#include "capture/tum_import.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const auto list = capture::ReadTumList(in, "fuzz");
    for (const auto& e : list) {
      if (!std::isfinite(e.time) || e.file.empty()) {
        std::fprintf(stderr, "fuzz: accepted a bad entry\n");
        std::abort();
      }
    }
    if (capture::AssociateTum(list, list, 0.02).size() > list.size()) {
      std::fprintf(stderr, "fuzz: more pairs than entries\n");
      std::abort();
    }
  });
}
