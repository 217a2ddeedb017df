// The TUM RGB-D benchmark layout (Sturm et al. 2012,
// https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats):
//   rgb.txt, depth.txt    "timestamp filename" per line ('#' lines are comments)
//   groundtruth.txt       "timestamp tx ty tz qx qy qz qw": the colour camera's
//                         optical centre and orientation in the world
//                         (world_from_cam, Hamilton quaternion, scalar last),
//                         camera axes x right, y down, z forward as ours
//   depth/*.png           16-bit, 5000 units per metre, 0 = no depth, registered
//                         to the colour camera
// Frames: each colour image with the depth image nearest in time, within
// `max_difference` seconds (associate.py's rule: the closest pairs first,
// each image used once); its pose interpolated at the colour timestamp
// between the two ground-truth poses around it (translation linear,
// rotation slerp), which must lie within `max_pose_gap` of each other.
// Frames with no depth or no pose within those bounds are left out and
// counted in one line. The camera: TUM's published calibration of the
// sequence's sensor (fr1, fr2: with their OpenCV distortion, undistorted on
// import; fr3: undistorted already), named by --camera or found in the
// sequence's name ("freiburg3" or "fr3" in the folder's or rgb.txt's
// name), or given as FX,FY,CX,CY (integer pixel centres, as TUM states
// them). CPU-only.
#pragma once

#include <filesystem>
#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera.h"
#include "capture/dataset.h"

namespace capture {

struct TumImportOptions {
  // "fr1" | "fr2" | "fr3" | "FX,FY,CX,CY"; empty: from the sequence's name.
  std::string camera;
  double depth_scale = 5000;     // depth units per metre
  double max_difference = 0.02;  // seconds between a colour and its depth image
  double max_pose_gap = 0.1;     // seconds between the ground-truth poses around a frame
  int every = 1;                 // every N-th frame (a 30 Hz sequence holds 30 per second)
  std::optional<Bounds> bounds;  // the object's box (m); default: what most frames agree on
  void Check() const;
};

struct TumStamped {
  double time = 0;
  std::string file;
};
struct TumPose {
  double time = 0;
  Rigid3 cam_from_world;
};

// The parsers alone, through streams (`name` in messages).
std::vector<TumStamped> ReadTumList(std::istream& in, const std::string& name);
std::vector<TumPose> ReadTumTrajectory(std::istream& in, const std::string& name);
// Pairs (index into `a`, index into `b`) of timestamps within
// `max_difference`, the closest first, each index used once; sorted by a.
std::vector<std::pair<size_t, size_t>> AssociateTum(const std::vector<TumStamped>& a,
                                                    const std::vector<TumStamped>& b,
                                                    double max_difference);
// The pose at `time` between its neighbours in `trajectory` (sorted by
// time); false when `time` lies outside it or its neighbours are more than
// `max_gap` apart.
bool InterpolateTumPose(const std::vector<TumPose>& trajectory, double time, double max_gap,
                        Rigid3& cam_from_world);
// TUM's calibration of a named sensor ("fr1", "fr2", "fr3") or FX,FY,CX,CY
// for a width x height image; InputError naming the text otherwise.
Camera TumCamera(const std::string& spec, int width, int height);

Dataset ImportTum(const std::filesystem::path& source, const std::filesystem::path& out,
                  const TumImportOptions& options = {},
                  const std::function<void(int, int)>& progress = {},
                  const std::function<void(const std::string&)>& note = {});

}  // namespace capture
