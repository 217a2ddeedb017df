// The depth-object part of `ibr demo` (issue 5), through the scene path
// (scene/scene.h -> ibr::LoadScene -> ibr::SceneRenderer): the default scene
// captures a textured mesh with the cube rig (Kautz-Seidel 2001, sec. 4: six
// orthographic RGB-D maps on the faces of its bounding cube); a turntable of
// its depth object is measured frame by frame against the true mesh rendered
// from the same camera.
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
  std::string scene = "spot-cube";  // a built-in scene (datasets/scenes/NAME.json) whose first
                                    // object is a depth object captured from a mesh
  int size = 512;                   // output pixels, square
  int frames = 8;  // turntable frames (the scene's orbit, with this count and size)
  void Check() const;
};

struct DepthObjectDemoResult {
  std::vector<std::string> names;
  std::vector<core::Image8> frames;  // RGBA8
  std::vector<core::ImageF> depths;  // camera z, 0 = empty
  std::vector<core::Image8> truth;   // the true mesh from the same cameras
  core::TimingStats
      timing;  // per frame: draw + readback (SceneRenderer::Render), after a warm-up frame
  std::string description;               // the scene's
  DepthObjectOptions render;             // the object's options from the scene file
  int capture_size = 0;                  // pixels per captured map
  double iou_mean = 0, iou_min = 1;      // silhouette vs the true mesh
  double depth_mean = 0, depth_p95 = 0;  // |depth error| over pixels both cover, in cube-edge units
                                         // (core/metrics.h: NaN if none)
  double capture_seconds = 0;
};

// A rendered frame against the true mesh seen by the same camera (rendered by
// capture::RenderView, the capture's own rasteriser).
struct MeshAccuracy {
  double iou = 1;                    // silhouette
  int64_t rendered_pixels = 0;       // covered in the rendering
  int64_t truth_pixels = 0;          // covered by the mesh
  std::vector<double> depth_errors;  // |depth - true depth| / edge over pixels both cover
  core::Image8 truth;                // RGBA8 true colour, alpha 0 where empty
};
MeshAccuracy CompareToMesh(render::ProgramCache& programs, const capture::SceneMesh& scene,
                           const ViewCamera& view, const core::ImageF& depth, double edge);

// Needs a current context.
DepthObjectDemoResult RunDepthObjectDemo(render::ProgramCache& programs,
                                         const DepthObjectDemoOptions& options);

// `ibr demo` whole: the paper's displaced donut (Kautz-Seidel 2001, sec.
// 3.4: 625 polygons, bumps, orthogonal slicing) beside its tessellated truth
// (color.png, depth.exr, ground_truth.png, ground_truth_depth.exr,
// side_by_side.png), and RunDepthObjectDemo's turntable
// (depth_object/NAME.png, NAME_depth.exr, depth_object_turntable.png), into
// `out`, replaced atomically (core::StagedDirectory); `size` px square.
// Returns the lines to print ("demo: ..."). Needs a current context.
std::vector<std::string> WriteDemo(render::ProgramCache& programs, const std::filesystem::path& out,
                                   int size);

// Where the shared test data lives: $IBR_SHARED_DATA, else ../shared/data
// beside the source tree this binary was built from.
std::filesystem::path SharedDataDir();

}  // namespace ibr
