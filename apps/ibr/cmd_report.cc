// `ibr report --out DIR [--quick]`: every bench in one run, written as one
// page (report.md, report.html with its images embedded) of what accuracy
// costs in time per technique, beside the papers and the peers
// (bench/report_page.h).
#include <fmt/format.h>

#include "apps/ibr/commands.h"
#include "bench/report_page.h"
#include "bench/report_summary.h"

namespace apps {
namespace {

void AddReportCommand(CLI::App& app) {
  static bench::ReportOptions options;
  auto* cmd = app.add_subcommand(
      "report",
      "Run every bench and write one page (report.md, report.html): error vs time per "
      "technique with the Pareto front, the papers' figures beside ours, a gallery of hard views");
  cmd->add_option("--out", options.out, "the report folder (new, empty or an earlier ibr output)")
      ->required();
  cmd->add_flag("--quick", options.quick, "every bench's small sweep (a smoke test, minutes)");
  static bool summary_only = false;
  cmd->add_flag("--summary-only", summary_only,
                "run no bench: rewrite DIR/summary.md (the headline results) from the CSVs an "
                "earlier report run left in DIR");
  cmd->callback([] {
    if (summary_only) {
      bench::WriteSummary(options.out);
      fmt::print("report: wrote {}\n", (options.out / "summary.md").string());
      return;
    }
    const bench::ReportResult result = bench::WriteReport(options);
    fmt::print("report: {} steps in {:.0f} s; wrote {} and report.html\n", result.steps.size(),
               result.seconds, (options.out / "report.md").string());
  });
}

}  // namespace

IBR_REGISTER_COMMAND("report", AddReportCommand);

}  // namespace apps
