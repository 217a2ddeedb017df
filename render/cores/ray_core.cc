#include "render/cores/ray_core.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"

namespace render {

std::string RayOutcomeName(RayOutcome outcome) {
  switch (outcome) {
    case RayOutcome::kNone:
      return "none";
    case RayOutcome::kHit:
      return "hit";
    case RayOutcome::kExited:
      return "exited";
    case RayOutcome::kEarlyTermination:
      return "early_termination";
  }
  return "unknown";
}

RayStepPolicy RayStepPolicyFromName(const std::string& name) {
  if (name == "fixed") return RayStepPolicy::kFixed;
  if (name == "threshold") return RayStepPolicy::kThreshold;
  if (name == "jacobian") return RayStepPolicy::kJacobian;
  core::ThrowInputError("RayStepPolicyFromName",
                        "unknown step policy '{}' (fixed, threshold, jacobian)", name);
}

std::string RayStepPolicyName(RayStepPolicy policy) {
  switch (policy) {
    case RayStepPolicy::kFixed:
      return "fixed";
    case RayStepPolicy::kThreshold:
      return "threshold";
    case RayStepPolicy::kJacobian:
      return "jacobian";
  }
  return "unknown";
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

void SetRayCoreUniforms(const Program& program, const RayCoreOptions& options) {
  options.Check();
  program.Set("u_ray_max_steps", options.max_steps);
  program.Set("u_ray_refine_steps", options.refine_steps);
  program.Set("u_ray_threshold", options.threshold);
  program.Set("u_ray_fine_step_scale", options.fine_step_scale);
}

}  // namespace render
