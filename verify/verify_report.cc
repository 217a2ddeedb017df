// What `ibr verify` prints, from the reports of verify/verify.h.
#include <fmt/format.h>

#include "verify/verify.h"

namespace ibr {

std::string FormatVerifyCase(const VerifyCaseResult& r, bool independent) {
  std::string s = fmt::format(
      "case {:5d}  {:7d} px  mismatched {:5d}  permitted {:5d}  real {:5d}{}  | {}{}\n", r.index,
      r.pixels, r.mismatched, r.permitted, r.real_errors,
      r.undecided > 0 ? fmt::format("  undecided {}", r.undecided) : "", r.description,
      independent
          ? fmt::format("  | independent: agree {}, band {} ({} disagree), real {}; ray: agree {}, "
                        "band {} ({} disagree), real {}",
                        r.independent.agree, r.independent.band, r.independent.band_disagree,
                        r.independent.real_errors, r.ray.agree, r.ray.band, r.ray.band_disagree,
                        r.ray.real_errors)
          : "");
  for (const std::string& diff : r.diff_images) s += fmt::format("            diff: {}\n", diff);
  return s;
}

std::string FormatVerifyReport(const VerifyReport& report, bool independent) {
  const VerifyCaseResult& t = report.total;
  std::string s = fmt::format("driver      {}\n", report.driver);
  s += fmt::format("cases       {} in {:.1f} s ({} failing)\n", report.cases, report.seconds,
                   report.failing_cases);
  s += fmt::format(
      "boundary    depth exactly on a slice: {} cases ({} tied decisions), N on the last slice: {} "
      "cases, axis ties: {} cases\n",
      report.boundary_cases[0], t.ties, report.boundary_cases[1], report.boundary_cases[2]);
  s += fmt::format(
      "pixels      {} compared, {} mismatched (stencil {}, depth/front slice {}, colour {})\n",
      t.pixels, t.mismatched, t.kinds.stencil, t.kinds.depth, t.kinds.color);
  s += fmt::format(
      "classes     permitted by the GL spec (division 2.5 ULP): {}, real errors: {}, undecided: "
      "{}\n",
      t.permitted, t.real_errors, t.undecided);
  if (!independent) return s;
  const IndependentComparison& i = t.independent;
  s += fmt::format(
      "independent slices: agree {}, tolerance band {} ({} disagree there), real errors {} "
      "(colour compared on {} pixels, {} outside its bound)\n",
      i.agree, i.band, i.band_disagree, i.real_errors, i.color_checked, i.color_errors);
  const IndependentComparison& y = t.ray;
  s += fmt::format(
      "independent ray:    {} pixels, {} object pixels, agree {} ({} of {} pixels with an "
      "alternative outcome took it), tolerance band {} ({} disagree there), real errors {} "
      "(colour compared on {} pixels, {} outside its bound; worst depth error / bound {:.3g})\n",
      y.pixels, y.covered, y.agree, y.alternative_taken, y.alternative_pixels, y.band,
      y.band_disagree, y.real_errors, y.color_checked, y.color_errors,
      y.max_depth_error_over_bound);
  return s;
}

std::string FormatHardReport(const HardReport& report) {
  std::string s =
      fmt::format("{:<14} {:>6} {:>10} {:>10} {:>9} {:>12} {:>8} {:>9}\n", "technique", "cases",
                  "pixels", "covered", "NaN/Inf", "inconsistent", "failing", "seconds");
  for (const HardTechniqueResult& t : report.techniques) {
    s += fmt::format("{:<14} {:>6} {:>10} {:>10} {:>9} {:>12} {:>8} {:>9.1f}\n", t.technique,
                     t.cases, t.pixels, t.covered, t.nonfinite, t.inconsistent, t.failing_cases,
                     t.seconds);
    for (const std::string& k : t.kinds) s += fmt::format("    {}\n", k);
  }
  s += fmt::format("hard cases: {:.1f} s\n", report.seconds);
  return s;
}

}  // namespace ibr
