// `ibr bench viewer --csv FILE [--out DIR]`: scripted orbits and parameter
// drags in a real viewer window (run it under `xvfb-run -a` without a
// screen). Flags -> viewer::RunViewerBench.
#ifdef IBR_HAVE_VIEWER

#include "apps/ibr/commands.h"
#include "apps/viewer/viewer_bench.h"

namespace apps {
namespace {

void AddViewerBench(CLI::App& app) {
  static viewer::ViewerBenchOptions options;
  auto* cmd = BenchGroup(app)->add_subcommand(
      "viewer",
      "Progressive viewer: frame rate while moving, time to the exact frame, exact = `ibr "
      "render`, PSNR of the moving frames (needs a display: xvfb-run -a)");
  AddBenchOutputs(cmd, options.csv, options.out, options.quick);
  AddWindowFlag(cmd, "ibr bench viewer", options.width, options.height);
  cmd->add_option("--frames", options.motion_frames, "moving frames per orbit and per drag")
      ->capture_default_str();
  cmd->add_option("--motion-ms", options.motion_frame_ms,
                  "the viewer's frame-time aim while moving, milliseconds")
      ->capture_default_str();
  cmd->add_option("--shared-data", options.shared_data,
                  "the shared data folder (meshes/, volumes/)");
  cmd->callback([] {
    options.out = CheckBenchOutputs("ibr bench viewer", options.csv, options.out);
    if (options.quick) {
      options.width = 320;
      options.height = 240;
      options.motion_frames = 12;
    }
    viewer::RunViewerBench(options);
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench viewer", AddViewerBench);

}  // namespace apps

#endif  // IBR_HAVE_VIEWER
