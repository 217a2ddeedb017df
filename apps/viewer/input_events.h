// Recorded input of a viewer session (`ibr view --record FILE`, `--replay
// FILE`): the mouse and key events the window received, in window pixels,
// with the frame each arrived before. A replay feeds them, frame by frame,
// through the same handlers as live input (viewer.cc), so it reproduces the
// session's edits and camera; timestamps are kept for the reader, not
// replayed (the frames run as fast as they render). CPU only: codes are
// GLFW's (buttons 0 left, 1 right, 2 middle; keys GLFW_KEY_*, letters their
// upper-case ASCII code; mods GLFW_MOD_* bits: 1 shift, 2 control, 4 alt).
//
// File (JSON, docs/guide/viewer.md):
// {"version": 1, "window": [W, H], "azimuth_deg": A, "elevation_deg": E, "panel": true,
//  "events": [{"frame": N, "t": seconds, "type": "move", "x": px, "y": px},
//             {"frame": N, "t": s, "type": "button", "button": 0, "action": "press", "mods": 0},
//             {"frame": N, "t": s, "type": "scroll", "dx": 0, "dy": 1},
//             {"frame": N, "t": s, "type": "key", "key": 82, "action": "press", "mods": 0}]}
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace viewer {

constexpr int kModControl = 2;  // GLFW_MOD_CONTROL in InputEvent::mods

struct InputEvent {
  enum class Type { kMove, kButton, kScroll, kKey };
  enum class Action { kRelease = 0, kPress = 1, kRepeat = 2 };  // GLFW's values
  Type type = Type::kMove;
  int frame = 0;        // fed before this frame is drawn (0, 1, ...)
  double t = 0;         // seconds since the session started
  double x = 0, y = 0;  // move: cursor (window pixels, y down); scroll: offsets
  int code = 0;         // button or key
  Action action = Action::kPress;
  int mods = 0;
  bool operator==(const InputEvent&) const = default;
};

// A session's input and the state it started from (the replay takes these
// over the command line's).
struct InputRecording {
  int width = 960, height = 720;  // window, pixels
  float azimuth_deg = 30, elevation_deg = 20;
  bool panel = true;
  std::vector<InputEvent> events;  // frames non-decreasing
  bool operator==(const InputRecording&) const = default;
};

void WriteRecording(std::ostream& out, const InputRecording& recording);
void WriteRecording(const std::filesystem::path& path, const InputRecording& recording);
// InputError naming `name` and the JSON pointer on any bad value.
InputRecording ReadRecording(std::istream& in, const std::string& name);
InputRecording ReadRecording(const std::filesystem::path& path);

}  // namespace viewer
