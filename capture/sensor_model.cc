#include "capture/sensor_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <vector>

#include "core/check.h"
#include "core/error.h"
#include "core/parse_number.h"

namespace capture {
namespace {

using nlohmann::json;

constexpr const char* kKeys =
    "sigma, model, quantize, edge, grazing, holes, hole-radius, flying, outliers, mask, seed";

double ParseNumber(std::string_view key, std::string_view text, std::string_view where) {
  const std::optional<double> value = core::ParseFiniteNumber(text);
  if (!value) core::ThrowInputError(where, "{}={}: not a number", key, text);
  return *value;
}

// A length: scene units, or percent of `diagonal` with a `%` suffix.
double ParseLength(std::string_view key, std::string_view text, double diagonal,
                   std::string_view where) {
  if (!text.empty() && text.back() == '%') {
    return ParseNumber(key, text.substr(0, text.size() - 1), where) / 100 * diagonal;
  }
  return ParseNumber(key, text, where);
}

int ParseInt(std::string_view key, std::string_view text, std::string_view where) {
  const double v = ParseNumber(key, text, where);
  if (v != std::floor(v) || std::abs(v) > 1e9)
    core::ThrowInputError(where, "{}={}: not a whole number", key, text);
  return static_cast<int>(v);
}

}  // namespace

void SensorModel::Check(std::string_view where) const {
  auto fraction = [&](const char* key, double v, double max) {
    if (!(v >= 0 && v <= max)) core::ThrowInputError(where, "{}={} outside [0, {}]", key, v, max);
  };
  if (!(sigma >= 0) || !std::isfinite(sigma))
    core::ThrowInputError(where, "sigma={} must be finite and >= 0", sigma);
  if (!(z_ref > 0) || !std::isfinite(z_ref))
    core::ThrowInputError(where, "reference depth {} must be finite and > 0", z_ref);
  if (!(quantize >= 0) || !std::isfinite(quantize))
    core::ThrowInputError(where, "quantize={} must be finite and >= 0", quantize);
  if (edge < 0 || edge > 64) core::ThrowInputError(where, "edge={} outside 0..64 pixels", edge);
  if (!(grazing_deg == 0 || (grazing_deg > 0 && grazing_deg < 90))) {
    core::ThrowInputError(where, "grazing={} must be 0 (off) or an angle in (0, 90) degrees",
                          grazing_deg);
  }
  // Holes and outliers over half the object leave no object to test.
  fraction("holes", holes, 0.5);
  fraction("outliers", outliers, 0.5);
  fraction("flying", flying, 1);
  if (hole_radius < 0 || hole_radius > 256)
    core::ThrowInputError(where, "hole-radius={} outside 0..256 pixels", hole_radius);
}

std::string SensorModel::Describe() const {
  if (empty()) return "exact (no sensor model)";
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : ", ") + part; };
  if (sigma > 0) {
    add(noise == Noise::kQuadratic
            ? fmt::format("depth noise {:.4g} at depth {:.4g}, quadratic in depth", sigma, z_ref)
            : fmt::format("depth noise {:.4g}", sigma));
  }
  if (quantize > 0) add(fmt::format("quantised to {:.4g}", quantize));
  if (edge > 0) add(fmt::format("no depth within {} px of an edge", edge));
  if (grazing_deg > 0) add(fmt::format("none beyond {:g} degrees from the normal", grazing_deg));
  if (holes > 0) add(fmt::format("{:g} % in holes of radius {} px", 100 * holes, hole_radius));
  if (flying > 0) add(fmt::format("{:g} % of edge pixels flying", 100 * flying));
  if (outliers > 0) add(fmt::format("{:g} % outliers", 100 * outliers));
  add(mask_from_depth ? "mask = valid depth" : "exact mask");
  add(fmt::format("seed {}", seed));
  return s;
}

json SensorModel::ToJson() const {
  return {{"sigma", sigma},
          {"model", std::string(core::EnumToName(kNoiseNames, noise))},
          {"z_ref", z_ref},
          {"quantize", quantize},
          {"edge", edge},
          {"grazing", grazing_deg},
          {"holes", holes},
          {"hole_radius", hole_radius},
          {"flying", flying},
          {"outliers", outliers},
          {"mask", mask_from_depth ? "depth" : "exact"},
          {"seed", seed}};
}

SensorModel SensorModel::FromJson(const json& j, std::string_view where) {
  if (!j.is_object()) core::ThrowInputError(where, "depth.noise is not an object");
  SensorModel m;
  try {
    m.sigma = j.value("sigma", 0.0);
    m.noise = core::EnumFromName(kNoiseNames, j.value("model", std::string("constant")), where,
                                 "depth.noise.model");
    m.z_ref = j.value("z_ref", 1.0);
    m.quantize = j.value("quantize", 0.0);
    m.edge = j.value("edge", 0);
    m.grazing_deg = j.value("grazing", 0.0);
    m.holes = j.value("holes", 0.0);
    m.hole_radius = j.value("hole_radius", 2);
    m.flying = j.value("flying", 0.0);
    m.outliers = j.value("outliers", 0.0);
    const std::string mask = j.value("mask", std::string("exact"));
    if (mask != "exact" && mask != "depth")
      core::ThrowInputError(where, "depth.noise.mask '{}' is not exact or depth", mask);
    m.mask_from_depth = mask == "depth";
    m.seed = j.value("seed", 1u);
  } catch (const json::exception& e) {
    core::ThrowInputError(where, "depth.noise: {}", e.what());
  }
  m.Check(fmt::format("{}: depth.noise", where));
  return m;
}

SensorModel ParseSensorModel(std::string_view spec, double diagonal, double z_ref) {
  const std::string where = fmt::format("--noise '{}'", spec);
  SensorModel m;
  m.z_ref = z_ref;
  size_t start = 0;
  while (start <= spec.size()) {
    const size_t end = std::min(spec.find(',', start), spec.size());
    const std::string_view item = spec.substr(start, end - start);
    start = end + 1;
    if (item.empty()) {
      if (end == spec.size()) break;
      continue;
    }
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      core::ThrowInputError(where, "'{}' is not key=value (keys: {})", item, kKeys);
    const std::string_view key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "sigma") {
      m.sigma = ParseLength(key, value, diagonal, where);
    } else if (key == "model") {
      const auto noise = core::FindEnum(SensorModel::kNoiseNames, value);
      if (!noise) {
        core::ThrowInputError(where, "model={}: {}", value,
                              core::EnumNameList(SensorModel::kNoiseNames));
      }
      m.noise = *noise;
    } else if (key == "quantize") {
      m.quantize = ParseLength(key, value, diagonal, where);
    } else if (key == "edge") {
      m.edge = ParseInt(key, value, where);
    } else if (key == "grazing") {
      m.grazing_deg = ParseNumber(key, value, where);
    } else if (key == "holes") {
      m.holes = ParseNumber(key, value, where);
    } else if (key == "hole-radius") {
      m.hole_radius = ParseInt(key, value, where);
    } else if (key == "flying") {
      m.flying = ParseNumber(key, value, where);
    } else if (key == "outliers") {
      m.outliers = ParseNumber(key, value, where);
    } else if (key == "mask") {
      if (value != "exact" && value != "depth")
        core::ThrowInputError(where, "mask={}: exact or depth", value);
      m.mask_from_depth = value == "depth";
    } else if (key == "seed") {
      const int seed = ParseInt(key, value, where);
      if (seed < 0) core::ThrowInputError(where, "seed={} must be >= 0", seed);
      m.seed = static_cast<uint32_t>(seed);
    } else {
      core::ThrowInputError(where, "unknown key '{}' (keys: {})", key, kKeys);
    }
  }
  m.Check(where);
  return m;
}

void ApplySensorModel(const SensorModel& model, const Camera& camera, const Rigid3& cam_from_world,
                      double near, double far, size_t view_index, core::ImageF& depth,
                      core::Image8& mask, const core::ImageF& normal) {
  model.Check("ApplySensorModel");
  const int w = depth.width(), h = depth.height();
  IBR_CHECK(mask.width() == w && mask.height() == h && depth.channels() == 1);
  IBR_CHECK(normal.empty() || (normal.width() == w && normal.height() == h));
  // Every view its own stream, the same on every run.
  std::mt19937_64 rng(static_cast<uint64_t>(model.seed) * 0x9E3779B97F4A7C15ull + view_index);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const core::ImageF clean = depth;
  auto z_at = [&](int x, int y) { return static_cast<double>(clean.at(x, y)); };
  auto valid = [&](int x, int y) {
    const float z = clean.at(x, y);
    return std::isfinite(z) && z > 0;
  };
  // The length one pixel spans at depth z: a step larger than 10 of them
  // between neighbours is a depth edge (a surface at 84 degrees from the
  // view has 10).
  const double pixels_per_unit = std::max(camera.fx(), camera.fy());
  auto footprint = [&](double z) {
    return camera.orthographic() ? 1.0 / pixels_per_unit : z / pixels_per_unit;
  };

  // Depth edges on the clean map: a valid pixel next to an invalid one (a
  // silhouette), or the near side of a step.
  std::vector<uint8_t> edge(static_cast<size_t>(w) * h, 0);
  // Per edge pixel the far side: its depth, or 0 where it is empty.
  std::vector<float> far_side(edge.size(), 0);
  std::vector<int> far_pixel(edge.size(), -1);
  const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!valid(x, y)) continue;
      const double z = z_at(x, y);
      for (int k = 0; k < 4; ++k) {
        const int nx = x + dx[k], ny = y + dy[k];
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const size_t p = static_cast<size_t>(y) * w + x;
        if (!valid(nx, ny)) {
          edge[p] = 1;
          if (far_pixel[p] < 0) far_pixel[p] = ny * w + nx;
        } else if (z_at(nx, ny) - z > 10 * footprint(z)) {
          edge[p] = 1;
          far_side[p] = std::max(far_side[p], static_cast<float>(z_at(nx, ny)));
        }
      }
    }
  }

  // Noise and quantisation first, on every valid pixel.
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!valid(x, y)) continue;
      double z = z_at(x, y);
      if (model.sigma > 0) z += model.SigmaAt(z) * gauss(rng);
      if (model.quantize > 0) z = std::round(z / model.quantize) * model.quantize;
      // A sensor reports no depth rather than a negative one.
      depth.at(x, y) = z > 0 ? static_cast<float>(z) : 0.0f;
    }
  }
  // Flying pixels: a pixel straddling a depth edge measures a mix of both
  // sides; at a silhouette the far side is the empty pixel, which takes a
  // depth trailing behind the edge.
  std::vector<uint8_t> flew(edge.size(), 0);
  if (model.flying > 0) {
    for (size_t p = 0; p < edge.size(); ++p) {
      if (!edge[p] || uniform(rng) >= model.flying) continue;
      const double z = depth.data()[p] > 0 ? depth.data()[p] : clean.data()[p];
      const double t = uniform(rng);
      if (far_side[p] > 0) {
        depth.data()[p] = static_cast<float>(z + t * (far_side[p] - z));
        flew[p] = 1;
      } else if (far_pixel[p] >= 0) {
        depth.data()[far_pixel[p]] = static_cast<float>(z * (1 + 0.25 * t));
        flew[far_pixel[p]] = 1;
      }
    }
  }
  // No depth within `edge` pixels of an edge (flying pixels excepted).
  if (model.edge > 0) {
    std::vector<uint8_t> drop(edge.size(), 0);
    const int r = model.edge - 1;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!edge[static_cast<size_t>(y) * w + x]) continue;
        for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r); ++yy) {
          for (int xx = std::max(0, x - r); xx <= std::min(w - 1, x + r); ++xx) {
            drop[static_cast<size_t>(yy) * w + xx] = 1;
          }
        }
      }
    }
    for (size_t p = 0; p < drop.size(); ++p) {
      if (drop[p] && !flew[p] && clean.data()[p] > 0) depth.data()[p] = 0;
    }
  }
  // Grazing angles: the view ray against the rendered normal.
  if (model.grazing_deg > 0 && !normal.empty()) {
    const double min_cos = std::cos(model.grazing_deg * M_PI / 180);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!valid(x, y)) continue;
        const glm::dvec3 n_world(normal.at(x, y, 0), normal.at(x, y, 1), normal.at(x, y, 2));
        if (glm::length(n_world) < 0.5) continue;
        const glm::dvec3 n = cam_from_world.rotation * glm::normalize(n_world);
        const glm::dvec3 ray = camera.orthographic()
                                   ? glm::dvec3(0, 0, 1)
                                   : glm::normalize(camera.UnprojectPixel(x, y, 1.0));
        if (std::abs(glm::dot(n, ray)) < min_cos) depth.at(x, y) = 0;
      }
    }
  }
  // The object's pixels: what holes and outliers are fractions of.
  std::vector<size_t> object;
  for (size_t p = 0; p < edge.size(); ++p) {
    if (clean.data()[p] > 0 && std::isfinite(clean.data()[p])) object.push_back(p);
  }
  if (model.holes > 0 && !object.empty()) {
    // Round blobs at random object pixels until the fraction is reached.
    const size_t target = static_cast<size_t>(std::llround(model.holes * object.size()));
    std::vector<uint8_t> holed(edge.size(), 0);
    size_t dropped = 0;
    const int r = model.hole_radius;
    for (size_t tries = 0; dropped < target && tries < 64 * object.size(); ++tries) {
      const size_t c = object[static_cast<size_t>(uniform(rng) * object.size()) % object.size()];
      const int cx = static_cast<int>(c % w), cy = static_cast<int>(c / w);
      for (int y = std::max(0, cy - r); y <= std::min(h - 1, cy + r) && dropped < target; ++y) {
        for (int x = std::max(0, cx - r); x <= std::min(w - 1, cx + r) && dropped < target; ++x) {
          const size_t p = static_cast<size_t>(y) * w + x;
          if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > r * r) continue;
          if (holed[p] || !(clean.data()[p] > 0)) continue;
          holed[p] = 1;
          ++dropped;
          depth.data()[p] = 0;
        }
      }
    }
  }
  if (model.outliers > 0 && !object.empty()) {
    // Stereo mismatches: a depth anywhere along the ray within the clip range.
    const size_t count = static_cast<size_t>(std::llround(model.outliers * object.size()));
    for (size_t i = 0; i < count; ++i) {
      const size_t p = object[static_cast<size_t>(uniform(rng) * object.size()) % object.size()];
      depth.data()[p] = static_cast<float>(near + uniform(rng) * (far - near));
    }
  }
  if (model.mask_from_depth) {
    for (size_t p = 0; p < edge.size(); ++p) mask.data()[p] = depth.data()[p] > 0 ? 255 : 0;
  }
}

}  // namespace capture
