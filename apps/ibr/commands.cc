#include "apps/ibr/commands.h"

#include <algorithm>
#include <map>

namespace apps {
namespace {
std::map<std::string, CommandAdder>& Registry() {
  static std::map<std::string, CommandAdder> registry;
  return registry;
}
}  // namespace

CommandRegistration::CommandRegistration(const char* name, CommandAdder add) {
  Registry().emplace(name, add);
}

void AddRegisteredCommands(CLI::App& app) {
  for (const auto& [name, add] : Registry()) add(app);
}

CLI::App* BenchGroup(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_name() == "bench") return sub;
  }
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print time, throughput and accuracy");
  bench->require_subcommand(1);
  return bench;
}

}  // namespace apps
