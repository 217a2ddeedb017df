#include "ibr/view_weights.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/check.h"

namespace ibr {

double AngleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  // atan2(|a x b|, a.b) keeps full precision near 0 and pi (acos does not).
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

std::vector<float> ViewDependentWeights(const std::vector<glm::dvec3>& map_directions,
                                        const glm::dvec3& view_direction, int count) {
  IBR_CHECK_GE(count, 1);
  const int n = static_cast<int>(map_directions.size());
  std::vector<float> weights(n, 0.0f);
  if (n == 0) return weights;
  std::vector<double> theta(n);
  for (int i = 0; i < n; ++i) theta[i] = AngleBetween(map_directions[i], view_direction);
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  // Stable: equal angles keep map order, so ties are resolved deterministically.
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return theta[a] < theta[b]; });
  const int k = std::min(count, n);
  const double theta_k = n > k ? theta[order[k]] : M_PI;
  if (theta[order[0]] == 0.0) {
    weights[order[0]] = 1.0f;
    return weights;
  }
  std::vector<double> w(k);
  double sum = 0;
  for (int j = 0; j < k; ++j) {
    w[j] = std::max(0.0, 1.0 - theta[order[j]] / theta_k) / theta[order[j]];
    sum += w[j];
  }
  for (int j = 0; j < k; ++j) {
    weights[order[j]] = sum > 0 ? static_cast<float>(w[j] / sum) : 1.0f / static_cast<float>(k);
  }
  return weights;
}

}  // namespace ibr
