// `ibr info`: what this machine's GL gives us.
#include <fmt/format.h>

#include "apps/ibr/commands.h"
#include "render/context.h"
#include "render/shader_program.h"

namespace apps {

namespace {
void AddInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Print the OpenGL context this machine gives (headless EGL)");
  cmd->callback([] {
    auto context = render::HeadlessContext::Create();
    const render::GlInfo& gl = context->info();
    fmt::print("OpenGL    {}.{} ({})\n", gl.major, gl.minor, gl.version);
    fmt::print("renderer  {}\nvendor    {}\nGLSL      {}\nplatform  EGL {}\n", gl.renderer,
               gl.vendor, gl.glsl_version, gl.platform);
    fmt::print("shaders   {} embedded files\n", render::ShaderSources::Embedded().Names().size());
  });
}
}  // namespace

IBR_REGISTER_COMMAND("info", AddInfoCommand);

}  // namespace apps
