// View-dependent texturing weights (Kautz-Seidel 2001, sec. 4.2, with the
// formula of ibr/view_weights.h): at most three non-zero, summing to one,
// falling with the angle, continuous as the camera moves, 1 at an input view.
#include "ibr/view_weights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

namespace ibr {
namespace {

std::vector<glm::dvec3> CubeDirections() {
  return {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
}

glm::dvec3 OnCircle(double a) { return glm::normalize(glm::dvec3(std::cos(a), std::sin(a), 0.3)); }

TEST(ViewWeightsTest, ThreeWeightsSumToOneAndFallWithAngle) {
  const auto dirs = CubeDirections();
  for (int i = 0; i < 720; ++i) {
    const glm::dvec3 v = OnCircle(i * M_PI / 360);
    const std::vector<float> w = ViewDependentWeights(dirs, v);
    EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-6);
    EXPECT_LE(std::count_if(w.begin(), w.end(), [](float x) { return x > 0; }), 3);
    for (size_t a = 0; a < dirs.size(); ++a) {
      for (size_t b = 0; b < dirs.size(); ++b) {
        if (w[a] > 0 && AngleBetween(dirs[a], v) < AngleBetween(dirs[b], v) - 1e-9) {
          EXPECT_GE(w[a], w[b]) << "smaller angle, smaller weight";
        }
      }
    }
  }
}

TEST(ViewWeightsTest, ContinuousAcrossSwapsOfTheBestThree) {
  // Around the full circle in 0.05 degree steps the weights move by at most a
  // few hundredths per step, including where a map enters or leaves the best
  // three (there its weight is ~0). "1/angle" weights would jump by ~0.3.
  const auto dirs = CubeDirections();
  std::vector<float> prev = ViewDependentWeights(dirs, OnCircle(0));
  double worst = 0;
  for (int i = 1; i <= 7200; ++i) {
    const std::vector<float> w = ViewDependentWeights(dirs, OnCircle(i * 2 * M_PI / 7200));
    for (size_t k = 0; k < w.size(); ++k)
      worst = std::max(worst, static_cast<double>(std::abs(w[k] - prev[k])));
    prev = w;
  }
  EXPECT_LT(worst, 0.02);
}

TEST(ViewWeightsTest, InputDirectionGetsAllTheWeight) {
  const auto dirs = CubeDirections();
  for (size_t i = 0; i < dirs.size(); ++i) {
    const std::vector<float> w = ViewDependentWeights(dirs, dirs[i]);
    EXPECT_EQ(w[i], 1.0f);
    // And nearly so just beside it.
    const std::vector<float> near =
        ViewDependentWeights(dirs, glm::normalize(dirs[i] + glm::dvec3(1e-3, 2e-3, 0)));
    EXPECT_GT(near[i], 0.99f);
  }
}

TEST(ViewWeightsTest, FewerMapsThanThree) {
  const std::vector<glm::dvec3> two = {{1, 0, 0}, {0, 1, 0}};
  const std::vector<float> w = ViewDependentWeights(two, glm::normalize(glm::dvec3(1, 1, 0)));
  EXPECT_NEAR(w[0], 0.5f, 1e-6);
  EXPECT_NEAR(w[1], 0.5f, 1e-6);
  EXPECT_TRUE(ViewDependentWeights({}, {0, 0, 1}).empty());
}

}  // namespace
}  // namespace ibr
