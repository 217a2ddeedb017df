// libFuzzer target: a TUM RGB-D groundtruth.txt (see fuzz_reader.h).
// Accepted poses are valid rigid transforms at increasing times, and every
// pose interpolated between them is one too.
#include "capture/tum_import.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size, [](std::istream& in) {
    const auto poses = capture::ReadTumTrajectory(in, "fuzz");
    for (size_t i = 0; i < poses.size(); ++i) {
      try {
        poses[i].cam_from_world.Check("fuzz", 1e-5);
        capture::Rigid3 mid;
        if (i > 0 && capture::InterpolateTumPose(poses, 0.5 * (poses[i - 1].time + poses[i].time),
                                                 1e300, mid)) {
          mid.Check("fuzz interpolated", 1e-5);
        }
      } catch (const core::InputError& e) {
        std::fprintf(stderr, "fuzz: accepted an invalid pose: %s\n", e.what());
        std::abort();
      }
    }
  });
}
