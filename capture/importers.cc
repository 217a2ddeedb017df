#include "capture/importers.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "capture/depth_scale.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/parse_number.h"

namespace capture {
namespace fs = std::filesystem;

void RedwoodImportOptions::Check() const {
  // 1e-3..1e6 depth units per metre: kilometres to micrometres.
  if (!(depth_scale >= 1e-3 && depth_scale <= 1e6)) {
    core::ThrowInputError("RedwoodImportOptions",
                          "--depth-scale {} outside 1e-3..1e6 (depth units per metre)",
                          depth_scale);
  }
  if (bounds) CheckBounds(*bounds, "--bounds");
}

void MiddleburyImportOptions::Check() const {
  if (!(threshold >= 0 && threshold <= 1)) {
    core::ThrowInputError("MiddleburyImportOptions", "--threshold {} outside [0, 1]", threshold);
  }
  if (dilate_iterations < 0 || erode_iterations < 0 || dilate_iterations > 100 ||
      erode_iterations > 100) {
    core::ThrowInputError("MiddleburyImportOptions", "dilate/erode iterations must be in 0..100");
  }
}

namespace {

std::ifstream Open(const fs::path& path, const char* where) {
  std::ifstream in(path, std::ios::binary);
  if (!in) core::ThrowFileError(where, path, "cannot open file");
  return in;
}

// The writer's "up" from its cameras (y down in every importer's source).
void SetMeanUp(DatasetWriter& writer, const std::function<void(const std::string&)>& note) {
  const glm::dvec3 up = MeanCameraUp(writer.dataset()).value_or(glm::dvec3(0, -1, 0));
  writer.SetUp(up);
  if (note) {
    note(fmt::format("up ({:.3f}, {:.3f}, {:.3f}) from the cameras (x axes level, image y down)",
                     up.x, up.y, up.z));
  }
}

// A view's depth kept for the bounds vote: every kStride-th pixel.
struct VoteMap {
  Rigid3 cam_from_world;
  core::ImageF depth;  // (width / kStride) x (height / kStride)
};
constexpr int kVoteStride = 8;

// The box around what most views agree on: points sampled from the voters'
// depth, kept where at least 30 % of the voters (and 2) measure a surface
// within 3 % of the point's depth there, then the 2nd-98th percentile of
// the kept points per axis, grown by 5 %. A room-scale sequence round an
// object gives the object and the floor beside it, not the room. nullopt
// when fewer than 3 voters or 100 kept points: the caller keeps every point.
std::optional<Bounds> AgreedBounds(const std::vector<VoteMap>& voters, const Camera& camera,
                                   size_t& kept_points, int& needed) {
  if (voters.size() < 3) return std::nullopt;
  needed = std::max(2, static_cast<int>(std::ceil(0.3 * voters.size())));
  const double s = kVoteStride;
  std::vector<glm::dvec3> kept;
  for (const VoteMap& from : voters) {
    const Rigid3 world_from_cam = from.cam_from_world.Inverse();
    for (int r = 0; r < from.depth.height(); r += 2) {
      for (int c = 0; c < from.depth.width(); c += 2) {
        const float z = from.depth.at(c, r);
        if (!(z > 0)) continue;
        const glm::dvec3 p = world_from_cam * camera.Unproject({(c + 0.5) * s, (r + 0.5) * s}, z);
        int agree = 0;
        for (const VoteMap& v : voters) {
          const glm::dvec3 q = v.cam_from_world * p;
          if (q.z <= 0) continue;
          const glm::dvec2 uv = camera.Project(q) / s;
          const int x = static_cast<int>(std::floor(uv.x)), y = static_cast<int>(std::floor(uv.y));
          if (x < 0 || y < 0 || x >= v.depth.width() || y >= v.depth.height()) continue;
          const float d = v.depth.at(x, y);
          agree += d > 0 && std::abs(d - q.z) < 0.03 * q.z;
        }
        if (agree >= needed) kept.push_back(p);
      }
    }
  }
  kept_points = kept.size();
  if (kept.size() < 100) return std::nullopt;
  return RobustBounds(kept, 2, 0.05);
}

}  // namespace

std::vector<double> ParseNumbers(const std::string& line, const std::string& where,
                                 int line_number) {
  std::istringstream s(line);
  std::vector<double> v;
  std::string tok;
  while (s >> tok) {
    const std::optional<double> x = core::ParseFiniteNumber(tok);
    if (!x) core::ThrowInputError(where, "line {}: '{}' is not a finite number", line_number, tok);
    v.push_back(*x);
  }
  return v;
}

std::vector<Rigid3> ReadRedwoodLog(std::istream& in, const std::string& name) {
  const std::string where = fmt::format("ReadRedwoodLog: '{}'", name);
  std::vector<Rigid3> poses;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (ParseNumbers(line, where, line_number).empty()) continue;
    const auto header = ParseNumbers(line, where, line_number);
    if (header.size() != 3)
      core::ThrowInputError(where, "line {}: expected \"i j n\", got {} numbers", line_number,
                            header.size());
    glm::dmat4 world_from_cam(1.0);
    for (int r = 0; r < 4; ++r) {
      if (!std::getline(in, line))
        core::ThrowInputError(where, "truncated: matrix row {} missing after line {}", r,
                              line_number);
      ++line_number;
      const auto row = ParseNumbers(line, where, line_number);
      if (row.size() != 4)
        core::ThrowInputError(where, "line {}: expected 4 numbers, got {}", line_number,
                              row.size());
      for (int c = 0; c < 4; ++c) world_from_cam[c][r] = row[c];
    }
    const Rigid3 pose = Rigid3::FromMat4(world_from_cam).Inverse();
    pose.Check(fmt::format("{}: frame {}", where, poses.size()), 1e-5);
    poses.push_back(pose);
  }
  if (poses.empty()) core::ThrowInputError(where, "no poses");
  return poses;
}

Camera ReadRedwoodIntrinsics(std::istream& in, const std::string& name) {
  const std::string where = fmt::format("ReadRedwoodIntrinsics: '{}'", name);
  int width = 0, height = 0;
  std::vector<double> k;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const char* key : {"width", "height"}) {
      if (!j.at(key).is_number_integer() || j.at(key).get<int64_t>() < 1 ||
          j.at(key).get<int64_t>() > 1 << 20) {
        core::ThrowInputError(where, "\"{}\" must be an integer image size, not {}", key,
                              j.at(key).dump());
      }
    }
    width = j.at("width").get<int>();
    height = j.at("height").get<int>();
    k = j.at("intrinsic_matrix").get<std::vector<double>>();
  } catch (const nlohmann::json::exception& e) {
    core::ThrowInputError(where, "bad intrinsics JSON: {}", e.what());
  }
  if (k.size() != 9)
    core::ThrowInputError(where, "intrinsic_matrix has {} numbers, expected 9", k.size());
  // Column-major 3x3: fx = k[0], fy = k[4], cx = k[6], cy = k[7]; Open3D's
  // integer pixel centres -> +0.5 in ours.
  const Camera camera = Camera::Pinhole(width, height, k[0], k[4], k[6] + 0.5, k[7] + 0.5);
  camera.Check(where);
  return camera;
}

std::optional<Bounds> ReadMiddleburyBounds(std::istream& in, const std::string& name) {
  const std::string where = fmt::format("ReadMiddleburyBounds: '{}'", name);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // "(x y z)" at `at`: the three tokens between the parentheses, or nothing
  // (a scan, not std::regex, whose recursion grows with the input).
  auto triple = [&](size_t at, size_t& end) -> std::optional<std::vector<std::string>> {
    if (at >= text.size() || text[at] != '(') return std::nullopt;
    // The next parenthesis of either kind: a '(' first means no triple here
    // (its tokens could not pass the check below), and stopping there keeps
    // the scan linear on inputs of many '(' and one late ')'.
    end = text.find_first_of("()", at + 1);
    if (end == std::string::npos || text[end] != ')') return std::nullopt;
    std::istringstream s(text.substr(at + 1, end - at - 1));
    std::vector<std::string> tokens;
    for (std::string t; s >> t;) tokens.push_back(t);
    if (tokens.size() != 3) return std::nullopt;
    for (const std::string& t : tokens) {
      if (t.find_first_not_of("-0123456789.eE+") != std::string::npos) return std::nullopt;
    }
    return tokens;
  };
  for (size_t at = text.find('('); at != std::string::npos; at = text.find('(', at + 1)) {
    size_t end = 0, end2 = 0;
    const auto lo = triple(at, end);
    if (!lo) continue;
    const size_t next = text.find_first_not_of(" \t\r\n", end + 1);
    const auto hi = next == std::string::npos ? std::nullopt : triple(next, end2);
    if (!hi) continue;
    double v[6];
    for (int i = 0; i < 6; ++i) {
      // The tokens may still be "-", "e" or "1e999": each must be one finite number.
      const std::string& t = i < 3 ? (*lo)[i] : (*hi)[i - 3];
      const std::vector<double> one = ParseNumbers(t, where, 1);
      if (one.size() != 1) core::ThrowInputError(where, "bounding box number '{}'", t);
      v[i] = one[0];
    }
    const Bounds bounds{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    CheckBounds(bounds, where);
    return bounds;
  }
  return std::nullopt;
}

Dataset WriteRgbdFrames(const std::vector<RgbdFrame>& frames, const Camera& camera,
                        double depth_scale, const std::optional<Bounds>& bounds,
                        const fs::path& out, const std::function<void(int, int)>& progress,
                        const std::function<void(const std::string&)>& note) {
  constexpr const char* kWhere = "WriteRgbdFrames";
  if (frames.empty()) core::ThrowInputError(kWhere, "no frames to import");
  const int width = camera.width, height = camera.height;
  // A distorted sensor (TUM fr1, fr2): colour resampled bilinearly into the
  // pinhole camera, depth by its nearest sample (a blend of two depths
  // across an edge is a point on neither surface).
  const Camera pinhole = camera.distorted() ? UndistortedCamera(camera) : camera;
  const core::ImageF map = camera.distorted() ? UndistortionMap(camera) : core::ImageF();
  if (note && camera.distorted()) {
    note(fmt::format("undistorting {} into PINHOLE fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}",
                     CameraModelName(camera.model), pinhole.fx(), pinhole.fy(), pinhole.cx(),
                     pinhole.cy()));
  }
  DatasetWriter writer(out);
  writer.SetDepthUnits("m");
  const int cam_id = writer.AddCamera(pinhole);
  // Every valid sensor point's box, and at most 64 frames spread over the
  // sequence kept small for the vote on the object's box (AgreedBounds).
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  std::vector<VoteMap> voters;
  const size_t vote_every = (frames.size() + 63) / 64;
  for (size_t i = 0; i < frames.size(); ++i) {
    const RgbdFrame& f = frames[i];
    core::Image<uint16_t> raw = core::ReadImage<uint16_t>(f.depth, 1);
    core::Image8 color = core::ReadImage<uint8_t>(f.color, 3);
    if (raw.width() != width || raw.height() != height) {
      core::ThrowFileError(kWhere, f.depth, "depth is {}x{}, camera is {}x{}", raw.width(),
                           raw.height(), width, height);
    }
    if (color.width() != width || color.height() != height) {
      core::ThrowFileError(kWhere, f.color, "colour is {}x{}, camera is {}x{}", color.width(),
                           color.height(), width, height);
    }
    if (camera.distorted()) {
      color = UndistortImage(camera, color);
      core::Image<uint16_t> undistorted(width, height, 1);
      for (int row = 0; row < height; ++row) {
        for (int col = 0; col < width; ++col) {
          // Sparse convention: pixel (c, r) spans [c, c + 1).
          const int sc = static_cast<int>(std::floor(map.at(col, row, 0)));
          const int sr = static_cast<int>(std::floor(map.at(col, row, 1)));
          undistorted.at(col, row) =
              sc >= 0 && sr >= 0 && sc < width && sr < height ? raw.at(sc, sr) : 0;
        }
      }
      raw = std::move(undistorted);
    }
    core::ImageF depth(width, height, 1);
    core::Image8 mask(width, height, 1);
    const Rigid3 world_from_cam = f.cam_from_world.Inverse();
    for (int row = 0; row < height; ++row) {
      for (int col = 0; col < width; ++col) {
        const size_t p = static_cast<size_t>(row) * width + col;
        depth.data()[p] = static_cast<float>(raw.data()[p] / depth_scale);
        mask.data()[p] = raw.data()[p] > 0 ? 255 : 0;
        if (raw.data()[p] == 0) continue;
        const glm::dvec3 p_in_world =
            world_from_cam * pinhole.UnprojectPixel(col, row, depth.data()[p]);
        lo = glm::min(lo, p_in_world);
        hi = glm::max(hi, p_in_world);
      }
    }
    if (i % vote_every == 0) {
      VoteMap v{f.cam_from_world, core::ImageF(width / kVoteStride, height / kVoteStride, 1)};
      for (int r = 0; r < v.depth.height(); ++r) {
        for (int c = 0; c < v.depth.width(); ++c) {
          v.depth.at(c, r) =
              depth.at(c * kVoteStride + kVoteStride / 2, r * kVoteStride + kVoteStride / 2);
        }
      }
      voters.push_back(std::move(v));
    }
    writer.AddView(f.name, cam_id, f.cam_from_world, color, depth, mask, {});
    if (progress) progress(static_cast<int>(i) + 1, static_cast<int>(frames.size()));
  }
  if (!(lo.x <= hi.x)) {
    core::ThrowFileError(kWhere, frames.front().depth.parent_path(),
                         "no valid depth pixel in any frame");
  }
  size_t kept = 0;
  int needed = 0;
  const Bounds all{lo, hi};
  const std::optional<Bounds> agreed =
      bounds ? std::nullopt : AgreedBounds(voters, pinhole, kept, needed);
  const Bounds box = bounds ? *bounds : agreed.value_or(all);
  writer.SetBounds(box);
  if (note) {
    note(fmt::format(
        "bounds ({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}) m: {}", box.min.x, box.min.y,
        box.min.z, box.max.x, box.max.y, box.max.z,
        bounds ? std::string("given (--bounds)")
        : agreed
            ? fmt::format("where at least {} of {} frames agree on a surface ({} points; every "
                          "point spans ({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}); "
                          "--bounds to give one)",
                          needed, voters.size(), kept, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z)
            : std::string("every valid point (too few frames agree for a tighter box; --bounds "
                          "to give one)")));
  }
  SetMeanUp(writer, note);
  writer.Commit();
  const DepthScaleReport scale = CheckDepthScale(writer.dataset());
  if (note && !scale.warning.empty()) {
    note(scale.suggested_factor > 0
             ? fmt::format("warning: {} (import with --depth-scale {:g} instead of {:g})",
                           scale.warning, depth_scale / scale.suggested_factor, depth_scale)
             : fmt::format("warning: {} (is --depth-scale {:g} the sensor's units per metre?)",
                           scale.warning, depth_scale));
  } else if (note) {
    note(fmt::format("depth: median {:.3g} m over {} frame(s){}", scale.median, scale.views,
                     scale.agreement >= 0 ? fmt::format(", {:.0f} % of samples agree between views",
                                                        100 * scale.agreement)
                                          : ""));
  }
  return writer.dataset();
}

Dataset ImportRedwood(const fs::path& source, const fs::path& out,
                      const RedwoodImportOptions& options,
                      const std::function<void(int, int)>& progress,
                      const std::function<void(const std::string&)>& note) {
  constexpr const char* kWhere = "ImportRedwood";
  options.Check();
  if (!fs::is_directory(source)) core::ThrowFileError(kWhere, source, "not a directory");
  const fs::path intrinsics_path = source / "camera_primesense.json";
  auto in = Open(intrinsics_path, kWhere);
  const Camera camera = ReadRedwoodIntrinsics(in, intrinsics_path.string());
  auto log = Open(source / "trajectory.log", kWhere);
  const std::vector<Rigid3> poses = ReadRedwoodLog(log, (source / "trajectory.log").string());

  std::vector<fs::path> colors;
  if (fs::is_directory(source / "color")) {
    for (const auto& e : fs::directory_iterator(source / "color")) colors.push_back(e.path());
  }
  std::sort(colors.begin(), colors.end());
  if (colors.empty()) core::ThrowFileError(kWhere, source / "color", "no colour images");
  if (colors.size() != poses.size()) {
    core::ThrowFileError(kWhere, source / "trajectory.log", "{} poses for {} colour images",
                         poses.size(), colors.size());
  }
  std::vector<RgbdFrame> frames;
  for (size_t i = 0; i < colors.size(); ++i) {
    const std::string stem = colors[i].stem().string();
    frames.push_back({stem, colors[i], source / "depth" / (stem + ".png"), poses[i]});
  }
  return WriteRgbdFrames(frames, camera, options.depth_scale, options.bounds, out, progress, note);
}

std::vector<MiddleburyView> ReadMiddleburyPar(std::istream& in, const std::string& name) {
  const std::string where = fmt::format("ReadMiddleburyPar: '{}'", name);
  std::string line;
  int line_number = 0;
  std::vector<MiddleburyView> views;
  std::optional<size_t> declared;
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream s(line);
    std::string first;
    if (!(s >> first)) continue;
    if (!declared) {
      const auto n = ParseNumbers(line, where, line_number);
      // Bounded before the cast: a huge count would overflow size_t.
      if (n.size() != 1 || n[0] < 1 || n[0] > 1e6 || n[0] != std::floor(n[0])) {
        core::ThrowInputError(where, "line {}: expected the image count (1..1000000)", line_number);
      }
      declared = static_cast<size_t>(n[0]);
      continue;
    }
    std::string rest;
    std::getline(s, rest);
    const auto v = ParseNumbers(rest, where, line_number);
    if (v.size() != 21)
      core::ThrowInputError(where, "line {}: expected name + 21 numbers, got {}", line_number,
                            v.size());
    if (std::abs(v[1]) > 1e-9 || std::abs(v[3]) > 1e-9 || std::abs(v[6]) > 1e-9 ||
        std::abs(v[7]) > 1e-9 || v[8] != 1) {
      core::ThrowInputError(where, "line {}: K is not [fx 0 cx; 0 fy cy; 0 0 1]", line_number);
    }
    MiddleburyView view;
    view.image = first;
    view.camera = Camera::Pinhole(1, 1, v[0], v[4], v[2] + 0.5, v[5] + 0.5);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) view.cam_from_world.rotation[c][r] = v[9 + 3 * r + c];
      view.cam_from_world.translation[r] = v[18 + r];
    }
    view.cam_from_world.Check(fmt::format("{}: line {}", where, line_number), 1e-5);
    // The file's 17-digit rotations are orthonormal only to ~1e-6 (dinoSR0001:
    // R^T R off by 1.4e-6, beyond Dataset's 1e-6 check): snap to the nearest
    // rotation (changes entries by ~1e-6).
    view.cam_from_world.rotation = NearestRotation(view.cam_from_world.rotation);
    views.push_back(view);
  }
  if (!declared) core::ThrowInputError(where, "empty file");
  if (views.size() != *declared)
    core::ThrowInputError(where, "declares {} images, has {}", *declared, views.size());
  return views;
}

Dataset ImportMiddlebury(const fs::path& source, const fs::path& out,
                         const MiddleburyImportOptions& options,
                         const std::function<void(int, int)>& progress) {
  constexpr const char* kWhere = "ImportMiddlebury";
  options.Check();
  if (!fs::is_directory(source)) core::ThrowFileError(kWhere, source, "not a directory");
  fs::path par;
  for (const auto& e : fs::directory_iterator(source)) {
    if (e.path().string().ends_with("_par.txt")) par = e.path();
  }
  if (par.empty()) core::ThrowFileError(kWhere, source, "no *_par.txt camera file");
  auto in = Open(par, kWhere);
  std::vector<MiddleburyView> views = ReadMiddleburyPar(in, par.string());
  std::sort(views.begin(), views.end(),
            [](const auto& a, const auto& b) { return a.image < b.image; });

  DatasetWriter writer(out);
  // README.txt: "(x y z)\n(x y z)" after "bounding box".
  if (std::ifstream readme(source / "README.txt"); readme) {
    if (const auto box = ReadMiddleburyBounds(readme, (source / "README.txt").string()))
      writer.SetBounds(*box);
  }
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  for (size_t i = 0; i < views.size(); ++i) {
    MiddleburyView& v = views[i];
    const fs::path image_path = source / v.image;
    core::Image8 color = core::ReadImage<uint8_t>(image_path, 3);
    v.camera.width = color.width();
    v.camera.height = color.height();
    v.camera.Check(fmt::format("{}: '{}'", kWhere, par.string()));
    const cv::Mat rgb(color.height(), color.width(), CV_8UC3, color.data());
    cv::Mat grey, mask_mat;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    cv::threshold(grey, mask_mat, options.threshold * 255.0, 255, cv::THRESH_BINARY);
    if (options.dilate_iterations > 0)
      cv::dilate(mask_mat, mask_mat, kernel, {-1, -1}, options.dilate_iterations);
    if (options.erode_iterations > 0)
      cv::erode(mask_mat, mask_mat, kernel, {-1, -1}, options.erode_iterations);
    core::Image8 mask(color.width(), color.height(), 1);
    for (int r = 0; r < mask.height(); ++r) {
      for (int c = 0; c < mask.width(); ++c) mask.at(c, r) = mask_mat.at<uint8_t>(r, c);
    }
    const int cam_id = writer.AddCamera(v.camera);
    writer.AddView(fs::path(v.image).stem().string(), cam_id, v.cam_from_world, color, {}, mask,
                   {});
    if (progress) progress(static_cast<int>(i) + 1, static_cast<int>(views.size()));
  }
  SetMeanUp(writer, {});
  writer.Commit();
  return writer.dataset();
}

}  // namespace capture
