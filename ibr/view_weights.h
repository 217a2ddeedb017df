// View-dependent texturing weights (Kautz-Seidel 2001, sec. 4.2): the three
// maps whose viewing directions are closest to the novel view's get weights
// that sum to one and fall with the angle; all others get zero.
//
// The paper says the weights are "proportional to the angles", which read
// literally gives the LARGEST angle the largest weight, and read as 1/angle
// jumps when a map enters or leaves the best three. We use the unstructured
// lumigraph penalty (Buehler et al. 2001) with k = 3:
//
//   theta_i = angle between map i's viewing direction and the view's,
//   theta_k = the 4th smallest angle (pi when there are fewer than 4 maps),
//   w'_i    = (1 - theta_i / theta_k) / theta_i   for the 3 smallest, 0 otherwise,
//   w_i     = w'_i / sum_j w'_j.
//
// Why: (1) w'_i falls monotonically with theta_i; (2) a map whose angle
// reaches theta_k (it is about to swap with the 4th) has weight -> 0, so the
// weights are continuous as the camera moves across a swap; (3) as
// theta_i -> 0 the 1/theta_i factor dominates, so w_i -> 1 and a view from an
// input camera reproduces that camera's colours. theta_i = 0 exactly gives
// that map weight 1. When the three smallest angles all equal theta_k (a
// degenerate tie) the three get 1/3 each.
#pragma once

#include <glm/glm.hpp>
#include <vector>

namespace ibr {

// `map_directions`: unit world-space viewing direction of each map (the
// direction it looks along, towards the object); `view_direction`: the novel
// view's, unit. Returns one weight per map; at most `count` are non-zero and
// they sum to 1 (exactly 0 for every map when the list is empty).
std::vector<float> ViewDependentWeights(const std::vector<glm::dvec3>& map_directions,
                                        const glm::dvec3& view_direction, int count = 3);

// Angle in radians between two unit vectors, robust near 0 and pi.
double AngleBetween(const glm::dvec3& a, const glm::dvec3& b);

}  // namespace ibr
