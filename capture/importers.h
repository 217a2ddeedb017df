// Real-data importers: Redwood RGB-D sequences and the Middlebury multi-view
// rings become datasets. CPU-only, no GL.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>

#include "capture/dataset.h"

namespace capture {

// ../shared/data/rgbd/redwood5 layout: color/NNNNN.jpg, depth/NNNNN.png
// (uint16, millimetres, 0 = invalid), trajectory.log (Redwood .log: "i j n"
// then a 4x4 world_from_cam per frame), camera_primesense.json (Open3D
// intrinsics, column-major K, integer pixel centres: cx + 0.5 here).
// Depth is written in metres; mask = valid depth; "up" = MeanCameraUp
// (sensor images are y down). `note` gets lines for the user:
// the up direction and, when CheckDepthScale finds the depths implausible,
// its warning with the --depth-scale that would fix it.
struct RedwoodImportOptions {
  double depth_scale = 1000;     // depth file units per metre (Redwood: mm; TUM RGB-D: 5000)
  std::optional<Bounds> bounds;  // the object's box (m); default: what most frames agree on
  void Check() const;
};
Dataset ImportRedwood(const std::filesystem::path& source, const std::filesystem::path& out,
                      const RedwoodImportOptions& options = {},
                      const std::function<void(int, int)>& progress = {},
                      const std::function<void(const std::string&)>& note = {});

// The RGB-D frames of a sequence with poses, as the RGB-D importers (Redwood,
// TUM) write them: colour as RGB, depth (16-bit PNG at `depth_scale` units
// per metre) in metres, mask = valid depth, a distorted `camera` undistorted
// into its PINHOLE (colour bilinear, depth nearest), bounds = `bounds` if
// given, else the box around what most frames agree on (a sequence round an
// object: the object, not the room; printed), else every valid point in
// the world; "up" = MeanCameraUp, then the depth-scale check
// (CheckDepthScale) with its warning and the --depth-scale that would fix it.
struct RgbdFrame {
  std::string name;
  std::filesystem::path color, depth;
  Rigid3 cam_from_world;
};
Dataset WriteRgbdFrames(const std::vector<RgbdFrame>& frames, const Camera& camera,
                        double depth_scale, const std::optional<Bounds>& bounds,
                        const std::filesystem::path& out,
                        const std::function<void(int, int)>& progress = {},
                        const std::function<void(const std::string&)>& note = {});

// Middlebury templeSparseRing / dinoSparseRing: *_par.txt lines
// "name k11..k33 r11..r33 t1 t2 t3" (P = K [R t], cam_from_world = (R, t),
// integer pixel centres: cx + 0.5 here), PNG photos, README.txt bounding box.
// R is snapped to the nearest rotation (SVD): the files' are orthonormal to
// ~1e-6 only. The integer-centre reading of K follows the calibration
// toolbox's C convention; the data cannot settle half a pixel (the README's
// tight box projects around every silhouette with either reading, see
// tests/capture/importers_test.cc).
// Masks (Seitz et al. 2006's silhouettes recipe, OpenCV): grey > threshold,
// then `dilate_iterations` 3x3 dilations and `erode_iterations` erosions.
// "up" = MeanCameraUp, as for the other importers.
struct MiddleburyImportOptions {
  double threshold = 0.19;  // of full scale on the grey image (the README's value)
  int dilate_iterations = 10;
  int erode_iterations = 7;
  void Check() const;
};
Dataset ImportMiddlebury(const std::filesystem::path& source, const std::filesystem::path& out,
                         const MiddleburyImportOptions& options = {},
                         const std::function<void(int, int)>& progress = {});

// The whitespace-separated finite numbers of one line of a text file (the
// readers here and in tum_import.h); InputError("where: line N: 'TOKEN' is
// not a finite number") otherwise.
std::vector<double> ParseNumbers(const std::string& line, const std::string& where,
                                 int line_number);

// The parsers alone, through streams (names used in messages).
std::vector<Rigid3> ReadRedwoodLog(std::istream& in,
                                   const std::string& name);  // cam_from_world per frame
struct MiddleburyView {
  std::string image;
  Camera camera;  // PINHOLE in our (+0.5) convention; size set by the importer
  Rigid3 cam_from_world;
};
std::vector<MiddleburyView> ReadMiddleburyPar(std::istream& in, const std::string& name);
// Redwood's camera_primesense.json: {"width", "height", "intrinsic_matrix"
// (9 numbers, column-major K)}; the camera is checked (sizes, focal lengths).
Camera ReadRedwoodIntrinsics(std::istream& in, const std::string& name);
// The bounding box of a Middlebury README.txt: the first "(x y z) (x y z)"
// pair; nullopt when the text holds none. Numbers must be finite and the box
// pass capture::CheckBounds.
std::optional<Bounds> ReadMiddleburyBounds(std::istream& in, const std::string& name);

}  // namespace capture
