// `ibr verify`: does this GL driver run the stencil / alpha-test intersection
// exactly? Random depth-object and visual-hull configurations against the
// bit-exact CPU mirror (and, with --independent, the double-precision
// reference); --hard: degenerate-case sweeps of every technique. Logic in
// ibr/verify.h.
#include <fmt/format.h>

#include "apps/ibr/commands.h"
#include "ibr/verify.h"
#include "render/gl/context.h"
#include "render/gl/shader_program.h"

namespace apps {
namespace {

void PrintCase(const ibr::VerifyCaseResult& r, bool independent) {
  fmt::print(
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
  for (const std::string& diff : r.diff_images) fmt::print("            diff: {}\n", diff);
}

void RunVerifyCommand(const ibr::VerifyOptions& o, bool hard) {
  o.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  if (hard) {
    const ibr::HardReport report = ibr::RunHardSweeps(
        programs, o, [](const std::string& line) { fmt::print(stderr, "{}\n", line); });
    fmt::print("{:<14} {:>6} {:>10} {:>10} {:>9} {:>12} {:>8} {:>9}\n", "technique", "cases",
               "pixels", "covered", "NaN/Inf", "inconsistent", "failing", "seconds");
    for (const ibr::HardTechniqueResult& t : report.techniques) {
      fmt::print("{:<14} {:>6} {:>10} {:>10} {:>9} {:>12} {:>8} {:>9.1f}\n", t.technique, t.cases,
                 t.pixels, t.covered, t.nonfinite, t.inconsistent, t.failing_cases, t.seconds);
      for (const std::string& k : t.kinds) fmt::print("    {}\n", k);
    }
    fmt::print("hard cases: {:.1f} s\n", report.seconds);
    if (!report.ok())
      throw CLI::RuntimeError("verify --hard: non-finite or inconsistent pixels (see the table)",
                              1);
    return;
  }
  const ibr::VerifyReport report = ibr::RunVerify(
      programs, o, [&](const ibr::VerifyCaseResult& r) { PrintCase(r, o.independent); });
  const ibr::VerifyCaseResult& t = report.total;
  fmt::print("driver      {}\n", report.driver);
  fmt::print("cases       {} in {:.1f} s ({} failing)\n", report.cases, report.seconds,
             report.failing_cases);
  fmt::print(
      "boundary    depth exactly on a slice: {} cases ({} tied decisions), N on the last slice: {} "
      "cases, "
      "axis ties: {} cases\n",
      report.boundary_cases[0], t.ties, report.boundary_cases[1], report.boundary_cases[2]);
  fmt::print(
      "pixels      {} compared, {} mismatched (stencil {}, depth/front slice {}, colour {})\n",
      t.pixels, t.mismatched, t.kinds.stencil, t.kinds.depth, t.kinds.color);
  fmt::print(
      "classes     permitted by the GL spec (division 2.5 ULP): {}, real errors: {}, undecided: "
      "{}\n",
      t.permitted, t.real_errors, t.undecided);
  if (o.independent) {
    const ibr::IndependentComparison& i = t.independent;
    fmt::print(
        "independent slices: agree {}, tolerance band {} ({} disagree there), real errors {} "
        "(colour compared on {} pixels, {} outside its bound)\n",
        i.agree, i.band, i.band_disagree, i.real_errors, i.color_checked, i.color_errors);
    const ibr::IndependentComparison& y = t.ray;
    fmt::print(
        "independent ray:    {} pixels, {} object pixels, agree {} ({} of {} pixels with an "
        "alternative outcome took it), tolerance band {} ({} disagree there), real errors {} "
        "(colour compared on {} pixels, {} outside its bound; worst depth error / bound {:.3g})\n",
        y.pixels, y.covered, y.agree, y.alternative_taken, y.alternative_pixels, y.band,
        y.band_disagree, y.real_errors, y.color_checked, y.color_errors,
        y.max_depth_error_over_bound);
  }
  if (!report.ok()) {
    throw CLI::RuntimeError(
        fmt::format("verify: {} real errors in {} cases",
                    t.real_errors + t.independent.real_errors + t.ray.real_errors,
                    report.failing_cases),
        1);
  }
  fmt::print("result      OK: no real errors\n");
}

void AddVerifyCommand(CLI::App& app) {
  static ibr::VerifyOptions o;
  static bool hard = false;
  static int cases = -1;
  auto* cmd = app.add_subcommand("verify",
                                 "Check this GL driver's stencil/alpha-test intersection against "
                                 "CPU references (exit 0 = no real error)");
  cmd->add_option("--cases", cases,
                  "random configurations (default 200; --hard: 1000 per technique)");
  cmd->add_option("--seed", o.seed, "random seed (same seed, same cases)")->capture_default_str();
  cmd->add_option("--first-case", o.first_case,
                  "index of the first case (cases are numbered per seed: --first-case I --cases 1 "
                  "reruns case I alone)")
      ->capture_default_str();
  cmd->add_option(
         "--method", o.method,
         "depth-object | hull | all (--hard also: displacement | ncs | relief | pom | crm)")
      ->capture_default_str();
  cmd->add_flag("--independent", o.independent,
                "also compare with the independent double-precision reference");
  cmd->add_flag("--hard", hard,
                "degenerate-case sweeps of every technique instead (NaN/Inf, outcome flags)");
  cmd->add_option("--out", o.out, "directory for diff images of failing cases");
  cmd->callback([] {
    o.cases = cases > 0 ? cases : hard ? 1000 : 200;
    o.hard = hard;
    if (cases == 0 || cases < -1) o.cases = cases;  // rejected by Check()
    RunVerifyCommand(o, hard);
  });
}

}  // namespace

IBR_REGISTER_COMMAND("verify", AddVerifyCommand);

}  // namespace apps
