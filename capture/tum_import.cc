#include "capture/tum_import.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <sstream>

#include "capture/importers.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/parse_number.h"

namespace capture {
namespace fs = std::filesystem;

void TumImportOptions::Check() const {
  constexpr const char* kWhere = "ibr import tum";
  if (!(depth_scale >= 1e-3 && depth_scale <= 1e6)) {
    core::ThrowInputError(kWhere, "--depth-scale {} outside 1e-3..1e6 (depth units per metre)",
                          depth_scale);
  }
  if (!(max_difference > 0 && max_difference <= 1))
    core::ThrowInputError(kWhere, "--max-difference {} outside (0, 1] seconds", max_difference);
  if (!(max_pose_gap > 0 && max_pose_gap <= 10))
    core::ThrowInputError(kWhere, "--max-pose-gap {} outside (0, 10] seconds", max_pose_gap);
  if (every < 1 || every > 100000)
    core::ThrowInputError(kWhere, "--every {} outside 1..100000", every);
  if (bounds) CheckBounds(*bounds, "--bounds");
}

namespace {

bool Comment(const std::string& line) {
  const size_t first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

std::vector<TumStamped> ReadListFile(const fs::path& path) {
  std::ifstream in(path);
  if (!in) core::ThrowFileError("ImportTum", path, "cannot open file");
  return ReadTumList(in, path.string());
}

}  // namespace

std::vector<TumStamped> ReadTumList(std::istream& in, const std::string& name) {
  const std::string where = fmt::format("ReadTumList: '{}'", name);
  std::vector<TumStamped> list;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (Comment(line)) continue;
    std::istringstream s(line);
    std::string time, file, extra;
    s >> time >> file;
    if (file.empty() || (s >> extra))
      core::ThrowInputError(where, "line {}: expected \"timestamp filename\"", n);
    const std::vector<double> v = ParseNumbers(time, where, n);
    if (v.size() != 1) core::ThrowInputError(where, "line {}: bad timestamp '{}'", n, time);
    list.push_back({v[0], file});
  }
  if (list.empty()) core::ThrowInputError(where, "no entries");
  return list;
}

std::vector<TumPose> ReadTumTrajectory(std::istream& in, const std::string& name) {
  const std::string where = fmt::format("ReadTumTrajectory: '{}'", name);
  std::vector<TumPose> poses;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (Comment(line)) continue;
    const std::vector<double> v = ParseNumbers(line, where, n);
    if (v.size() != 8)
      core::ThrowInputError(where,
                            "line {}: expected \"timestamp tx ty tz qx qy qz qw\", got {} numbers",
                            n, v.size());
    const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
    if (std::abs(norm - 1) > 1e-3)
      core::ThrowInputError(where, "line {}: quaternion of length {:.6g}, not 1", n, norm);
    const Rigid3 world_from_cam = Rigid3::FromQuaternion(
        {v[7] / norm, v[4] / norm, v[5] / norm, v[6] / norm}, {v[1], v[2], v[3]});
    if (!poses.empty() && !(v[0] > poses.back().time))
      core::ThrowInputError(where, "line {}: timestamp {} not after the previous one", n, v[0]);
    poses.push_back({v[0], world_from_cam.Inverse()});
  }
  if (poses.empty()) core::ThrowInputError(where, "no poses");
  return poses;
}

std::vector<std::pair<size_t, size_t>> AssociateTum(const std::vector<TumStamped>& a,
                                                    const std::vector<TumStamped>& b,
                                                    double max_difference) {
  // Candidates within the bound (b sorted by time: a window per entry of a),
  // then the closest pairs first, each index once (associate.py).
  std::vector<size_t> order(b.size());
  for (size_t j = 0; j < b.size(); ++j) order[j] = j;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return b[x].time < b[y].time; });
  struct Candidate {
    double difference;
    size_t i, j;
  };
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    auto it = std::lower_bound(order.begin(), order.end(), a[i].time - max_difference,
                               [&](size_t j, double t) { return b[j].time < t; });
    for (; it != order.end() && b[*it].time <= a[i].time + max_difference; ++it)
      candidates.push_back({std::abs(b[*it].time - a[i].time), i, *it});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return x.difference != y.difference ? x.difference < y.difference
                                        : (x.i != y.i ? x.i < y.i : x.j < y.j);
  });
  std::vector<bool> used_a(a.size()), used_b(b.size());
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const Candidate& c : candidates) {
    if (used_a[c.i] || used_b[c.j]) continue;
    used_a[c.i] = used_b[c.j] = true;
    pairs.emplace_back(c.i, c.j);
  }
  std::sort(pairs.begin(), pairs.end(),
            [&](const auto& x, const auto& y) { return a[x.first].time < a[y.first].time; });
  return pairs;
}

bool InterpolateTumPose(const std::vector<TumPose>& trajectory, double time, double max_gap,
                        Rigid3& cam_from_world) {
  auto after = std::lower_bound(trajectory.begin(), trajectory.end(), time,
                                [](const TumPose& p, double t) { return p.time < t; });
  if (after == trajectory.end()) return false;
  if (after->time == time) {
    cam_from_world = after->cam_from_world;
    return true;
  }
  if (after == trajectory.begin()) return false;
  const auto before = after - 1;
  if (after->time - before->time > max_gap) return false;
  const double s = (time - before->time) / (after->time - before->time);
  // The camera's motion: its centre moves on a line, its orientation on the
  // shortest arc (glm::slerp picks the nearer of q and -q).
  const Rigid3 a = before->cam_from_world.Inverse(), b = after->cam_from_world.Inverse();
  const glm::dquat qa = glm::quat_cast(a.rotation), qb = glm::quat_cast(b.rotation);
  Rigid3 world_from_cam;
  world_from_cam.rotation = glm::mat3_cast(glm::normalize(glm::slerp(qa, qb, s)));
  world_from_cam.translation = (1 - s) * a.translation + s * b.translation;
  cam_from_world = world_from_cam.Inverse();
  return true;
}

Camera TumCamera(const std::string& spec, int width, int height) {
  // TUM's published calibrations of the colour cameras (fx, fy, cx, cy;
  // d0..d4 = OpenCV k1, k2, p1, p2, k3), integer pixel centres: + 0.5 here.
  struct Known {
    const char* name;
    double fx, fy, cx, cy, d[5];
  };
  static constexpr Known kKnown[] = {
      {"fr1", 517.3, 516.5, 318.6, 255.3, {0.2624, -0.9531, -0.0054, 0.0026, 1.1633}},
      {"fr2", 520.9, 521.0, 325.1, 249.7, {0.2312, -0.7849, -0.0033, -0.0001, 0.9172}},
      {"fr3", 535.4, 539.2, 320.1, 247.6, {0, 0, 0, 0, 0}},
  };
  for (const Known& k : kKnown) {
    if (spec != k.name) continue;
    if (k.d[0] == 0) return Camera::Pinhole(width, height, k.fx, k.fy, k.cx + 0.5, k.cy + 0.5);
    Camera c;
    c.model = CameraModel::kFullOpenCv;
    c.width = width;
    c.height = height;
    c.params = {k.fx,   k.fy,   k.cx + 0.5, k.cy + 0.5, k.d[0], k.d[1],
                k.d[2], k.d[3], k.d[4],     0,          0,      0};
    c.Check(fmt::format("TUM {}", k.name));
    return c;
  }
  const std::optional<std::vector<double>> v = core::ParseNumberList(spec);
  if (!v || v->size() != 4) {
    core::ThrowInputError("ibr import tum",
                          "--camera '{}' is neither fr1, fr2, fr3 nor FX,FY,CX,CY", spec);
  }
  const Camera c = Camera::Pinhole(width, height, (*v)[0], (*v)[1], (*v)[2] + 0.5, (*v)[3] + 0.5);
  c.Check(fmt::format("--camera '{}'", spec));
  return c;
}

Dataset ImportTum(const fs::path& source, const fs::path& out, const TumImportOptions& options,
                  const std::function<void(int, int)>& progress,
                  const std::function<void(const std::string&)>& note) {
  constexpr const char* kWhere = "ImportTum";
  options.Check();
  if (!fs::is_directory(source)) core::ThrowFileError(kWhere, source, "not a directory");
  const std::vector<TumStamped> rgb = ReadListFile(source / "rgb.txt");
  const std::vector<TumStamped> depth = ReadListFile(source / "depth.txt");
  std::vector<TumPose> trajectory;
  {
    std::ifstream in(source / "groundtruth.txt");
    if (!in) {
      core::ThrowFileError(kWhere, source / "groundtruth.txt",
                           "cannot open file (ibr imports sequences with ground-truth poses)");
    }
    trajectory = ReadTumTrajectory(in, (source / "groundtruth.txt").string());
  }

  // The sensor: given, or named in the sequence's folder name or its rgb.txt
  // header ("rgbd_dataset_freiburg3_cabinet").
  std::string spec = options.camera;
  if (spec.empty()) {
    std::string names = fs::absolute(source).lexically_normal().filename().string() + " ";
    std::ifstream in(source / "rgb.txt");
    for (std::string line; std::getline(in, line) && Comment(line);) names += line + " ";
    std::transform(names.begin(), names.end(), names.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (const char* n : {"1", "2", "3"}) {
      if (names.find(std::string("freiburg") + n) != std::string::npos ||
          names.find(std::string("fr") + n) != std::string::npos) {
        spec = std::string("fr") + n;
        break;
      }
    }
    if (spec.empty()) {
      core::ThrowFileError(kWhere, source,
                           "which TUM sensor took it? Neither the folder's name nor rgb.txt names "
                           "freiburg1/2/3: give --camera fr1|fr2|fr3 or FX,FY,CX,CY");
    }
    if (note)
      note(fmt::format("camera: TUM {} (from the sequence's name; --camera to change)", spec));
  }
  const core::ImageHeader first = core::ReadImageHeader(source / rgb.front().file);
  const Camera camera = TumCamera(spec, first.width, first.height);

  const auto pairs = AssociateTum(rgb, depth, options.max_difference);
  std::vector<RgbdFrame> frames;
  size_t no_pose = 0, taken = 0;
  for (const auto& [i, j] : pairs) {
    Rigid3 pose;
    if (!InterpolateTumPose(trajectory, rgb[i].time, options.max_pose_gap, pose)) {
      ++no_pose;
      continue;
    }
    if (taken++ % options.every != 0) continue;
    // The colour file's name without folder and extension: its timestamp.
    frames.push_back({fs::path(rgb[i].file).stem().string(), source / rgb[i].file,
                      source / depth[j].file, pose});
  }
  if (note) {
    note(fmt::format(
        "{} of {} colour images with depth within {:g} s and a pose{}{}{}", pairs.size() - no_pose,
        rgb.size(), options.max_difference,
        no_pose ? fmt::format(" ({} outside the ground truth's time or gaps over {:g} s)", no_pose,
                              options.max_pose_gap)
                : "",
        pairs.size() < rgb.size() ? fmt::format("; {} without depth", rgb.size() - pairs.size())
                                  : "",
        options.every > 1 ? fmt::format("; every {}th taken: {}", options.every, frames.size())
                          : ""));
  }
  if (frames.empty()) {
    core::ThrowFileError(kWhere, source,
                         "no colour image has a depth image within {:g} s and a ground-truth pose "
                         "(--max-difference, --max-pose-gap)",
                         options.max_difference);
  }
  return WriteRgbdFrames(frames, camera, options.depth_scale, options.bounds, out, progress, note);
}

}  // namespace capture
