#include "ibr/dataset_maps.h"

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

MapSet MapsFromDataset(const capture::Dataset& dataset, double padding) {
  const std::string where = "MapsFromDataset: '" + dataset.root.string() + "'";
  if (!dataset.bounds)
    core::ThrowInputError(where, "the dataset has no bounds (dataset.json \"bounds\")");
  const capture::Bounds& b = *dataset.bounds;
  const glm::dvec3 ext = b.extent();
  const double pad = padding * std::max({ext.x, ext.y, ext.z});
  MapSet set;
  set.source = dataset.root.string();
  set.world_from_box = BoxFromBounds(b.min - pad, b.max + pad);
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
