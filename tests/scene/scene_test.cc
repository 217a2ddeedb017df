// scene/scene.h: good scenes parse to the values written; bad ones fail with
// one InputError naming the file and the JSON pointer of the offending value.
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <sstream>

#include "core/error.h"
#include "datasets/embedded.h"

namespace scene {
namespace {
namespace fs = std::filesystem;

class SceneTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("ibr_scene_test_{}", ::getpid());
    fs::create_directories(dir_ / "ds");
    for (const char* f : {"h.png", "c.png", "m.obj", "v.dat"}) std::ofstream(dir_ / f) << "x";
    options_.base_dir = dir_;
    options_.shared_data = dir_;
  }
  void TearDown() override { fs::remove_all(dir_); }

  Scene Read(const std::string& text) {
    std::istringstream in(text);
    return ReadScene(in, "s.json", options_);
  }
  // The error message, or "" if it parsed.
  std::string Error(const std::string& text) {
    try {
      Read(text);
    } catch (const core::InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
  ReadOptions options_;
};

constexpr const char* kTwoObjects = R"({
  "version": 1,
  "description": "a depth object and a displaced torus",
  "cameras": {"orbit": {"count": 3, "size": 64, "elevation_deg": 30, "fov_deg": 45, "up": [0, 0, 1]}},
  "lights": [{"type": "head"}],
  "objects": [
    {"name": "cow", "type": "depth-object", "transform": {"translate": [-1, 0, 0]},
     "images": {"capture": {"shape": "sphere", "rig": "cube", "size": 128}},
     "slicing": "ray", "slices": 64, "texturing": "visibility", "robust": 1},
    {"name": "torus", "type": "displaced-mesh", "enabled": false,
     "transform": {"translate": [1, 0, 0], "rotate_deg": [90, 0, 0], "scale": 0.5},
     "mesh": {"shape": "torus"}, "height": {"generator": "bumps", "texels": 64}, "texture": "c.png",
     "method": "ncs", "max_displacement": 0.1, "tiling": 2},
    {"type": "mesh", "mesh": {"file": "m.obj"}},
    {"type": "visual-hull", "images": {"dataset": "ds"}},
    {"type": "displaced-mesh", "mesh": {"file": "m.obj"}, "height": {"file": "h.png"}}
  ]
})";

TEST_F(SceneTest, GoodSceneGivesTheValuesWritten) {
  const Scene s = Read(kTwoObjects);
  EXPECT_EQ(s.description, "a depth object and a displaced torus");
  EXPECT_EQ(s.cameras.kind, Cameras::Kind::kOrbit);
  EXPECT_EQ(s.cameras.orbit_count, 3);
  EXPECT_EQ(s.cameras.orbit_size, 64);
  EXPECT_EQ(s.cameras.orbit_up, glm::dvec3(0, 0, 1));
  ASSERT_EQ(s.lights.size(), 1u);
  ASSERT_EQ(s.objects.size(), 5u);
  const Object& cow = s.objects[0];
  EXPECT_EQ(cow.type, ObjectType::kDepthObject);
  EXPECT_TRUE(cow.enabled);
  EXPECT_EQ(cow.world_from_object, glm::translate(glm::dmat4(1.0), glm::dvec3(-1, 0, 0)));
  EXPECT_EQ(cow.images.capture_mesh.shape, "sphere");
  EXPECT_EQ(cow.images.capture_size, 128);
  EXPECT_EQ(cow.settings.GetString("slicing", ""), "ray");
  EXPECT_EQ(cow.settings.GetInt("slices", 0), 64);
  EXPECT_EQ(cow.settings.GetString("method", ""), "depth-object");  // from the type
  EXPECT_EQ(cow.settings.Find("slices")->where, "ReadScene: 's.json' /objects/0/slices");
  const Object& torus = s.objects[1];
  EXPECT_FALSE(torus.enabled);
  EXPECT_EQ(torus.height.generator, "bumps");
  EXPECT_EQ(torus.height.texels, 64);
  EXPECT_EQ(torus.texture, dir_ / "c.png");
  EXPECT_DOUBLE_EQ(torus.settings.GetDouble("max_displacement", 0), 0.1);
  // translate * rotate_x(90) * scale: the object's +y goes to world +z, scaled.
  const glm::dvec4 y = torus.world_from_object * glm::dvec4(0, 1, 0, 1);
  EXPECT_NEAR(y.x, 1, 1e-12);
  EXPECT_NEAR(y.y, 0, 1e-12);
  EXPECT_NEAR(y.z, 0.5, 1e-12);
  EXPECT_EQ(s.objects[2].name, "object_2");
  EXPECT_EQ(s.objects[2].mesh.file, dir_ / "m.obj");
  EXPECT_EQ(s.objects[3].type, ObjectType::kVisualHull);
  EXPECT_EQ(s.objects[3].images.dataset, dir_ / "ds");
  EXPECT_EQ(s.objects[4].height.file, dir_ / "h.png");
}

TEST_F(SceneTest, CameraListAndDatasetCameras) {
  const Scene a = Read(R"({"version": 1, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}}],
    "cameras": {"list": [{"name": "front", "width": 64, "height": 48, "fx": 50, "fy": 50, "cx": 32, "cy": 24,
      "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5]]},
      {"name": "top", "width": 32, "height": 32, "fx": 10, "fy": 10, "cx": 16, "cy": 16, "orthographic": true,
      "cam_from_world": [[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 5]]}]}})");
  ASSERT_EQ(a.cameras.list.size(), 2u);
  EXPECT_EQ(a.cameras.list[0].cam_from_world[3], glm::dvec4(0, 0, 5, 1));
  EXPECT_TRUE(a.cameras.list[1].orthographic);
  EXPECT_EQ(a.cameras.list[1].cam_from_world[1], glm::dvec4(0, 0, 1, 0));  // column 1 = (0, 0, 1)
  const Scene b = Read(R"({"version": 1, "cameras": {"dataset": "ds", "size": 128},
    "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "transform": {"matrix": [[2, 0, 0, 1], [0, 2, 0, 0], [0, 0, 2, 0]]}}]})");
  EXPECT_EQ(b.cameras.kind, Cameras::Kind::kDataset);
  EXPECT_EQ(b.cameras.dataset_size, 128);
  EXPECT_EQ(b.objects[0].world_from_object[0], glm::dvec4(2, 0, 0, 0));
  EXPECT_EQ(b.objects[0].world_from_object[3], glm::dvec4(1, 0, 0, 1));
}

// Each bad scene: the error names the file and this JSON pointer.
struct BadScene {
  const char* what;
  const char* text;
  const char* pointer;
};

#define OBJ R"("objects": [{"type": "mesh", "mesh": {"shape": "cup"}}])"
#define CAM R"("cameras": {"orbit": {}})"

TEST_F(SceneTest, BadScenesNameTheFileAndThePointer) {
  const BadScene bad[] = {
      {"not JSON", "{", ""},
      {"not an object", "[1]", " /:"},
      {"no version", "{" CAM ", " OBJ "}", " /:"},
      {"future version", R"({"version": 2, )" CAM ", " OBJ "}", "/version"},
      {"version a string", R"({"version": "1", )" CAM ", " OBJ "}", "/version"},
      {"unknown top key", R"({"version": 1, "colour": 1, )" CAM ", " OBJ "}", "/colour"},
      {"no cameras", R"({"version": 1, )" OBJ "}", " /:"},
      {"two camera kinds", R"({"version": 1, "cameras": {"orbit": {}, "dataset": "ds"}, )" OBJ "}",
       "/cameras"},
      {"orbit count 0", R"({"version": 1, "cameras": {"orbit": {"count": 0}}, )" OBJ "}",
       "/cameras/orbit/count"},
      {"orbit unknown key", R"({"version": 1, "cameras": {"orbit": {"radius": 3}}, )" OBJ "}",
       "/cameras/orbit/radius"},
      {"orbit up wrong length", R"({"version": 1, "cameras": {"orbit": {"up": [0, 1]}}, )" OBJ "}",
       "/cameras/orbit/up"},
      {"camera dataset missing", R"({"version": 1, "cameras": {"dataset": "nope"}, )" OBJ "}",
       "/cameras/dataset"},
      {"camera without fy",
       R"({"version": 1, "cameras": {"list": [{"name": "a", "width": 4, "height": 4, "fx": 1, "cx": 2, "cy": 2, "cam_from_world": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}]}, )" OBJ
       "}",
       "/cameras/list/0"},
      {"camera pose not a rotation",
       R"({"version": 1, "cameras": {"list": [{"name": "a", "width": 4, "height": 4, "fx": 1, "fy": 1, "cx": 2, "cy": 2, "cam_from_world": [[2,0,0,0],[0,1,0,0],[0,0,1,0]]}]}, )" OBJ
       "}",
       "/cameras/list/0/cam_from_world"},
      {"camera pose row short",
       R"({"version": 1, "cameras": {"list": [{"name": "a", "width": 4, "height": 4, "fx": 1, "fy": 1, "cx": 2, "cy": 2, "cam_from_world": [[1,0,0,0],[0,1,0],[0,0,1,0]]}]}, )" OBJ
       "}",
       "/cameras/list/0/cam_from_world/1"},
      {"camera name with slash",
       R"({"version": 1, "cameras": {"list": [{"name": "../a", "width": 4, "height": 4, "fx": 1, "fy": 1, "cx": 2, "cy": 2, "cam_from_world": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}]}, )" OBJ
       "}",
       "/cameras/list/0/name"},
      {"unknown light", R"({"version": 1, )" CAM R"(, "lights": [{"type": "spot"}], )" OBJ "}",
       "/lights/0/type"},
      {"no objects", R"({"version": 1, )" CAM R"(, "objects": []})", "/objects"},
      {"object not an object", R"({"version": 1, )" CAM R"(, "objects": [3]})", "/objects/0"},
      {"unknown object type", R"({"version": 1, )" CAM R"(, "objects": [{"type": "cloud"}]})",
       "/objects/0/type"},
      {"inline transfer opacity 2",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "volume", "volume": "v.dat", "transfer": {"points": [[0, 1, 1, 1, 2]]}}]})",
       "/objects/0/transfer"},
      {"volume without its file", R"({"version": 1, )" CAM R"(, "objects": [{"type": "volume"}]})",
       "exactly one of \"volume\" or \"shared_volume\""},
      {"volume, unknown key",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "volume", "volume": "v.dat", "slices": 4}]})",
       "/objects/0/slices"},
      {"deform without its mesh", R"({"version": 1, )" CAM R"(, "objects": [{"type": "deform"}]})",
       "missing \"mesh\""},
      {"deform, unknown key",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "deform", "mesh": {"shape": "torus"}, "slices": 4}]})",
       "/objects/0/slices"},
      {"deform, capture key in its mesh",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "deform", "mesh": {"shape": "torus", "rig": "cube"}}]})",
       "/objects/0/mesh/rig"},
      {"deform, two meshes",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "deform", "mesh": {"shape": "torus", "file": "m.obj"}}]})",
       "/objects/0/mesh"},
      {"deform, shared mesh missing",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "deform", "mesh": {"shared_mesh": "meshes/none.obj"}}]})",
       "/objects/0/mesh/shared_mesh"},
      {"deform, option not a scalar",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "deform", "mesh": {"shape": "torus"}, "cut": ["solid"]}]})",
       "/objects/0/cut"},
      {"deform, deformations not a list",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "deform", "mesh": {"shape": "torus"}, "deformations": "twist"}]})",
       "/objects/0/deformations"},
      {"volume, two files",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "volume", "volume": "v.dat", "shared_volume": "v.dat"}]})",
       "exactly one of \"volume\" or \"shared_volume\""},
      {"volume, shared volume missing",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "volume", "shared_volume": "volumes/none.dat"}]})",
       "/objects/0/shared_volume"},
      {"unknown object key",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "colour": "red"}]})",
       "/objects/0/colour"},
      {"effect key of another type",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "slicing": "ray"}]})",
       "/objects/0/slicing"},
      {"effect value an array",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "depth-object", "images": {"dataset": "ds"}, "slices": [1]}]})",
       "/objects/0/slices"},
      {"enabled a string",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "enabled": "yes"}]})",
       "/objects/0/enabled"},
      {"unknown shape",
       R"({"version": 1, )" CAM R"(, "objects": [{"type": "mesh", "mesh": {"shape": "teapot"}}]})",
       "/objects/0/mesh/shape"},
      {"mesh file missing",
       R"({"version": 1, )" CAM R"(, "objects": [{"type": "mesh", "mesh": {"file": "gone.obj"}}]})",
       "/objects/0/mesh/file"},
      {"shape and file",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup", "file": "m.obj"}}]})",
       "/objects/0/mesh"},
      {"displaced without height",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "displaced-mesh", "mesh": {"shape": "torus"}}]})",
       "/objects/0"},
      {"height file missing",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "displaced-mesh", "mesh": {"shape": "torus"}, "height": {"file": "none.png"}}]})",
       "/objects/0/height/file"},
      {"unknown generator",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "displaced-mesh", "mesh": {"shape": "torus"}, "height": {"generator": "waves"}}]})",
       "/objects/0/height/generator"},
      {"texels too small",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "displaced-mesh", "mesh": {"shape": "torus"}, "height": {"generator": "bumps", "texels": 2}}]})",
       "/objects/0/height/texels"},
      {"texture missing",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "texture": "none.png"}]})",
       "/objects/0/texture"},
      {"images missing", R"({"version": 1, )" CAM R"(, "objects": [{"type": "depth-object"}]})",
       "/objects/0"},
      {"images dataset missing",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "depth-object", "images": {"dataset": "nope"}}]})",
       "/objects/0/images/dataset"},
      {"shared mesh missing",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "depth-object", "images": {"capture": {"shared_mesh": "meshes/none.obj"}}}]})",
       "/objects/0/images/capture/shared_mesh"},
      {"capture size a float",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "depth-object", "images": {"capture": {"shape": "cup", "size": 64.5}}}]})",
       "/objects/0/images/capture/size"},
      {"negative scale",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "transform": {"scale": -1}}]})",
       "/objects/0/transform/scale"},
      {"matrix with translate",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "transform": {"translate": [0,0,0], "matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}}]})",
       "/objects/0/transform/matrix"},
      {"rotate a string",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"type": "mesh", "mesh": {"shape": "cup"}, "transform": {"rotate_deg": [0, "90", 0]}}]})",
       "/objects/0/transform/rotate_deg/1"},
      {"duplicate names",
       R"({"version": 1, )" CAM
       R"(, "objects": [{"name": "a", "type": "mesh", "mesh": {"shape": "cup"}}, {"name": "a", "type": "mesh", "mesh": {"shape": "cup"}}]})",
       "/objects/1/name"},
  };
  EXPECT_GE(std::size(bad), 20u);
  for (const BadScene& b : bad) {
    const std::string e = Error(b.text);
    EXPECT_NE(e, "") << b.what << ": accepted";
    EXPECT_NE(e.find("'s.json'"), std::string::npos) << b.what << ": " << e;
    EXPECT_NE(e.find(b.pointer), std::string::npos)
        << b.what << ": no pointer '" << b.pointer << "' in: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << b.what << ": not one line: " << e;
  }
}

TEST_F(SceneTest, SettingsNameWhereAWrongTypeCameFrom) {
  const Scene s = Read(
      R"({"version": 1, )" CAM
      R"(, "objects": [{"type": "depth-object", "images": {"dataset": "ds"}, "slices": "many"}]})");
  try {
    s.objects[0].settings.GetInt("slices", 1);
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "ReadScene: 's.json' /objects/0/slices: expected an integer, got \"many\"");
  }
}

TEST_F(SceneTest, MissingSceneFileIsAnInputError) {
  EXPECT_THROW(ReadScene(dir_ / "absent.json", dir_), core::InputError);
}

// The built-in scenes (datasets/scenes/*.json) are scene files of this format.
TEST_F(SceneTest, BuiltinScenesParse) {
  options_.check_files = false;
  int n = 0;
  for (const auto& f : datasets::EmbeddedFiles()) {
    std::istringstream in{std::string(f.source)};
    EXPECT_NO_THROW(ReadScene(in, std::string(f.name), options_)) << f.name;
    ++n;
  }
  EXPECT_GE(n, 5);
}

}  // namespace
}  // namespace scene
