// core/enum_names.h: the generic table lookups, and every core table through
// its module's FromName/Name functions.
#include "core/enum_names.h"

#include <gtest/gtest.h>

#include "core/deformation.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/volume_displacement.h"
#include "tests/support/enum_table_checks.h"

namespace core {
namespace {

enum class Colour { kRed, kGreen, kBlue };
constexpr EnumName<Colour> kColourNames[] = {
    {Colour::kRed, "red"},
    {Colour::kGreen, "green", "green[:shade]"},
    {Colour::kBlue, "blue"},
    {Colour::kRed, "crimson"},  // an alias
};
static_assert(EnumNamesUnique(kColourNames));
// Lookups are constexpr: a table can be checked at compile time.
static_assert(FindEnum(kColourNames, "blue") == Colour::kBlue);
static_assert(!FindEnum(kColourNames, "Blue").has_value());  // names are case-sensitive
static_assert(EnumToName(kColourNames, Colour::kRed) == "red");
constexpr EnumName<Colour> kTwice[] = {{Colour::kRed, "red"}, {Colour::kBlue, "red"}};
static_assert(!EnumNamesUnique(kTwice));

TEST(EnumNames, BothDirections) {
  EXPECT_EQ(EnumFromName(kColourNames, "green", "Where", "colour"), Colour::kGreen);
  EXPECT_EQ(EnumFromName(kColourNames, "crimson", "Where", "colour"), Colour::kRed);
  EXPECT_EQ(EnumToName(kColourNames, Colour::kRed), "red");  // the first entry, not the alias
  EXPECT_EQ(EnumToName(kColourNames, static_cast<Colour>(7)), "unknown");
  EXPECT_EQ(EnumNameList(kColourNames), "red, green[:shade], blue, crimson");
}

TEST(EnumNames, AnUnknownNameListsEveryName) {
  try {
    EnumFromName(kColourNames, "mauve", "ColourFromName", "colour");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "ColourFromName: unknown colour 'mauve' (red, green[:shade], blue, crimson)");
  }
  EXPECT_THROW(EnumFromName(kColourNames, "", "W", "colour"), InputError);
}

TEST(EnumNames, CoreTables) {
  test_support::ExpectEnumTable(kDeformationKindNames, DeformationKindFromName, DeformationKindName,
                                "deformation");
  test_support::ExpectEnumTable(kCutModeNames, CutModeFromName, CutModeName, "cut");
  test_support::ExpectEnumTable(kHeightPatternNames, HeightPatternFromName, HeightPatternName,
                                "height pattern");
  // The messages the commands print are the ones they printed before the tables.
  try {
    CutModeFromName("thin");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "CutModeFromName: unknown cut 'thin' (none, hollow, solid, thick:T)");
  }
  try {
    DeformationKindFromName("squash");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "DeformationKindFromName: unknown deformation 'squash' (twist, bend, "
                 "pull, knife, peel, clip, cutaway, wedge, slices, seam, wave)");
  }
}

}  // namespace
}  // namespace core
