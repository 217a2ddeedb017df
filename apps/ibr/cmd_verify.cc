// `ibr verify`: does this GL driver run the stencil / alpha-test intersection
// exactly? Random depth-object and visual-hull configurations against the
// bit-exact CPU mirror (and, with --independent, the double-precision
// reference); --hard: degenerate-case sweeps of every technique. Logic and
// report text in verify/verify.h.
#include <fmt/format.h>

#include "apps/ibr/commands.h"
#include "render/gl/context.h"
#include "render/gl/shader_program.h"
#include "verify/verify.h"

namespace apps {
namespace {

void RunVerifyCommand(const ibr::VerifyOptions& o, bool hard) {
  o.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  if (hard) {
    const ibr::HardReport report = ibr::RunHardSweeps(
        programs, o, [](const std::string& line) { fmt::print(stderr, "{}\n", line); });
    fmt::print("{}", ibr::FormatHardReport(report));
    if (!report.ok())
      throw CLI::RuntimeError("verify --hard: non-finite or inconsistent pixels (see the table)",
                              1);
    return;
  }
  const ibr::VerifyReport report = ibr::RunVerify(programs, o, [&](const ibr::VerifyCaseResult& r) {
    fmt::print("{}", ibr::FormatVerifyCase(r, o.independent));
  });
  fmt::print("{}", ibr::FormatVerifyReport(report, o.independent));
  if (!report.ok()) {
    const ibr::VerifyCaseResult& t = report.total;
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
