// `ibr demo`: the main job on the built-in default scene: the displaced donut
// (issue 4) beside its tessellated truth, and the default scene's depth
// object (spot-cube, through the scene path) beside the true mesh. The job:
// ibr::WriteDemo (ibr/jobs/demo_job.h).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "apps/ibr/commands.h"
#include "ibr/jobs/demo_job.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

struct DemoOptions {
  std::filesystem::path out = "demo-output";  // directory, replaced atomically
  int size = 512;                             // pixels, square
};

void AddDemoCommand(CLI::App& app) {
  static DemoOptions options;
  auto* cmd = app.add_subcommand("demo", "Render the built-in default scene and write images");
  cmd->add_option("--out", options.out, "output directory")->capture_default_str();
  cmd->add_option("--size", options.size, "image width = height in pixels")->capture_default_str();
  cmd->callback([] {
    auto context = render::HeadlessContext::Create();
    render::CheckFrameSize("ibr demo", "--size", options.size, options.size, /*min_side=*/16);
    spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
    render::ProgramCache programs;
    for (const std::string& line : ibr::WriteDemo(programs, options.out, options.size))
      fmt::print("{}\n", line);
  });
}

}  // namespace

IBR_REGISTER_COMMAND("demo", AddDemoCommand);

}  // namespace apps
