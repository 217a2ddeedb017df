// The built-in scenes (datasets/scenes/*.json): every definition parses, its
// capture and render options are valid, its object can be loaded; bad
// definitions are InputErrors naming the scene.
#include "ibr/scene_options.h"

#include <gtest/gtest.h>

#include "capture/builtin_scenes.h"
#include "core/error.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

TEST(BuiltinScenes, EveryDefinitionIsValidAndItsObjectLoads) {
  const std::vector<std::string> names = capture::BuiltinSceneNames();
  ASSERT_GE(names.size(), 5u);
  EXPECT_NE(std::find(names.begin(), names.end(), "spot-cube"), names.end()) << "the demo's scene";
  for (const std::string& name : names) {
    const capture::BuiltinScene scene = capture::LoadBuiltinScene(name);
    EXPECT_EQ(scene.name, name);
    EXPECT_FALSE(scene.description.empty()) << name;
    EXPECT_NO_THROW(DepthObjectOptionsFromJson(scene.render, name)) << name;
    if (!scene.shape.empty()) {
      EXPECT_GT(capture::LoadBuiltinSceneMesh(scene, {}).mesh.triangle_count(), 0u) << name;
    } else if (!test_support::SharedData(scene.shared_mesh).empty()) {
      const auto mesh = capture::LoadBuiltinSceneMesh(scene, test_support::SharedData(""));
      EXPECT_GT(mesh.mesh.triangle_count(), 100u) << name;
    }
  }
  const DepthObjectOptions demo =
      DepthObjectOptionsFromJson(capture::LoadBuiltinScene("spot-cube").render, "x");
  EXPECT_EQ(demo.texturing, Texturing::kViewDependent);
  EXPECT_EQ(demo.slicing, Slicing::kRay);  // the fastest path, and the smooth one
  EXPECT_TRUE(demo.subtexel_depth);
  EXPECT_EQ(demo.slices, DepthObjectOptions::kAutoSlices);
}

// depth_lookup: sub-texel depth where it applies (ray-path depth objects),
// nearest texels elsewhere; asking for sub-texel where it cannot apply is an
// error naming the key.
TEST(SceneOptions, DepthLookupDefaultsToSubtexelWhereItApplies) {
  const auto options = [](const char* text) {
    return DepthObjectOptionsFromJson(nlohmann::json::parse(text), "scene.json /objects/0");
  };
  EXPECT_TRUE(options(R"({"slicing": "ray"})").subtexel_depth);
  EXPECT_FALSE(options(R"({"slicing": "ray", "depth_lookup": "nearest"})").subtexel_depth);
  EXPECT_TRUE(options(R"({"slicing": "ray", "depth_lookup": "subtexel"})").subtexel_depth);
  EXPECT_FALSE(options(R"({"slicing": "orthogonal"})").subtexel_depth);
  EXPECT_FALSE(options(R"({"slicing": "screen"})").subtexel_depth);
  EXPECT_FALSE(options(R"({"slicing": "ray", "method": "visual-hull"})").subtexel_depth);
  for (const char* bad :
       {R"({"slicing": "orthogonal", "depth_lookup": "subtexel"})",
        R"({"slicing": "ray", "method": "visual-hull", "depth_lookup": "subtexel"})",
        R"({"slicing": "ray", "depth_lookup": "bicubic"})",
        R"({"slicing": "ray", "depth_lookup": 1})"}) {
    try {
      options(bad);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("depth_lookup"), std::string::npos) << e.what();
    }
  }
}

// `ibr render DATASET` and `ibr view DATASET` share one flag set: the ray
// path by default (sub-texel depth with it); --outside unset, for the
// command to choose from the cameras' coverage (ibr::ChooseOutsidePolicy).
TEST(SceneOptions, CommandLineDefaultsAreTheRayPath) {
  const DepthObjectFlags flags;
  EXPECT_EQ(flags.slicing, "ray");
  EXPECT_TRUE(flags.outside.empty());
  const DepthObjectOptions o = DepthObjectOptionsFrom(SettingsFromFlags(flags));
  EXPECT_EQ(o.slicing, Slicing::kRay);
  EXPECT_TRUE(o.subtexel_depth);
  EXPECT_EQ(SettingsFromFlags(flags).Find("outside"), nullptr) << "not set: the command decides";
  DepthObjectFlags fail = flags;
  fail.outside = "fail";
  EXPECT_EQ(DepthObjectOptionsFrom(SettingsFromFlags(fail)).outside, OutsidePolicy::kFail);
}

TEST(BuiltinScenes, BadDefinitionsNameTheScene) {
  // Scene files (scene/scene.h) that the reader or the built-in rules refuse.
  const char* bad[] = {
      "not json",
      R"({"version": 1, "cameras": {"orbit": {}}})",  // no object
      R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "depth-object", "images": )"
      R"({"capture": {"shape": "cup", "shared_mesh": "meshes/spot.obj"}}}]})",  // both
      R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "depth-object", "images": )"
      R"({"capture": {}}}]})",  // neither
      R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "depth-object", "images": )"
      R"({"capture": {"shape": "cup", "rig": "hexagon"}}}]})",  // bad rig
      R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "depth-object", "images": )"
      R"({"capture": {"shape": "cup", "size": 3}}}]})",  // absurd size
      R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}}]})",  // not image-based
  };
  for (const char* text : bad) {
    try {
      capture::ParseBuiltinScene("broken-scene", text);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("broken-scene"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(capture::LoadBuiltinScene("no-such-scene"), core::InputError);
  EXPECT_THROW(DepthObjectOptionsFromJson(nlohmann::json::parse(R"({"slicing": "diagonal"})"), "s"),
               core::InputError);
  EXPECT_THROW(DepthObjectOptionsFromJson(nlohmann::json::parse(R"({"slices": "many"})"), "s"),
               core::InputError);
  EXPECT_THROW(DepthObjectOptionsFromJson(nlohmann::json::parse(R"({"slices": 0})"), "s"),
               core::InputError);
}

}  // namespace
}  // namespace ibr
