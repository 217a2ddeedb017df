#include "capture/colmap_dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_io.h"

namespace capture {
namespace fs = std::filesystem;

void ColmapExportOptions::Check() const {
  if (point_step_px < 1 || point_step_px > 4096) {
    core::ThrowInputError("ColmapExportOptions", "point_step_px {} outside 1..4096", point_step_px);
  }
  if (!(visibility_tolerance > 0 && visibility_tolerance < 1)) {
    core::ThrowInputError("ColmapExportOptions", "visibility_tolerance {} outside (0, 1)",
                          visibility_tolerance);
  }
}

void ColmapImportOptions::Check() const {
  if (input_type != "auto" && input_type != "geometric" && input_type != "photometric") {
    core::ThrowInputError("ColmapImportOptions",
                          "input type '{}' is not auto, geometric or photometric", input_type);
  }
  choice.Check();
  if (!(bounds_percentile >= 0 && bounds_percentile < 50)) {
    core::ThrowInputError("ColmapImportOptions", "bounds percentile {} outside [0, 50)",
                          bounds_percentile);
  }
  if (!(bounds_margin >= 0 && bounds_margin <= 10)) {
    core::ThrowInputError("ColmapImportOptions", "bounds margin {} outside [0, 10]", bounds_margin);
  }
}

namespace {

bool Valid(float d) { return std::isfinite(d) && d > 0; }

// Camera-frame unit normals facing the camera, from the dataset's world
// normals or, without them, from depth differences.
core::ImageF CameraNormals(const Dataset& dataset, size_t i, const core::ImageF& depth) {
  const DatasetView& view = dataset.views[i];
  const Camera& cam = dataset.camera(view);
  const glm::dmat3& r = view.cam_from_world.rotation;
  core::ImageF out(cam.width, cam.height, 3);
  core::ImageF world;
  if (!view.normal.empty()) world = dataset.LoadNormal(i);
  for (int row = 0; row < cam.height; ++row) {
    for (int col = 0; col < cam.width; ++col) {
      const float d = depth.at(col, row);
      if (!Valid(d)) continue;
      glm::dvec3 n(0, 0, -1);
      if (!world.empty()) {
        n = r * glm::dvec3(world.at(col, row, 0), world.at(col, row, 1), world.at(col, row, 2));
      } else if (col > 0 && row > 0 && col + 1 < cam.width && row + 1 < cam.height) {
        const float l = depth.at(col - 1, row), rr = depth.at(col + 1, row);
        const float u = depth.at(col, row - 1), dn = depth.at(col, row + 1);
        if (Valid(l) && Valid(rr) && Valid(u) && Valid(dn)) {
          const glm::dvec3 dx =
              cam.UnprojectPixel(col + 1, row, rr) - cam.UnprojectPixel(col - 1, row, l);
          const glm::dvec3 dy =
              cam.UnprojectPixel(col, row + 1, dn) - cam.UnprojectPixel(col, row - 1, u);
          const glm::dvec3 c = glm::cross(dx, dy);
          if (glm::length(c) > 0) n = c;
        }
      }
      if (!(glm::length(n) > 0)) n = {0, 0, -1};
      n = glm::normalize(n);
      if (glm::dot(n, cam.UnprojectPixel(col, row, 1.0)) > 0) n = -n;
      for (int c = 0; c < 3; ++c) out.at(col, row, c) = static_cast<float>(n[c]);
    }
  }
  return out;
}

}  // namespace

void ExportColmapWorkspace(const Dataset& dataset, const fs::path& workspace,
                           const ColmapExportOptions& options,
                           const std::function<void(int, int)>& progress) {
  constexpr const char* kWhere = "ExportColmapWorkspace";
  options.Check();
  dataset.Check(kWhere);
  std::vector<size_t> views;
  for (size_t i = 0; i < dataset.views.size(); ++i) {
    const DatasetView& v = dataset.views[i];
    if (dataset.camera(v).orthographic()) {
      core::ThrowInputError(
          kWhere,
          "view '{}' has an orthographic camera: COLMAP has no orthographic model "
          "(capture with a ring:N or sphere:N rig)",
          v.name);
    }
    if (v.depth.empty())
      core::ThrowInputError(kWhere, "view '{}' has no depth: a dense workspace needs depth",
                            v.name);
    views.push_back(i);
  }
  core::StagedDirectory staged(workspace);
  const fs::path ws = staged.path();
  for (const char* d : {"images", "sparse", "stereo/depth_maps", "stereo/normal_maps",
                        "stereo/consistency_graphs"}) {
    fs::create_directories(ws / d);
  }
  colmap::SparseModel model;
  std::vector<core::ImageF> depths;
  std::vector<core::Image8> colors;
  std::vector<std::string> names;
  for (size_t k = 0; k < views.size(); ++k) {
    const size_t i = views[k];
    const DatasetView& view = dataset.views[i];
    const Camera& cam = dataset.camera(view);
    const std::string name = view.name + ".png";
    names.push_back(name);
    colors.push_back(dataset.LoadColor(i));
    depths.push_back(dataset.LoadDepth(i));
    core::ImageF& depth = depths.back();
    for (float& d : depth.values())
      if (!Valid(d)) d = 0;  // COLMAP: <= 0 invalid; no NaN
    core::WriteImage(ws / "images" / name, colors.back());
    const core::ImageF normals = CameraNormals(dataset, i, depth);
    for (const char* type : {"geometric", "photometric"}) {
      colmap::WriteDenseMap(ws / "stereo/depth_maps" / fmt::format("{}.{}.bin", name, type), depth);
      colmap::WriteDenseMap(ws / "stereo/normal_maps" / fmt::format("{}.{}.bin", name, type),
                            normals);
    }
    const uint32_t camera_id = static_cast<uint32_t>(view.camera_id);
    if (!model.cameras.contains(camera_id)) {
      const Camera dense = DenseFromCamera(cam);
      model.cameras.emplace(camera_id, Camera::Pinhole(cam.width, cam.height, dense.fx(),
                                                       dense.fy(), dense.cx(), dense.cy()));
    }
    colmap::Image image;
    image.image_id = static_cast<uint32_t>(k + 1);
    image.qvec = view.cam_from_world.Quaternion();
    image.tvec = {view.cam_from_world.translation.x, view.cam_from_world.translation.y,
                  view.cam_from_world.translation.z};
    image.camera_id = camera_id;
    image.name = name;
    model.images.emplace(image.image_id, image);
    if (progress) progress(static_cast<int>(k) + 1, static_cast<int>(views.size()));
  }
  // Sparse points with tracks: stereo_fusion builds its image overlap graph
  // from shared sparse points (COLMAP-FORMATS.md).
  uint64_t next_point = 1;
  for (size_t k = 0; k < views.size(); ++k) {
    const DatasetView& view = dataset.views[views[k]];
    const Camera& cam = dataset.camera(view);
    const Rigid3 world_from_cam = view.cam_from_world.Inverse();
    for (int row = options.point_step_px / 2; row < cam.height; row += options.point_step_px) {
      for (int col = options.point_step_px / 2; col < cam.width; col += options.point_step_px) {
        const float d = depths[k].at(col, row);
        if (!Valid(d)) continue;
        const glm::dvec3 p = world_from_cam * cam.UnprojectPixel(col, row, d);
        colmap::Point3D point;
        point.point3D_id = next_point;
        point.xyz = {p.x, p.y, p.z};
        for (int c = 0; c < 3; ++c) point.rgb[c] = colors[k].at(col, row, c);
        for (size_t j = 0; j < views.size(); ++j) {
          const DatasetView& other = dataset.views[views[j]];
          const Camera& oc = dataset.camera(other);
          const glm::dvec3 q = other.cam_from_world * p;
          if (!(q.z > 0)) continue;
          const glm::dvec2 uv = oc.Project(q);
          const int c2 = static_cast<int>(std::floor(uv.x)),
                    r2 = static_cast<int>(std::floor(uv.y));
          if (c2 < 0 || r2 < 0 || c2 >= oc.width || r2 >= oc.height) continue;
          const float od = depths[j].at(c2, r2);
          if (!Valid(od) || std::abs(od - q.z) > options.visibility_tolerance * q.z) continue;
          colmap::Image& im = model.images.at(static_cast<uint32_t>(j + 1));
          point.track.push_back({im.image_id, static_cast<uint32_t>(im.points2D.size())});
          // Keypoint in the exported (dense-shifted) camera: u - 0.5.
          im.points2D.push_back({uv.x - 0.5, uv.y - 0.5, point.point3D_id});
        }
        if (point.track.size() < 2) {
          // Not shared: drop the observations just added (only its own view).
          for (const auto& el : point.track) model.images.at(el.image_id).points2D.pop_back();
          continue;
        }
        model.points3D.emplace(next_point++, std::move(point));
      }
    }
  }
  if (model.points3D.empty()) {
    core::ThrowInputError(
        kWhere, "no 3D point is seen by two views: colmap stereo_fusion would fuse nothing");
  }
  model.Check(kWhere);
  colmap::WriteSparseModel(ws / "sparse", model, options.format);
  core::AtomicWriteStream(ws / "stereo/fusion.cfg",
                          [&](std::ostream& o) { colmap::WriteFusionConfig(o, names); });
  std::vector<colmap::PatchMatchEntry> entries;
  for (const auto& n : names) entries.push_back({n, "__auto__, 20"});
  core::AtomicWriteStream(ws / "stereo/patch-match.cfg",
                          [&](std::ostream& o) { colmap::WritePatchMatchConfig(o, entries); });
  staged.Commit();
}

namespace {

fs::path FindSparseDir(const fs::path& source) {
  for (const fs::path& candidate : {source / "sparse" / "0", source / "sparse", source}) {
    if (colmap::IsSparseModelDir(candidate)) return candidate;
  }
  core::ThrowFileError(
      "ImportColmap", source,
      "no COLMAP model (cameras.bin/.txt) in sparse/0, sparse/ or the folder itself");
}

// The mask of photo `name` in `dir`: NAME.png (COLMAP's ImageReader.mask_path
// convention), NAME, or NAME's stem + ".png"; empty path when none exists.
fs::path FindMask(const fs::path& dir, const std::string& name) {
  for (const fs::path& candidate :
       {dir / (name + ".png"), dir / name, dir / fs::path(name).replace_extension(".png")}) {
    if (fs::is_regular_file(candidate)) return candidate;
  }
  return {};
}

std::string FormatBox(const Bounds& b) {
  return fmt::format("min ({:.4g}, {:.4g}, {:.4g}) max ({:.4g}, {:.4g}, {:.4g})", b.min.x, b.min.y,
                     b.min.z, b.max.x, b.max.y, b.max.z);
}

}  // namespace

Dataset ImportColmap(const fs::path& source, const fs::path& out,
                     const ColmapImportOptions& options,
                     const std::function<void(int, int)>& progress,
                     const std::function<void(const std::string&)>& note) {
  constexpr const char* kWhere = "ImportColmap";
  options.Check();
  if (!fs::is_directory(source)) core::ThrowFileError(kWhere, source, "not a directory");
  const bool dense = fs::is_directory(source / "stereo" / "depth_maps");
  const fs::path sparse_dir = dense ? source / "sparse" : FindSparseDir(source);
  const colmap::SparseModel model = colmap::ReadSparseModel(sparse_dir);
  if (model.images.empty())
    core::ThrowFileError(kWhere, sparse_dir, "model has no registered images");
  const fs::path images_dir = options.images.empty() ? source / "images" : options.images;
  if (!fs::is_directory(images_dir))
    core::ThrowFileError(kWhere, images_dir, "image folder does not exist");
  if (!options.masks.empty() && dense) {
    core::ThrowFileError(kWhere, options.masks,
                         "--masks is for sparse models: a dense workspace's masks are its valid "
                         "depth");
  }
  if (!options.masks.empty() && !fs::is_directory(options.masks))
    core::ThrowFileError(kWhere, options.masks, "mask folder does not exist");
  // Dense workspaces without sparse points: the box from sampled depth.
  std::vector<glm::dvec3> depth_points;

  const auto say = [&](const std::string& line) {
    if (note) note(line);
  };
  // Which dense maps: geometric where any exist (COLMAP's consistent ones),
  // else the photometric ones a workspace without geometric consistency has.
  std::string input_type = options.input_type;
  if (dense) {
    auto any_of_type = [&](const std::string& type) {
      for (const auto& e : fs::directory_iterator(source / "stereo" / "depth_maps")) {
        const std::string n = e.path().filename().string();
        if (n.size() > type.size() + 5 && n.ends_with("." + type + ".bin")) return true;
      }
      return false;
    };
    const bool geometric = any_of_type("geometric"), photometric = any_of_type("photometric");
    if (input_type == "auto") {
      input_type = geometric || !photometric ? "geometric" : "photometric";
      if (input_type == "photometric") {
        say("warning: the workspace has photometric depth maps only (no geometric consistency "
            "pass): they are noisier; using them");
      }
    } else if (!any_of_type(input_type)) {
      core::ThrowFileError(
          kWhere, source / "stereo" / "depth_maps", "no {} depth maps{}", input_type,
          (input_type == "geometric" ? photometric : geometric)
              ? fmt::format(" (there are {} ones: --input-type {})",
                            input_type == "geometric" ? "photometric" : "geometric",
                            input_type == "geometric" ? "photometric" : "geometric")
              : "");
    }
  }

  // Image order by name; --views / --hold-out choose among them.
  std::vector<const colmap::Image*> order;
  for (const auto& [id, im] : model.images) order.push_back(&im);
  std::sort(order.begin(), order.end(), [](auto* a, auto* b) { return a->name < b->name; });
  if (!options.choice.views.empty() || !options.choice.hold_out.empty()) {
    std::vector<std::string> names;
    for (const colmap::Image* im : order) names.push_back(im->name);
    std::vector<const colmap::Image*> kept;
    for (size_t i :
         options.choice.Apply(names, fmt::format("{}: '{}'", kWhere, sparse_dir.string())))
      kept.push_back(order[i]);
    order = std::move(kept);
    say(fmt::format("{} of {} photos chosen ({})", order.size(), model.images.size(),
                    options.choice.views.empty() ? "--hold-out" : "--views"));
  }
  // Photos whose image or depth map is missing are left out (a partial
  // workspace), each named; an import left with none is an error.
  std::vector<std::string> missing;
  std::erase_if(order, [&](auto* im) {
    fs::path need = images_dir / im->name;
    if (fs::exists(need) && dense) {
      need = source / "stereo/depth_maps" / fmt::format("{}.{}.bin", im->name, input_type);
    }
    if (fs::exists(need)) return false;
    missing.push_back(need.string());
    return true;
  });
  if (!missing.empty()) {
    say(fmt::format("warning: {} of {} photos left out, a file missing: {}{}", missing.size(),
                    missing.size() + order.size(), missing.front(),
                    missing.size() > 1 ? fmt::format(" and {} more", missing.size() - 1) : ""));
  }
  if (order.empty()) {
    core::ThrowFileError(
        kWhere, source, "no photo left to import{}",
        missing.empty() ? "" : fmt::format(" (first missing: {})", missing.front()));
  }

  DatasetWriter writer(out);
  std::map<uint32_t, int> camera_ids;
  for (size_t k = 0; k < order.size(); ++k) {
    const colmap::Image& im = *order[k];
    const Camera& colmap_cam = model.cameras.at(im.camera_id);
    const fs::path image_path = images_dir / im.name;
    core::Image8 color = core::ReadImage<uint8_t>(image_path);
    if (color.width() != colmap_cam.width || color.height() != colmap_cam.height) {
      core::ThrowFileError(kWhere, image_path, "image is {}x{}, its camera {} is {}x{}",
                           color.width(), color.height(), im.camera_id, colmap_cam.width,
                           colmap_cam.height);
    }
    if (color.channels() == 1 || color.channels() == 4) {
      core::Image8 rgb(color.width(), color.height(), 3);
      for (int y = 0; y < color.height(); ++y)
        for (int x = 0; x < color.width(); ++x)
          for (int c = 0; c < 3; ++c)
            rgb.at(x, y, c) = color.at(x, y, color.channels() == 1 ? 0 : c);
      color = std::move(rgb);
    } else if (color.channels() != 3) {
      core::ThrowFileError(kWhere, image_path, "{} channels", color.channels());
    }
    Camera camera;
    core::ImageF depth, normal;
    core::Image8 mask;
    if (dense) {
      if (colmap_cam.distorted()) {
        core::ThrowFileError(kWhere, sparse_dir,
                             "camera {} is {}: a dense workspace has undistorted cameras",
                             im.camera_id, CameraModelName(colmap_cam.model));
      }
      camera = CameraFromDense(colmap_cam);
      const fs::path depth_path =
          source / "stereo/depth_maps" / fmt::format("{}.{}.bin", im.name, input_type);
      depth = colmap::ReadDenseMap(depth_path);
      if (depth.channels() != 1 || depth.width() != camera.width ||
          depth.height() != camera.height) {
        core::ThrowFileError(kWhere, depth_path, "depth map is {}x{}x{}, camera is {}x{}x1",
                             depth.width(), depth.height(), depth.channels(), camera.width,
                             camera.height);
      }
      mask = core::Image8(camera.width, camera.height, 1);
      for (size_t p = 0; p < depth.pixel_count(); ++p) {
        float& d = depth.data()[p];
        if (!Valid(d)) d = 0;  // COLMAP writes 0 (or negative) for invalid
        mask.data()[p] = d > 0 ? 255 : 0;
      }
      if (model.points3D.empty()) {
        // At most about 2 million samples over every view (48 MB).
        const double pixels = static_cast<double>(camera.width) * camera.height * order.size();
        const int step = std::max(8, static_cast<int>(std::ceil(std::sqrt(pixels / 2e6))));
        const Rigid3 world_from_cam = im.cam_from_world().Inverse();
        for (int row = 0; row < camera.height; row += step) {
          for (int col = 0; col < camera.width; col += step) {
            const float d = depth.at(col, row);
            if (d > 0) depth_points.push_back(world_from_cam * camera.UnprojectPixel(col, row, d));
          }
        }
      }
      const fs::path normal_path =
          source / "stereo/normal_maps" / fmt::format("{}.{}.bin", im.name, input_type);
      if (fs::exists(normal_path)) {
        const core::ImageF n_cam = colmap::ReadDenseMap(normal_path);
        if (n_cam.channels() != 3 || n_cam.width() != camera.width ||
            n_cam.height() != camera.height) {
          core::ThrowFileError(kWhere, normal_path, "normal map is {}x{}x{}, camera is {}x{}x3",
                               n_cam.width(), n_cam.height(), n_cam.channels(), camera.width,
                               camera.height);
        }
        normal = core::ImageF(camera.width, camera.height, 3);
        const glm::dmat3 rt = glm::transpose(im.cam_from_world().rotation);
        for (size_t p = 0; p < depth.pixel_count(); ++p) {
          if (!(depth.data()[p] > 0)) continue;
          glm::dvec3 n(n_cam.data()[3 * p], n_cam.data()[3 * p + 1], n_cam.data()[3 * p + 2]);
          if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) {
            core::ThrowFileError(kWhere, normal_path, "non-finite normal at pixel {}", p);
          }
          const double len = glm::length(n);
          if (!(len > 0.5)) continue;  // no normal: leave 0
          n = rt * (n / len);
          for (int c = 0; c < 3; ++c) normal.data()[3 * p + c] = static_cast<float>(n[c]);
        }
      }
    } else {
      // Sparse: same pixel convention; remove distortion with OpenCV.
      camera = UndistortedCamera(colmap_cam);
      color = UndistortImage(colmap_cam, color);
      if (!options.masks.empty()) {
        const fs::path mask_path = FindMask(options.masks, im.name);
        if (mask_path.empty()) {
          core::ThrowFileError(kWhere, options.masks,
                               "no mask for '{}' (looked for {}.png, {}, {})", im.name, im.name,
                               im.name, fs::path(im.name).replace_extension(".png").string());
        }
        core::Image8 m = core::ReadImage<uint8_t>(mask_path, 1);
        if (m.width() != colmap_cam.width || m.height() != colmap_cam.height) {
          core::ThrowFileError(kWhere, mask_path, "mask is {}x{}, its photo {}x{}", m.width(),
                               m.height(), colmap_cam.width, colmap_cam.height);
        }
        mask = UndistortImage(colmap_cam, m);
        for (uint8_t& v : mask.values()) v = v > 127 ? 255 : 0;
      }
    }
    if (!camera_ids.contains(im.camera_id)) camera_ids[im.camera_id] = writer.AddCamera(camera);
    std::string name = fs::path(im.name).replace_extension().string();
    for (char& c : name)
      if (c == '/' || c == '\\') c = '_';
    writer.AddView(name, camera_ids[im.camera_id], im.cam_from_world(), color, depth, mask, normal);
    if (progress) progress(static_cast<int>(k) + 1, static_cast<int>(order.size()));
  }
  std::vector<glm::dvec3> points;
  for (const auto& [id, p] : model.points3D) points.emplace_back(p.xyz[0], p.xyz[1], p.xyz[2]);
  const char* from = "sparse points";
  if (points.empty()) {
    points = std::move(depth_points);
    from = "depth samples";
  }
  if (!points.empty()) {
    const Bounds box = RobustBounds(points, options.bounds_percentile, options.bounds_margin);
    const Bounds all = RobustBounds(points, 0, 0);
    const glm::dvec3 e = box.extent(), ea = all.extent();
    const double ratio = std::max({ea.x / e.x, ea.y / e.y, ea.z / e.z});
    say(
        fmt::format("bounds {} from {:g}-{:g} % of {} {} per axis, +{:g} % margin (every point: "
                    "{}, up to {:.3g}x a side)",
                    FormatBox(box), options.bounds_percentile, 100 - options.bounds_percentile,
                    points.size(), from, 100 * options.bounds_margin, FormatBox(all), ratio));
    writer.SetBounds(box);
  } else {
    say("bounds: none (the model has no 3D points): give the object's box in dataset.json "
        "\"bounds\" before rendering");
  }
  writer.SetUp(MeanCameraUp(writer.dataset()).value_or(glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = *writer.dataset().up;
  say(fmt::format("up ({:.3f}, {:.3f}, {:.3f}) from the cameras (x axes level, image y down)", up.x,
                  up.y, up.z));
  writer.Commit();
  if (dense) {
    say("renders as a depth object (ibr render/view DATASET) or, from the valid-depth masks, a "
        "visual hull (--method visual-hull)");
  } else if (!options.masks.empty()) {
    say("renders as a visual hull (ibr render/view DATASET --method visual-hull); no depth, so "
        "no depth object");
  } else {
    say(fmt::format(
        "sparse model only: {} views with poses and colour but no depth and no masks, so neither "
        "a depth object (needs depth) nor a visual hull (needs masks) can be rendered from it; "
        "its cameras serve as novel views (ibr render OTHER --cameras DATASET). To render it: run "
        "COLMAP's dense steps (image_undistorter, patch_match_stereo, which needs CUDA) and import "
        "the workspace (ibr import colmap WS), or import again with --masks DIR (a silhouette per "
        "photo, NAME.png, > 127 = object)",
        writer.dataset().views.size()));
  }
  return writer.dataset();
}

}  // namespace capture
