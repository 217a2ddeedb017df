// Datasets <-> COLMAP workspaces. CPU-only, no GL.
//
// Pixel centres (camera.h): a COLMAP dense workspace's depth/normal map
// element (col, row) lies on the ray K^-1 (col, row, 1) (integer centres),
// while our pixel (col, row) lies on K^-1 (col + 0.5, row + 0.5, 1). So:
// - export writes cameras with cx - 0.5, cy - 0.5 (DenseFromCamera): our depth
//   pixels are then exactly the rays colmap's stereo_fusion uses; keypoints
//   (points2D) are written consistently with that camera;
// - dense import applies the inverse (CameraFromDense), so depth stays exact;
// - sparse import keeps cx, cy as they are (COLMAP's sparse convention is ours).
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "capture/colmap_io.h"
#include "capture/dataset.h"

namespace capture {

struct ColmapExportOptions {
  colmap::ModelFormat format = colmap::ModelFormat::kBinary;  // sparse/ files
  // Sparse points for fusion's overlap graph: one sample every `point_step_px`
  // pixels of each depth map (default: ~40x40 samples per 512 px view).
  int point_step_px = 12;
  // A sample is observed by another view when that view's depth at the
  // projected pixel agrees to this fraction of the camera distance.
  double visibility_tolerance = 0.005;
  void Check() const;
};

// Writes WS/images/, WS/sparse/ (PINHOLE cameras, poses, points + tracks),
// WS/stereo/{depth_maps,normal_maps}/<name>.{geometric,photometric}.bin,
// WS/stereo/fusion.cfg, WS/stereo/patch-match.cfg, WS/stereo/consistency_graphs/.
// Views need depth (normals are computed from the dataset's normal/ images;
// views without normals get normals from depth gradients). Orthographic
// cameras are rejected (COLMAP has no such model). Staged: nothing is left on
// failure. Image names are "<view name>.png".
void ExportColmapWorkspace(const Dataset& dataset, const std::filesystem::path& workspace,
                           const ColmapExportOptions& options = {},
                           const std::function<void(int, int)>& progress = {});

struct ColmapImportOptions {
  std::string input_type = "geometric";  // dense maps: "geometric" or "photometric"
  std::filesystem::path images;          // sparse import: image folder (default SRC/images)
  void Check() const;
};

// A dense workspace (WS/stereo/depth_maps exists) becomes a dataset with
// depth (0 where colmap wrote <= 0), normals (world frame) when the normal
// maps exist, masks = valid depth. A sparse model (SRC/sparse/0, SRC/sparse
// or SRC itself) with images becomes a dataset with poses and undistorted
// colour, no depth. Returns the dataset written to `out`.
Dataset ImportColmap(const std::filesystem::path& source, const std::filesystem::path& out,
                     const ColmapImportOptions& options = {},
                     const std::function<void(int, int)>& progress = {});

}  // namespace capture
