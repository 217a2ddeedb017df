// The enum <-> name tables of ibr/ (core/enum_names.h) through their
// FromName/Name functions: round trips over every entry, the unknown-name
// message.
#include <gtest/gtest.h>

#include "core/error.h"
#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "ibr/mesh_export.h"
#include "tests/support/enum_table_checks.h"

namespace ibr {
namespace {

TEST(IbrEnumNames, EveryTable) {
  using test_support::ExpectEnumTable;
  ExpectEnumTable(kMethodNames, MethodFromName, MethodName, "method");
  ExpectEnumTable(kSlicingNames, SlicingFromName, SlicingName, "slicing");
  ExpectEnumTable(kSlicePathNames, SlicePathFromName, SlicePathName, "slice path");
  ExpectEnumTable(kTexturingNames, TexturingFromName, TexturingName, "texturing");
  ExpectEnumTable(kDisplacementMethodNames, DisplacementMethodFromName, DisplacementMethodName,
                  "method");
  // The dataset policies are parsed from scene keys (ibr/scene_options.cc).
  ExpectEnumTable(
      kOutsidePolicyNames,
      [](const std::string& n) {
        return core::EnumFromName(kOutsidePolicyNames, n, "t", "policy");
      },
      [](OutsidePolicy p) { return core::EnumToName(kOutsidePolicyNames, p); }, "policy");
  ExpectEnumTable(
      kInvalidDepthPolicyNames,
      [](const std::string& n) {
        return core::EnumFromName(kInvalidDepthPolicyNames, n, "t", "policy");
      },
      [](InvalidDepthPolicy p) { return core::EnumToName(kInvalidDepthPolicyNames, p); }, "policy");
  ExpectEnumTable(
      kMeshColouringNames, MeshColouringFromName,
      [](MeshColouring c) { return core::EnumToName(kMeshColouringNames, c); }, "colouring");
  const std::vector<std::string> names = DisplacementMethodNames();
  ASSERT_EQ(names.size(), std::size(kDisplacementMethodNames));
  for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(names[i], kDisplacementMethodNames[i].name);
}

}  // namespace
}  // namespace ibr
