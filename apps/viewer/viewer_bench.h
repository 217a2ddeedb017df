// `ibr bench viewer`: scripted sessions of the progressive viewer in a real
// window (under Xvfb here): per scene, an orbit and a parameter drag, each
// followed by a rest. Measures the frame rate while moving, the time from
// the last moving frame to the exact frame shown, whether that frame equals
// what ibr::RenderSceneToDataset (`ibr render SCENE.json`) writes from the
// same camera, and the PSNR of the reduced moving frames (scaled up as the
// window shows them) against the exact frames of their cameras.
#pragma once

#include <filesystem>
#include <string>

#include "bench/report.h"

namespace viewer {

struct ViewerBenchOptions {
  std::filesystem::path csv;
  std::filesystem::path out;          // plots and the table; empty: the CSV's folder
  bool quick = false;                 // small window, few frames (the smoke test's)
  int width = 960, height = 720;      // window, pixels
  int motion_frames = 60;             // moving frames per orbit and per drag
  double motion_frame_ms = 55;        // the viewer's adaptive budget (ViewerOptions)
  std::filesystem::path shared_data;  // meshes/ and volumes/; empty: the default
  void Check() const;
};

// Runs every scene; prints and writes the table; returns it.
bench::Table RunViewerBench(const ViewerBenchOptions& options);

}  // namespace viewer
