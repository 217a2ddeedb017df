#include "capture/colmap_dataset.h"

#include <fmt/format.h>

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
  if (input_type != "geometric" && input_type != "photometric") {
    core::ThrowInputError("ColmapImportOptions", "input type '{}' is not geometric or photometric",
                          input_type);
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

Bounds PointBounds(const colmap::SparseModel& model) {
  Bounds b{glm::dvec3(INFINITY), glm::dvec3(-INFINITY)};
  for (const auto& [id, p] : model.points3D) {
    const glm::dvec3 x(p.xyz[0], p.xyz[1], p.xyz[2]);
    b.min = glm::min(b.min, x);
    b.max = glm::max(b.max, x);
  }
  return b;
}

}  // namespace

Dataset ImportColmap(const fs::path& source, const fs::path& out,
                     const ColmapImportOptions& options,
                     const std::function<void(int, int)>& progress) {
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

  // Image order: fusion.cfg order for dense workspaces when present, else by name.
  std::vector<const colmap::Image*> order;
  for (const auto& [id, im] : model.images) order.push_back(&im);
  std::sort(order.begin(), order.end(), [](auto* a, auto* b) { return a->name < b->name; });

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
          source / "stereo/depth_maps" / fmt::format("{}.{}.bin", im.name, options.input_type);
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
      const fs::path normal_path =
          source / "stereo/normal_maps" / fmt::format("{}.{}.bin", im.name, options.input_type);
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
    }
    if (!camera_ids.contains(im.camera_id)) camera_ids[im.camera_id] = writer.AddCamera(camera);
    std::string name = fs::path(im.name).replace_extension().string();
    for (char& c : name)
      if (c == '/' || c == '\\') c = '_';
    writer.AddView(name, camera_ids[im.camera_id], im.cam_from_world(), color, depth, mask, normal);
    if (progress) progress(static_cast<int>(k) + 1, static_cast<int>(order.size()));
  }
  if (!model.points3D.empty()) writer.SetBounds(PointBounds(model));
  writer.Commit();
  return writer.dataset();
}

}  // namespace capture
