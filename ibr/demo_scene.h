// The depth-object part of `ibr demo` (issue 5): capture a textured mesh with
// the cube rig (Kautz-Seidel 2001, sec. 4: six orthographic RGB-D maps on the
// faces of its bounding cube), render a turntable of its depth object, and
// measure each frame against the true mesh rendered from the same camera.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "capture/synthetic.h"
#include "core/image.h"
#include "core/timing.h"
#include "ibr/depth_object.h"
#include "render/gl/shader_program.h"

namespace ibr {

struct DepthObjectDemoOptions {
  std::filesystem::path mesh;  // OBJ/PLY (textured: Spot)
  int capture_size = 512;      // pixels per cube face map
  int size = 512;              // output pixels, square
  int frames = 8;              // turntable frames around the y axis
  DepthObjectOptions render;   // method, slicing, slices, texturing
  void Check() const;
};

struct DepthObjectDemoResult {
  std::vector<std::string> names;
  std::vector<core::Image8> frames;   // RGBA8
  std::vector<core::ImageF> depths;   // camera z, 0 = empty
  std::vector<core::Image8> truth;    // the true mesh from the same cameras
  core::TimingStats timing;           // GPU render per frame (glFinish), after one warm-up frame
  double iou_mean = 0, iou_min = 1;   // silhouette vs the true mesh
  double depth_mean = 0, depth_p95 = 0;  // |depth error| over pixels both cover, in cube-edge units (core/metrics.h: NaN if none)
  double capture_seconds = 0;
};

// A rendered frame against the true mesh seen by the same camera (rendered by
// capture::RenderView, the capture's own rasteriser).
struct MeshAccuracy {
  double iou = 1;                  // silhouette
  std::vector<double> depth_errors;  // |depth - true depth| / edge over pixels both cover
  core::Image8 truth;              // RGBA8 true colour, alpha 0 where empty
};
MeshAccuracy CompareToMesh(render::ProgramCache& programs, const capture::SceneMesh& scene,
                           const ViewCamera& view, const core::ImageF& depth, double edge);

// Needs a current context.
DepthObjectDemoResult RunDepthObjectDemo(render::ProgramCache& programs, const DepthObjectDemoOptions& options);

// Where the shared test data lives: $IBR_SHARED_DATA, else ../shared/data
// beside the source tree this binary was built from.
std::filesystem::path SharedDataDir();

}  // namespace ibr
