// Honest GPU timing: wall clock around the work plus glFinish (GL_TIME_ELAPSED
// is broken on llvmpipe, shared/HEADLESS-GL.md), after warm-up frames that
// absorb shader compilation, reported as the median of N frames.
#pragma once

#include <functional>

#include "core/timing.h"

namespace render {

struct FrameTimerOptions {
  int warmup_frames = 2;  // the first frame includes LLVM shader compilation
  int timed_frames = 7;   // median of these; odd so the median is a sample

  void Check() const;
};

// Runs `frame` warmup + timed times, each followed by glFinish.
core::TimingStats TimeFrames(const std::function<void()>& frame,
                             const FrameTimerOptions& options = {});

}  // namespace render
