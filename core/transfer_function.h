// A 1D transfer function for direct volume rendering: piecewise-linear RGBA
// over the normalised scalar s in [0, 1] (the value the volume's 3D texture
// holds, core::Volume::ToNormalized) or, with units kData, over the volume's
// stored values (HU for a CT), converted to s once the volume is known
// (NormalizedTransfer). Opacity is per reference sampling distance of one
// voxel; the volume pass corrects it for its actual slice spacing.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace core {

// What a transfer point's s is: the normalised scalar in [0, 1] (presets,
// JSON files without "units") or a value in the volume's stored units.
enum class TransferUnits { kNormalized, kData };

struct TransferPoint {
  double s = 0;          // normalised scalar in [0, 1], or a stored value (kData)
  glm::dvec4 rgba{0.0};  // colour in [0, 1], opacity per voxel in [0, 1]
  bool operator==(const TransferPoint&) const = default;
};

struct TransferFunction {
  std::vector<TransferPoint> points;  // strictly increasing s; at least one
  TransferUnits units = TransferUnits::kNormalized;

  // InputError("where: ...") for no points, NaN/Inf, colours or opacities
  // outside [0, 1], s outside [0, 1] (kNormalized only) or s not increasing.
  void Check(std::string_view where) const;
  // Linear interpolation between points, constant beyond the ends.
  glm::dvec4 Evaluate(double s) const;
  // `n` samples at s = i / (n - 1): the texture the pass uploads (texel i at
  // s = i / (n - 1), so a lookup uses coordinate (s (n - 1) + 0.5) / n).
  std::vector<glm::vec4> Table(int n = 256) const;
  bool operator==(const TransferFunction&) const = default;
};

// `table` with each opacity corrected for a sampling distance of `exponent`
// reference distances, a' = 1 - (1 - a)^exponent (in double, rounded to
// float); colours unchanged. What the volume pass uploads for its slice
// spacing, so a fragment does no pow: the corrected entries are then
// interpolated linearly, as a GPU's filter does (tables pre-corrected per
// sampling distance, as VTK's vtkOpenGLVolumeOpacityTable rebuilds its own).
std::vector<glm::vec4> OpacityCorrectedTable(std::vector<glm::vec4> table, double exponent);

// `tf` over the normalised scalar of a volume whose stored values `range`
// [lo, hi] map to 0 and 1 (core::Volume::NormalizationRange): the same
// function of the stored value, cut to [lo, hi] (the ends evaluated there).
// A kNormalized function is returned unchanged.
TransferFunction NormalizedTransfer(const TransferFunction& tf, const glm::dvec2& range);

// The default when no transfer function is named, in stored units: white,
// transparent at `lo` ramping to opaque at `hi` (callers pass a percentile
// window, e.g. the 50th and 99th, so a 12-bit scan in 16 bits or a CT in HU
// is not black). hi <= lo is widened to lo + 1.
TransferFunction WindowTransfer(double lo, double hi);

// Built-in presets: "tooth", "neghip", "bucky" (one per shared volume),
// "ramp" (grey, opacity = s), "empty" (fully transparent).
TransferFunction TransferPreset(std::string_view name);
std::vector<std::string> TransferPresetNames();

// JSON: {"points": [[s, r, g, b, a], ...], "units": "normalized" | "data"}
// ("units" optional, default normalized; "data": s in the volume's stored
// units, e.g. HU); NaN (or "nan" strings), values outside [0, 1] and unsorted
// points are InputErrors naming the file.
TransferFunction ReadTransferFunction(std::istream& in, std::string_view name);
TransferFunction ReadTransferFunction(const std::filesystem::path& path);
// The JSON text ReadTransferFunction reads back to `tf` bit for bit (each
// number with the digits that parse back to its bits): what a scene's inline
// "transfer" object holds (`ibr view --save-scene` of an edited function).
std::string TransferFunctionJson(const TransferFunction& tf);
// A preset name, else a JSON file; a name that is neither is an InputError
// listing the presets.
TransferFunction TransferFromPresetOrFile(const std::string& preset_or_path);

}  // namespace core
