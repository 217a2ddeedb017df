// Fill-rate calibration: how many fragments per second this machine shades
// for a trivial textured, alpha-tested full-screen pass (the cost model of one
// slice). Benchmarks report their speed as a fraction of this figure. With
// FillRateOptions::volume_fetch, the same for one 3D lookup and blending.
#pragma once

#include "render/gl/frame_timer.h"
#include "render/gl/shader_program.h"

namespace render {

struct FillRateOptions {
  int width = 512;             // pixels of the target
  int height = 512;            // pixels
  int layers_per_frame = 64;   // full-screen passes per timed frame (overdraw)
  bool linear_filter = false;  // NEAREST models the slicing passes' default lookups
  // Instead of the 2D lookup and alpha test: one trilinear lookup of a 64^3
  // R16 texture (LINEAR always) per fragment, blended premultiplied (ONE,
  // ONE_MINUS_SRC_ALPHA): the floor of a direct-volume-rendering slice
  // fragment (ibr bench volume reports it beside the calibration).
  bool volume_fetch = false;
  FrameTimerOptions timer{2, 5};

  void Check() const;
};

struct FillRate {
  double fragments_per_second = 0;  // median frame
  double ms_per_frame = 0;          // median
  double fragments_per_frame = 0;
};

// Needs a current context.
FillRate MeasureFillRate(ProgramCache& programs, const FillRateOptions& options = {});

}  // namespace render
