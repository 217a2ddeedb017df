// The one bench translation unit that includes OpenVDB's MeshToVolume.
#include "bench/openvdb_sdf.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "core/metrics.h"

namespace bench {

struct OpenVdbLevelSet::Impl {
  openvdb::FloatGrid::Ptr grid;
};

OpenVdbLevelSet::OpenVdbLevelSet(const core::TriangleMesh& closed, const core::DistanceField& like,
                                 double half_width_voxels)
    : impl_(std::make_unique<Impl>()) {
  openvdb::initialize();
  // Index (i, j, k) is our node (i, j, k): voxel size = our spacing,
  // translated to our origin (the Python peer leaves it at 0: same cost).
  openvdb::math::Transform::Ptr transform =
      openvdb::math::Transform::createLinearTransform(like.spacing);
  transform->postTranslate(openvdb::Vec3d(like.origin.x, like.origin.y, like.origin.z));
  std::vector<openvdb::Vec3s> points;
  points.reserve(closed.positions.size());
  for (const glm::vec3& p : closed.positions) points.emplace_back(p.x, p.y, p.z);
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(closed.triangle_count());
  for (size_t t = 0; t < closed.triangle_count(); ++t) {
    triangles.emplace_back(closed.indices[3 * t], closed.indices[3 * t + 1],
                           closed.indices[3 * t + 2]);
  }
  const auto start = std::chrono::steady_clock::now();
  impl_->grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(
      *transform, points, triangles, static_cast<float>(half_width_voxels));
  seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

OpenVdbLevelSet::~OpenVdbLevelSet() = default;

int64_t OpenVdbLevelSet::active_voxels() const {
  return static_cast<int64_t>(impl_->grid->activeVoxelCount());
}

bool OpenVdbLevelSet::Value(int i, int j, int k, float* value) const {
  return impl_->grid->tree().probeValue(openvdb::Coord(i, j, k), *value);
}

void MeasureSdfAccuracy(const core::MeshDistance& distance, const core::DistanceField& field,
                        const OpenVdbLevelSet* level_set, int64_t max_samples, SdfAccuracy* ours,
                        SdfAccuracy* openvdb) {
  // Band nodes by our field (exact there: core/distance_field_test), the
  // truth from CGAL at each; then nodes drawn uniformly over the grid.
  std::vector<glm::ivec3> band;
  for (int k = 0; k < field.size.z; ++k)
    for (int j = 0; j < field.size.y; ++j)
      for (int i = 0; i < field.size.x; ++i) {
        if (std::abs(field.At(i, j, k)) <= field.exact_band) band.emplace_back(i, j, k);
      }
  std::vector<glm::ivec3> nodes;
  const size_t stride = std::max<size_t>(1, band.size() / std::max<int64_t>(1, max_samples));
  for (size_t n = 0; n < band.size(); n += stride) nodes.push_back(band[n]);
  const size_t band_count = nodes.size();
  std::mt19937 random(35);
  for (size_t n = 0; n < band_count; ++n) {
    nodes.emplace_back(std::uniform_int_distribution<int>(0, field.size.x - 1)(random),
                       std::uniform_int_distribution<int>(0, field.size.y - 1)(random),
                       std::uniform_int_distribution<int>(0, field.size.z - 1)(random));
  }
  std::vector<double> ours_errors, vdb_errors;
  *ours = SdfAccuracy{};
  *openvdb = SdfAccuracy{};
  for (size_t n = 0; n < nodes.size(); ++n) {
    const glm::ivec3 v = nodes[n];
    const double truth = distance.SignedDistance(field.origin + field.spacing * glm::dvec3(v));
    auto compare = [&](SdfAccuracy* a, std::vector<double>* errors, bool has, float value) {
      ++a->sign_samples;
      // Nodes within float rounding of the surface may take either sign.
      if (std::abs(truth) > 1e-6 * field.spacing && (truth < 0) != (value < 0)) ++a->sign_errors;
      if (n >= band_count || std::abs(truth) > field.exact_band) return;
      ++a->band_samples;
      if (!has) {
        ++a->missing;
        return;
      }
      errors->push_back(std::abs(value - truth) / field.spacing);
    };
    compare(ours, &ours_errors, true, field.At(v.x, v.y, v.z));
    if (level_set) {
      float value = 0;
      const bool has = level_set->Value(v.x, v.y, v.z, &value);
      compare(openvdb, &vdb_errors, has, value);
    }
  }
  auto finish = [](SdfAccuracy* a, const std::vector<double>& errors) {
    a->max_error_voxels = errors.empty() ? NAN : *std::max_element(errors.begin(), errors.end());
    a->p95_error_voxels = core::Percentile(errors, 0.95);
  };
  finish(ours, ours_errors);
  finish(openvdb, vdb_errors);
}

}  // namespace bench
