// The `ibr` subcommands register themselves: each cmd_*.cc file defines an
// adder and registers it with IBR_REGISTER_COMMAND, so adding a command never
// edits main.cc. An adder creates its subcommand (options + callback) on `app`.
// Callbacks throw core::InputError on bad input; main() prints it as one
// "ibr: error: ..." line and exits 1, and outputs are staged so nothing
// partial is left behind.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

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

}  // namespace apps

#define IBR_REGISTER_COMMAND_CONCAT2(a, b) a##b
#define IBR_REGISTER_COMMAND_CONCAT(a, b) IBR_REGISTER_COMMAND_CONCAT2(a, b)
#define IBR_REGISTER_COMMAND(name, adder)                 \
  static const ::apps::CommandRegistration IBR_REGISTER_COMMAND_CONCAT( \
      ibr_command_registration_, __LINE__)(name, adder)
