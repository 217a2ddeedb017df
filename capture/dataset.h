// Registered RGB-D datasets on disk. CPU-only, no GL.
//
//   DIR/dataset.json   the manifest (schema below)
//   DIR/color/*.png    RGB or RGBA 8-bit, row 0 at the top
//   DIR/depth/*.exr    float32, 1 channel, camera z (see camera.h), 0 or
//                      non-finite = invalid; optional per view
//   DIR/mask/*.png     8-bit, 1 channel, > 127 = object (silhouette)
//   DIR/normal/*.exr   float32, 3 channels, unit WORLD-frame normal facing the
//                      camera, 0 where invalid; optional
//
// dataset.json (version 1):
// {
//   "format": "ibr-dataset", "version": 1,
//   "depth": {"kind": "camera_z", "units": "m" | "scene units", "invalid": "0 or non-finite",
//             "noise": {...}},   // optional: the sensor model applied (sensor_model.h)
//   "normal_frame": "world",
//   "bounds": {"min": [x, y, z], "max": [x, y, z]},        // optional, world frame
//   "up": [x, y, z],     // optional: the world's up direction (unit), written by the
//                        // importers of y-down cameras (COLMAP, RGB-D, Middlebury)
//                        // from the cameras (MeanCameraUp); orbits turn around it
//   "cameras": [{"id": 1, "model": "PINHOLE", "width": 640, "height": 480,
//                "params": [fx, fy, cx, cy]}],              // params in COLMAP order
//   "views": [{"name": "view_000", "camera": 1,
//              "cam_from_world": [[r00, r01, r02, t0], [r10, r11, r12, t1], [r20, r21, r22, t2]],
//              "color": "color/view_000.png", "depth": "depth/view_000.exr",   // depth optional
//              "mask": "mask/view_000.png", "normal": "normal/view_000.exr"}]  // both optional
// }
// A cameras-only file (novel views for `ibr render --cameras`) is the same
// manifest whose views name no images (ReadCameras).
// Cameras use the sparse pixel convention (pixel centre at +0.5). Dataset
// cameras are undistorted (PINHOLE, SIMPLE_PINHOLE or ORTHOGRAPHIC): importers
// undistort images first.
#pragma once

#include <filesystem>
#include <istream>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "capture/camera.h"
#include "capture/sensor_model.h"
#include "core/atomic_file.h"
#include "core/image.h"

namespace capture {

// Limits every dataset obeys (docs/guide/limits.md, "Datasets"), checked by
// Dataset::Check on read (before any image is opened) and on write.
struct DatasetLimits {
  size_t max_views = 4096;
  int64_t max_total_pixels = int64_t{1} << 30;  // over all views' cameras
  double max_coordinate = 1e6;                  // |bounds|, |camera centre|, depth (scene units)
  double min_extent = 1e-4;                     // every side of the bounds (scene units)
  // Every side of the bounds over the largest |coordinate|: float (24-bit
  // mantissa) must resolve the box in thousands of steps.
  double min_relative_extent = 1e-4;
};
inline constexpr DatasetLimits kDatasetLimits;

struct Bounds {
  glm::dvec3 min{0.0};
  glm::dvec3 max{0.0};
  glm::dvec3 centre() const { return 0.5 * (min + max); }
  glm::dvec3 extent() const { return max - min; }
  bool operator==(const Bounds&) const = default;
};

struct DatasetView {
  std::string name;   // unique, used for file names
  int camera_id = 0;  // key into Dataset::cameras
  Rigid3 cam_from_world;
  std::string color;   // relative paths inside the dataset directory
  std::string depth;   // empty = no depth for this view
  std::string mask;    // empty = no mask
  std::string normal;  // empty = no normals
  bool operator==(const DatasetView&) const = default;
};

struct Dataset {
  std::map<int, Camera> cameras;
  std::vector<DatasetView> views;
  std::string depth_units = "scene units";  // "m" for metric data
  // The sensor model its depth went through (ibr capture --noise), when the
  // capture states one; absent: the source says nothing of its noise.
  std::optional<SensorModel> depth_noise;
  std::optional<Bounds> bounds;
  // The world's up direction (unit), when the source says or implies it
  // (importers of y-down cameras); absent: DefaultUp derives it.
  std::optional<glm::dvec3> up;
  std::filesystem::path root;  // directory the relative paths are relative to (not serialised)

  const Camera& camera(const DatasetView& view) const { return cameras.at(view.camera_id); }
  // Throws core::InputError ("where: ...") naming the first inconsistency:
  // bad camera, unknown camera id, invalid pose, duplicate name, unsafe path.
  // `images` false: views may name no colour image (a cameras-only file).
  void Check(std::string_view where, bool images = true) const;

  // Loading one view's images; each validates the file against the view's
  // camera (size, channels, finite/non-negative values) and throws
  // core::InputError naming the file.
  core::Image8 LoadColor(size_t view) const;   // 3 channels RGB
  core::ImageF LoadDepth(size_t view) const;   // 1 channel; empty view.depth -> InputError
  core::Image8 LoadMask(size_t view) const;    // 1 channel; empty view.mask -> InputError
  core::ImageF LoadNormal(size_t view) const;  // 3 channels
  bool operator==(const Dataset& other) const {
    return cameras == other.cameras && views == other.views && depth_units == other.depth_units &&
           bounds == other.bounds && up == other.up && depth_noise == other.depth_noise;
  }
};

// What the reader will use a dataset for, when that limits it more than
// kDatasetLimits: checked on the manifest, before a view is parsed or any
// image is opened.
struct DatasetUse {
  size_t max_views = kDatasetLimits.max_views;
  std::string purpose;  // named in the error ("maps of one depth object"); empty = none
  // Cameras only: views need not name images, and named images are not opened.
  bool cameras_only = false;
};

// The manifest alone, through streams (`name` is used in messages).
Dataset ReadManifest(std::istream& in, const std::string& name, const DatasetUse& use = {});
void WriteManifest(std::ostream& out, const Dataset& dataset);

// Reads DIR/dataset.json, checks it, and checks that every referenced file
// exists and has the camera's size (headers only). `check_pixels` also loads
// every image and validates values.
Dataset ReadDataset(const std::filesystem::path& dir, bool check_pixels = false,
                    const DatasetUse& use = {});

// Writes a dataset into a staged directory: images view by view, manifest on
// Commit(); nothing is left at `dir` if Commit() is not reached.
class DatasetWriter {
 public:
  explicit DatasetWriter(const std::filesystem::path& dir);
  // Adds a camera, returns its id (1, 2, ...).
  int AddCamera(const Camera& camera);
  // Writes the images and records the view. Depth/mask/normal may be empty
  // (not written). Image sizes must match the camera (InputError otherwise).
  // color: 3 or 4 channels (alpha is dropped); mask: 1 channel.
  void AddView(const std::string& name, int camera_id, const Rigid3& cam_from_world,
               const core::Image8& color, const core::ImageF& depth, const core::Image8& mask,
               const core::ImageF& normal);
  void SetBounds(const Bounds& bounds) { dataset_.bounds = bounds; }
  void SetUp(const glm::dvec3& up);  // normalised; InputError unless finite and non-zero
  void SetDepthUnits(const std::string& units) { dataset_.depth_units = units; }
  void SetDepthNoise(const SensorModel& model) { dataset_.depth_noise = model; }
  const Dataset& dataset() const { return dataset_; }
  // Checks the dataset, writes dataset.json, renames into place.
  void Commit();

 private:
  core::StagedDirectory staged_;
  Dataset dataset_;
};

// The cameras (and poses) of a dataset directory or of a manifest file
// (DIR/dataset.json or any FILE.json in the manifest's format) whose views
// may name no images: novel views for a render.
Dataset ReadCameras(const std::filesystem::path& path);

// The world's up as the cameras imply it, for cameras whose image y points
// down (every camera here, camera.h) held roughly upright: the direction
// least along every camera's x axis (upright cameras hold x level, whatever
// their tilt), nearest -(mean of the y axes), which settles what the x axes
// leave free (one view: its -y). Within 5 degrees of a world axis it snaps
// to that axis. nullopt when the mean y vanishes (cameras rolled every way).
std::optional<glm::dvec3> MeanCameraUp(const Dataset& dataset);

// The up direction an orbit around the dataset uses by default and where it
// came from: dataset.json's "up", else MeanCameraUp, else +y.
struct UpChoice {
  glm::dvec3 up{0, 1, 0};
  std::string source;  // "dataset.json \"up\"", "the input cameras' mean up", "+y (default)"
};
UpChoice DefaultUp(const Dataset& dataset);

// InputError("where: bounds ...") unless finite, min <= max, within
// kDatasetLimits.max_coordinate and every side at least min_extent and
// min_relative_extent of the largest coordinate.
void CheckBounds(const Bounds& bounds, std::string_view where);
// The box of `points` from per-axis percentiles (lo..100-lo),
// widened by `margin` of each side; with fewer than 20 points the min/max
// box (percentiles of so few are the extremes anyway). InputError when empty.
Bounds RobustBounds(const std::vector<glm::dvec3>& points, double percentile, double margin);
// "X0,Y0,Z0,X1,Y1,Z1" (a flag's text) as a checked box; InputError naming
// `where` otherwise.
Bounds ParseBounds(std::string_view text, std::string_view where);

// An importer's --views / --hold-out: which of a source's photos it takes
// (a held-out photo is a novel view to judge a reconstruction by).
struct ViewChoice {
  std::vector<std::string> views;     // only these (empty: every photo)
  std::vector<std::string> hold_out;  // every photo but these
  void Check() const;                 // InputError when both are given
  // The indices of `names` (the photos' file names or relative paths, in
  // import order) kept. A given name matches a photo's name, that name
  // without its extension, or its stem; InputError("where: no photo named
  // 'X' (N photos)") when one matches none.
  std::vector<size_t> Apply(const std::vector<std::string>& names, std::string_view where) const;
};

// Validation of images against a camera, shared by the readers (depth: 0 or
// non-finite = invalid, else in 0..kDatasetLimits.max_coordinate).
void CheckDepthValues(const core::ImageF& depth, const std::string& where);
void CheckNormalValues(const core::ImageF& normal, const std::string& where);

}  // namespace capture
