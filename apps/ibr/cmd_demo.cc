// `ibr demo`: the main job on the built-in default scene. It grows with the
// renderer's capabilities.
#include <filesystem>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <spdlog/spdlog.h>

#include "apps/ibr/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "render/context.h"
#include "render/frame_timer.h"
#include "render/mesh_pass.h"

namespace apps {
namespace {

struct DemoOptions {
  std::filesystem::path out = "demo-output";  // directory, replaced atomically
  int size = 512;                             // pixels, square
};

void RunDemo(const DemoOptions& options) {
  if (options.size < 16 || options.size > 8192) {
    core::ThrowInputError("ibr demo", "--size {} is outside 16..8192", options.size);
  }
  auto context = render::HeadlessContext::Create();
  spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
  render::ProgramCache programs;

  // A torus, the paper's displacement example base surface, on the default
  // camera: 30 degrees above the ring plane.
  const render::GpuMesh torus(core::MakeTorus(1.0f, 0.4f, 64, 32));
  render::ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt({0, -3.2f, 1.8f}, {0, 0, 0}, {0, 0, 1});
  const double f = 1.1 * options.size;
  view.clip_from_cam = core::ClipFromCamPerspective(f, f, options.size / 2.0, options.size / 2.0,
                                                    options.size, options.size, 0.1, 20.0);
  render::RenderTarget target(render::MeshTargetOptions(options.size, options.size));
  const core::TimingStats timing =
      render::TimeFrames([&] { render::DrawMesh(programs, target, torus, view); });
  const render::MeshFrame frame = render::RenderMesh(programs, torus, view, options.size, options.size);

  core::StagedDirectory out(options.out);
  core::WriteImage(out.path() / "color.png", frame.color);
  core::WriteImage(out.path() / "depth.exr", frame.depth);
  out.Commit();
  fmt::print("demo: torus, {}x{} px, {:.2f} ms/frame (median of {})\n", options.size, options.size,
             timing.median_ms, timing.samples);
  fmt::print("demo: wrote {}\n", std::filesystem::absolute(options.out / "color.png").string());
}

void AddDemoCommand(CLI::App& app) {
  static DemoOptions options;
  auto* cmd = app.add_subcommand("demo", "Render the built-in default scene and write images");
  cmd->add_option("--out", options.out, "output directory")->capture_default_str();
  cmd->add_option("--size", options.size, "image width = height in pixels")->capture_default_str();
  cmd->callback([] { RunDemo(options); });
}

}  // namespace

IBR_REGISTER_COMMAND("demo", AddDemoCommand);

}  // namespace apps
