// Novel cameras: orbits put `up` at the top of every image (the scene
// files' orbit "up" too), arcs stay within their span around `towards`,
// --up parses axis names and three numbers; the default --outside from the
// cameras' coverage of the box (ChooseOutsidePolicy).
#include "ibr/views.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "ibr/dataset_maps.h"
#include "ibr/image_maps.h"

namespace ibr {
namespace {

// The camera's x and y axes in world (rows of cam_from_world's rotation).
glm::dvec3 Axis(const ViewCamera& v, int row) {
  return {v.cam_from_world[0][row], v.cam_from_world[1][row], v.cam_from_world[2][row]};
}

TEST(OrbitViews, UpIsAtTheTopOfEveryImage) {
  const glm::dmat4 box = BoxFromBounds({-1, -2, -3}, {1, 2, 3});
  for (const glm::dvec3 up : {glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1),
                              glm::normalize(glm::dvec3(1, -2, 0.5))}) {
    OrbitOptions o;
    o.count = 7;
    o.up = up;
    for (const NamedView& v : OrbitViews(box, o)) {
      // Image y points down: the camera's y axis is -up's part across the view.
      EXPECT_NEAR(glm::dot(Axis(v.view, 0), up), 0, 1e-6) << "x is level";
      EXPECT_LT(glm::dot(Axis(v.view, 1), up), -0.9) << "y points down, away from up";
    }
  }
}

TEST(OrbitViews, SceneOrbitUpIsHonoured) {
  std::istringstream in(R"({"version": 1, "cameras": {"orbit": {"count": 3, "up": [0, -1, 0]}},
      "objects": [{"type": "mesh", "mesh": {"shape": "sphere"}}]})");
  const scene::Scene s = scene::ReadScene(in, "scene.json", {.check_files = false});
  const std::vector<NamedView> views =
      SceneCameraViews(s.cameras, BoxFromBounds({-1, -1, -1}, {1, 1, 1}));
  ASSERT_EQ(views.size(), 3u);
  for (const NamedView& v : views) EXPECT_GT(Axis(v.view, 1).y, 0.9) << "up -y: image y is +y";
}

TEST(OrbitViews, AnArcSpansItsDegreesAroundTowards) {
  OrbitOptions o;
  o.count = 5;
  o.arc_deg = 90;
  o.elevation_deg = 0;
  o.towards = {1, 0.3, 0};  // its part along up does not count
  const std::vector<NamedView> views = OrbitViews(BoxFromBounds({-1, -1, -1}, {1, 1, 1}), o);
  ASSERT_EQ(views.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    const glm::dmat4 world_from_cam = glm::inverse(views[i].view.cam_from_world);
    const glm::dvec3 eye(world_from_cam[3]);
    const double az = std::atan2(eye.z, eye.x) * 180 / M_PI;
    // The look-at is built in float (core::CamFromWorldLookAt): 1e-5 degrees.
    EXPECT_NEAR(std::abs(az), std::abs(-45 + 22.5 * i), 1e-5) << i;
  }
}

TEST(ParseUp, AxisNamesAndThreeNumbers) {
  EXPECT_EQ(ParseUp("-y", "--up"), glm::dvec3(0, -1, 0));
  EXPECT_EQ(ParseUp("z", "--up"), glm::dvec3(0, 0, 1));
  EXPECT_NEAR(glm::length(ParseUp("0,-2,0", "--up") - glm::dvec3(0, -1, 0)), 0, 1e-15);
  EXPECT_NEAR(glm::length(ParseUp("1 1 0", "--up") - glm::normalize(glm::dvec3(1, 1, 0))), 0,
              1e-15);
  for (const char* bad : {"", "w", "0,0,0", "1,2", "1,2,3,4", "1,nan,0", "1,x,0", "1e999,0,0"}) {
    try {
      ParseUp(bad, "--up");
      ADD_FAILURE() << bad;
    } catch (const core::InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--up: ", 0), 0u) << e.what();
    }
  }
}

// One pinhole map looking down +z at the box from z = -5, seeing a cone
// that covers a small part of it; the full cube rig sees all of it.
TEST(ChooseOutsidePolicy, OneViewFailsTheSurroundingRigPasses) {
  MapSet one;
  one.world_from_box = BoxFromBounds({-1, -1, -1}, {1, 1, 1});
  ImageMap m;
  m.camera = MapCamera::Pinhole(32, 32, 256, 256, 16, 16);  // a narrow cone: half-angle 3.6 degrees
  m.cam_from_world = glm::dmat4(1.0);
  m.cam_from_world[3] = glm::dvec4(0, 0, 5, 1);  // camera at z = -5
  one.maps.push_back(m);
  const OutsideChoice single = ChooseOutsidePolicy(one);
  EXPECT_GT(single.unseen, 0.5);
  EXPECT_EQ(single.policy, OutsidePolicy::kFail);
  EXPECT_NE(single.reason.find("--outside pass"), std::string::npos) << single.reason;
  // Six orthographic maps covering the box's faces see every point.
  MapSet cube;
  cube.world_from_box = one.world_from_box;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      ImageMap c;
      c.camera = MapCamera::Orthographic(32, 32, 14, 14, 16, 16);  // 2.3 units wide
      glm::dvec3 z(0.0), x(0.0);
      z[axis] = sign;
      x[(axis + 1) % 3] = 1;
      const glm::dvec3 y = glm::cross(z, x);
      glm::dmat4 r(1.0);
      for (int k = 0; k < 3; ++k) r[k] = glm::dvec4(x[k], y[k], z[k], 0);
      r[3] = glm::dvec4(0, 0, 3, 1);
      c.cam_from_world = r;
      cube.maps.push_back(c);
    }
  }
  const OutsideChoice all = ChooseOutsidePolicy(cube);
  EXPECT_EQ(all.unseen, 0.0);
  EXPECT_EQ(all.policy, OutsidePolicy::kPass);
}

}  // namespace
}  // namespace ibr
