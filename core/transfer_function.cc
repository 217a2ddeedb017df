#include "core/transfer_function.h"

#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/check.h"
#include "core/error.h"

namespace core {

void TransferFunction::Check(std::string_view where) const {
  if (points.empty()) ThrowInputError(where, "transfer function has no points");
  for (size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i];
    if (!std::isfinite(p.s) || (units == TransferUnits::kNormalized && (p.s < 0 || p.s > 1))) {
      ThrowInputError(where, "transfer point {}: s {} is not {}", i, p.s,
                      units == TransferUnits::kNormalized ? "in [0, 1]" : "finite");
    }
    for (double v : {p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a}) {
      if (!std::isfinite(v) || v < 0 || v > 1) {
        ThrowInputError(where, "transfer point {}: value {} is not in [0, 1]", i, v);
      }
    }
    if (i > 0 && !(p.s > points[i - 1].s)) {
      ThrowInputError(where, "transfer point {}: s {} does not increase", i, p.s);
    }
  }
}

glm::dvec4 TransferFunction::Evaluate(double s) const {
  if (s <= points.front().s) return points.front().rgba;
  if (s >= points.back().s) return points.back().rgba;
  const auto it = std::upper_bound(points.begin(), points.end(), s,
                                   [](double v, const TransferPoint& p) { return v < p.s; });
  const TransferPoint& b = *it;
  const TransferPoint& a = *(it - 1);
  const double t = (s - a.s) / (b.s - a.s);
  return glm::mix(a.rgba, b.rgba, t);
}

std::vector<glm::vec4> TransferFunction::Table(int n) const {
  IBR_CHECK(units == TransferUnits::kNormalized);  // NormalizedTransfer first
  std::vector<glm::vec4> table(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    table[static_cast<size_t>(i)] = glm::vec4(Evaluate(static_cast<double>(i) / (n - 1)));
  return table;
}

std::vector<glm::vec4> OpacityCorrectedTable(std::vector<glm::vec4> table, double exponent) {
  for (glm::vec4& e : table)
    e.a = static_cast<float>(1 - std::pow(std::max(1 - static_cast<double>(e.a), 0.0), exponent));
  return table;
}

TransferFunction NormalizedTransfer(const TransferFunction& tf, const glm::dvec2& range) {
  if (tf.units == TransferUnits::kNormalized) return tf;
  IBR_CHECK(range.y > range.x);
  const auto to_s = [&](double value) { return (value - range.x) / (range.y - range.x); };
  TransferFunction out;
  // The stored-unit function is linear between points and the map to s is
  // linear, so evaluating at the ends and keeping the points inside is exact.
  out.points.push_back({0.0, tf.Evaluate(range.x)});
  for (const TransferPoint& p : tf.points) {
    const double s = to_s(p.s);
    if (s > 0 && s < 1) out.points.push_back({s, p.rgba});
  }
  out.points.push_back({1.0, tf.Evaluate(range.y)});
  return out;
}

TransferFunction WindowTransfer(double lo, double hi) {
  if (!(hi > lo)) hi = lo + 1;
  TransferFunction tf;
  tf.units = TransferUnits::kData;
  // White throughout: the opacity ramp alone carries the window (a grey
  // colour ramp as well would darken the low end twice).
  tf.points = {TransferPoint{lo, {1, 1, 1, 0}}, TransferPoint{hi, {1, 1, 1, 1}}};
  return tf;
}

TransferFunction TransferPreset(std::string_view name) {
  TransferFunction tf;
  using P = TransferPoint;
  if (name == "tooth") {
    // Tooth CT (uint8): the air around the tooth is 0.27-0.33 (99% of the
    // boundary voxels <= 0.33); dentine orange from 0.5, enamel white above 0.7.
    tf.points = {
        P{0.0, {0, 0, 0, 0}},         P{0.46, {0, 0, 0, 0}},      P{0.52, {0.8, 0.45, 0.25, 0.1}},
        P{0.6, {0.9, 0.7, 0.5, 0.3}}, P{0.72, {1, 1, 0.95, 0.7}}, P{1.0, {1, 1, 1, 0.9}}};
  } else if (name == "neghip") {
    tf.points = {P{0.0, {0, 0, 0, 0}},           P{0.1, {0, 0, 0, 0}},
                 P{0.25, {0.2, 0.4, 1.0, 0.05}}, P{0.5, {0.2, 1.0, 0.4, 0.2}},
                 P{0.8, {1.0, 0.3, 0.2, 0.6}},   P{1.0, {1, 1, 1, 0.8}}};
  } else if (name == "bucky") {
    tf.points = {P{0.0, {0, 0, 0, 0}}, P{0.2, {0, 0, 0, 0}}, P{0.4, {0.3, 0.5, 1.0, 0.1}},
                 P{0.7, {1.0, 0.9, 0.3, 0.5}}, P{1.0, {1, 1, 1, 0.8}}};
  } else if (name == "ramp") {
    tf.points = {P{0.0, {0, 0, 0, 0}}, P{1.0, {1, 1, 1, 1}}};
  } else if (name == "empty") {
    tf.points = {P{0.0, {0, 0, 0, 0}}};
  } else {
    ThrowInputError("TransferPreset", "unknown preset '{}' (tooth, neghip, bucky, ramp, empty)",
                    name);
  }
  return tf;
}

std::vector<std::string> TransferPresetNames() {
  return {"tooth", "neghip", "bucky", "ramp", "empty"};
}

TransferFunction ReadTransferFunction(std::istream& in, std::string_view name) {
  const std::string where = fmt::format("ReadTransferFunction: '{}'", name);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    ThrowInputError(where, "not JSON: {}", e.what());
  }
  if (!j.is_object() || !j.contains("points") || !j["points"].is_array()) {
    ThrowInputError(where, "expected {{\"points\": [[s, r, g, b, a], ...]}}");
  }
  TransferFunction tf;
  if (j.contains("units")) {
    const auto& u = j["units"];
    if (u == "data") {
      tf.units = TransferUnits::kData;
    } else if (u == "normalized") {
      tf.units = TransferUnits::kNormalized;
    } else {
      ThrowInputError(where, "units {}: expected \"normalized\" or \"data\"", u.dump());
    }
  }
  for (const auto& p : j["points"]) {
    if (!p.is_array() || p.size() != 5)
      ThrowInputError(where, "each point must be [s, r, g, b, a]");
    double v[5];
    for (int k = 0; k < 5; ++k) {
      if (p[k].is_number()) {
        v[k] = p[k].get<double>();
      } else if (p[k].is_string()) {
        // JSON has no NaN; writers that emit "nan"/"inf" strings get a clear error.
        ThrowInputError(where, "value '{}' is not a finite number", p[k].get<std::string>());
      } else {
        ThrowInputError(where, "each point must be 5 numbers");
      }
    }
    tf.points.push_back({v[0], {v[1], v[2], v[3], v[4]}});
  }
  tf.Check(where);
  return tf;
}

TransferFunction ReadTransferFunction(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    ThrowFileError("ReadTransferFunction", path, "no such file");
  std::ifstream in(path);
  if (!in) ThrowFileError("ReadTransferFunction", path, "cannot open");
  return ReadTransferFunction(in, path.string());
}

std::string TransferFunctionJson(const TransferFunction& tf) {
  nlohmann::json points = nlohmann::json::array();
  for (const TransferPoint& p : tf.points)
    points.push_back({p.s, p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a});
  const nlohmann::json j = {{"units", tf.units == TransferUnits::kData ? "data" : "normalized"},
                            {"points", points}};
  return j.dump();  // nlohmann writes doubles with round-trip precision
}

TransferFunction TransferFromPresetOrFile(const std::string& preset_or_path) {
  const auto names = TransferPresetNames();
  if (std::find(names.begin(), names.end(), preset_or_path) != names.end())
    return TransferPreset(preset_or_path);
  std::error_code ec;
  if (!std::filesystem::exists(preset_or_path, ec)) {
    ThrowInputError("transfer function", "'{}' is neither a preset ({}) nor a JSON file",
                    preset_or_path, fmt::join(names, ", "));
  }
  return ReadTransferFunction(std::filesystem::path(preset_or_path));
}

}  // namespace core
