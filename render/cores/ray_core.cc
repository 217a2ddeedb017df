#include "render/cores/ray_core.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"
#include "render/gl/uniform.h"

namespace render {

std::string RayOutcomeName(RayOutcome outcome) {
  return std::string(core::EnumToName(kRayOutcomeNames, outcome));
}

RayStepPolicy RayStepPolicyFromName(const std::string& name) {
  return core::EnumFromName(kRayStepPolicyNames, name, "RayStepPolicyFromName", "step policy");
}

std::string RayStepPolicyName(RayStepPolicy policy) {
  return std::string(core::EnumToName(kRayStepPolicyNames, policy));
}

void RayCoreOptions::Check() const {
  if (max_steps < 1 || max_steps > 65536) {
    core::ThrowInputError("RayCoreOptions", "max_steps {} outside 1..65536", max_steps);
  }
  if (refine_steps < 0 || refine_steps > kMaxRayRefineSteps) {
    core::ThrowInputError("RayCoreOptions", "refine_steps {} outside 0..{}", refine_steps,
                          kMaxRayRefineSteps);
  }
  if (!std::isfinite(threshold) || threshold < 0) {
    core::ThrowInputError("RayCoreOptions", "threshold {} must be finite and >= 0", threshold);
  }
  if (!(fine_step_scale > 0 && fine_step_scale <= 1)) {
    core::ThrowInputError("RayCoreOptions", "fine_step_scale {} outside (0, 1]", fine_step_scale);
  }
}

std::vector<std::string> RayCoreDefines(const RayCoreOptions& options) {
  options.Check();
  std::vector<std::string> defines = {
      fmt::format("RAY_OUTCOME_HIT {}", static_cast<int>(RayOutcome::kHit)),
      fmt::format("RAY_OUTCOME_EXITED {}", static_cast<int>(RayOutcome::kExited)),
      fmt::format("RAY_OUTCOME_EARLY_TERMINATION {}",
                  static_cast<int>(RayOutcome::kEarlyTermination)),
  };
  switch (options.step_policy) {
    case RayStepPolicy::kFixed:
      defines.push_back("RAY_STEP_FIXED");
      break;
    case RayStepPolicy::kThreshold:
      defines.push_back("RAY_STEP_THRESHOLD");
      break;
    case RayStepPolicy::kJacobian:
      defines.push_back("RAY_STEP_JACOBIAN");
      break;
  }
  defines.push_back(options.refinement == RayRefinement::kBisection ? "RAY_REFINE_BISECTION"
                                                                    : "RAY_REFINE_SECANT");
  return defines;
}

namespace {

// The u_ray_* uniforms of shaders/cores/ray_core.glsl.
struct RayCoreUniforms {
  explicit RayCoreUniforms(const Program& p)
      : max_steps(p, "u_ray_max_steps"),
        refine_steps(p, "u_ray_refine_steps"),
        threshold(p, "u_ray_threshold"),
        fine_step_scale(p, "u_ray_fine_step_scale") {}
  Uniform<int> max_steps;
  Uniform<int> refine_steps;
  Uniform<float> threshold;
  Uniform<float> fine_step_scale;
};

}  // namespace

void SetRayCoreUniforms(const Program& program, const RayCoreOptions& options) {
  options.Check();
  const auto& u = program.Typed<RayCoreUniforms>();
  u.max_steps.Set(options.max_steps);
  u.refine_steps.Set(options.refine_steps);
  u.threshold.Set(options.threshold);
  u.fine_step_scale.Set(options.fine_step_scale);
}

}  // namespace render
