// ibr: reconstruct and view objects from registered depth images.
#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <iterator>
#include <memory>
#include <string>

#include "apps/ibr/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "render/gl/program_binary_cache.h"

namespace {

// "%*" in the log pattern: seconds since the process started, so a log file
// shows how long each stage took.
const auto g_start = std::chrono::steady_clock::now();

class ElapsedFlag : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg&, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - g_start).count();
    fmt::format_to(std::back_inserter(dest), "{:7.2f}s", s);
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<ElapsedFlag>();
  }
};

}  // namespace

int main(int argc, char** argv) {
  // Staging folders go with the process on Ctrl-C / kill; progress reaches a
  // log file line by line.
  core::InstallCleanupSignalHandlers();
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::setvbuf(stderr, nullptr, _IONBF, 0);
  std::string command_line = "ibr";
  for (int i = 1; i < argc; ++i) command_line += std::string(" ") + argv[i];
  core::SetOutputDescription(command_line);
  // Compiled shader programs are kept between runs under ibr's own cache
  // folder ($IBR_CACHE_DIR, else $XDG_CACHE_HOME/ibr or ~/.cache/ibr;
  // IBR_CACHE_DIR=off disables it); set before any GL context exists.
  render::EnableShaderCache(render::DefaultShaderCacheDir());

  CLI::App app{"ibr: image-based rendering of depth objects, visual hulls and displaced surfaces"};
  app.require_subcommand(1);
  // Root options (--overwrite, --log-level) may follow the command too.
  app.fallthrough();
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error|off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  // Every step whose memory grows with the input checks this budget before
  // allocating (core/memory_budget.h).
  std::string memory_budget;
  app.add_option("--memory-budget", memory_budget,
                 "memory a run may plan to use: 8G, 512M, 25% (default: half of physical "
                 "memory, or IBR_MEMORY_BUDGET)");
  // The one way past the rule that ibr replaces only files it wrote
  // (core/atomic_file.h); a folder ibr did not write is never replaced.
  bool overwrite = false;
  app.add_flag("--overwrite", overwrite,
               "replace an existing output file that ibr did not write (never a folder)");
  app.parse_complete_callback([&] {
    core::SetOverwriteFiles(overwrite);
    if (!memory_budget.empty()) core::SetMemoryBudget(core::ParseMemorySize(memory_budget));
    spdlog::set_level(spdlog::level::from_str(log_level));
    apps::NoteCommandLineInputs(app);
  });
  // Progress and warnings go to stderr (stdout holds results), unbuffered.
  spdlog::set_default_logger(spdlog::stderr_color_st("ibr"));
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<ElapsedFlag>('*').set_pattern("%^[%l]%$ %* %v");
  spdlog::set_formatter(std::move(formatter));

  apps::AddRegisteredCommands(app);

  try {
    apps::CheckSubcommandNames(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ExtrasError& e) {
    // An unknown flag: name it and the nearest valid one.
    const std::string message = apps::UnknownFlagMessage(app, argc, argv);
    std::fprintf(stderr, "ibr: error: %s\n", message.empty() ? e.what() : message.c_str());
    return e.get_exit_code() != 0 ? e.get_exit_code() : 2;
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
  } catch (...) {
    std::fprintf(stderr, "ibr: error: unknown exception\n");
    return 1;
  }
  return 0;
}
