// NeRF-style `transforms.json` (the Blender synthetic scenes of Mildenhall
// et al. 2020, instant-ngp, nerfstudio) as a dataset. CPU-only.
//
// The file: intrinsics at the top level, or per frame overriding them:
// `camera_angle_x` (horizontal field of view, radians; fy = fx, principal
// point at the image centre), or `fl_x`, `fl_y`, `cx`, `cy` in pixels with
// `w`, `h` (pixel centres at half-integers, ours), plus nerfstudio's OpenCV
// `k1`, `k2`, `p1`, `p2` (undistorted on import). `frames`: `file_path`
// (relative to the file's folder; without an extension, as the Blender
// scenes write it, `.png` then `.jpg` is tried) and `transform_matrix`, the
// 4x4 camera-to-world matrix of an OpenGL camera (x right, y up, looking
// down -z): ours (x right, y down, z forward) is it turned half a turn about
// x, cam_from_world = diag(1, -1, -1) * inverse(transform_matrix).
// Masks: the image's alpha (> 127 = object) where it has one, or
// nerfstudio's `mask_path`; depth: nerfstudio's `depth_file_path` (16-bit
// PNG or EXR) times `depth_unit_scale_factor` (default 1e-3 for 16-bit, 1 for
// float). Bounds: the box of the masks' coarse visual hull (a 64^3 grid over
// the region the cameras look at), else of the depth points, else that
// region itself; printed.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "capture/dataset.h"

namespace capture {

struct NerfImportOptions {
  ViewChoice choice;  // --views / --hold-out, by file_path (or its stem)
  void Check() const;
};

// SRC: a transforms*.json file, or a folder holding transforms.json (else
// transforms_train.json, said).
Dataset ImportNerf(const std::filesystem::path& source, const std::filesystem::path& out,
                   const NerfImportOptions& options = {},
                   const std::function<void(int, int)>& progress = {},
                   const std::function<void(const std::string&)>& note = {});

// One frame's camera and pose from the document `top` and its frame
// `frame` for an image of width x height (used when the file gives no `w`,
// `h`); InputError naming `where` on a missing or bad key.
struct NerfFrame {
  Camera camera;
  Rigid3 cam_from_world;
};
NerfFrame ParseNerfFrame(const nlohmann::json& top, const nlohmann::json& frame, int width,
                         int height, const std::string& where);

}  // namespace capture
