#include "apps/ibr/commands.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"

namespace apps {
namespace {
std::map<std::string, CommandAdder>& Registry() {
  static std::map<std::string, CommandAdder> registry;
  return registry;
}

// Every existing path among the chosen subcommands' option values.
void NoteInputs(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* option : sub->get_options()) {
      // The options that name what a command writes.
      if (option->check_lname("out") || option->check_lname("csv") ||
          option->check_lname("screenshot"))
        continue;
      for (const std::string& value : option->results()) {
        std::error_code ec;
        if (!value.empty() && std::filesystem::exists(value, ec)) core::NoteInputPath(value);
      }
    }
    NoteInputs(*sub);
  }
}

}  // namespace

CommandRegistration::CommandRegistration(const char* name, CommandAdder add) {
  Registry().emplace(name, add);
}

void AddRegisteredCommands(CLI::App& app) {
  for (const auto& [name, add] : Registry()) add(app);
}

void AddDepthObjectFlags(CLI::App* cmd, ibr::DepthObjectFlags& f) {
  cmd->add_option("--method", f.method, "depth-object | visual-hull")->capture_default_str();
  cmd->add_option("--slicing", f.slicing, "orthogonal | screen | ray")->capture_default_str();
  cmd->add_option("--slice-path", f.slice_path,
                  "orthogonal/screen slices: exact (stencil passes) | fast (one draw)")
      ->capture_default_str();
  cmd->add_option("--slices", f.slices,
                  "slices through the box per frame (ray: steps), or auto (one per depth texel)")
      ->capture_default_str();
  cmd->add_option("--robust", f.robust, "keep pixels where at least N-K maps agree")
      ->capture_default_str();
  cmd->add_option("--texturing", f.texturing, "vdt | visibility | none | vdt-paper")
      ->capture_default_str();
  cmd->add_option("--outside", f.outside,
                  "points outside a map's image: pass | fail (default: fail when part of the box "
                  "is seen by no view, else pass; printed)");
  cmd->add_option("--invalid-depth", f.invalid_depth,
                  "depth 0 inside the mask: empty | no-constraint")
      ->capture_default_str();
  cmd->add_option("--max-maps", f.max_maps,
                  "maps a frame tests: the nearest N to the view direction (0 = all)")
      ->capture_default_str();
  cmd->add_option("--depth-lookup", f.depth_lookup,
                  "depth objects on the ray path: subtexel (the default there) | nearest");
}

namespace {
void ParseWindow(const std::string& text, const std::string& where, int& width, int& height) {
  int w = 0, h = 0;
  char x = 0;
  if (std::sscanf(text.c_str(), "%d%c%d", &w, &x, &h) != 3 || x != 'x')
    core::ThrowInputError(where, "--window '{}' is not WIDTHxHEIGHT", text);
  width = w;
  height = h;
}
}  // namespace

void AddWindowFlag(CLI::App* cmd, const std::string& where, int& width, int& height,
                   const std::string& default_size) {
  ParseWindow(default_size, where, width, height);
  cmd->add_option_function<std::string>(
         "--window",
         [where, &width, &height](const std::string& text) {
           ParseWindow(text, where, width, height);
         },
         "window size WIDTHxHEIGHT in pixels")
      ->default_str(default_size);
}

void AddBenchOutputs(CLI::App* cmd, std::filesystem::path& csv, std::filesystem::path& out,
                     bool& quick) {
  cmd->add_option("--csv", csv, "CSV file for the table")->required();
  cmd->add_option("--out", out, "directory for the plots");
  cmd->add_flag("--quick", quick, "small sweep (the smoke test's)");
}

std::filesystem::path CheckBenchOutputs(const std::string& where, const std::filesystem::path& csv,
                                        const std::filesystem::path& out) {
  const std::filesystem::path csv_dir = csv.parent_path().empty() ? "." : csv.parent_path();
  if (!std::filesystem::is_directory(csv_dir))
    core::ThrowInputError(where, "--csv '{}': no such directory", csv.string());
  return out.empty() ? csv_dir : out;
}

CLI::App* BenchGroup(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_name() == "bench") return sub;
  }
  CLI::App* bench =
      app.add_subcommand("bench", "Benchmarks that print time, throughput and accuracy");
  bench->require_subcommand(1);
  return bench;
}

void CheckSubcommandNames(const CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* current = &app;
  std::string path = "ibr";
  for (int i = 1; i < argc; ++i) {
    const std::string token = argv[i];
    if (token == "--") return;
    if (!token.empty() && token[0] == '-') {
      // The root's valued options; every group's other options are flags.
      if (current == &app && (token == "--log-level" || token == "--memory-budget")) ++i;
      continue;
    }
    std::vector<const CLI::App*> subs =
        current->get_subcommands([](const CLI::App*) { return true; });
    if (subs.empty()) return;  // a leaf command: the rest are its arguments
    const CLI::App* next = nullptr;
    std::vector<std::string> names;
    for (const CLI::App* sub : subs) {
      names.push_back(sub->get_name());
      if (sub->check_name(token)) next = sub;
    }
    if (next == nullptr) {
      std::sort(names.begin(), names.end());
      throw core::InputError(fmt::format(
          "unknown subcommand '{}'{} (valid: {})", token,
          current == &app ? std::string() : fmt::format(" of '{}'", path), fmt::join(names, ", ")));
    }
    current = next;
    path += " " + next->get_name();
  }
}

void NoteCommandLineInputs(const CLI::App& app) {
  NoteInputs(app);
  // Refuse an --out that overlaps an input now, before any work is done (the
  // writers check again when they create the output).
  for (const CLI::App* sub = &app; sub != nullptr;) {
    const auto chosen = sub->get_subcommands();
    for (const CLI::Option* option : sub->get_options()) {
      if (option->check_lname("out") && !option->results().empty()) {
        core::CheckNotAnInput("--out", option->results().front());
      }
    }
    sub = chosen.empty() ? nullptr : chosen.front();
  }
}

}  // namespace apps
