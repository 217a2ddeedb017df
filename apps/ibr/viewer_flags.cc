// The viewer's presentation flags (camera start, screenshots, progressive
// frames, recording), shared by the commands that open a viewer window.
#ifdef IBR_HAVE_VIEWER

#include "apps/ibr/viewer_flags.h"

namespace apps {

void AddViewerFlags(CLI::App* cmd, viewer::ViewerOptions& v) {
  cmd->add_option("--azimuth", v.azimuth_degrees, "initial orbit azimuth, degrees")
      ->capture_default_str();
  cmd->add_option("--elevation", v.elevation_degrees, "initial orbit elevation, degrees")
      ->capture_default_str();
  cmd->add_option("--screenshot", v.screenshot,
                  "render --frames frames, save the window to this PNG and exit (no interaction)");
  cmd->add_option("--frames", v.frames, "frames before the screenshot")->capture_default_str();
  cmd->add_flag("--no-panel{false}", v.panel,
                "hide the control panel (screenshots of the object alone)");
  cmd->add_option("--coarse", v.coarse_factor,
                  "resolution divisor while the view or a parameter moves: 0 = adaptive (frames "
                  "of about --motion-ms), N = fixed, 1 = always full resolution")
      ->capture_default_str();
  cmd->add_option("--motion-ms", v.motion_frame_ms,
                  "adaptive divisor: the frame time, in milliseconds, a moving frame aims at")
      ->capture_default_str();
  cmd->add_option("--frame-out", v.frame_out,
                  "with --screenshot or --replay: also save the last exact frame (RGBA PNG, no "
                  "panel)");
  cmd->add_option("--camera-out", v.camera_out,
                  "with --screenshot or --replay: also save its camera (a cameras-only "
                  "dataset.json for "
                  "`ibr render --cameras`)");
  cmd->add_option("--record", v.record,
                  "write the session's mouse and key events to this JSON file when the window "
                  "closes (docs/guide/viewer.md)");
}

}  // namespace apps

#endif  // IBR_HAVE_VIEWER
