// The defaults the scene-key table documents (scene/scene_keys.h) are what
// the option parsers do when the key is absent: each written default parses,
// and the enum and number defaults give the same options as no key at all.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "ibr/deform_object.h"
#include "ibr/scene_options.h"
#include "ibr/volume_object.h"
#include "render/cores/ray_core.h"
#include "scene/scene_keys.h"

namespace ibr {
namespace {

std::string Default(std::string_view kind, std::string_view key) {
  const scene::ObjectKindSpec* k = scene::FindObjectKind(kind);
  EXPECT_NE(k, nullptr) << kind;
  for (const scene::KeySpec& s : k->keys) {
    if (s.key == key) return std::string(s.default_value);
  }
  ADD_FAILURE() << kind << " has no key " << key;
  return "";
}

// The default as a scene file would hold it: a JSON number or bool where
// the text is one, else a string.
scene::Settings One(std::string_view key, const std::string& value) {
  scene::Settings s;
  nlohmann::json v = nlohmann::json::parse(value, nullptr, /*allow_exceptions=*/false);
  if (v.is_discarded() || v.is_object() || v.is_array()) v = value;
  s.Set(std::string(key), v, std::string(key));
  return s;
}

// Keys whose default is a value a user could type (not a description).
bool Typeable(const scene::KeySpec& k) {
  return !k.default_value.empty() && k.default_value.find(' ') == std::string_view::npos &&
         k.default_value != "auto" && k.effect;
}

TEST(SceneKeysDefaults, EveryWrittenDefaultParses) {
  for (const scene::ObjectKindSpec& kind : scene::ObjectKinds()) {
    for (const scene::KeySpec& k : kind.keys) {
      if (!Typeable(k)) continue;
      const scene::Settings s = One(k.key, std::string(k.default_value));
      SCOPED_TRACE(std::string(kind.name) + "." + std::string(k.key));
      switch (kind.type) {
        case scene::ObjectType::kDepthObject:
        case scene::ObjectType::kVisualHull:
          // Sub-texel depth applies to depth objects on the ray path only.
          if (k.key != "depth_lookup") {
            EXPECT_NO_THROW(DepthObjectOptionsFrom(s));
          }
          break;
        case scene::ObjectType::kDisplacedMesh:
          EXPECT_NO_THROW(DisplacedMeshOptionsFrom(s));
          break;
        case scene::ObjectType::kVolume:
          EXPECT_NO_THROW(VolumeObjectOptionsFrom(s));
          break;
        case scene::ObjectType::kDeform:
          EXPECT_NO_THROW(DeformObjectOptionsFrom(s));
          break;
        case scene::ObjectType::kMesh:
          break;
      }
    }
  }
}

TEST(SceneKeysDefaults, DefaultsEqualWhatTheParsersDoWithoutTheKey) {
  const DepthObjectOptions d = DepthObjectOptionsFrom({});
  EXPECT_EQ(Default("depth-object", "slicing"), SlicingName(d.slicing));
  EXPECT_EQ(Default("depth-object", "slice_path"), SlicePathName(d.slice_path));
  EXPECT_EQ(Default("depth-object", "texturing"), TexturingName(d.texturing));
  EXPECT_EQ(Default("depth-object", "robust"), std::to_string(d.robust_k));
  EXPECT_EQ(Default("depth-object", "refine_steps"), std::to_string(d.refine_steps));
  EXPECT_EQ(Default("depth-object", "max_maps"), std::to_string(d.max_maps));
  EXPECT_EQ(Default("depth-object", "outside"),
            d.outside == OutsidePolicy::kPass ? "pass" : "fail");

  const DisplacedMeshOptions m = DisplacedMeshOptionsFrom({});
  EXPECT_EQ(Default("displaced-mesh", "method"), DisplacementMethodName(m.method));
  EXPECT_FLOAT_EQ(static_cast<float>(std::stod(Default("displaced-mesh", "max_displacement"))),
                  m.max_displacement);
  EXPECT_EQ(std::stod(Default("displaced-mesh", "tiling")), m.tiling);
  EXPECT_EQ(Default("displaced-mesh", "slices"), std::to_string(m.slices));
  EXPECT_EQ(Default("displaced-mesh", "steps"), std::to_string(m.steps));

  const VolumeObjectOptions v = VolumeObjectOptionsFrom({});
  EXPECT_EQ(Default("volume", "map_size"), std::to_string(v.map_size));
  EXPECT_EQ(std::stod(Default("volume", "spacing")), v.pass.sampling_distance_voxels);
  EXPECT_EQ(Default("volume", "displacement_bits"), std::to_string(v.pass.displacement_bits));
  EXPECT_EQ(Default("volume", "lighting"), render::VolumeLightingName(v.pass.lighting));
  EXPECT_EQ(Default("volume", "jacobian"), render::VolumeJacobianName(v.pass.jacobian));

  const DeformObjectOptions f = DeformObjectOptionsFrom({});
  EXPECT_EQ(std::stod(Default("deform", "step_voxels")), f.pass.step_voxels);
  EXPECT_EQ(Default("deform", "resolution"), std::to_string(f.sdf_resolution));
  EXPECT_EQ(Default("deform", "skip"), f.pass.skip_empty ? "true" : "false");
  EXPECT_EQ(Default("deform", "skip_object"), f.pass.skip_object ? "true" : "false");
  EXPECT_EQ(Default("deform", "cap_holes"), f.cap_holes ? "true" : "false");
  EXPECT_EQ(Default("deform", "solid"), f.pass.solid_search ? "search" : "csg");
}

// refine_steps has one range, the ray core's: the key's range names it, the
// scene parser and DepthObjectOptions::Check accept its ends and refuse one past.
TEST(SceneKeysDefaults, RefineStepsHaveOneRange) {
  const int max = render::kMaxRayRefineSteps;
  const scene::ObjectKindSpec* kind = scene::FindObjectKind("depth-object");
  ASSERT_NE(kind, nullptr);
  std::string range;
  for (const scene::KeySpec& k : kind->keys) {
    if (k.key == "refine_steps" && k.range) range = scene::RangeText(*k.range);
  }
  EXPECT_EQ(range, "[0, " + std::to_string(max) + "]");
  for (const int steps : {0, max}) {
    DepthObjectOptions o;
    EXPECT_NO_THROW(o = DepthObjectOptionsFrom(One("refine_steps", std::to_string(steps))));
    EXPECT_EQ(o.refine_steps, steps);
    EXPECT_NO_THROW(o.Check());
  }
  for (const int steps : {-1, max + 1}) {
    EXPECT_THROW(DepthObjectOptionsFrom(One("refine_steps", std::to_string(steps))),
                 core::InputError)
        << steps;
    DepthObjectOptions o;
    o.refine_steps = steps;
    EXPECT_THROW(o.Check(), core::InputError) << steps;
  }
}

}  // namespace
}  // namespace ibr
