// The viewer's transfer-function editor as a model, CPU only (no ImGui; the
// panel that draws it is apps/viewer/transfer_function_panel.cc): a volume's
// histogram in its stored units, colour and opacity control points in those
// units that are added, moved and deleted, presets, and radiology's
// window/level mapped onto the function.
//
// Window/level: the window of a function is the span of its control points,
// centre (level) = (first + last) / 2, width = last - first; setting a new
// window maps every point linearly from the old span onto the new one, so a
// linear ramp becomes the radiologist's ramp from level - width/2 to
// level + width/2 and a shaped preset keeps its shape while it is slid and
// stretched. A drag with the modifier (DragWindowLevel) follows the usual
// convention: right widens the window, down raises the level.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/transfer_function.h"
#include "core/volume.h"

namespace viewer {

// Voxel counts over [lo, hi] (stored units) in equal bins; bin i holds values
// in [lo + i w, lo + (i + 1) w), the last bin also hi. Non-finite voxels are
// not counted.
struct Histogram {
  double lo = 0, hi = 1;
  std::vector<int64_t> counts;
  double BinWidth() const { return (hi - lo) / static_cast<double>(counts.size()); }
  // log(1 + count) of bin i over the largest such value, in [0, 1]: what
  // the panel draws (a CT's air would flatten every other bin linearly).
  double LogHeight(size_t i) const;
};
// The histogram of `volume`'s stored values over its data range [min, max]
// in `bins` bins (a single-valued volume: [min, min + 1]).
Histogram VolumeHistogram(const core::Volume& volume, int bins = 256);

struct WindowLevel {
  double centre = 0;  // level, stored units
  double width = 1;   // window, stored units, > 0
};
// The span of `tf`'s points (a single point: width 0).
WindowLevel WindowOf(const core::TransferFunction& tf);
// `tf` with its points mapped linearly from WindowOf(tf) onto `wl`
// (a single point moves to the centre). InputError for a width that is not
// finite and > 0.
core::TransferFunction WithWindow(const core::TransferFunction& tf, const WindowLevel& wl);
// The window after a drag of `pixels` (window pixels, y down) from `start`:
// each pixel moves the width (x) and the centre (y) by `units_per_pixel`;
// the width stays >= units_per_pixel.
WindowLevel DragWindowLevel(const WindowLevel& start, const glm::dvec2& pixels,
                            double units_per_pixel);

// The editor's presets: every core preset (core::TransferPresetNames, over
// the normalised scalar, here in stored units) and "linear ramp" (grey,
// transparent at the data minimum to opaque at the maximum).
std::vector<std::string> EditorPresetNames();

class TransferEditor {
 public:
  // `tf` in either units; `range` the volume's normalisation range (what
  // s = 0 and 1 mean), `data` its [min, max].
  TransferEditor(const core::TransferFunction& tf, const glm::dvec2& range, const glm::dvec2& data);

  // Always in stored units (core::TransferUnits::kData), Check() passes.
  const core::TransferFunction& transfer() const { return tf_; }
  const glm::dvec2& data_range() const { return data_; }

  // A point at `value` with the colour and opacity the curve has there
  // (opacity `opacity` if given); its index. A point already at `value`
  // is returned unchanged.
  size_t AddPoint(double value, std::optional<double> opacity = std::nullopt);
  // Point `i` to `value` (kept strictly between its neighbours) and
  // `opacity` (clamped to [0, 1]).
  void MovePoint(size_t i, double value, double opacity);
  void SetColour(size_t i, const glm::dvec3& rgb);  // clamped to [0, 1]
  // Removes point `i`; the last point is kept (a function has one at least).
  bool DeletePoint(size_t i);
  // The point nearest (value, opacity) within `tolerance` (units of the
  // curve's axes scaled by `scale`: value / scale.x, opacity / scale.y).
  std::optional<size_t> Pick(double value, double opacity, const glm::dvec2& scale,
                             double tolerance) const;
  // A preset of EditorPresetNames(); InputError otherwise.
  void ApplyPreset(const std::string& name);
  WindowLevel window() const { return WindowOf(tf_); }
  void SetWindow(const WindowLevel& wl) { tf_ = WithWindow(tf_, wl); }

 private:
  core::TransferFunction tf_;
  glm::dvec2 range_;  // normalisation range: s in [0, 1] -> stored units
  glm::dvec2 data_;
};

}  // namespace viewer
