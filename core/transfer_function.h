// A 1D transfer function for direct volume rendering: piecewise-linear RGBA
// over the normalised scalar s in [0, 1] (the value a 3D texture of the volume
// returns). Opacity is per reference sampling distance of one voxel; the
// volume pass corrects it for its actual slice spacing.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace core {

struct TransferPoint {
  double s = 0;          // normalised scalar in [0, 1]
  glm::dvec4 rgba{0.0};  // colour in [0, 1], opacity per voxel in [0, 1]
};

struct TransferFunction {
  std::vector<TransferPoint> points;  // strictly increasing s; at least one

  // InputError("where: ...") for no points, NaN/Inf, values outside [0, 1],
  // or s not increasing.
  void Check(std::string_view where) const;
  // Linear interpolation between points, constant beyond the ends.
  glm::dvec4 Evaluate(double s) const;
  // `n` samples at s = i / (n - 1): the texture the pass uploads (texel i at
  // s = i / (n - 1), so a lookup uses coordinate (s (n - 1) + 0.5) / n).
  std::vector<glm::vec4> Table(int n = 256) const;
};

// `table` with each opacity corrected for a sampling distance of `exponent`
// reference distances, a' = 1 - (1 - a)^exponent (in double, rounded to
// float); colours unchanged. What the volume pass uploads for its slice
// spacing, so a fragment does no pow: the corrected entries are then
// interpolated linearly, as a GPU's filter does (tables pre-corrected per
// sampling distance, as VTK's vtkOpenGLVolumeOpacityTable rebuilds its own).
std::vector<glm::vec4> OpacityCorrectedTable(std::vector<glm::vec4> table, double exponent);

// Built-in presets: "tooth", "neghip", "bucky" (one per shared volume),
// "ramp" (grey, opacity = s), "empty" (fully transparent).
TransferFunction TransferPreset(std::string_view name);
std::vector<std::string> TransferPresetNames();

// JSON: {"points": [[s, r, g, b, a], ...]}; NaN (or "nan" strings), values
// outside [0, 1] and unsorted points are InputErrors naming the file.
TransferFunction ReadTransferFunction(std::istream& in, std::string_view name);
TransferFunction ReadTransferFunction(const std::filesystem::path& path);
// A preset name, else a JSON file.
TransferFunction TransferFromPresetOrFile(const std::string& preset_or_path);

}  // namespace core
