#include "render/gl/frame_timer.h"

#include <vector>

#include "core/error.h"
#include "render/gl/gl.h"

namespace render {

void FrameTimerOptions::Check() const {
  if (warmup_frames < 0 || warmup_frames > 1000 || timed_frames < 1 || timed_frames > 100000) {
    core::ThrowInputError("FrameTimerOptions", "warmup {} / timed {} frames out of range",
                          warmup_frames, timed_frames);
  }
}

core::TimingStats TimeFrames(const std::function<void()>& frame, const FrameTimerOptions& options) {
  options.Check();
  for (int i = 0; i < options.warmup_frames; ++i) {
    frame();
    glFinish();
  }
  std::vector<double> samples;
  samples.reserve(static_cast<size_t>(options.timed_frames));
  for (int i = 0; i < options.timed_frames; ++i) {
    glFinish();
    core::Stopwatch watch;
    frame();
    glFinish();
    samples.push_back(watch.ElapsedMs());
  }
  return core::Summarize(std::move(samples));
}

}  // namespace render
