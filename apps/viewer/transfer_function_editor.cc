#include "apps/viewer/transfer_function_editor.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "core/check.h"
#include "core/error.h"

namespace viewer {

double Histogram::LogHeight(size_t i) const {
  double top = 0;
  for (int64_t c : counts) top = std::max(top, std::log1p(static_cast<double>(c)));
  return top > 0 ? std::log1p(static_cast<double>(counts[i])) / top : 0;
}

Histogram VolumeHistogram(const core::Volume& volume, int bins) {
  IBR_CHECK_GT(bins, 0);
  Histogram h;
  h.lo = std::numeric_limits<double>::infinity();
  h.hi = -h.lo;
  for (int z = 0; z < volume.dims.z; ++z)
    for (int y = 0; y < volume.dims.y; ++y)
      for (int x = 0; x < volume.dims.x; ++x) {
        const double v = volume.Value(x, y, z);
        if (!std::isfinite(v)) continue;
        h.lo = std::min(h.lo, v);
        h.hi = std::max(h.hi, v);
      }
  if (!(h.hi >= h.lo)) h.lo = h.hi = 0;  // no finite voxel
  if (h.hi == h.lo) h.hi = h.lo + 1;
  h.counts.assign(static_cast<size_t>(bins), 0);
  const double width = h.BinWidth();
  for (int z = 0; z < volume.dims.z; ++z)
    for (int y = 0; y < volume.dims.y; ++y)
      for (int x = 0; x < volume.dims.x; ++x) {
        const double v = volume.Value(x, y, z);
        if (!std::isfinite(v)) continue;
        const auto b = static_cast<size_t>(std::max((v - h.lo) / width, 0.0));
        ++h.counts[std::min(b, h.counts.size() - 1)];
      }
  return h;
}

WindowLevel WindowOf(const core::TransferFunction& tf) {
  const double lo = tf.points.front().s, hi = tf.points.back().s;
  return {0.5 * (lo + hi), hi - lo};
}

core::TransferFunction WithWindow(const core::TransferFunction& tf, const WindowLevel& wl) {
  if (!std::isfinite(wl.centre) || !std::isfinite(wl.width) || !(wl.width > 0)) {
    core::ThrowInputError("window/level", "centre {} / width {}: need finite values, width > 0",
                          wl.centre, wl.width);
  }
  const WindowLevel from = WindowOf(tf);
  core::TransferFunction out = tf;
  const size_t n = out.points.size();
  if (n == 1) {
    out.points[0].s = wl.centre;
    return out;
  }
  const double lo = wl.centre - 0.5 * wl.width;
  for (size_t i = 0; i < n; ++i) {
    // The ends exactly at the window's ends; interior points keep their
    // fraction of the span.
    const double f = i == 0       ? 0.0
                     : i + 1 == n ? 1.0
                                  : (tf.points[i].s - tf.points[0].s) / from.width;
    out.points[i].s = lo + f * wl.width;
  }
  // Rounding in a very narrow window can merge neighbours: nudge them apart.
  for (size_t i = 1; i < out.points.size(); ++i) {
    if (!(out.points[i].s > out.points[i - 1].s))
      out.points[i].s = std::nextafter(out.points[i - 1].s, std::numeric_limits<double>::max());
  }
  return out;
}

WindowLevel DragWindowLevel(const WindowLevel& start, const glm::dvec2& pixels,
                            double units_per_pixel) {
  WindowLevel wl;
  wl.width = std::max(start.width + pixels.x * units_per_pixel, units_per_pixel);
  wl.centre = start.centre + pixels.y * units_per_pixel;
  return wl;
}

std::vector<std::string> EditorPresetNames() {
  std::vector<std::string> names = core::TransferPresetNames();
  names.push_back("linear ramp");
  return names;
}

TransferEditor::TransferEditor(const core::TransferFunction& tf, const glm::dvec2& range,
                               const glm::dvec2& data)
    : range_(range), data_(data) {
  IBR_CHECK(range.y > range.x);
  tf_ = tf;
  if (tf_.units == core::TransferUnits::kNormalized) {
    for (core::TransferPoint& p : tf_.points) p.s = range.x + p.s * (range.y - range.x);
    tf_.units = core::TransferUnits::kData;
  }
  tf_.Check("TransferEditor");
}

size_t TransferEditor::AddPoint(double value, std::optional<double> opacity) {
  const auto it = std::lower_bound(tf_.points.begin(), tf_.points.end(), value,
                                   [](const core::TransferPoint& p, double v) { return p.s < v; });
  if (it != tf_.points.end() && it->s == value) return static_cast<size_t>(it - tf_.points.begin());
  core::TransferPoint p{value, tf_.Evaluate(value)};
  if (opacity) p.rgba.a = std::clamp(*opacity, 0.0, 1.0);
  const auto index = it - tf_.points.begin();
  tf_.points.insert(it, p);
  return static_cast<size_t>(index);
}

void TransferEditor::MovePoint(size_t i, double value, double opacity) {
  IBR_CHECK_LT(i, tf_.points.size());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double lo = i > 0 ? std::nextafter(tf_.points[i - 1].s, kInf) : -kInf;
  const double hi = i + 1 < tf_.points.size() ? std::nextafter(tf_.points[i + 1].s, -kInf) : kInf;
  if (std::isfinite(value)) tf_.points[i].s = std::clamp(value, lo, hi);
  if (std::isfinite(opacity)) tf_.points[i].rgba.a = std::clamp(opacity, 0.0, 1.0);
}

void TransferEditor::SetColour(size_t i, const glm::dvec3& rgb) {
  IBR_CHECK_LT(i, tf_.points.size());
  const glm::dvec3 c = glm::clamp(rgb, 0.0, 1.0);
  tf_.points[i].rgba = glm::dvec4(c, tf_.points[i].rgba.a);
}

bool TransferEditor::DeletePoint(size_t i) {
  IBR_CHECK_LT(i, tf_.points.size());
  if (tf_.points.size() == 1) return false;
  tf_.points.erase(tf_.points.begin() + static_cast<std::ptrdiff_t>(i));
  return true;
}

std::optional<size_t> TransferEditor::Pick(double value, double opacity, const glm::dvec2& scale,
                                           double tolerance) const {
  std::optional<size_t> best;
  double best_d = tolerance;
  for (size_t i = 0; i < tf_.points.size(); ++i) {
    const glm::dvec2 d((tf_.points[i].s - value) / scale.x,
                       (tf_.points[i].rgba.a - opacity) / scale.y);
    if (glm::length(d) <= best_d) {
      best_d = glm::length(d);
      best = i;
    }
  }
  return best;
}

void TransferEditor::ApplyPreset(const std::string& name) {
  core::TransferFunction tf;
  if (name == "linear ramp") {
    tf.units = core::TransferUnits::kData;
    const double hi = data_.y > data_.x ? data_.y : data_.x + 1;
    tf.points = {{data_.x, {0, 0, 0, 0}}, {hi, {1, 1, 1, 1}}};
  } else {
    tf = core::TransferPreset(name);  // InputError for an unknown name
  }
  *this = TransferEditor(tf, range_, data_);
}

}  // namespace viewer
