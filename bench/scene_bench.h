// `ibr bench scene`: what an effect costs a scene when it is on, when it is
// named but disabled ("enabled": false) and when it is absent, measured in
// one run (interleaved rounds; ratios are medians of per-round ratios). A scene renderer builds
// only the passes its enabled objects name, so disabled and absent should cost the same; the ratios
// to "absent" are printed, written as CSV and plotted.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/report.h"

namespace bench {

struct SceneBenchOptions {
  int size = 384;    // frame width = height, pixels
  int rounds = 96;   // interleaved rounds (absent, disabled, absent again; order rotated)
  int on_every = 8;  // the effect on joins every on_every-th round (its ratio is not the question)
  int frames = 2;    // timed frames per configuration per round (the round's figure: their median)
  bool quick = false;  // two effects, small frames: a CI smoke run
  void Check() const;
};

struct SceneBenchResult {
  // effect, on_ms, disabled_ms, absent_ms (medians over every frame),
  // on_over_absent, disabled_over_absent, absent_again_over_absent (medians
  // of per-round ratios; the last, a second scene without the effect, is
  // the noise floor), the same three of the process's CPU time per frame
  // (`_cpu`); `_lo` / `_hi` the distribution-free 95 % interval of the
  // disabled and absent-again medians (core::MedianConfidenceInterval; NaN
  // under 6 rounds) and its coverage; programs_on, programs_disabled,
  // programs_absent (compiled by that scene); samples_* and primitives_*,
  // the GL work of one frame (GL_SAMPLES_PASSED, GL_PRIMITIVES_GENERATED)
  Table table;
};

// Needs a current context. Each configuration compiles into its own program
// cache (its count is a column).
SceneBenchResult RunSceneBench(const SceneBenchOptions& options);
// CSV + ratio plots into `out_dir`: scene_bench.png (the effect on),
// scene_bench_disabled.png (disabled, its interval, the noise floor, the 2 % limit).
void WriteSceneBench(const SceneBenchResult& result, const std::filesystem::path& csv,
                     const std::filesystem::path& out_dir);

}  // namespace bench
