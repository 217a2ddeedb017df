#include "apps/ibr/kind_flags.h"

#include <fmt/format.h>

#include <vector>

namespace apps {

void AddKindFlags(CLI::App* cmd, const scene::ObjectKindSpec& kind, scene::Settings& settings,
                  const std::string& where_prefix) {
  for (const scene::KeySpec& k : kind.keys) {
    if (k.flag.empty()) continue;
    const std::string names(k.flag), key(k.key), type(k.type);
    const std::string where = where_prefix + names.substr(0, names.find(','));
    std::string help(k.help);
    if (k.range) help += " " + scene::RangeText(*k.range);
    help += fmt::format(" (default: {})", k.default_value);
    scene::Settings* s = &settings;
    if (type == "bool" && k.default_value == "false") {
      cmd->add_flag_callback(
          names, [s, key, where] { s->Set(key, true, where); }, help);
    } else if (type == "bool") {
      cmd->add_option_function<bool>(
          names, [s, key, where](const bool& v) { s->Set(key, v, where); }, help);
    } else if (type == "integer") {
      cmd->add_option_function<int>(
          names, [s, key, where](const int& v) { s->Set(key, v, where); }, help);
    } else if (type == "number") {
      cmd->add_option_function<double>(
          names, [s, key, where](const double& v) { s->Set(key, v, where); }, help);
    } else if (type.find("list") != std::string::npos) {
      // Repeated or comma-separated values, joined as a scene file writes them.
      cmd->add_option_function<std::vector<std::string>>(
             names,
             [s, key, where](const std::vector<std::string>& v) {
               s->Set(key, fmt::format("{}", fmt::join(v, ",")), where);
             },
             help)
          ->delimiter(',');
    } else {
      cmd->add_option_function<std::string>(
          names, [s, key, where](const std::string& v) { s->Set(key, v, where); }, help);
    }
  }
}

}  // namespace apps
