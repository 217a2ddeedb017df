// From capture/ datasets to the plain inputs of the ibr passes.
#pragma once

#include <filesystem>
#include <vector>

#include "capture/camera.h"
#include "capture/dataset.h"
#include "ibr/image_maps.h"
#include "ibr/views.h"

namespace ibr {

// PINHOLE, SIMPLE_PINHOLE or ORTHOGRAPHIC; InputError for distorted models
// (undistort first: capture::UndistortImage).
MapCamera MapCameraFrom(const capture::Camera& camera, const std::string& where);
glm::dmat4 Mat4From(const capture::Rigid3& cam_from_world);

// Reads DIR as the maps of one depth object or visual hull: capture::ReadDataset
// with at most kMaxMaps views, counted on the manifest before a view is parsed
// or any image opened; the error names DIR/dataset.json.
capture::Dataset ReadMapDataset(const std::filesystem::path& dir);

// Loads every view's depth (if any), colour and mask (if any). The box is the
// dataset's bounds padded by `padding` of their largest extent on every side
// (InputError when the dataset has no bounds).
MapSet MapsFromDataset(const capture::Dataset& dataset, double padding = 0.02);

// The views of a dataset as novel cameras (its images are not loaded).
std::vector<ViewCamera> ViewsFromDataset(const capture::Dataset& dataset);
// The same, named after the dataset's views and, with width > 0, resized to
// that width (ResizeCamera); width 0 keeps each camera's own size.
std::vector<NamedView> NamedViewsFromDataset(const capture::Dataset& dataset, int width = 0);

}  // namespace ibr
