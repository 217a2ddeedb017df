#include "capture/nerf_import.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/error.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "core/metrics.h"

namespace capture {
namespace fs = std::filesystem;
using nlohmann::json;

void NerfImportOptions::Check() const { choice.Check(); }

namespace {

// A finite number at `key` of `j` (the frame's, else the document's).
std::optional<double> Number(const json& top, const json& frame, const char* key,
                             const std::string& where) {
  const json* from = frame.contains(key) ? &frame : top.contains(key) ? &top : nullptr;
  if (!from) return std::nullopt;
  const json& v = from->at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    core::ThrowInputError(where, "\"{}\" is not a finite number", key);
  return v.get<double>();
}

}  // namespace

NerfFrame ParseNerfFrame(const json& top, const json& frame, int width, int height,
                         const std::string& where) {
  if (!frame.is_object()) core::ThrowInputError(where, "a frame is not an object");
  if (const auto w = Number(top, frame, "w", where)) width = static_cast<int>(*w);
  if (const auto h = Number(top, frame, "h", where)) height = static_cast<int>(*h);
  double fx = 0, fy = 0;
  if (const auto angle = Number(top, frame, "camera_angle_x", where)) {
    if (!(*angle > 0 && *angle < M_PI))
      core::ThrowInputError(where, "camera_angle_x {} outside (0, pi)", *angle);
    fx = fy = 0.5 * width / std::tan(0.5 * *angle);
  }
  if (const auto f = Number(top, frame, "fl_x", where)) fx = *f;
  if (const auto f = Number(top, frame, "fl_y", where)) fy = *f;
  if (fy == 0) fy = fx;
  if (!(fx > 0)) core::ThrowInputError(where, "no focal length (camera_angle_x or fl_x)");
  const double cx = Number(top, frame, "cx", where).value_or(0.5 * width);
  const double cy = Number(top, frame, "cy", where).value_or(0.5 * height);
  NerfFrame f;
  const double k1 = Number(top, frame, "k1", where).value_or(0),
               k2 = Number(top, frame, "k2", where).value_or(0),
               p1 = Number(top, frame, "p1", where).value_or(0),
               p2 = Number(top, frame, "p2", where).value_or(0);
  if (k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0) {
    f.camera.model = CameraModel::kOpenCv;
    f.camera.width = width;
    f.camera.height = height;
    f.camera.params = {fx, fy, cx, cy, k1, k2, p1, p2};
  } else {
    f.camera = Camera::Pinhole(width, height, fx, fy, cx, cy);
  }
  f.camera.Check(where);
  if (!frame.contains("transform_matrix"))
    core::ThrowInputError(where, "a frame has no \"transform_matrix\"");
  std::vector<std::vector<double>> m;
  try {
    m = frame.at("transform_matrix").get<std::vector<std::vector<double>>>();
  } catch (const json::exception&) {
    core::ThrowInputError(where, "\"transform_matrix\" is not a 4x4 array of numbers");
  }
  if (m.size() < 3 || m[0].size() != 4 || m[1].size() != 4 || m[2].size() != 4)
    core::ThrowInputError(where, "\"transform_matrix\" is not 4x4 (or 3x4)");
  // world_from_cam_gl (rows of the file) turned into ours: flip y and z.
  Rigid3 world_from_cam;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) world_from_cam.rotation[c][r] = m[r][c] * (c == 0 ? 1.0 : -1.0);
    world_from_cam.translation[r] = m[r][3];
  }
  // A scaled or mirrored matrix is refused; exporters write rotations to a
  // few digits only, so what passes is snapped to the nearest rotation.
  f.cam_from_world = world_from_cam.Inverse();
  f.cam_from_world.Check(where, 1e-2);
  f.cam_from_world.rotation = NearestRotation(f.cam_from_world.rotation);
  f.cam_from_world.translation = -f.cam_from_world.rotation * world_from_cam.translation;
  return f;
}

Dataset ImportNerf(const fs::path& source, const fs::path& out, const NerfImportOptions& options,
                   const std::function<void(int, int)>& progress,
                   const std::function<void(const std::string&)>& note) {
  constexpr const char* kWhere = "ImportNerf";
  options.Check();
  auto say = [&](const std::string& line) {
    if (note) note(line);
  };
  fs::path file = source;
  if (fs::is_directory(source)) {
    file = source / "transforms.json";
    if (!fs::exists(file) && fs::exists(source / "transforms_train.json")) {
      file = source / "transforms_train.json";
      say("reading transforms_train.json (no transforms.json; give a file to read another split)");
    }
  }
  if (!fs::is_regular_file(file)) core::ThrowFileError(kWhere, file, "does not exist");
  const std::string where = fmt::format("{}: '{}'", kWhere, file.string());
  json top;
  {
    std::ifstream in(file);
    try {
      top = json::parse(in);
    } catch (const json::exception& e) {
      core::ThrowInputError(where, "not valid JSON ({})", e.what());
    }
  }
  if (!top.is_object() || !top.contains("frames") || !top.at("frames").is_array())
    core::ThrowInputError(where, "no \"frames\" array");
  const json& frames = top.at("frames");
  if (frames.empty()) core::ThrowInputError(where, "\"frames\" is empty");
  if (frames.size() > kDatasetLimits.max_views)
    core::ThrowInputError(where, "{} frames; at most {}", frames.size(), kDatasetLimits.max_views);
  const fs::path root = file.parent_path();

  // Every frame's file_path, and its image: as given, else with .png or .jpg.
  std::vector<std::string> file_paths;
  for (const json& frame : frames) {
    if (!frame.is_object() || !frame.contains("file_path") || !frame.at("file_path").is_string())
      core::ThrowInputError(where, "a frame has no \"file_path\" string");
    file_paths.push_back(frame.at("file_path").get<std::string>());
  }
  auto image_of = [&](size_t i) -> fs::path {
    const fs::path p = root / file_paths[i];
    for (const fs::path& c : {p, fs::path(p.string() + ".png"), fs::path(p.string() + ".jpg")})
      if (fs::is_regular_file(c)) return c;
    return p;
  };
  const std::vector<size_t> chosen = options.choice.Apply(file_paths, where);

  struct Loaded {
    std::string name;
    NerfFrame frame;
    core::Image8 color, mask;
    core::ImageF depth;
  };
  // Every frame is held until the box is known: estimated first (colour,
  // mask and depth of each at the first image's size).
  {
    const core::ImageHeader first = core::ReadImageHeader(image_of(0));
    core::CheckMemory(
        frames.size() * static_cast<uint64_t>(first.width) * first.height * 8, "ibr import nerf",
        fmt::format("{} frames of {}x{} px", frames.size(), first.width, first.height));
  }
  std::vector<Loaded> views;
  std::vector<std::string> missing;
  for (size_t i : chosen) {
    const json& fr = frames[i];
    const fs::path image = image_of(i);
    if (!fs::is_regular_file(image)) {
      missing.push_back(image.string());
      continue;
    }
    Loaded v;
    v.name = image.stem().string();
    for (char& c : v.name)
      if (c == '/' || c == '\\' || c == '.') c = '_';
    const core::Image8 rgba = core::ReadImage<uint8_t>(image);
    v.frame = ParseNerfFrame(top, fr, rgba.width(), rgba.height(),
                             fmt::format("{}: frames[{}]", where, i));
    if (rgba.width() != v.frame.camera.width || rgba.height() != v.frame.camera.height) {
      core::ThrowFileError(kWhere, image, "image is {}x{}, the file says {}x{}", rgba.width(),
                           rgba.height(), v.frame.camera.width, v.frame.camera.height);
    }
    // Colour as read (the dataset writer drops an alpha channel); grey
    // (with or without alpha) as RGB.
    const int channels = rgba.channels();
    if (channels >= 3) {
      v.color = rgba;
    } else {
      v.color = core::Image8(rgba.width(), rgba.height(), 3);
      for (size_t p = 0; p < rgba.pixel_count(); ++p)
        for (int c = 0; c < 3; ++c) v.color.data()[3 * p + c] = rgba.data()[channels * p];
    }
    if (channels == 2 || channels == 4) {
      v.mask = core::Image8(rgba.width(), rgba.height(), 1);
      for (size_t p = 0; p < rgba.pixel_count(); ++p)
        v.mask.data()[p] = rgba.data()[channels * p + channels - 1] > 127 ? 255 : 0;
    } else if (fr.contains("mask_path") && fr.at("mask_path").is_string()) {
      const fs::path mp = root / fr.at("mask_path").get<std::string>();
      v.mask = core::ReadImage<uint8_t>(mp, 1);
      if (v.mask.width() != rgba.width() || v.mask.height() != rgba.height())
        core::ThrowFileError(kWhere, mp, "mask is {}x{}, its image {}x{}", v.mask.width(),
                             v.mask.height(), rgba.width(), rgba.height());
      for (uint8_t& m : v.mask.values()) m = m > 127 ? 255 : 0;
    }
    if (fr.contains("depth_file_path") && fr.at("depth_file_path").is_string()) {
      const fs::path dp = root / fr.at("depth_file_path").get<std::string>();
      const bool exr = dp.extension() == ".exr";
      const double scale =
          Number(top, fr, "depth_unit_scale_factor", where).value_or(exr ? 1.0 : 1e-3);
      if (exr) {
        v.depth = core::ReadImage<float>(dp, 1);
      } else {
        const core::Image<uint16_t> raw = core::ReadImage<uint16_t>(dp, 1);
        v.depth = core::ImageF(raw.width(), raw.height(), 1);
        for (size_t p = 0; p < raw.pixel_count(); ++p) v.depth.data()[p] = raw.data()[p];
      }
      if (v.depth.width() != rgba.width() || v.depth.height() != rgba.height())
        core::ThrowFileError(kWhere, dp, "depth is {}x{}, its image {}x{}", v.depth.width(),
                             v.depth.height(), rgba.width(), rgba.height());
      for (float& d : v.depth.values())
        d = std::isfinite(d) && d > 0 ? static_cast<float>(d * scale) : 0.0f;
    }
    if (v.frame.camera.distorted()) {
      const Camera distorted = v.frame.camera;
      v.color = UndistortImage(distorted, v.color);
      if (!v.mask.empty()) {
        v.mask = UndistortImage(distorted, v.mask);
        for (uint8_t& m : v.mask.values()) m = m > 127 ? 255 : 0;
      }
      if (!v.depth.empty())
        core::ThrowInputError(where, "frames[{}]: depth with a distorted camera is not supported",
                              i);
      v.frame.camera = UndistortedCamera(distorted);
    }
    views.push_back(std::move(v));
    if (progress) progress(static_cast<int>(views.size()), static_cast<int>(chosen.size()));
  }
  if (!missing.empty()) {
    say(fmt::format("warning: {} frame(s) left out, their image missing: {}{}", missing.size(),
                    missing.front(),
                    missing.size() > 1 ? fmt::format(" and {} more", missing.size() - 1) : ""));
  }
  if (views.empty()) core::ThrowInputError(where, "no frame left to import");

  // The region the cameras look at: the point nearest every optical axis,
  // and the half size a median camera sees at its distance.
  glm::dmat3 a(0.0);
  glm::dvec3 b(0.0);
  std::vector<double> reach;
  for (const Loaded& v : views) {
    const glm::dvec3 o = v.frame.cam_from_world.Centre();
    const glm::dvec3 d = glm::transpose(v.frame.cam_from_world.rotation) * glm::dvec3(0, 0, 1);
    const glm::dmat3 p = glm::dmat3(1.0) - glm::outerProduct(d, d);
    a += p;
    b += p * o;
  }
  glm::dvec3 centre(0.0);
  if (std::abs(glm::determinant(a)) > 1e-9) {
    centre = glm::inverse(a) * b;
  } else {
    for (const Loaded& v : views) centre += v.frame.cam_from_world.Centre() / double(views.size());
  }
  for (const Loaded& v : views) {
    const double dist = glm::length(v.frame.cam_from_world.Centre() - centre);
    reach.push_back(dist * 0.5 * v.frame.camera.width / v.frame.camera.fx());
  }
  const double half = core::Median(reach);
  Bounds region{centre - glm::dvec3(half), centre + glm::dvec3(half)};

  DatasetWriter writer(out);
  std::optional<Bounds> box;
  const bool masks =
      std::all_of(views.begin(), views.end(), [](const Loaded& v) { return !v.mask.empty(); });
  std::string from;
  if (masks) {
    // A coarse visual hull over the region.
    constexpr int kGrid = 64;
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    const double cell = 2 * half / kGrid;
    for (int z = 0; z < kGrid; ++z) {
      for (int y = 0; y < kGrid; ++y) {
        for (int x = 0; x < kGrid; ++x) {
          const glm::dvec3 p = region.min + cell * glm::dvec3(x + 0.5, y + 0.5, z + 0.5);
          // Inside every mask that sees it, and seen by half the views:
          // a voxel outside most frusta is constrained by too few.
          bool inside = true;
          size_t seen = 0;
          for (const Loaded& v : views) {
            const glm::dvec3 q = v.frame.cam_from_world * p;
            if (q.z <= 0) continue;
            const glm::dvec2 uv = v.frame.camera.Project(q);
            const int c = static_cast<int>(std::floor(uv.x)),
                      r = static_cast<int>(std::floor(uv.y));
            if (c < 0 || r < 0 || c >= v.mask.width() || r >= v.mask.height()) continue;
            ++seen;
            if (v.mask.at(c, r) == 0) {
              inside = false;
              break;
            }
          }
          if (!inside || 2 * seen < views.size()) continue;
          lo = glm::min(lo, p - 0.5 * cell);
          hi = glm::max(hi, p + 0.5 * cell);
        }
      }
    }
    if (lo.x <= hi.x) {
      const glm::dvec3 grow = 0.05 * (hi - lo) + cell;
      box = Bounds{lo - grow, hi + grow};
      from = "the masks' coarse visual hull";
    }
  }
  if (!box) {
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const Loaded& v : views) {
      if (v.depth.empty()) continue;
      const Rigid3 world_from_cam = v.frame.cam_from_world.Inverse();
      for (int r = 0; r < v.depth.height(); r += 4)
        for (int c = 0; c < v.depth.width(); c += 4)
          if (v.depth.at(c, r) > 0) {
            const glm::dvec3 p =
                world_from_cam * v.frame.camera.UnprojectPixel(c, r, v.depth.at(c, r));
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
          }
    }
    if (lo.x <= hi.x) {
      box = Bounds{lo, hi};
      from = "the depth points";
    }
  }
  if (!box) {
    box = region;
    from =
        "the region the cameras look at (no masks, no depth: give \"bounds\" in dataset.json if "
        "the object is smaller)";
  }
  std::vector<std::pair<Camera, int>> cameras;  // one id per distinct camera
  for (const Loaded& v : views) {
    auto it = std::find_if(cameras.begin(), cameras.end(),
                           [&](const auto& c) { return c.first == v.frame.camera; });
    if (it == cameras.end()) {
      cameras.emplace_back(v.frame.camera, writer.AddCamera(v.frame.camera));
      it = cameras.end() - 1;
    }
    writer.AddView(v.name, it->second, v.frame.cam_from_world, v.color, v.depth, v.mask, {});
  }
  writer.SetBounds(*box);
  writer.SetUp(MeanCameraUp(writer.dataset()).value_or(glm::dvec3(0, 0, 1)));
  const glm::dvec3 up = *writer.dataset().up;
  say(fmt::format("bounds ({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}) from {}", box->min.x,
                  box->min.y, box->min.z, box->max.x, box->max.y, box->max.z, from));
  say(
      fmt::format("up ({:.3f}, {:.3f}, {:.3f}) from the cameras; cameras converted from OpenGL "
                  "axes (y up, looking down -z) to x right, y down, z forward",
                  up.x, up.y, up.z));
  writer.Commit();
  return writer.dataset();
}

}  // namespace capture
