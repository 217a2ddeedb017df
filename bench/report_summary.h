// The report's headline results: at most ten rows, each one figure a user
// asks first (how accurate is the default path, what does it cost beside the
// peer, what does a cut or a displaced volume cost), computed from the CSVs a
// report run wrote, and written as DIR/summary.md. README.md links it, so the
// prose never carries a figure of its own.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "bench/report.h"

namespace bench {

// An RFC 4180 CSV as Table::WriteCsv writes it (quoted cells, doubled
// quotes). InputError naming the file on a ragged or unterminated row.
Table ReadCsv(std::istream& in, const std::string& name);
Table ReadCsv(const std::filesystem::path& path);

struct SummaryRow {
  std::string what;    // the question, e.g. "depth object, default path: accuracy"
  std::string result;  // the figures, e.g. "IoU >= 0.991, p95 depth error <= 0.0045 cube edges"
  std::string data;    // the CSV it came from, relative to the report folder
};

// The headline rows the report folder's CSVs support (a row whose CSV or rows
// are missing, as after a partial run, is left out), at most ten.
std::vector<SummaryRow> SummaryRows(const std::filesystem::path& report_dir);

// summary.md's text for those rows.
std::string SummaryMarkdown(const std::vector<SummaryRow>& rows);

// Writes DIR/summary.md (atomically). `dir` is a report folder: its
// .ibr-output marker must exist; summary.md is added to the marker's list so
// a later `ibr report` may replace it. InputError if `dir` is no ibr output,
// if summary.md exists but ibr did not write it, or if no row can be made.
void WriteSummary(const std::filesystem::path& dir);

}  // namespace bench
