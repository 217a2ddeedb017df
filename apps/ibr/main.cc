// ibr: reconstruct and view objects from registered depth images.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "apps/ibr/commands.h"
#include "core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"ibr: image-based rendering of depth objects, visual hulls and displaced surfaces"};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error|off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  app.parse_complete_callback([&] { spdlog::set_level(spdlog::level::from_str(log_level)); });
  spdlog::set_pattern("%^[%l]%$ %v");

  apps::AddRegisteredCommands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error (CLI11's own printer adds a hint line).
    std::fprintf(stderr, "ibr: error: %s\n", e.what());
    return e.get_exit_code() != 0 ? e.get_exit_code() : 2;
  } catch (const core::InputError& e) {
    std::fprintf(stderr, "ibr: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ibr: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
