// The `ibr` subcommands. Each Add*Command registers its options and a
// callback on `app`; the callback throws core::InputError on bad input, which
// main() turns into one "ibr: error: ..." line and exit code 1.
#pragma once

#include <CLI/CLI.hpp>

namespace apps {

void AddInfoCommand(CLI::App& app);
void AddDemoCommand(CLI::App& app);
void AddBenchCommand(CLI::App& app);

}  // namespace apps
