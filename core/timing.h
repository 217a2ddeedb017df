// Wall-clock timing statistics shared by benchmarks and the GL frame timer.
#pragma once

#include <chrono>
#include <vector>

namespace core {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void Restart() { start_ = std::chrono::steady_clock::now(); }
  double ElapsedMs() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// CPU time of the whole process (every thread: llvmpipe's rasteriser threads
// run inside it), in milliseconds: the work a frame did, which other
// processes' load on the machine changes far less than the wall clock.
class CpuStopwatch {
 public:
  CpuStopwatch() : start_ms_(NowMs()) {}
  void Restart() { start_ms_ = NowMs(); }
  double ElapsedMs() const { return NowMs() - start_ms_; }
  static double NowMs();

 private:
  double start_ms_;
};

// Summary of repeated measurements (milliseconds).
struct TimingStats {
  double median_ms = 0;
  double min_ms = 0;
  double max_ms = 0;
  double mean_ms = 0;
  int samples = 0;
};

// Median/min/max/mean of `samples_ms` (empty input gives all zeros).
TimingStats Summarize(std::vector<double> samples_ms);

}  // namespace core
