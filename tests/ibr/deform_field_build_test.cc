// ibr::DeformFieldBuild (a deform object's distance field built on a worker
// thread) and the deferred field of a moved box (UpdateDeformObject's
// defer_reach): whatever path a field takes, the data an update ends with
// equals MakeDeformObject of the options it ends with, bit for bit (CPU
// only: the distance field needs no context).
#include <gtest/gtest.h>

#include <memory>

#include "core/mesh.h"
#include "ibr/deform_object.h"

namespace ibr {
namespace {

core::TriangleMesh Sphere() { return core::MakeSphere(1.0f, 16, 32); }

DeformObjectOptions Knife(double opening) {
  DeformObjectOptions o;
  core::Deformation d;
  d.kind = core::DeformationKind::kKnife;
  SetDeformationDefaults(d);
  d.amount = opening;
  o.deformation.terms = {d};
  o.pass.cut = core::CutMode::kSolid;
  o.sdf_resolution = 24;  // a small field: the test is about which field, not its quality
  return o;
}

// The field, texture and placement of `a` and `b` are the same bits.
void ExpectSameData(const DeformObjectData& a, const DeformObjectData& b) {
  EXPECT_EQ(a.sdf.size, b.sdf.size);
  EXPECT_EQ(a.sdf.origin, b.sdf.origin);
  EXPECT_EQ(a.sdf.spacing, b.sdf.spacing);
  EXPECT_TRUE(a.sdf.values == b.sdf.values) << "the fields differ";
  EXPECT_EQ(a.sdf_reach, b.sdf_reach);
  EXPECT_EQ(a.placement.object_from_box, b.placement.object_from_box);
  EXPECT_EQ(a.field_placement.object_from_box, b.field_placement.object_from_box);
  EXPECT_EQ(a.max_displacement, b.max_displacement);
  EXPECT_TRUE(a.texture.rgba == b.texture.rgba) << "the deformation textures differ";
}

// A drag that outgrows the field defers it; the field built in the
// background for the drag's end is installed at rest, with its reach in the
// options, and equals a fresh build of those options.
TEST(DeformFieldBuild, ServedBuildEqualsAFreshBuild) {
  const DeformObjectOptions start = Knife(0.05);
  auto data = std::make_shared<DeformObjectData>(MakeDeformObject(Sphere(), start, "test"));
  DeformObjectOptions moved = Knife(0.4);
  const DeformObjectChange deferred =
      UpdateDeformObject(*data, start, moved, "test", nullptr, /*defer_reach=*/true);
  ASSERT_TRUE(deferred.implicit_deferred) << "an opening of 0.4 outgrows a field for 0.05";
  EXPECT_FALSE(deferred.implicit);
  EXPECT_LT(data->sdf_reach, data->max_displacement);

  DeformObjectOptions wanted = moved;
  wanted.sdf_reach = 2.0 * data->max_displacement;
  DeformFieldBuild build(data, wanted, "test", /*threads=*/1);
  EXPECT_EQ(build.reach(), 2.0 * data->max_displacement);
  EXPECT_TRUE(build.Serves(moved, data->placement, data->max_displacement));

  DeformObjectOptions rest = moved;
  const int builds = data->implicit_builds;
  const DeformObjectChange change = UpdateDeformObject(*data, moved, rest, "test", nullptr,
                                                       /*defer_reach=*/false, &build);
  EXPECT_TRUE(change.implicit);
  EXPECT_FALSE(change.implicit_deferred);
  EXPECT_TRUE(build.Used());
  EXPECT_EQ(data->implicit_builds, builds + 1);
  ASSERT_TRUE(rest.sdf_reach.has_value());
  EXPECT_EQ(*rest.sdf_reach, build.reach());
  ExpectSameData(*data, MakeDeformObject(Sphere(), rest, "test"));
}

// A build for another box does not serve: the update rebuilds itself and
// the build is left unused.
TEST(DeformFieldBuild, BuildForAnotherBoxIsNotUsed) {
  const DeformObjectOptions start = Knife(0.15);
  auto data = std::make_shared<DeformObjectData>(MakeDeformObject(Sphere(), start, "test"));
  DeformFieldBuild build(data, start, "test");
  DeformObjectOptions moved = start;
  moved.translation = {0.1, 0.0, 0.0};
  const core::Placement moved_box =
      DeformPlacement(moved, core::Box3d{{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}});
  EXPECT_FALSE(build.Serves(moved, moved_box, data->max_displacement));
  DeformObjectOptions rest = moved;
  const DeformObjectChange change =
      UpdateDeformObject(*data, start, rest, "test", nullptr, /*defer_reach=*/false, &build);
  EXPECT_TRUE(change.implicit);
  EXPECT_FALSE(build.Used());
  ExpectSameData(*data, MakeDeformObject(Sphere(), rest, "test"));
}

// A moved box keeps its field while deferring (the field's box stays where
// it was built), and the update without deferral rebuilds it for the new
// box: then the data equals a fresh build.
TEST(DeformFieldBuild, MovedBoxDefersItsFieldUntilRest) {
  const DeformObjectOptions start = Knife(0.15);
  DeformObjectData data = MakeDeformObject(Sphere(), start, "test");
  const core::DistanceField before = data.sdf;
  DeformObjectOptions moved = start;
  moved.translation = {0.12, 0.0, 0.0};
  const DeformObjectChange moving =
      UpdateDeformObject(data, start, moved, "test", nullptr, /*defer_reach=*/true);
  EXPECT_TRUE(moving.implicit_deferred);
  EXPECT_FALSE(moving.implicit);
  EXPECT_TRUE(data.sdf.values == before.values);
  EXPECT_NE(data.placement.object_from_box, data.field_placement.object_from_box);
  DeformObjectOptions rest = moved;
  const DeformObjectChange settled =
      UpdateDeformObject(data, moved, rest, "test", nullptr, /*defer_reach=*/false);
  EXPECT_TRUE(settled.implicit);
  EXPECT_EQ(data.placement.object_from_box, data.field_placement.object_from_box);
  ExpectSameData(data, MakeDeformObject(Sphere(), rest, "test"));
}

}  // namespace
}  // namespace ibr
