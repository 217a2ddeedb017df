// The `ibr` subcommands register themselves: each cmd_*.cc file defines an
// adder and registers it with IBR_REGISTER_COMMAND, so adding a command never
// edits main.cc. An adder creates its subcommand (options + callback) on `app`.
// Callbacks throw core::InputError on bad input; main() prints it as one
// "ibr: error: ..." line and exits 1, and outputs are staged so nothing
// partial is left behind.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "ibr/scene_options.h"
#include "scene/scene.h"

namespace apps {

using CommandAdder = void (*)(CLI::App& app);

struct CommandRegistration {
  CommandRegistration(const char* name, CommandAdder add);
};

// Adds every registered command to `app`, in name order.
void AddRegisteredCommands(CLI::App& app);

// The `ibr bench` group, created on first use: benchmarks add themselves as
// its subcommands (`ibr bench fillrate`, `ibr bench displacement`, ...).
CLI::App* BenchGroup(CLI::App& app);

// The depth-object flags (--method, --slicing, --slices, --robust, --texturing,
// --outside, --invalid-depth) bound to `flags`, with their defaults shown;
// shared by `ibr render` and `ibr view`, mapped to options by
// ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(flags)).
void AddDepthObjectFlags(CLI::App* cmd, ibr::DepthObjectFlags& flags);

// --window WIDTHxHEIGHT (pixels) into `width`, `height`, which start at
// `default_size`; shared by `ibr view` and `ibr bench viewer`. A value that
// is not WIDTHxHEIGHT: core::InputError "WHERE: --window 'X' is not WIDTHxHEIGHT".
void AddWindowFlag(CLI::App* cmd, const std::string& where, int& width, int& height,
                   const std::string& default_size = "960x720");

// A bench's outputs: --csv FILE (required), --out DIR (plots) and --quick (the
// small sweep of the smoke test).
void AddBenchOutputs(CLI::App* cmd, std::filesystem::path& csv, std::filesystem::path& out,
                     bool& quick);

// Checks, before minutes of measuring, that --csv's folder exists; returns
// --out, or the CSV's folder when --out is empty.
std::filesystem::path CheckBenchOutputs(const std::string& where, const std::filesystem::path& csv,
                                        const std::filesystem::path& out);

// Throws core::InputError "unknown subcommand 'X' of 'ibr import' (valid:
// colmap, middlebury, redwood)" when argv names a subcommand that does not
// exist where one is required (CLI11 alone says "A subcommand is required").
void CheckSubcommandNames(const CLI::App& app, int argc, const char* const* argv);

// Notes every existing path given to the chosen subcommand (positional or
// option, except the outputs --out, --csv and --screenshot) as an input
// (core::NoteInputPath), so no output of the command can replace, sit inside
// or contain it.
// For a command line CLI11 refused with unexpected arguments: "'ibr render'
// has no option '--orbti'; did you mean '--orbit'?" (empty when every
// --flag is known).
std::string UnknownFlagMessage(const CLI::App& app, int argc, const char* const* argv);

void NoteCommandLineInputs(const CLI::App& app);

}  // namespace apps

#define IBR_REGISTER_COMMAND_CONCAT2(a, b) a##b
#define IBR_REGISTER_COMMAND_CONCAT(a, b) IBR_REGISTER_COMMAND_CONCAT2(a, b)
#define IBR_REGISTER_COMMAND(name, adder)                                                         \
  static const ::apps::CommandRegistration IBR_REGISTER_COMMAND_CONCAT(ibr_command_registration_, \
                                                                       __LINE__)(name, adder)
