#include "capture/depth_scale.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/memory_budget.h"
#include "core/metrics.h"

namespace capture {
namespace {

// The working range of consumer RGB-D sensors (see the header), metres.
constexpr double kMetricMin = 0.3, kMetricMax = 5.0;
// Baseline below which two views cannot tell a scale (fraction of depth).
constexpr double kMinBaseline = 0.02;
// Agreement of a reprojected depth with the other view's (fraction of z).
constexpr double kAgreeTolerance = 0.03;
// The usual unit confusions: mm vs TUM's 1/5000 m, 1/10 mm vs mm, mm vs m.
constexpr std::array<double, 8> kFactors = {0.2, 5, 0.1, 10, 0.001, 1000, 0.5, 2};

struct Sample {
  int col, row;
  float depth;
};

bool Valid(float d) { return std::isfinite(d) && d > 0; }

// About 4096 valid pixels of a depth map, on a regular grid.
std::vector<Sample> SampleDepth(const core::ImageF& depth) {
  const int64_t pixels = int64_t{depth.width()} * depth.height();
  const int step = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(pixels) / 4096)));
  std::vector<Sample> samples;
  for (int row = step / 2; row < depth.height(); row += step) {
    for (int col = step / 2; col < depth.width(); col += step) {
      const float d = depth.at(col, row);
      if (Valid(d)) samples.push_back({col, row, d});
    }
  }
  return samples;
}

// View b's depth at image point uv, bilinear between four valid pixels
// within kAgreeTolerance of each other (one surface); 0 otherwise. A
// nearest lookup would add the surface's slope over half a pixel to the
// residual, more than a sensor's noise at low resolution.
// `weights2`: the sum of the squared weights, by which the interpolation
// scales the variance of b's noise.
float Bilinear(const core::ImageF& depth, const glm::dvec2& uv, double& weights2) {
  const double x = uv.x - 0.5, y = uv.y - 0.5;
  const int c = static_cast<int>(std::floor(x)), r = static_cast<int>(std::floor(y));
  if (c < 0 || r < 0 || c + 1 >= depth.width() || r + 1 >= depth.height()) return 0;
  const float d[4] = {depth.at(c, r), depth.at(c + 1, r), depth.at(c, r + 1),
                      depth.at(c + 1, r + 1)};
  const auto [lo, hi] = std::minmax({d[0], d[1], d[2], d[3]});
  if (!Valid(lo) || hi - lo > kAgreeTolerance * lo) return 0;
  const double fx = x - c, fy = y - r;
  weights2 = ((1 - fx) * (1 - fx) + fx * fx) * ((1 - fy) * (1 - fy) + fy * fy);
  return static_cast<float>((1 - fy) * ((1 - fx) * d[0] + fx * d[1]) +
                            fy * ((1 - fx) * d[2] + fx * d[3]));
}

// Of view a's samples scaled by `factor` that land on view b's valid depth
// (also scaled), the fraction within kAgreeTolerance; -1 when fewer than 50 land.
// `residuals` (factor 1): view b's depth minus the reprojected one, for the
// samples that agree, scaled to one map's noise.
double Agreement(const Dataset& d, size_t a, const std::vector<Sample>& samples, size_t b,
                 const core::ImageF& depth_b, double factor,
                 std::vector<double>* residuals = nullptr) {
  const DatasetView &va = d.views[a], &vb = d.views[b];
  const Camera &ca = d.camera(va), &cb = d.camera(vb);
  const Rigid3 world_from_a = va.cam_from_world.Inverse();
  size_t landed = 0, agree = 0;
  for (const Sample& s : samples) {
    const glm::dvec3 q =
        vb.cam_from_world * (world_from_a * ca.UnprojectPixel(s.col, s.row, factor * s.depth));
    if (!(q.z > 0)) continue;
    const glm::dvec2 uv = cb.Project(q);
    const int col = static_cast<int>(std::floor(uv.x)), row = static_cast<int>(std::floor(uv.y));
    if (col < 0 || row < 0 || col >= cb.width || row >= cb.height) continue;
    const float other = depth_b.at(col, row);
    if (!Valid(other)) continue;
    ++landed;
    const bool agrees = std::abs(factor * other - q.z) <= kAgreeTolerance * q.z;
    agree += agrees;
    if (residuals && agrees) {
      // Scaled to one map's noise: the residual's variance is a's plus the
      // interpolated b's, sigma^2 (1 + weights2).
      double weights2 = 1;
      const float smooth = Bilinear(depth_b, uv, weights2);
      if (smooth > 0) residuals->push_back((smooth - q.z) / std::sqrt(1 + weights2));
    }
  }
  return landed < 50 ? -1.0 : static_cast<double>(agree) / static_cast<double>(landed);
}

}  // namespace

DepthScaleReport CheckDepthScale(const Dataset& dataset, size_t max_views) {
  DepthScaleReport report;
  std::vector<size_t> views;
  for (size_t i = 0; i < dataset.views.size() && views.size() < max_views; ++i)
    if (!dataset.views[i].depth.empty()) views.push_back(i);
  if (views.empty()) return report;
  report.views = views.size();

  std::vector<float> all;
  std::vector<std::vector<Sample>> samples(views.size());
  // Two depth maps are held at a time (the first view's samples and one more).
  std::vector<std::array<double, kFactors.size() + 1>> pair_agreement;
  std::vector<double> residuals;
  double median_first = 0;
  for (size_t k = 0; k < views.size(); ++k) {
    const Camera& camera = dataset.camera(dataset.views[views[k]]);
    core::CheckMemory(2 * sizeof(float) * static_cast<uint64_t>(camera.width) * camera.height,
                      "CheckDepthScale", "two depth maps");
    core::ImageF depth = dataset.LoadDepth(views[k]);
    samples[k] = SampleDepth(depth);
    for (const Sample& s : samples[k]) all.push_back(s.depth);
    // Pairs of the first view with each later one: the baseline grows
    // along a sequence (consecutive sensor frames are a few mm apart).
    if (k > 0 && !samples[0].empty()) {
      const size_t a = views[0], b = views[k];
      const double baseline = glm::length(dataset.views[a].cam_from_world.Centre() -
                                          dataset.views[b].cam_from_world.Centre());
      if (baseline >= kMinBaseline * median_first) {
        std::array<double, kFactors.size() + 1> row{};
        row[0] = Agreement(dataset, a, samples[0], b, depth, 1.0, &residuals);
        for (size_t f = 0; f < kFactors.size(); ++f)
          row[f + 1] = Agreement(dataset, a, samples[0], b, depth, kFactors[f]);
        if (row[0] >= 0) pair_agreement.push_back(row);
      }
    }
    if (k == 0 && !samples[0].empty()) {
      std::vector<double> z;
      for (const Sample& s : samples[0]) z.push_back(s.depth);
      median_first = core::Median(std::move(z));
    }
  }
  report.samples = all.size();
  if (all.empty()) return report;
  report.median = core::Median(std::vector<double>(all.begin(), all.end()));
  report.pairs = pair_agreement.size();
  if (residuals.size() >= 100) {
    // The residuals are already scaled to one map's noise: their robust
    // deviation (1.4826 MAD) is its sigma.
    const double median = core::Median(residuals);
    for (double& r : residuals) r = std::abs(r - median);
    report.noise_sigma = 1.4826 * core::Median(residuals);
    report.noise_samples = residuals.size();
  }

  // Mean agreement over the pairs for factor index f (0 = as is).
  auto agreement = [&](size_t f) {
    double sum = 0;
    size_t n = 0;
    for (const auto& row : pair_agreement) {
      if (row[f] < 0) continue;
      sum += row[f];
      ++n;
    }
    return n ? sum / static_cast<double>(n) : -1.0;
  };
  const bool metric = dataset.depth_units == "m";
  auto metric_ok = [&](double factor) {
    const double m = factor * report.median;
    return !metric || (m >= kMetricMin && m <= kMetricMax);
  };
  report.agreement = agreement(0);
  const double base = report.agreement;
  // The views disagree when one of the usual factors makes them agree
  // clearly better: at least 60 % of the samples, 20 points above as is
  // (a partly matching wrong scale, e.g. large flat walls, still meets some).
  auto helps = [&](size_t g) { return agreement(g) >= 0.6 && agreement(g) >= base + 0.2; };
  bool views_fine = true;
  for (size_t g = 1; g <= kFactors.size() && base >= 0; ++g) views_fine = views_fine && !helps(g);
  const bool range_fine = metric_ok(1.0);
  if (range_fine && views_fine) return report;

  std::string why;
  if (!range_fine) {
    why = fmt::format("median depth {:.3g} m is outside the {}-{} m working range of RGB-D sensors",
                      report.median, kMetricMin, kMetricMax);
  }
  if (!views_fine) {
    why += fmt::format(
        "{}{:.0f} % of the depth samples reprojected between {} view pair(s) meet the other "
        "view's depth (within {:.0f} %), clearly fewer than at another scale",
        why.empty() ? "" : "; ", 100 * report.agreement, report.pairs, 100 * kAgreeTolerance);
  }
  for (size_t f = 0; f < kFactors.size(); ++f) {
    // Where the views agree as they are, a factor must keep them agreeing.
    const bool views_then =
        base < 0 || (views_fine ? agreement(f + 1) >= base - 0.1 : helps(f + 1));
    if (metric_ok(kFactors[f]) && views_then) {
      report.suggested_factor = kFactors[f];
      break;
    }
  }
  report.warning =
      report.suggested_factor > 0
          ? fmt::format("depth scale looks wrong: {}; depths x {:g} would be plausible", why,
                        report.suggested_factor)
          : fmt::format("depth scale looks wrong: {}", why);
  return report;
}

}  // namespace capture
