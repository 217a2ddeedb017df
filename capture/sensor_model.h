// A depth sensor's errors, applied to a clean synthetic capture so that
// tests and benches can feed the depth-object paths what users bring:
// RGB-D sensors (noise growing with depth, no depth at silhouette edges and
// at grazing angles, holes on dark or shiny surfaces, flying pixels where a
// pixel straddles a depth edge) and stereo matching (outliers). CPU-only.
//
// One spec string, as `ibr capture --noise` takes it: comma-separated
// key=value pairs, e.g. "sigma=0.3%,model=quadratic,holes=0.02,edge=1".
// Lengths are in the scene's units, or, with a `%` suffix, in percent of the
// diagonal of the captured object's bounding box (the same spec then means
// the same for a mesh of any size). Keys:
//   sigma=L        depth noise, standard deviation at the reference depth (0)
//   model=constant|quadratic
//                  constant: sigma at every depth; quadratic: sigma (z / z_ref)^2,
//                  as structured-light sensors (Khoshelham-Elberink 2012) (constant)
//   quantize=L     depth rounded to multiples of L (0: off)
//   edge=N         no depth within N pixels of a silhouette or depth edge (0)
//   grazing=DEG    no depth where the view ray meets the surface more than DEG
//                  degrees from its normal (0: off)
//   holes=F        fraction of the object's pixels without depth, in round
//                  blobs of hole-radius=R pixels (0; R 2)
//   flying=F       fraction of depth-edge pixels that take a depth between
//                  the near and the far side (0)
//   outliers=F     fraction of the object's pixels whose depth is replaced by
//                  one drawn uniformly over the view's clip range (0)
//   mask=exact|depth
//                  exact: the object mask is left as rendered; depth: the mask
//                  is where depth is valid, as imported sensor data has it (exact)
//   seed=N         the random stream (1); every view draws its own from it
// The colour image is never changed. The model applied, resolved to scene
// units, is recorded in dataset.json (depth.noise) and read back with it.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>

#include "capture/camera.h"
#include "core/enum_names.h"
#include "core/image.h"

namespace capture {

struct SensorModel {
  enum class Noise { kConstant, kQuadratic };
  static constexpr core::EnumName<Noise> kNoiseNames[] = {{Noise::kConstant, "constant"},
                                                          {Noise::kQuadratic, "quadratic"}};
  double sigma = 0;  // scene units at z_ref
  Noise noise = Noise::kConstant;
  double z_ref = 1;     // reference depth of a quadratic model, scene units
  double quantize = 0;  // scene units, 0 = off
  int edge = 0;         // pixels
  double grazing_deg = 0;
  double holes = 0;
  int hole_radius = 2;
  double flying = 0;
  double outliers = 0;
  bool mask_from_depth = false;
  uint32_t seed = 1;

  // Whether it changes anything at all.
  bool empty() const {
    return sigma == 0 && quantize == 0 && edge == 0 && grazing_deg == 0 && holes == 0 &&
           flying == 0 && outliers == 0 && !mask_from_depth;
  }
  // The noise's standard deviation at depth z.
  double SigmaAt(double z) const {
    return noise == Noise::kQuadratic ? sigma * (z / z_ref) * (z / z_ref) : sigma;
  }
  // InputError("where: ...") naming the first value out of range.
  void Check(std::string_view where) const;
  // One line for the log: every value that is set, in scene units.
  std::string Describe() const;
  nlohmann::json ToJson() const;
  static SensorModel FromJson(const nlohmann::json& j, std::string_view where);
  bool operator==(const SensorModel&) const = default;
};
static_assert(core::EnumNamesUnique(SensorModel::kNoiseNames));

// Parses a spec (above). `diagonal`: what a `%` length is a percent of;
// `z_ref`: the reference depth of a quadratic model (the capture uses the
// mean distance from its cameras to the object's centre). InputError naming
// the key on an unknown key, a malformed or out-of-range value.
SensorModel ParseSensorModel(std::string_view spec, double diagonal, double z_ref);

// One view's depth (camera z, 0 = none), mask and world normals (from the
// same render), seen by `camera` at `cam_from_world` with clip range [near,
// far], through the sensor: the depth and (mask=depth) the mask change.
// Deterministic in (model.seed, view_index).
void ApplySensorModel(const SensorModel& model, const Camera& camera, const Rigid3& cam_from_world,
                      double near, double far, size_t view_index, core::ImageF& depth,
                      core::Image8& mask, const core::ImageF& normal);

}  // namespace capture
