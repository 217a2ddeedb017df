// `ibr verify`: stencil-correctness testing of a GL implementation with the
// depth-object / visual-hull algorithm (Kautz-Seidel 2001, sec. 4.1, stencil
// steps 2(a)-(f)) as the probe.
//
// Verification: random configurations (rigs, sizes, methods, slicings,
// robust k, outside/invalid policies, orthographic and perspective views,
// constructed boundary cases) are drawn on the current driver
// (DepthObjectRenderer::DrawSlices, the exact stencil path) and every
// pixel's stencil count, front slice (first-surface depth) and accumulated
// colour is compared with the bit-exact CPU mirror (verify/reference.h).
// Each mismatching pixel is classified:
//  - permitted: the GL spec allows it. GLSL gives division 2.5 ULP, not
//    correct rounding (GLSL 4.50, sec. 4.7.1); with `precise` every other
//    operation of the decision path is correctly rounded and unfused. The
//    pixel is replayed with every admissible quotient at each division of
//    each fragment (view point, map u, map v: all floats within 2.5 ULP of the
//    exact quotient) and the GPU's stencil, colour and depth are reachable;
//  - real error: no admissible choice of quotients reproduces the GPU.
// With `independent`, the double-precision reference
// (verify/independent_reference.h) is compared as well (agreement outside its
// tolerance band; disagreements outside it are real errors): the slice
// frame's stencil, front slice, depth and accumulated colour (its own
// view-dependent weights), and the same case drawn by the one-pass ray path
// (DrawRay) against the reference's march (coverage, hit depth, colour).
//
// Hard-case sweeps (RunHardSweeps): random degenerate configurations per
// technique (depth objects, hulls, slicing displacement, NCS / relief / POM)
// rendered in full; every output pixel must be finite and the outcome flags
// consistent with the coverage.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "verify/independent_reference.h"
#include "render/gl/shader_program.h"

namespace ibr {

struct VerifyOptions {
  int cases = 100;    // random configurations (hard: per technique)
  uint32_t seed = 1;  // deterministic: the same seed gives the same cases
  // Index of the first case run: case i of a seed is the same whatever ran
  // before it, so --first-case i --cases 1 reruns a failing case alone.
  int first_case = 0;
  // "depth-object", "hull" or "all"; hard sweeps also take one technique:
  // "displacement", "ncs", "relief", "pom", "crm".
  std::string method = "all";
  bool hard = false;         // RunHardSweeps sets it (widens `method`)
  bool independent = false;  // also compare with the independent reference
  // Where diff images of failing cases go (created; empty = none written).
  std::filesystem::path out;
  // Test-only hooks: 1 = the bit-exact mirror evaluates slice s at slice
  // s + 1's plane (an off-by-one), which must surface as real errors;
  // 2 = the GPU's depth is replaced by what a driver whose division returns
  // the largest admissible quotient (~2 ULP high, allowed by GLSL) would
  // write, which must be classified as permitted.
  int inject_fault = 0;
  void Check() const;
};

// Mismatching pixels by kind (a pixel can count in several kinds).
struct MismatchKinds {
  int64_t stencil = 0;  // stencil byte differs
  int64_t depth = 0;    // first-surface depth / front slice differs (bits)
  int64_t color = 0;    // accumulated colour differs (bits)
};

struct VerifyCaseResult {
  int index = 0;
  std::string description;  // rig, sizes, method, slicing, k, policies, view, boundary kind
  int64_t pixels = 0;       // pixels compared
  int64_t mismatched = 0;   // pixels differing from the mirror in any bit
  int64_t permitted = 0;    // ... reachable under the spec's division tolerance
  int64_t real_errors = 0;  // ... not reachable
  int64_t undecided = 0;    // ... search too large to decide (counted, not failed)
  MismatchKinds kinds;
  int64_t ties = 0;  // decisions with camera z == map depth exactly (mirror)
  int64_t finished_on_last_slice = 0;
  // Independent reference (when asked): the slice path (stencil, front
  // slice, depth, colour) and the ray path (DrawRay with the case's options
  // and Slicing::kRay: coverage, hit depth, colour), which the bit-exact
  // mirror does not cover.
  // Counts only (the diff images are left empty).
  IndependentComparison independent, ray;
  std::vector<std::string> diff_images;  // written for a failing case (slices and/or ray)
};

struct VerifyReport {
  std::string driver;  // GL_RENDERER / GL_VERSION
  int cases = 0;
  double seconds = 0;
  VerifyCaseResult total;             // sums (index, description unused)
  int failing_cases = 0;              // cases with real errors
  int boundary_cases[3] = {0, 0, 0};  // depth on a slice, N on the last slice, axis tie
  bool ok() const {
    return total.real_errors == 0 && total.independent.real_errors == 0 &&
           total.ray.real_errors == 0;
  }
};

// Needs a current context. `on_case` is called after every case (progress).
VerifyReport RunVerify(render::ProgramCache& programs, const VerifyOptions& options,
                       const std::function<void(const VerifyCaseResult&)>& on_case = {});

// ---- hard cases ----
struct HardTechniqueResult {
  std::string technique;  // "depth-object", "hull", "displacement", "ncs", "relief", "pom",
                          // "crm"
  int cases = 0;
  int64_t pixels = 0;        // output pixels checked
  int64_t covered = 0;       // pixels drawn
  int64_t nonfinite = 0;     // NaN/Inf in any output channel
  int64_t inconsistent = 0;  // outcome flags / coverage / depth disagreeing
  int failing_cases = 0;
  double seconds = 0;              // wall clock of this technique's sweep
  std::vector<std::string> kinds;  // the degenerate kinds the sweep drew, with counts
};
struct HardReport {
  double seconds = 0;
  std::vector<HardTechniqueResult> techniques;
  bool ok() const;
};
HardReport RunHardSweeps(render::ProgramCache& programs, VerifyOptions options,
                         const std::function<void(const std::string&)>& progress = {});

// ---- what `ibr verify` prints (verify/verify_report.cc) ----
// One case's line (and its diff image lines), newline-terminated.
std::string FormatVerifyCase(const VerifyCaseResult& r, bool independent);
// The summary after every case (driver, cases, boundary cases, pixels,
// classes, and with `independent` the two independent comparisons),
// newline-terminated; the verdict is report.ok().
std::string FormatVerifyReport(const VerifyReport& report, bool independent);
// The hard sweeps' table, one row per technique with its kinds, and the time.
std::string FormatHardReport(const HardReport& report);

}  // namespace ibr
