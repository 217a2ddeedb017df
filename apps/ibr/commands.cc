#include "apps/ibr/commands.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
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

// The options that name what a command writes.
bool IsOutputOption(const CLI::Option* option) {
  for (const char* name :
       {"out", "csv", "screenshot", "save-scene", "frame-out", "camera-out", "record"}) {
    if (option->check_lname(name)) return true;
  }
  return false;
}

// The file kinds ibr writes as single files.
bool IsOutputFileName(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* e : {".png", ".exr", ".jpg", ".jpeg", ".tif", ".tiff", ".ply", ".obj", ".mtl",
                        ".glb", ".csv", ".json", ".nrrd", ".nhdr", ".dat", ".raw"}) {
    if (ext == e) return true;
  }
  return false;
}

// Every existing path among the chosen subcommands' option values.
void NoteInputs(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* option : sub->get_options()) {
      if (IsOutputOption(option)) continue;
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
  // Checked before the minutes of measuring, not when the plots are written.
  if (!out.empty() && !std::filesystem::is_directory(out)) {
    core::ThrowInputError(where,
                          "--out '{}': no such folder (the plots go into a folder that "
                          "exists; create it first)",
                          out.string());
  }
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
  // Refuse an output that overlaps an input, or an existing file ibr did not
  // write, now, before any work is done (the writers check again when they
  // create the output). A folder output is checked by its StagedDirectory.
  for (const CLI::App* sub = &app; sub != nullptr;) {
    const auto chosen = sub->get_subcommands();
    for (const CLI::Option* option : sub->get_options()) {
      if (!IsOutputOption(option) || option->results().empty()) continue;
      const std::filesystem::path path = option->results().front();
      if (path.empty()) continue;
      const std::string flag = "--" + option->get_lnames().front();
      if (option->check_lname("out")) core::CheckNotAnInput(flag, path);
      std::error_code ec;
      // A file output (named by the kind of file it writes): a folder output
      // (DIR, no such extension) is its StagedDirectory's to check.
      if (IsOutputFileName(path) &&
          (std::filesystem::is_regular_file(std::filesystem::symlink_status(path, ec)) ||
           std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec)))) {
        core::CheckReplaceableFile(flag, path);
      }
      const std::filesystem::path parent = path.parent_path();
      if (path.has_extension() && !parent.empty() && !std::filesystem::is_directory(parent, ec)) {
        core::ThrowFileError(flag, path, "its folder '{}' does not exist", parent.string());
      }
    }
    sub = chosen.empty() ? nullptr : chosen.front();
  }
}

namespace {
// Levenshtein distance, for "did you mean".
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string UnknownFlagMessage(const CLI::App& app, int argc, const char* const* argv) {
  // The leaf command named on the command line (CheckSubcommandNames passed).
  const CLI::App* leaf = &app;
  std::string path = "ibr";
  // Other words are option values and positionals: passed over.
  for (int i = 1; i < argc; ++i) {
    const std::string token = argv[i];
    if (token == "--") break;
    if (token.empty() || token[0] == '-') continue;
    for (const CLI::App* sub : leaf->get_subcommands([](const CLI::App*) { return true; })) {
      if (sub->check_name(token)) {
        leaf = sub;
        path += " " + sub->get_name();
        break;
      }
    }
  }
  std::vector<std::string> flags;
  for (const CLI::App* a = leaf; a != nullptr; a = a->get_parent()) {
    for (const CLI::Option* option : a->get_options()) {
      for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    }
  }
  for (int i = 1; i < argc; ++i) {
    std::string token = argv[i];
    if (token == "--") break;
    if (token.rfind("--", 0) != 0) continue;
    token = token.substr(0, token.find('='));
    if (std::find(flags.begin(), flags.end(), token) != flags.end()) continue;
    std::string best;
    size_t best_distance = 4;  // at most three edits away: a typo, not another word
    for (const std::string& flag : flags) {
      const size_t d = EditDistance(token, flag);
      if (d < best_distance) best_distance = d, best = flag;
    }
    if (best.empty()) {
      return fmt::format("'{}' has no option '{}' (see '{} --help')", path, token, path);
    }
    return fmt::format("'{}' has no option '{}'; did you mean '{}'?", path, token, best);
  }
  return {};
}

}  // namespace apps
