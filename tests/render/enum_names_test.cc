// The enum <-> name tables of render/ (core/enum_names.h) through their
// FromName/Name functions: round trips over every entry, the unknown-name
// message.
#include <gtest/gtest.h>

#include "core/error.h"
#include "render/cores/ray_core.h"
#include "render/cores/slicing.h"
#include "render/passes/deform_pass.h"
#include "render/passes/relief_surface_pass.h"
#include "render/passes/volume_pass.h"
#include "tests/support/enum_table_checks.h"

namespace render {
namespace {

TEST(RenderEnumNames, EveryTable) {
  using test_support::ExpectEnumTable;
  ExpectEnumTable(kDeformImplicitNames, DeformImplicitFromName, DeformImplicitName, "implicit");
  ExpectEnumTable(kReliefMethodNames, ReliefMethodFromName, ReliefMethodName, "method");
  ExpectEnumTable(kVolumeLightingNames, VolumeLightingFromName, VolumeLightingName, "lighting");
  ExpectEnumTable(kVolumeJacobianNames, VolumeJacobianFromName, VolumeJacobianName, "Jacobian");
  ExpectEnumTable(kSliceFamilyNames, SliceFamilyFromName, SliceFamilyName, "slicing family");
  ExpectEnumTable(kRayStepPolicyNames, RayStepPolicyFromName, RayStepPolicyName, "step policy");
  // RayOutcome is only ever named (outcome images, reports), never parsed.
  const auto outcome_from_name = [](const std::string& name) {
    return core::EnumFromName(kRayOutcomeNames, name, "test", "outcome");
  };
  ExpectEnumTable(kRayOutcomeNames, outcome_from_name, RayOutcomeName, "outcome");
  EXPECT_EQ(RayOutcomeName(RayOutcome::kEarlyTermination), "early_termination");
  // "surface-aligned" is an alias: accepted, never produced.
  EXPECT_EQ(SliceFamilyFromName("surface-aligned"), SliceFamily::kSurfaceAligned);
  EXPECT_EQ(SliceFamilyName(SliceFamily::kSurfaceAligned), "surface");
}

}  // namespace
}  // namespace render
