// The ray core, C++ side: options, the #defines that select the step policy
// and refinement, the uniforms, and the per-pixel outcome codes shared with
// shaders/cores/ray_core.glsl (whose header documents the GLSL contract: the
// includer supplies RayField, optionally RayBend / RayInDomain / RayJacobian,
// and the hooks RAY_REJECT + RayRejectHit (reject a crossing and march on),
// RAY_BOTH_CROSSINGS (a hit is a change of side either way), RAY_SKIP +
// RaySkip (empty-space skipping: a crossing-free distance in t units, given
// the field's value at the sample) and RAY_SECOND_FIELD (a rejected crossing
// switches the search to a second field and back: Correa 2007's solid cuts);
// it never copies the marching loop). RayResult counts the field evaluations
// per ray (samples). Used by NCS, POM and relief mapping
// (render/passes/relief_surface_pass.h) and by the depth-object ray variant and the
// cut/deformation shaders.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "render/gl/handles.h"

namespace render {

// What happened to one ray; the integer values are the GLSL RAY_OUTCOME_*
// codes (RayCoreDefines inserts them), so outcome images read back as these.
enum class RayOutcome : int {
  kNone = 0,              // no ray was cast at this pixel
  kHit = 1,               // crossed into the solid; the crossing was refined
  kExited = 2,            // left the domain (box exit, above the shell, off the chart)
  kEarlyTermination = 3,  // ran out of steps while still inside the domain (Chen-Chang sec. 5)
};
inline constexpr core::EnumName<RayOutcome> kRayOutcomeNames[] = {
    {RayOutcome::kNone, "none"},
    {RayOutcome::kHit, "hit"},
    {RayOutcome::kExited, "exited"},
    {RayOutcome::kEarlyTermination, "early_termination"},
};
static_assert(core::EnumNamesUnique(kRayOutcomeNames));
std::string RayOutcomeName(RayOutcome outcome);

// The bit of a frame's outcome (render/passes/pass.h) set when any ray at the
// pixel ended with `outcome` (ray passes OR 1u << RayOutcome per ray).
constexpr uint32_t OutcomeBit(RayOutcome outcome) { return 1u << static_cast<int>(outcome); }

// How the linear search chooses its step (Correa-Silver-Chen 2007, sec. 3.1.1).
enum class RayStepPolicy {
  kFixed,      // the includer's step every time
  kThreshold,  // steps times fine_step_scale where |field| < threshold (Hadwiger et al. 2005)
  kJacobian,   // step / |J_{T^-1} v| (Correa 2007 eq. 4); the includer supplies RayJacobian
};
inline constexpr core::EnumName<RayStepPolicy> kRayStepPolicyNames[] = {
    {RayStepPolicy::kFixed, "fixed"},
    {RayStepPolicy::kThreshold, "threshold"},
    {RayStepPolicy::kJacobian, "jacobian"},
};
static_assert(core::EnumNamesUnique(kRayStepPolicyNames));
// "fixed", "threshold", "jacobian" (InputError otherwise).
RayStepPolicy RayStepPolicyFromName(const std::string& name);
std::string RayStepPolicyName(RayStepPolicy policy);

enum class RayRefinement {
  kBisection,  // relief mapping's binary search [POC05]
  kSecant,     // one intersection with the linear approximation (POM [Tat06])
};

// The most bisection steps a ray-core refinement takes (RayCoreOptions,
// and every option that feeds it: depth objects' refine_steps, scene key
// `refine_steps`): past ~24 a float crossing no longer moves.
inline constexpr int kMaxRayRefineSteps = 64;

struct RayCoreOptions {
  // Linear-search samples per ray; a ray still inside its domain after them
  // is an early termination. 64 is relief mapping's usual budget.
  int max_steps = 64;
  // Bisection iterations after the first inside sample: the crossing is then
  // known to 1/2^(n+1) of one step. 8 halves a 1/64 step below 1e-4.
  int refine_steps = 8;
  RayStepPolicy step_policy = RayStepPolicy::kFixed;
  RayRefinement refinement = RayRefinement::kBisection;
  // kThreshold: field magnitude (field units) under which steps shrink; 0.04
  // is the value of Correa 2007, Fig. 3(c).
  float threshold = 0.04f;
  // kThreshold: step factor near the surface, in (0, 1].
  float fine_step_scale = 0.25f;

  void Check() const;  // InputError on out-of-range values
  bool operator==(const RayCoreOptions&) const = default;
};

// The #defines a program including ray_core.glsl needs: outcome codes, step
// policy, refinement. Append them to ProgramDesc::defines.
std::vector<std::string> RayCoreDefines(const RayCoreOptions& options);

// Sets u_ray_* on `program` (which must be in use).
void SetRayCoreUniforms(const Program& program, const RayCoreOptions& options);

}  // namespace render
