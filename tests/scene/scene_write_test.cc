// scene/scene_write.h: read -> write -> read gives the scene read first,
// field for field (files compared as normalised absolute paths), for every
// object kind and camera kind and for the built-in scene files; writing
// again gives the same text.
#include "scene/scene_write.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "datasets/embedded.h"

namespace scene {
namespace {
namespace fs = std::filesystem;

fs::path Normal(const fs::path& p) { return p.empty() ? p : fs::absolute(p).lexically_normal(); }

void ExpectEqualMesh(const MeshSource& a, const MeshSource& b) {
  EXPECT_EQ(a.shape, b.shape);
  EXPECT_EQ(Normal(a.file), Normal(b.file));
  EXPECT_EQ(a.where, b.where);
}

void ExpectEqual(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.description, b.description);
  const Cameras &ca = a.cameras, &cb = b.cameras;
  EXPECT_EQ(ca.kind, cb.kind);
  EXPECT_EQ(ca.orbit_count, cb.orbit_count);
  EXPECT_EQ(ca.orbit_size, cb.orbit_size);
  EXPECT_EQ(ca.orbit_elevation_deg, cb.orbit_elevation_deg);
  EXPECT_EQ(ca.orbit_fov_deg, cb.orbit_fov_deg);
  EXPECT_EQ(ca.orbit_up, cb.orbit_up);
  EXPECT_EQ(Normal(ca.dataset), Normal(cb.dataset));
  EXPECT_EQ(ca.dataset_size, cb.dataset_size);
  ASSERT_EQ(ca.list.size(), cb.list.size());
  for (size_t i = 0; i < ca.list.size(); ++i) {
    const ExplicitCamera &x = ca.list[i], &y = cb.list[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    EXPECT_EQ(x.fx, y.fx);
    EXPECT_EQ(x.fy, y.fy);
    EXPECT_EQ(x.cx, y.cx);
    EXPECT_EQ(x.cy, y.cy);
    EXPECT_EQ(x.orthographic, y.orthographic);
    EXPECT_EQ(x.cam_from_world, y.cam_from_world);  // bit for bit
  }
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) EXPECT_EQ(a.lights[i].type, b.lights[i].type);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    SCOPED_TRACE(a.objects[i].name);
    const Object &x = a.objects[i], &y = b.objects[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.enabled, y.enabled);
    EXPECT_EQ(x.world_from_object, y.world_from_object);  // bit for bit
    EXPECT_EQ(Normal(x.images.dataset), Normal(y.images.dataset));
    ExpectEqualMesh(x.images.capture_mesh, y.images.capture_mesh);
    EXPECT_EQ(x.images.capture_rig, y.images.capture_rig);
    EXPECT_EQ(x.images.capture_size, y.images.capture_size);
    ExpectEqualMesh(x.mesh, y.mesh);
    EXPECT_EQ(Normal(x.height.file), Normal(y.height.file));
    EXPECT_EQ(x.height.generator, y.height.generator);
    EXPECT_EQ(x.height.texels, y.height.texels);
    EXPECT_EQ(Normal(x.texture), Normal(y.texture));
    EXPECT_EQ(Normal(x.volume), Normal(y.volume));
    EXPECT_EQ(x.where, y.where);
    ASSERT_EQ(x.settings.values().size(), y.settings.values().size());
    for (const auto& [key, setting] : x.settings.values()) {
      const Setting* other = y.settings.Find(key);
      ASSERT_NE(other, nullptr) << key;
      if (key == "transfer" && setting.value.is_string() && setting.value != "ramp" &&
          setting.value != "tooth") {
        EXPECT_EQ(Normal(setting.value.get<std::string>()),
                  Normal(other->value.get<std::string>()));
      } else {
        EXPECT_EQ(setting.value, other->value) << key;
      }
      EXPECT_EQ(setting.where, other->where) << key;
    }
  }
}

class SceneWriteTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("ibr_scene_write_test_" + std::to_string(::getpid()));
    options_.base_dir = dir_;
    options_.shared_data = dir_ / "shared";
    options_.check_files = false;  // the files' contents are not read
  }

  Scene Read(const std::string& text) {
    std::istringstream in(text);
    return ReadScene(in, "s.json", options_);
  }
  // read -> write -> read equals; the second write equals the first.
  void RoundTrip(const std::string& text) {
    const Scene first = Read(text);
    std::ostringstream written;
    WriteScene(written, first, {.base_dir = dir_});
    SCOPED_TRACE(written.str());
    const Scene second = Read(written.str());
    ExpectEqual(first, second);
    std::ostringstream again;
    WriteScene(again, second, {.base_dir = dir_});
    EXPECT_EQ(written.str(), again.str());
  }

  fs::path dir_;
  ReadOptions options_;
};

// Every object kind with structural and effect keys, an orbit's cameras.
TEST_F(SceneWriteTest, EveryObjectKindRoundTrips) {
  RoundTrip(R"({"version": 1, "description": "all kinds",
    "cameras": {"orbit": {"count": 3, "size": 97, "elevation_deg": 12.5, "fov_deg": 33,
                          "up": [0, 0, 1]}},
    "lights": [{"type": "head"}],
    "objects": [
      {"type": "depth-object", "name": "d", "images": {"dataset": "caps/cup"},
       "slicing": "ray", "slices": "auto", "robust": 1,
       "transform": {"translate": [0.1, -0.2, 0.3], "rotate_deg": [10, 20, 30], "scale": 0.7}},
      {"type": "visual-hull", "name": "h", "enabled": false,
       "images": {"capture": {"shared_mesh": "meshes/spot.obj", "rig": "ring:6", "size": 64}}},
      {"type": "displaced-mesh", "mesh": {"shape": "torus"},
       "height": {"generator": "bumps", "texels": 32}, "texture": "../elsewhere/t.png",
       "method": "relief", "max_displacement": 0.05, "tiling": 2},
      {"type": "displaced-mesh", "mesh": {"file": "m.obj"}, "height": {"file": "h.png"}},
      {"type": "mesh", "mesh": {"shape": "sphere"}, "transform": {"scale": [1, 2, 3]}},
      {"type": "volume", "volume": "v/ball.dat", "transfer": "ramp", "effect": "peel",
       "mode": "iso:40", "spacing": 0.5, "map_size": 32},
      {"type": "volume", "shared_volume": "volumes/tooth.dat", "transfer": "tf.json"},
      {"type": "volume", "volume": "v/ball.dat",
       "transfer": {"units": "data", "points": [[-12.5, 0, 0, 0, 0], [0.1, 1, 0.5, 0.25, 0.75]]}},
      {"type": "deform", "mesh": {"shared_mesh": "meshes/spot.obj"},
       "deformation": "knife,twist", "amount": "0.2,1.5", "width": 0.5, "cut": "thick:0.02",
       "placement": "0.1,0,0,0,0,30,1.2", "skip": true, "resolution": 64,
       "transform": {"matrix": [[0, -1, 0, 0.25], [1, 0, 0, 1e-7], [0, 0, 1, -3]]}}
    ]})");
}

TEST_F(SceneWriteTest, DatasetAndListCamerasRoundTrip) {
  RoundTrip(R"({"version": 1, "cameras": {"dataset": "cams", "size": 320},
    "objects": [{"type": "mesh", "mesh": {"shape": "box"}}]})");
  RoundTrip(R"({"version": 1, "cameras": {"list": [
      {"name": "a", "width": 64, "height": 48, "fx": 50.5, "fy": 51, "cx": 32, "cy": 24.25,
       "cam_from_world": [[0.6, 0, -0.8, 0.1], [0, 1, 0, -0.2], [0.8, 0, 0.6, 3.3333333333333335]]},
      {"name": "b", "width": 8, "height": 8, "fx": 4, "fy": 4, "cx": 4, "cy": 4,
       "orthographic": true, "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}]},
    "objects": [{"type": "mesh", "mesh": {"shape": "box"}}]})");
}

// Files under the scene's folder are written relative to it, others absolute.
TEST_F(SceneWriteTest, FilesRelativeUnderTheFolderElseAbsolute) {
  const Scene s = Read(R"({"version": 1, "cameras": {"orbit": {}}, "objects": [
      {"type": "mesh", "mesh": {"file": "sub/m.obj"}, "texture": "../t.png"}]})");
  const nlohmann::json j = SceneToJson(s, {.base_dir = dir_});
  EXPECT_EQ(j["objects"][0]["mesh"]["file"], "sub/m.obj");
  EXPECT_EQ(j["objects"][0]["texture"], (dir_.parent_path() / "t.png").string());
}

// The built-in scenes (datasets/scenes/*.json) round-trip.
TEST_F(SceneWriteTest, BuiltInScenesRoundTrip) {
  int scenes = 0;
  for (const datasets::EmbeddedFile& f : datasets::EmbeddedFiles()) {
    if (!f.name.ends_with(".json")) continue;
    SCOPED_TRACE(std::string(f.name));
    RoundTrip(std::string(f.source));
    ++scenes;
  }
  EXPECT_GE(scenes, 5);
}

}  // namespace
}  // namespace scene
