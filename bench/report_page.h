// `ibr report`: every bench in one run, written as one page (report.md, and
// report.html with its images embedded) that shows what accuracy costs in
// time for every technique, beside the papers and the peers: the machine;
// per technique family an error-vs-time plot (bench/tradeoff.h) or the
// bench's cost plot where it measures no error; the papers' figures beside
// ours (bench/paper_tables.h); the hard views beside their truth with error
// heat maps (bench/gallery.h); the Pareto front of each family.
//
// The folder is staged and renamed into place (core::StagedDirectory): it
// must be new, empty, or an earlier ibr output; nothing is left half-written.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace bench {

struct ReportOptions {
  std::filesystem::path out;  // required: the report folder
  bool quick = false;         // every bench's small sweep (the smoke test; minutes)
  void Check() const;
};

struct ReportStep {
  std::string name;  // "displacement", "ncs", ...
  double seconds = 0;
};

struct ReportResult {
  std::vector<ReportStep> steps;
  double seconds = 0;
};

// Runs every step (progress on stderr) and writes the folder. Needs no
// current context (each step makes its own).
ReportResult WriteReport(const ReportOptions& options);

// The progress estimate: seconds left before step `index` (0-based) of
// `names` starts, given the durations of the steps done (`done`, in order)
// and those a previous run of the same mode recorded (`previous`, by name).
// Uses the previous run when it has every remaining step, else the mean of
// the steps done times the steps left; NaN with neither.
double EstimateSecondsLeft(const std::vector<std::string>& names, size_t index,
                           const std::vector<double>& done,
                           const std::map<std::string, double>& previous);

// The per-step durations recorded in `file` (report_timings.csv: step, mode,
// seconds) for `mode` ("quick" or "full"); empty if absent or unreadable.
std::map<std::string, double> ReadStepTimings(const std::filesystem::path& file,
                                              const std::string& mode);

}  // namespace bench
