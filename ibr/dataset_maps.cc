#include "ibr/dataset_maps.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/error.h"

namespace ibr {

MapCamera MapCameraFrom(const capture::Camera& camera, const std::string& where) {
  camera.Check(where);
  if (camera.distorted()) {
    core::ThrowInputError(where, "camera model {} has lens distortion; undistort the images first",
                          capture::CameraModelName(camera.model));
  }
  MapCamera m;
  m.orthographic = camera.orthographic();
  m.fx = camera.fx();
  m.fy = camera.fy();
  m.cx = camera.cx();
  m.cy = camera.cy();
  m.width = camera.width;
  m.height = camera.height;
  return m;
}

glm::dmat4 Mat4From(const capture::Rigid3& cam_from_world) {
  glm::dmat4 m(cam_from_world.rotation);
  m[3] = glm::dvec4(cam_from_world.translation, 1.0);
  return m;
}

// The map limit is an input limit no larger than a dataset's (the reader
// then names only the one number).
static_assert(kMaxMaps <= capture::kDatasetLimits.max_views);

capture::Dataset ReadMapDataset(const std::filesystem::path& dir) {
  return capture::ReadDataset(
      dir, false, {kMaxMaps, "maps of one depth object or visual hull (ibr::kMaxMaps)"});
}

glm::dmat4 DatasetBox(const capture::Dataset& dataset, double padding) {
  if (!dataset.bounds) {
    core::ThrowInputError("MapsFromDataset: '" + dataset.root.string() + "'",
                          "the dataset has no bounds (dataset.json \"bounds\")");
  }
  const capture::Bounds& b = *dataset.bounds;
  const glm::dvec3 ext = b.extent();
  const double pad = padding * std::max({ext.x, ext.y, ext.z});
  return BoxFromBounds(b.min - pad, b.max + pad);
}

MapSet MapsFromDataset(const capture::Dataset& dataset, double padding) {
  const std::string where = "MapsFromDataset: '" + dataset.root.string() + "'";
  MapSet set;
  set.source = dataset.root.string();
  set.world_from_box = DatasetBox(dataset, padding);
  for (size_t i = 0; i < dataset.views.size(); ++i) {
    const capture::DatasetView& v = dataset.views[i];
    ImageMap m;
    m.name = v.name;
    m.camera = MapCameraFrom(dataset.camera(v), where + ": view '" + v.name + "'");
    m.cam_from_world = Mat4From(v.cam_from_world);
    if (!v.depth.empty()) m.depth = dataset.LoadDepth(i);
    if (!v.mask.empty()) m.mask = dataset.LoadMask(i);
    if (!v.color.empty()) m.color = dataset.LoadColor(i);
    set.maps.push_back(std::move(m));
  }
  set.Check(where);
  return set;
}

double UnseenBoxFraction(const MapSet& maps) {
  constexpr int kGrid = 16;
  int64_t unseen = 0;
  for (int i = 0; i < kGrid * kGrid * kGrid; ++i) {
    const glm::dvec4 u((i % kGrid + 0.5) / kGrid, ((i / kGrid) % kGrid + 0.5) / kGrid,
                       (i / (kGrid * kGrid) + 0.5) / kGrid, 1.0);
    const glm::dvec4 p = maps.world_from_box * u;
    bool seen = false;
    for (const ImageMap& m : maps.maps) {
      const glm::dvec3 q(m.cam_from_world * p);
      double col = 0, row = 0;
      if (m.camera.Project(q, col, row) && m.camera.InImage(col, row)) {
        seen = true;
        break;
      }
    }
    unseen += !seen;
  }
  return static_cast<double>(unseen) / (kGrid * kGrid * kGrid);
}

OutsideChoice ChooseOutsidePolicy(const MapSet& maps) {
  OutsideChoice choice;
  choice.unseen = UnseenBoxFraction(maps);
  if (choice.unseen > kMaxUnseenForPass) {
    choice.policy = OutsidePolicy::kFail;
    choice.reason = fmt::format(
        "outside fail: {:.0f} % of the box is seen by no input view (one view, or views from one "
        "side); --outside pass would fill it with a grey block, so only what every view sees is "
        "kept (--outside pass to keep the unseen part)",
        100 * choice.unseen);
  } else {
    choice.reason = fmt::format(
        "outside pass: the views see {:.0f} % of the box; a view does not carve what it did not "
        "see (--outside fail keeps only what every view sees)",
        100 * (1 - choice.unseen));
  }
  return choice;
}

std::vector<ViewCamera> ViewsFromDataset(const capture::Dataset& dataset) {
  std::vector<ViewCamera> views;
  for (const capture::DatasetView& v : dataset.views) {
    views.push_back({MapCameraFrom(dataset.camera(v), "ViewsFromDataset: view '" + v.name + "'"),
                     Mat4From(v.cam_from_world)});
  }
  return views;
}

std::vector<NamedView> NamedViewsFromDataset(const capture::Dataset& dataset, int width) {
  const std::vector<ViewCamera> cams = ViewsFromDataset(dataset);
  std::vector<NamedView> views;
  for (size_t i = 0; i < cams.size(); ++i) {
    NamedView v{dataset.views[i].name, cams[i]};
    if (width > 0) v.view.camera = ResizeCamera(v.view.camera, width);
    views.push_back(std::move(v));
  }
  return views;
}

}  // namespace ibr
