// From capture/ datasets to the plain inputs of the ibr passes.
#pragma once

#include <filesystem>
#include <vector>

#include "capture/camera.h"
#include "capture/dataset.h"
#include "ibr/depth_object.h"
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

// The dataset's bounds padded by `padding` of their largest extent on every
// side, as [0,1]^3 -> world (InputError when the dataset has no bounds).
glm::dmat4 DatasetBox(const capture::Dataset& dataset, double padding = 0.02);

// Loads every view's depth (if any), colour and mask (if any). The box is the
// dataset's bounds padded by `padding` of their largest extent on every side
// (InputError when the dataset has no bounds).
MapSet MapsFromDataset(const capture::Dataset& dataset, double padding = 0.02);

// The fraction of the maps' box that no map's camera sees (outside every
// image or behind every pinhole camera), sampled on a 16^3 grid of cell
// centres: 0 when the cameras surround the object, most of the box for a
// single view.
double UnseenBoxFraction(const MapSet& maps);

// The --outside policy a render uses when none is given: kPass (a camera
// that did not see a region cannot carve it, DepthObjectOptions::outside)
// unless more than kMaxUnseenForPass of the box is seen by no camera at all
// (one view, or views from one side): kPass fills that part with a grey
// block (nothing carves it, no map colours it), so kFail, which keeps only
// what every camera sees (Kautz-Seidel 2001, sec. 4: the object lies inside
// every map's view). `reason` says which and why, naming the flag.
inline constexpr double kMaxUnseenForPass = 0.02;
struct OutsideChoice {
  OutsidePolicy policy = OutsidePolicy::kPass;
  double unseen = 0;   // UnseenBoxFraction
  std::string reason;  // one line for the user
};
OutsideChoice ChooseOutsidePolicy(const MapSet& maps);

// The views of a dataset as novel cameras (its images are not loaded).
std::vector<ViewCamera> ViewsFromDataset(const capture::Dataset& dataset);
// The same, named after the dataset's views and, with width > 0, resized to
// that width (ResizeCamera); width 0 keeps each camera's own size.
std::vector<NamedView> NamedViewsFromDataset(const capture::Dataset& dataset, int width = 0);

}  // namespace ibr
