#include "capture/dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>

#include "capture/input_kind.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/parse_number.h"

namespace capture {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "ibr-dataset";
constexpr int kVersion = 1;

// The parse callback that counts the elements of the top-level "views"
// array as the parser meets them and stops the parse (ViewLimitExceeded) at
// the first one over `limit`: a 100,000-view manifest is refused after
// `limit` views are built, in the one parse that builds the document.
// Depths are nlohmann's: the top-level keys and "views" itself at 1, its
// elements at 2 (an object or array starts there, a scalar is a value there).
struct ViewLimitExceeded {};
class ViewCounter {
 public:
  explicit ViewCounter(size_t limit) : limit_(limit) {}
  bool operator()(int depth, json::parse_event_t event, json& parsed) {
    using E = json::parse_event_t;
    if (depth == 1 && event == E::key) {
      top_key_ = parsed.get<std::string>();
    } else if (depth == 1 && event == E::array_start) {
      in_views_ = top_key_ == "views";
    } else if (depth == 1 && event == E::array_end) {
      in_views_ = false;
    } else if (depth == 2 && in_views_ &&
               (event == E::object_start || event == E::array_start || event == E::value)) {
      if (++views_ > limit_) throw ViewLimitExceeded{};
    }
    return true;
  }

 private:
  size_t limit_;
  size_t views_ = 0;
  bool in_views_ = false;
  std::string top_key_;
};

// A relative path that stays inside the dataset directory.
bool SafeRelativePath(const std::string& p) {
  if (p.empty()) return false;
  const fs::path path(p);
  if (path.is_absolute()) return false;
  for (const auto& part : path) {
    if (part == "..") return false;
  }
  return true;
}

// Typed access with messages naming the manifest and the JSON path.
template <typename T>
T Get(const json& j, const char* key, const std::string& where, const std::string& ctx) {
  if (!j.is_object() || !j.contains(key))
    core::ThrowInputError(where, "{}: missing \"{}\"", ctx, key);
  try {
    return j.at(key).get<T>();
  } catch (const json::exception& e) {
    core::ThrowInputError(where, "{}.{}: wrong type ({})", ctx, key, e.what());
  }
}

// An integer: refuses 64.5, "64", 1e300 (nlohmann's get<int> truncates).
int GetInt(const json& j, const char* key, const std::string& where, const std::string& ctx) {
  if (!j.is_object() || !j.contains(key))
    core::ThrowInputError(where, "{}: missing \"{}\"", ctx, key);
  const json& v = j.at(key);
  if (v.is_number_integer()) {
    const auto i = v.get<int64_t>();
    if (i >= INT32_MIN && i <= INT32_MAX) return static_cast<int>(i);
  } else if (v.is_number_float()) {
    const double d = v.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::abs(d) <= INT32_MAX)
      return static_cast<int>(d);
  }
  core::ThrowInputError(where, "{}.{}: {} is not an integer", ctx, key, v.dump());
}

std::string OptionalString(const json& j, const char* key, const std::string& where,
                           const std::string& ctx) {
  if (!j.contains(key) || j.at(key).is_null()) return {};
  return Get<std::string>(j, key, where, ctx);
}

glm::dvec3 GetVec3(const json& j, const char* key, const std::string& where,
                   const std::string& ctx) {
  const auto v = Get<std::vector<double>>(j, key, where, ctx);
  if (v.size() != 3)
    core::ThrowInputError(where, "{}.{}: expected 3 numbers, got {}", ctx, key, v.size());
  return {v[0], v[1], v[2]};
}

}  // namespace

void Dataset::Check(std::string_view where, bool images) const {
  for (const auto& [id, camera] : cameras) {
    camera.Check(fmt::format("{}: camera {}", where, id));
    if (camera.distorted()) {
      core::ThrowInputError(where,
                            "camera {} has lens distortion ({}): datasets hold undistorted "
                            "images",
                            id, CameraModelName(camera.model));
    }
  }
  if (views.empty()) core::ThrowInputError(where, "no views");
  if (views.size() > kDatasetLimits.max_views) {
    core::ThrowInputError(where, "{} views; at most {} are supported", views.size(),
                          kDatasetLimits.max_views);
  }
  int64_t pixels = 0;
  std::set<std::string> names;
  for (const auto& view : views) {
    const std::string ctx = fmt::format("{}: view '{}'", where, view.name);
    if (view.name.empty()) core::ThrowInputError(where, "a view has an empty name");
    if (!names.insert(view.name).second) core::ThrowInputError(ctx, "duplicate view name");
    if (!cameras.contains(view.camera_id))
      core::ThrowInputError(ctx, "unknown camera id {}", view.camera_id);
    view.cam_from_world.Check(ctx);
    const glm::dvec3 centre = view.cam_from_world.Centre();
    if (!(glm::length(centre) <= kDatasetLimits.max_coordinate)) {
      core::ThrowInputError(
          ctx, "camera centre ({}, {}, {}) is farther than {} scene units from the origin",
          centre.x, centre.y, centre.z, kDatasetLimits.max_coordinate);
    }
    if (cameras.contains(view.camera_id)) {
      const Camera& camera = cameras.at(view.camera_id);
      pixels += int64_t{camera.width} * camera.height;
      if (pixels > kDatasetLimits.max_total_pixels) {
        core::ThrowInputError(where, "the views hold more than {} pixels in all (at view '{}')",
                              kDatasetLimits.max_total_pixels, view.name);
      }
    }
    if ((images || !view.color.empty()) && !SafeRelativePath(view.color))
      core::ThrowInputError(ctx, "bad color path '{}'", view.color);
    for (const std::string* p : {&view.depth, &view.mask, &view.normal}) {
      if (!p->empty() && !SafeRelativePath(*p)) core::ThrowInputError(ctx, "bad path '{}'", *p);
    }
  }
  if (bounds) CheckBounds(*bounds, where);
  if (up && !(std::isfinite(up->x) && std::isfinite(up->y) && std::isfinite(up->z) &&
              std::abs(glm::length(*up) - 1) < 1e-6)) {
    core::ThrowInputError(where, "up ({}, {}, {}) is not a finite unit vector", up->x, up->y,
                          up->z);
  }
}

Bounds RobustBounds(const std::vector<glm::dvec3>& points, double percentile, double margin) {
  if (points.empty()) core::ThrowInputError("RobustBounds", "no points");
  Bounds b;
  std::vector<double> axis(points.size());
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < points.size(); ++i) axis[i] = points[i][k];
    std::sort(axis.begin(), axis.end());
    const size_t n = axis.size();
    // Nearest-rank percentiles; the extremes below 20 points.
    const size_t lo = n < 20 ? 0 : static_cast<size_t>(std::floor(percentile / 100 * (n - 1)));
    const size_t hi = n < 20 ? n - 1 : n - 1 - lo;
    const double side = axis[hi] - axis[lo];
    b.min[k] = axis[lo] - margin * side;
    b.max[k] = axis[hi] + margin * side;
  }
  return b;
}

Bounds ParseBounds(std::string_view text, std::string_view where) {
  const std::optional<std::vector<double>> v = core::ParseNumberList(text);
  if (!v || v->size() != 6) {
    core::ThrowInputError(where, "'{}' is not six numbers X0,Y0,Z0,X1,Y1,Z1", text);
  }
  const Bounds b{{(*v)[0], (*v)[1], (*v)[2]}, {(*v)[3], (*v)[4], (*v)[5]}};
  CheckBounds(b, where);
  return b;
}

void ViewChoice::Check() const {
  if (!views.empty() && !hold_out.empty())
    core::ThrowInputError("ViewChoice", "give --views or --hold-out, not both");
}

std::vector<size_t> ViewChoice::Apply(const std::vector<std::string>& names,
                                      std::string_view where) const {
  Check();
  auto named = [](const std::string& photo, const std::string& n) {
    const fs::path p(photo);
    return photo == n || fs::path(p).replace_extension().string() == n || p.stem().string() == n;
  };
  const std::vector<std::string>& given = views.empty() ? hold_out : views;
  for (const std::string& n : given) {
    if (std::none_of(names.begin(), names.end(),
                     [&](const auto& photo) { return named(photo, n); }))
      core::ThrowInputError(where, "no photo named '{}' ({} photos)", n, names.size());
  }
  std::vector<size_t> kept;
  for (size_t i = 0; i < names.size(); ++i) {
    const bool is_named = std::any_of(given.begin(), given.end(),
                                      [&](const std::string& n) { return named(names[i], n); });
    if (given.empty() || is_named == !views.empty()) kept.push_back(i);
  }
  return kept;
}

void CheckBounds(const Bounds& bounds, std::string_view where) {
  const glm::dvec3 &lo = bounds.min, &hi = bounds.max;
  const std::string box =
      fmt::format("bounds min ({}, {}, {}) max ({}, {}, {})", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
  double largest = 0;
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(lo[k]) || !std::isfinite(hi[k]) || lo[k] > hi[k]) {
      core::ThrowInputError(where, "{}: not finite or min > max", box);
    }
    largest = std::max({largest, std::abs(lo[k]), std::abs(hi[k])});
  }
  if (largest > kDatasetLimits.max_coordinate) {
    core::ThrowInputError(where, "{}: coordinates beyond +-{} scene units", box,
                          kDatasetLimits.max_coordinate);
  }
  // The renderer works in float: each side must span many float steps of the
  // largest coordinate, and not be vanishingly small.
  const double min_extent =
      std::max(kDatasetLimits.min_extent, kDatasetLimits.min_relative_extent * largest);
  for (int k = 0; k < 3; ++k) {
    if (!(hi[k] - lo[k] >= min_extent)) {
      core::ThrowInputError(where, "{}: side {} is {:.3g} scene units; at least {:.3g} is needed",
                            box, "xyz"[k], hi[k] - lo[k], min_extent);
    }
  }
}

void CheckDepthValues(const core::ImageF& depth, const std::string& where) {
  for (float d : depth.values()) {
    // Invalid = 0 or non-finite; a finite negative depth is nonsense.
    if (std::isfinite(d) && d < 0) core::ThrowInputError(where, "negative depth {}", d);
    if (std::isfinite(d) && d > kDatasetLimits.max_coordinate) {
      core::ThrowInputError(where, "depth {} is beyond {} scene units", d,
                            kDatasetLimits.max_coordinate);
    }
  }
}

void CheckNormalValues(const core::ImageF& normal, const std::string& where) {
  for (size_t i = 0; i < normal.pixel_count(); ++i) {
    const float* n = normal.data() + 3 * i;
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2])) {
      core::ThrowInputError(where, "non-finite normal at pixel {}", i);
    }
    const float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    // Half-float storage in the renderer: unit length to ~1e-3.
    if (len2 != 0 && std::abs(len2 - 1) > 0.02f) {
      core::ThrowInputError(where, "normal at pixel {} is not unit length (|n|^2 = {})", i, len2);
    }
  }
}

namespace {

template <typename T>
void CheckSize(const core::Image<T>& image, const Camera& camera, const fs::path& path,
               const char* where) {
  if (image.width() != camera.width || image.height() != camera.height) {
    core::ThrowFileError(where, path, "image is {}x{}, camera is {}x{}", image.width(),
                         image.height(), camera.width, camera.height);
  }
}

}  // namespace

core::Image8 Dataset::LoadColor(size_t i) const {
  const DatasetView& view = views.at(i);
  const fs::path path = root / view.color;
  core::Image8 image = core::ReadImage<uint8_t>(path);
  CheckSize(image, camera(view), path, "Dataset::LoadColor");
  if (image.channels() == 3) return image;
  if (image.channels() != 4 && image.channels() != 1) {
    core::ThrowFileError("Dataset::LoadColor", path, "expected 1, 3 or 4 channels, got {}",
                         image.channels());
  }
  core::Image8 rgb(image.width(), image.height(), 3);
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = image.at(x, y, image.channels() == 1 ? 0 : c);
    }
  }
  return rgb;
}

namespace {

// A view's optional image `file` (view.depth, view.mask, view.normal) with
// `channels` channels, the camera's size; `what` names it in errors.
template <typename T>
core::Image<T> LoadViewImage(const Dataset& dataset, size_t i, std::string DatasetView::*file,
                             int channels, const char* where, const char* what) {
  const DatasetView& view = dataset.views.at(i);
  if ((view.*file).empty()) core::ThrowInputError(where, "view '{}' has no {}", view.name, what);
  const fs::path path = dataset.root / (view.*file);
  core::Image<T> image = core::ReadImage<T>(path, channels);
  CheckSize(image, dataset.camera(view), path, where);
  return image;
}

}  // namespace

core::ImageF Dataset::LoadDepth(size_t i) const {
  constexpr const char* kWhere = "Dataset::LoadDepth";
  core::ImageF depth = LoadViewImage<float>(*this, i, &DatasetView::depth, 1, kWhere, "depth");
  CheckDepthValues(depth, fmt::format("{}: '{}'", kWhere, (root / views[i].depth).string()));
  return depth;
}

core::Image8 Dataset::LoadMask(size_t i) const {
  return LoadViewImage<uint8_t>(*this, i, &DatasetView::mask, 1, "Dataset::LoadMask", "mask");
}

core::ImageF Dataset::LoadNormal(size_t i) const {
  constexpr const char* kWhere = "Dataset::LoadNormal";
  core::ImageF normal = LoadViewImage<float>(*this, i, &DatasetView::normal, 3, kWhere, "normals");
  CheckNormalValues(normal, fmt::format("{}: '{}'", kWhere, (root / views[i].normal).string()));
  return normal;
}

Dataset ReadManifest(std::istream& in, const std::string& name, const DatasetUse& use) {
  const std::string where = fmt::format("ReadManifest: '{}'", name);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The view count is checked as the views are parsed (before the document
  // holds more than the limit): the limit of this use, else the dataset limit.
  const size_t max_views = std::min(use.max_views, kDatasetLimits.max_views);
  const std::string why = use.purpose.empty() || max_views == kDatasetLimits.max_views
                              ? ""
                              : fmt::format(" {}", use.purpose);
  json j;
  try {
    j = json::parse(text, ViewCounter(max_views));
  } catch (const ViewLimitExceeded&) {
    core::ThrowInputError(where, "more than {} views; at most {}{} are supported", max_views,
                          max_views, why);
  } catch (const json::exception& e) {
    core::ThrowInputError(where, "not valid JSON ({})", e.what());
  }
  if (!j.is_object()) core::ThrowInputError(where, "top level is not an object");
  if (Get<std::string>(j, "format", where, "manifest") != kFormat) {
    core::ThrowInputError(where, "\"format\" is not \"{}\"", kFormat);
  }
  const int version = GetInt(j, "version", where, "manifest");
  if (version != kVersion)
    core::ThrowInputError(where, "unsupported version {} (expected {})", version, kVersion);

  Dataset dataset;
  const json depth = j.contains("depth") ? j.at("depth") : json::object();
  if (depth.contains("kind") && Get<std::string>(depth, "kind", where, "depth") != "camera_z") {
    core::ThrowInputError(where, "depth.kind must be \"camera_z\"");
  }
  if (depth.contains("units"))
    dataset.depth_units = Get<std::string>(depth, "units", where, "depth");
  if (depth.contains("noise") && !depth.at("noise").is_null())
    dataset.depth_noise = SensorModel::FromJson(depth.at("noise"), where);
  if (j.contains("normal_frame") &&
      Get<std::string>(j, "normal_frame", where, "manifest") != "world") {
    core::ThrowInputError(where, "normal_frame must be \"world\"");
  }
  if (j.contains("bounds") && !j.at("bounds").is_null()) {
    const json& b = j.at("bounds");
    dataset.bounds = Bounds{GetVec3(b, "min", where, "bounds"), GetVec3(b, "max", where, "bounds")};
  }
  if (j.contains("up") && !j.at("up").is_null()) {
    const glm::dvec3 up = GetVec3(j, "up", where, "manifest");
    const double length = glm::length(up);
    if (!(std::isfinite(length) && length > 1e-9))
      core::ThrowInputError(where, "\"up\" ({}, {}, {}) is zero or not finite", up.x, up.y, up.z);
    dataset.up = up / length;
  }
  const json cameras = Get<json>(j, "cameras", where, "manifest");
  if (!cameras.is_array()) core::ThrowInputError(where, "\"cameras\" is not an array");
  for (size_t i = 0; i < cameras.size(); ++i) {
    const std::string ctx = fmt::format("cameras[{}]", i);
    const json& c = cameras[i];
    const int id = GetInt(c, "id", where, ctx);
    const auto model_name = Get<std::string>(c, "model", where, ctx);
    const auto model = CameraModelFromName(model_name);
    if (!model) core::ThrowInputError(where, "{}: unknown camera model '{}'", ctx, model_name);
    Camera camera{*model, GetInt(c, "width", where, ctx), GetInt(c, "height", where, ctx),
                  Get<std::vector<double>>(c, "params", where, ctx)};
    if (!dataset.cameras.emplace(id, camera).second)
      core::ThrowInputError(where, "{}: duplicate camera id {}", ctx, id);
  }
  const json views = Get<json>(j, "views", where, "manifest");
  if (!views.is_array()) core::ThrowInputError(where, "\"views\" is not an array");
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string ctx = fmt::format("views[{}]", i);
    const json& v = views[i];
    DatasetView view;
    view.name = Get<std::string>(v, "name", where, ctx);
    view.camera_id = GetInt(v, "camera", where, ctx);
    const auto m = Get<std::vector<std::vector<double>>>(v, "cam_from_world", where, ctx);
    if (m.size() != 3 || m[0].size() != 4 || m[1].size() != 4 || m[2].size() != 4) {
      core::ThrowInputError(where, "{}.cam_from_world: expected 3 rows of 4 numbers", ctx);
    }
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) view.cam_from_world.rotation[c][r] = m[r][c];
      view.cam_from_world.translation[r] = m[r][3];
    }
    view.color = use.cameras_only ? OptionalString(v, "color", where, ctx)
                                  : Get<std::string>(v, "color", where, ctx);
    view.depth = OptionalString(v, "depth", where, ctx);
    view.mask = OptionalString(v, "mask", where, ctx);
    view.normal = OptionalString(v, "normal", where, ctx);
    dataset.views.push_back(std::move(view));
  }
  dataset.Check(where, !use.cameras_only);
  return dataset;
}

void WriteManifest(std::ostream& out, const Dataset& dataset) {
  json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["depth"] = {
      {"kind", "camera_z"}, {"units", dataset.depth_units}, {"invalid", "0 or non-finite"}};
  if (dataset.depth_noise) j["depth"]["noise"] = dataset.depth_noise->ToJson();
  j["normal_frame"] = "world";
  if (dataset.bounds) {
    const auto& b = *dataset.bounds;
    j["bounds"] = {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
  }
  if (dataset.up) j["up"] = {dataset.up->x, dataset.up->y, dataset.up->z};
  json cameras = json::array();
  for (const auto& [id, c] : dataset.cameras) {
    cameras.push_back({{"id", id},
                       {"model", CameraModelName(c.model)},
                       {"width", c.width},
                       {"height", c.height},
                       {"params", c.params}});
  }
  j["cameras"] = cameras;
  json views = json::array();
  for (const auto& v : dataset.views) {
    json m = json::array();
    for (int r = 0; r < 3; ++r) {
      const auto& R = v.cam_from_world.rotation;
      m.push_back({R[0][r], R[1][r], R[2][r], v.cam_from_world.translation[r]});
    }
    json jv = {{"name", v.name}, {"camera", v.camera_id}, {"cam_from_world", m}};
    if (!v.color.empty()) jv["color"] = v.color;
    if (!v.depth.empty()) jv["depth"] = v.depth;
    if (!v.mask.empty()) jv["mask"] = v.mask;
    if (!v.normal.empty()) jv["normal"] = v.normal;
    views.push_back(jv);
  }
  j["views"] = views;
  // nlohmann writes doubles with 17 significant digits: round trips are exact.
  out << j.dump(2) << "\n";
}

Dataset ReadDataset(const fs::path& dir, bool check_pixels, const DatasetUse& use) {
  const fs::path manifest = dir / "dataset.json";
  // Not a dataset folder: say what it is and which command takes it.
  if (!fs::is_directory(dir)) CheckDatasetInput("ReadDataset", dir, /*scene_ok=*/false);
  std::ifstream in(manifest, std::ios::binary);
  if (!in) core::ThrowFileError("ReadDataset", manifest, "cannot open (missing dataset.json?)");
  Dataset dataset = ReadManifest(in, manifest.string(), use);
  dataset.root = dir;
  for (size_t i = 0; i < dataset.views.size() && !use.cameras_only; ++i) {
    const DatasetView& view = dataset.views[i];
    const Camera& camera = dataset.camera(view);
    for (const std::string* rel : {&view.color, &view.depth, &view.mask, &view.normal}) {
      if (rel->empty()) continue;
      const fs::path path = dir / *rel;
      const core::ImageHeader header = core::ReadImageHeader(path);
      if (header.width != camera.width || header.height != camera.height) {
        core::ThrowFileError("ReadDataset", path, "image is {}x{}, camera {} is {}x{}",
                             header.width, header.height, view.camera_id, camera.width,
                             camera.height);
      }
    }
    if (check_pixels) {
      dataset.LoadColor(i);
      if (!view.depth.empty()) dataset.LoadDepth(i);
      if (!view.mask.empty()) dataset.LoadMask(i);
      if (!view.normal.empty()) dataset.LoadNormal(i);
    }
  }
  return dataset;
}

Dataset ReadCameras(const fs::path& path) {
  const DatasetUse use{.purpose = "", .cameras_only = true};
  if (fs::is_directory(path)) return ReadDataset(path, false, use);
  std::ifstream in(path, std::ios::binary);
  if (!in) core::ThrowFileError("ReadCameras", path, "cannot open (a dataset folder or its JSON)");
  Dataset dataset = ReadManifest(in, path.string(), use);
  dataset.root = path.parent_path();
  return dataset;
}

std::optional<glm::dvec3> MeanCameraUp(const Dataset& dataset) {
  glm::dvec3 sum(0.0);
  glm::dmat3 xx(0.0);  // sum of x x^T over the cameras' x axes
  for (const DatasetView& v : dataset.views) {
    // Rows 0 and 1 of cam_from_world's rotation: the camera's x and y axes in world.
    const glm::dmat3& r = v.cam_from_world.rotation;
    const glm::dvec3 x(r[0][0], r[1][0], r[2][0]);
    sum -= glm::dvec3(r[0][1], r[1][1], r[2][1]);
    xx += glm::outerProduct(x, x);
  }
  const double length = glm::length(sum);
  // Less than a tenth of the views' count: the cameras are rolled every way.
  if (!(length > 0.1 * static_cast<double>(dataset.views.size()))) return std::nullopt;
  // Level cameras hold x across up, tilted ones too (their y leans with the
  // tilt, so views looking down from one side lean their mean -y toward
  // them): up is the direction least along every x, the smallest
  // eigenvector of sum x x^T, found by inverse iteration from -(mean y),
  // which also picks the answer where x leaves it free (one view: -y itself).
  const double eps = 1e-9 * (xx[0][0] + xx[1][1] + xx[2][2]) + 1e-12;
  const glm::dmat3 inverse = glm::inverse(xx + eps * glm::dmat3(1.0));
  glm::dvec3 up = sum / length;
  for (int i = 0; i < 50; ++i) up = glm::normalize(inverse * up);
  if (glm::dot(up, sum) < 0) up = -up;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(up[k]) > std::cos(5.0 * M_PI / 180.0)) {
      const double sign = up[k] > 0 ? 1.0 : -1.0;
      up = glm::dvec3(0.0);
      up[k] = sign;
    }
  }
  return up;
}

UpChoice DefaultUp(const Dataset& dataset) {
  if (dataset.up) return {*dataset.up, "dataset.json \"up\""};
  if (const auto mean = MeanCameraUp(dataset)) return {*mean, "the input cameras' mean up"};
  return {{0, 1, 0}, "+y (the input cameras are rolled every way)"};
}

void DatasetWriter::SetUp(const glm::dvec3& up) {
  const double length = glm::length(up);
  if (!(std::isfinite(length) && length > 1e-9))
    core::ThrowInputError("DatasetWriter::SetUp", "up ({}, {}, {}) is zero or not finite", up.x,
                          up.y, up.z);
  dataset_.up = up / length;
}

DatasetWriter::DatasetWriter(const fs::path& dir) : staged_(dir) { dataset_.root = staged_.path(); }

int DatasetWriter::AddCamera(const Camera& camera) {
  camera.Check("DatasetWriter::AddCamera");
  const int id = static_cast<int>(dataset_.cameras.size()) + 1;
  dataset_.cameras.emplace(id, camera);
  return id;
}

void DatasetWriter::AddView(const std::string& name, int camera_id, const Rigid3& cam_from_world,
                            const core::Image8& color, const core::ImageF& depth,
                            const core::Image8& mask, const core::ImageF& normal) {
  const std::string where = fmt::format("DatasetWriter::AddView: view '{}'", name);
  if (!dataset_.cameras.contains(camera_id))
    core::ThrowInputError(where, "unknown camera id {}", camera_id);
  const Camera& camera = dataset_.cameras.at(camera_id);
  auto check_size = [&](int w, int h, int channels, std::initializer_list<int> allowed,
                        const char* what) {
    if (w != camera.width || h != camera.height) {
      core::ThrowInputError(where, "{} is {}x{}, camera is {}x{}", what, w, h, camera.width,
                            camera.height);
    }
    if (std::find(allowed.begin(), allowed.end(), channels) == allowed.end()) {
      core::ThrowInputError(where, "{} has {} channels", what, channels);
    }
  };
  cam_from_world.Check(where);
  DatasetView view{name, camera_id, cam_from_world, "color/" + name + ".png", {}, {}, {}};
  fs::create_directories(staged_.path() / "color");
  check_size(color.width(), color.height(), color.channels(), {3, 4}, "color");
  if (color.channels() == 4) {
    core::Image8 rgb(color.width(), color.height(), 3);
    for (size_t p = 0; p < color.pixel_count(); ++p) {
      for (int c = 0; c < 3; ++c) rgb.data()[3 * p + c] = color.data()[4 * p + c];
    }
    core::WriteImage(staged_.path() / view.color, rgb);
  } else {
    core::WriteImage(staged_.path() / view.color, color);
  }
  if (!depth.empty()) {
    check_size(depth.width(), depth.height(), depth.channels(), {1}, "depth");
    CheckDepthValues(depth, where);
    view.depth = "depth/" + name + ".exr";
    fs::create_directories(staged_.path() / "depth");
    core::WriteImage(staged_.path() / view.depth, depth);
  }
  if (!mask.empty()) {
    check_size(mask.width(), mask.height(), mask.channels(), {1}, "mask");
    view.mask = "mask/" + name + ".png";
    fs::create_directories(staged_.path() / "mask");
    core::WriteImage(staged_.path() / view.mask, mask);
  }
  if (!normal.empty()) {
    check_size(normal.width(), normal.height(), normal.channels(), {3}, "normal");
    CheckNormalValues(normal, where);
    view.normal = "normal/" + name + ".exr";
    fs::create_directories(staged_.path() / "normal");
    core::WriteImage(staged_.path() / view.normal, normal);
  }
  dataset_.views.push_back(std::move(view));
}

void DatasetWriter::Commit() {
  dataset_.Check("DatasetWriter::Commit");
  core::AtomicWriteStream(staged_.path() / "dataset.json",
                          [&](std::ostream& out) { WriteManifest(out, dataset_); });
  staged_.Commit();
  dataset_.root = staged_.final_path();
}

}  // namespace capture
