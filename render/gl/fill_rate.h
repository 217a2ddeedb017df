// Fill-rate calibration: how many fragments per second this machine shades
// for a trivial textured, alpha-tested full-screen pass (the cost model of one
// slice). Benchmarks report their speed as a fraction of this figure. With
// FillRateOptions::work, the same for the floors of (displaced) volume rendering.
#pragma once

#include "render/gl/frame_timer.h"
#include "render/gl/shader_program.h"

namespace render {

struct FillRateOptions {
  int width = 512;             // pixels of the target
  int height = 512;            // pixels
  int layers_per_frame = 64;   // full-screen passes per timed frame (overdraw)
  bool linear_filter = false;  // NEAREST models the slicing passes' default lookups
  // What each fragment does: the calibration's 2D lookup and alpha test, or
  // the floors of direct volume rendering (ibr bench volume reports them
  // beside the calibration): one trilinear lookup of a 64^3 R16 volume
  // (LINEAR always) classified by a 256-entry RGBA32F transfer function,
  // blended premultiplied (ONE, ONE_MINUS_SRC_ALPHA); with
  // kDisplacedVolumeBlend, a trilinear lookup of a 32^3 RGBA32F map first,
  // the volume read where it points (two dependent 3D lookups).
  enum class Work { kTexture2DAlphaTest, kVolumeBlend, kDisplacedVolumeBlend };
  Work work = Work::kTexture2DAlphaTest;
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
