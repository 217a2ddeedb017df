// The distance-field peer of `ibr bench deform` in C++: OpenVDB's
// narrow-band level set of a closed mesh (tools::meshToLevelSet, what
// bench/openvdb_peer.py calls through pyopenvdb) on our field's nodes, and
// both fields' accuracy against CGAL's exact signed distance at sample nodes.
#pragma once

#include <cstdint>
#include <memory>

#include "core/distance_field.h"
#include "core/mesh.h"

namespace bench {

// How close a field comes to CGAL's exact signed distance (MeshDistance):
// distance errors in voxels at the nodes whose exact |distance| is within the
// band (every one up to `max_samples`, else an even stride through them),
// sign errors at those and at as many nodes spread over the whole grid.
struct SdfAccuracy {
  int64_t band_samples = 0;     // nodes compared within the band
  int64_t missing = 0;          // of them, outside the builder's band (no value)
  double max_error_voxels = 0;  // over the band samples with a value
  double p95_error_voxels = 0;
  int64_t sign_samples = 0;  // band samples plus the grid-wide ones
  int64_t sign_errors = 0;   // nodes whose sign differs from CGAL's inside test
};

// OpenVDB's level set of `closed` on the nodes of `like` (same origin and
// spacing), `half_width_voxels` wide on each side, timed around the call.
class OpenVdbLevelSet {
 public:
  OpenVdbLevelSet(const core::TriangleMesh& closed, const core::DistanceField& like,
                  double half_width_voxels);
  ~OpenVdbLevelSet();
  OpenVdbLevelSet(const OpenVdbLevelSet&) = delete;
  OpenVdbLevelSet& operator=(const OpenVdbLevelSet&) = delete;
  double seconds() const { return seconds_; }
  int64_t active_voxels() const;
  // Value at node (i, j, k); false outside the band (then only its sign holds).
  bool Value(int i, int j, int k, float* value) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double seconds_ = 0;
};

// The accuracy of `field` (ours, every node has a value) and of `level_set`
// (null: skipped) against `distance`'s exact queries at the same nodes.
void MeasureSdfAccuracy(const core::MeshDistance& distance, const core::DistanceField& field,
                        const OpenVdbLevelSet* level_set, int64_t max_samples, SdfAccuracy* ours,
                        SdfAccuracy* openvdb);

}  // namespace bench
