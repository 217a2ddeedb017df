// libFuzzer target: a NeRF transforms.json's cameras (see fuzz_reader.h).
// Every frame ParseNerfFrame accepts has a checked camera and a valid pose.
#include <nlohmann/json.hpp>

#include "capture/nerf_import.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const nlohmann::json top = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!top.is_object() || !top.contains("frames") || !top.at("frames").is_array()) return;
    for (const nlohmann::json& frame : top.at("frames")) {
      const capture::NerfFrame f = capture::ParseNerfFrame(top, frame, 64, 48, "fuzz");
      try {
        f.camera.Check("fuzz");
        f.cam_from_world.Check("fuzz", 1e-2);
      } catch (const core::InputError& e) {
        std::fprintf(stderr, "fuzz: accepted an invalid frame: %s\n", e.what());
        std::abort();
      }
    }
  });
}
