// libFuzzer target: the scene file reader (scene/scene.h). No writer: only a
// clean rejection (core::InputError naming the file and pointer) or a result.
// Referenced files are not checked (the fuzzer's paths rarely exist).
#include "fuzz/fuzz_reader.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    scene::ReadOptions options;
    options.check_files = false;
    return scene::ReadScene(in, "fuzz", options);
  });
}
