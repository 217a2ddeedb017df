// Deform objects in scene files (ibr/deform_object.h, ibr/scene_renderer.h):
// the scene draws exactly what the library call `ibr deform` makes with the
// same options (same pass, pixel for pixel), composites with a mesh by
// camera z, builds nothing when disabled, and bad option values name the
// file and the JSON pointer.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <sstream>

#include "capture/synthetic.h"
#include "core/error.h"
#include "ibr/deform_object.h"
#include "ibr/scene_renderer.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

// One 96 x 96 pinhole at world z = -4 looking +z.
constexpr const char* kCamera =
    R"({"list": [{"name": "v", "width": 96, "height": 96, "fx": 110, "fy": 110, "cx": 48, "cy": 48,)"
    R"( "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 4]]}]})";

scene::Scene Parse(const std::string& objects, const std::string& cameras = kCamera) {
  std::istringstream in(R"({"version": 1, "cameras": )" + cameras + R"(, "objects": [)" + objects +
                        "]}");
  scene::ReadOptions options;
  options.check_files = false;
  return scene::ReadScene(in, "test.json", options);
}

// A knife cut through a torus, its box turned so the cut faces the camera.
constexpr const char* kKnife =
    R"({"name": "cut", "type": "deform", "mesh": {"shape": "torus"}, "deformation": "knife",)"
    R"( "cut": "solid", "resolution": 48, "transform": {"translate": [0.2, 0.1, 0], "rotate_deg": [20, 155, 0]}})";

class SceneDeformTest : public test_support::GlTest {};

TEST_F(SceneDeformTest, SceneDrawsWhatTheLibraryCallDraws) {
  const scene::Scene s = Parse(kKnife);
  const LoadedScene loaded = LoadScene(programs(), s);
  SceneRenderer renderer(programs(), loaded);
  EXPECT_EQ(renderer.PassNames(), std::vector<std::string>{"deform"});
  const ViewCamera& view = loaded.views.front().view;
  const render::Frame scene_frame = renderer.Render(view);

  // `ibr deform`'s path (ibr::RenderDeform): the same options, the mesh in its
  // own frame, the view carried into the normalised frame.
  const DeformObjectOptions options = DeformObjectOptionsFrom(s.objects[0].settings);
  EXPECT_EQ(options.pass.cut, core::CutMode::kSolid);
  ASSERT_EQ(options.deformation.terms.size(), 1u);
  EXPECT_EQ(options.deformation.terms[0].kind, core::DeformationKind::kKnife);
  const DeformObjectData data =
      MakeDeformObject(capture::MakeShapeScene("torus").mesh, options, "torus");
  render::DeformPass pass(programs(), data.Inputs(), options.pass);
  render::ViewSetup setup = ViewSetupFor(view, loaded.bounds);
  setup.cam_from_world =
      glm::mat4(view.cam_from_world * s.objects[0].world_from_object * data.object_from_norm);
  render::RenderTarget target(render::FrameTargetOptions(96, 96));
  render::DrawFrame(target, pass, setup);
  const render::Frame frame = render::ReadFrame(target);

  test_support::WriteDebugImage("scene_deform_knife.png", scene_frame.color);
  EXPECT_EQ(scene_frame.color, frame.color);
  EXPECT_EQ(scene_frame.depth, frame.depth);
  // Not a blank frame: the torus covers the middle, and the knife's solid
  // cut shows cut faces.
  int covered = 0, cut_faces = 0;
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      covered += scene_frame.Covered(x, y);
      cut_faces += (frame.outcome.at(x, y) & render::kDeformCutFaceBit) != 0;
    }
  }
  EXPECT_GT(covered, 500);
  EXPECT_GT(cut_faces, 20);
  // Camera z of what is seen lies within the object's world bounds.
  for (float z : scene_frame.depth.values()) {
    if (z == 0) continue;
    ASSERT_GT(z, 4 + loaded.bounds.min.z - 1e-3);
    ASSERT_LT(z, 4 + loaded.bounds.max.z + 1e-3);
  }
  EXPECT_NO_GL_ERROR();
}

// Per pixel, the composite is the nearer of the two objects rendered alone
// (each alone: the other named but disabled).
TEST_F(SceneDeformTest, DeformAndMeshCompositeByCameraZ) {
  const std::string twist =
      R"({"name": "twist", "type": "deform", "mesh": {"shape": "torus"}, "deformation": "twist",)"
      R"( "resolution": 48, "transform": {"rotate_deg": [-70, 0, 0]}})";
  const std::string box = R"({"name": "box", "type": "mesh", "mesh": {"shape": "box"},)"
                          R"( "transform": {"translate": [0.5, 0, -0.2], "scale": 0.35}})";
  const auto off = [](std::string o) { return o.insert(o.size() - 1, R"(, "enabled": false)"), o; };
  const auto render = [&](const std::string& objects, std::vector<std::string>* passes) {
    const LoadedScene loaded = LoadScene(programs(), Parse(objects));
    SceneRenderer renderer(programs(), loaded);
    if (passes) *passes = renderer.PassNames();
    return renderer.Render(loaded.views.front().view);
  };
  std::vector<std::string> passes;
  const render::Frame a = render(twist + "," + off(box), &passes);
  EXPECT_EQ(passes, std::vector<std::string>{"deform"});
  const render::Frame b = render(off(twist) + "," + box, &passes);
  EXPECT_EQ(passes, std::vector<std::string>{"mesh"});
  const render::Frame both = render(twist + "," + box, &passes);
  EXPECT_EQ(passes, (std::vector<std::string>{"deform", "mesh"}));
  int overlap = 0, deform_wins = 0, mesh_wins = 0;
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      const float za = a.depth.at(x, y), zb = b.depth.at(x, y), z = both.depth.at(x, y);
      const float want = za > 0 && zb > 0 ? std::min(za, zb) : std::max(za, zb);
      // Clip ranges differ with the scene bounds: camera z agrees up to
      // float rounding (the deform pass writes gl_FragDepth from it).
      ASSERT_NEAR(z, want, 2e-4f * std::max(want, 1.0f)) << x << "," << y;
      if (za > 0 && zb > 0 && std::abs(za - zb) > 0.02f) {
        ++overlap;
        (za < zb ? deform_wins : mesh_wins)++;
        const render::Frame& winner = za < zb ? a : b;
        for (int c = 0; c < 4; ++c)
          ASSERT_NEAR(both.color.at(x, y, c), winner.color.at(x, y, c), 2) << x << "," << y;
      }
    }
  }
  EXPECT_GT(overlap, 50) << "the box and the torus should overlap in the image";
  EXPECT_GT(mesh_wins, 10);
  EXPECT_GT(deform_wins, 10);
  EXPECT_NO_GL_ERROR();
}

TEST_F(SceneDeformTest, DisabledDeformObjectBuildsNothing) {
  const std::string sphere = R"({"name": "ball", "type": "mesh", "mesh": {"shape": "sphere"}})";
  const auto build = [&](const std::string& objects) {
    render::ProgramCache programs;
    const LoadedScene loaded = LoadScene(programs, Parse(objects));
    SceneRenderer renderer(programs, loaded);
    renderer.Render(loaded.views.front().view);
    bool deform = false;
    for (const auto& [file, n] : programs.compiled_by_file())
      deform = deform || file.find("deform") != std::string::npos;
    return std::pair{renderer.PassNames(), deform};
  };
  std::string knife_off = kKnife;
  knife_off.insert(knife_off.size() - 1, R"(, "enabled": false)");
  const auto [passes_off, deform_off] = build(sphere + "," + knife_off);
  EXPECT_EQ(passes_off, std::vector<std::string>{"mesh"});
  EXPECT_FALSE(deform_off);
  const auto [passes_on, deform_on] = build(sphere + "," + kKnife);
  EXPECT_EQ(passes_on, (std::vector<std::string>{"mesh", "deform"}));
  EXPECT_TRUE(deform_on);
}

// Bad option values: one InputError naming the file and the value's pointer,
// also for a disabled object (its options are checked, nothing is built).
TEST(SceneDeformOptions, BadValuesNameThePointer) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"("deformation": "wobble")", "/objects/0/deformation"},
      {R"("deformation": "twist", "amount": "1,2")", "/objects/0/amount"},
      {R"("amount": "x")", "/objects/0/amount"},
      {R"("deformation": "twist", "width": 3)", "/objects/0/width"},
      {R"("cut": "sliced")", "/objects/0/cut"},
      {R"("cut": "thick:0")", "/objects/0/cut"},
      {R"("cut": "thick:nan")", "/objects/0/cut"},
      {R"("region": "1,2,3")", "/objects/0/region"},
      {R"("region": "1,0,0,0,1,1")", "/objects/0/region"},
      {R"("placement": "0,0")", "/objects/0/placement"},
      {R"("placement": "0,0,0,0,0,0,-1")", "/objects/0/placement"},
      {R"("step": "sometimes")", "/objects/0/step"},
      {R"("step_voxels": 1000)", "/objects/0/step_voxels"},
      {R"("skip": "yes")", "/objects/0/skip"},
      {R"("resolution": 4)", "/objects/0/resolution"},
      {R"("resolution": 64.5)", "/objects/0/resolution"},
      {R"("cap_holes": 1)", "/objects/0/cap_holes"},
      {R"("implicit": "octree")", "/objects/0/implicit"},
      {R"("implicit": 3)", "/objects/0/implicit"},
      {R"("deformations": [])", "/objects/0/deformations"},
      {R"("deformations": [{"name": "melt"}])", "/objects/0/deformations/0/name"},
      {R"("deformations": [{"name": "clip"}, {"name": "clip", "depth": 1}])",
       "/objects/0/deformations/1/depth"},
      {R"("deformations": [{"name": "wave", "amount": "big"}])",
       "/objects/0/deformations/0/amount"},
      {R"("deformations": [{"name": "wave", "placement": "0,0"}])",
       "/objects/0/deformations/0/placement"},
      {R"("deformations": [{"name": "peel", "amount": 4}])", "/objects/0/deformations/0"},
      {R"("deformation": "twist", "deformations": [{"name": "peel"}])", "/objects/0/deformation"},
  };
  render::ProgramCache programs;  // no context needed: nothing is built
  for (const auto& [keys, pointer] : bad) {
    for (const char* enabled : {"true", "false"}) {
      const std::string object =
          std::string(R"({"type": "deform", "mesh": {"shape": "torus"}, "enabled": )") + enabled +
          ", " + keys + "}";
      const std::string other = R"(, {"type": "mesh", "mesh": {"shape": "sphere"}})";
      const scene::Scene s = Parse(object + other);
      try {
        LoadScene(programs, s);
        ADD_FAILURE() << keys << ": accepted";
      } catch (const core::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("'test.json' " + pointer + ":"), std::string::npos)
            << keys << ": " << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      }
    }
  }
}

}  // namespace
}  // namespace ibr
