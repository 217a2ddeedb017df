// libFuzzer target: the transfer-function JSON reader (core/transfer_function.h,
// `ibr volume --transfer FILE`). No writer: a clean rejection
// (core::InputError naming the file) or a function whose every table entry is
// finite and in [0, 1].
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/transfer_function.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const core::TransferFunction tf = core::ReadTransferFunction(in, "fuzz");
    for (const glm::vec4& rgba : tf.Table(16)) {
      for (int c = 0; c < 4; ++c) {
        if (!std::isfinite(rgba[c]) || rgba[c] < 0 || rgba[c] > 1) {
          std::fprintf(stderr, "fuzz: accepted a transfer function with table value %g\n",
                       static_cast<double>(rgba[c]));
          std::abort();
        }
      }
    }
    return tf;
  });
}
