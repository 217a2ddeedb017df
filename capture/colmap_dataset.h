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
#include <vector>

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
  // Dense maps: "geometric" or "photometric"; "auto": geometric where the
  // workspace has any, else photometric (said with a warning).
  std::string input_type = "auto";
  ViewChoice choice;             // --views / --hold-out, by photo name
  std::filesystem::path images;  // sparse import: image folder (default SRC/images)
  // Sparse import: silhouettes, one 8-bit image per photo (> 127 = object),
  // found as COLMAP's ImageReader.mask_path names them (NAME.png for photo
  // NAME), or NAME itself, or NAME's stem + ".png". Empty: no masks.
  std::filesystem::path masks;
  // The box spans this percentile and 100 minus it of the points per axis
  // (sparse points, else sampled dense depth): SfM models hold stray points
  // far from the object (one made a box 34x the object), which a min/max
  // box would swallow. 1 % of 1000 points drops 10 per side and axis.
  double bounds_percentile = 1;
  double bounds_margin = 0.05;  // added on every side, fraction of each side's length
  void Check() const;
};

// A dense workspace (WS/stereo/depth_maps exists) becomes a dataset with
// depth (0 where colmap wrote <= 0), normals (world frame) when the normal
// maps exist, masks = valid depth. A sparse model (SRC/sparse/0, SRC/sparse
// or SRC itself) with images becomes a dataset with poses and undistorted
// colour, no depth (masks with options.masks). Either way the dataset's
// "up" is MeanCameraUp (COLMAP's cameras are y down) and its
// bounds are RobustBounds of the sparse points (dense: of the depth maps when
// the model has none). `note` gets lines for the user: the box and where it
// came from, what the dataset can be rendered as and, when nothing, how to
// add depth or masks. Returns the dataset written to `out`.
Dataset ImportColmap(const std::filesystem::path& source, const std::filesystem::path& out,
                     const ColmapImportOptions& options = {},
                     const std::function<void(int, int)>& progress = {},
                     const std::function<void(const std::string&)>& note = {});

}  // namespace capture
