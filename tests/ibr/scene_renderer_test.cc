// ibr/scene_renderer.h: a scene builds only the passes, programs and textures
// its enabled objects name (counted by the program cache and the texture
// allocation counter), and objects composite by camera z.
#include "ibr/scene_renderer.h"

#include <gtest/gtest.h>

#include <sstream>

#include "core/error.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {

scene::Scene Parse(const std::string& objects,
                   const std::string& cameras = R"({"orbit": {"count": 2, "size": 96}})") {
  std::istringstream in(R"({"version": 1, "cameras": )" + cameras + R"(, "objects": [)" + objects +
                        "]}");
  scene::ReadOptions options;
  options.check_files = false;
  return scene::ReadScene(in, "test.json", options);
}

constexpr const char* kSphere = R"({"name": "ball", "type": "mesh", "mesh": {"shape": "sphere"}})";
constexpr const char* kTorusDisabled =
    R"({"name": "torus", "type": "displaced-mesh", "enabled": false, "mesh": {"shape": "torus"},)"
    R"( "height": {"generator": "bumps", "texels": 64}, "method": "slices-orthogonal", "slices": 16,)"
    R"( "transform": {"translate": [3, 0, 0]}})";
constexpr const char* kTorusOn =
    R"({"name": "torus", "type": "displaced-mesh", "mesh": {"shape": "torus"},)"
    R"( "height": {"generator": "bumps", "texels": 64}, "method": "slices-orthogonal", "slices": 16,)"
    R"( "transform": {"translate": [3, 0, 0]}})";

// What building and rendering one frame of a scene costs in programs and textures.
struct Built {
  std::map<std::string, int> programs;  // compiled, by file
  int64_t textures = 0;                 // created during build + one frame
  std::vector<std::string> passes;
  render::Frame frame;
};

Built Build(const scene::Scene& s) {
  render::ProgramCache programs;
  const int64_t before = render::Texture::created_count();
  const LoadedScene loaded = LoadScene(programs, s);
  SceneRenderer renderer(programs, loaded);
  Built b;
  b.frame = renderer.Render(loaded.views.front().view);
  b.textures = render::Texture::created_count() - before;
  b.programs = programs.compiled_by_file();
  b.passes = renderer.PassNames();
  return b;
}

bool CompiledAny(const Built& b, const std::string& part) {
  for (const auto& [file, n] : b.programs) {
    if (file.find(part) != std::string::npos) return true;
  }
  return false;
}

using SceneRendererTest = test_support::GlTest;

TEST_F(SceneRendererTest, DisabledOrAbsentEffectBuildsNothing) {
  const Built absent = Build(Parse(kSphere));
  const Built disabled = Build(Parse(std::string(kSphere) + "," + kTorusDisabled));
  const Built on = Build(Parse(std::string(kSphere) + "," + kTorusOn));
  EXPECT_EQ(absent.passes, std::vector<std::string>{"mesh"});
  EXPECT_EQ(disabled.passes, std::vector<std::string>{"mesh"});
  EXPECT_EQ(on.passes, (std::vector<std::string>{"mesh", "displacement:slices-orthogonal"}));
  for (const Built* b : {&absent, &disabled}) {
    EXPECT_FALSE(CompiledAny(*b, "displacement"))
        << "a scene without (enabled) displacement compiled it";
    EXPECT_FALSE(CompiledAny(*b, "relief"));
    EXPECT_FALSE(CompiledAny(*b, "depth_object"));
    EXPECT_TRUE(CompiledAny(*b, "mesh."));
  }
  EXPECT_EQ(disabled.programs, absent.programs);
  EXPECT_EQ(disabled.textures, absent.textures);
  EXPECT_TRUE(CompiledAny(on, "displacement"));
  // At least the displacement texture and its target's attachments.
  EXPECT_GT(on.textures, absent.textures);
  EXPECT_EQ(disabled.frame.color, absent.frame.color);
  EXPECT_NO_GL_ERROR();
}

TEST_F(SceneRendererTest, DepthObjectSceneCompilesNoDisplacementOrMeshProgram) {
  // The mesh program is used by the synthetic capture (capture::RenderView) too;
  // what matters here is no displacement or relief code.
  const Built b = Build(
      Parse(R"({"type": "visual-hull", "images": {"capture": {"shape": "sphere", "size": 64}},)"
            R"( "slicing": "ray", "slices": 32})"));
  EXPECT_EQ(b.passes, std::vector<std::string>{"visual-hull"});
  EXPECT_FALSE(CompiledAny(b, "displacement"));
  EXPECT_FALSE(CompiledAny(b, "relief"));
  EXPECT_FALSE(CompiledAny(b, "tangent_maps"));
  EXPECT_TRUE(CompiledAny(b, "depth_object_ray"));
  EXPECT_FALSE(CompiledAny(b, "depth_object.frag")) << "ray slicing needs no slice program";
  EXPECT_NO_GL_ERROR();
}

// Two spheres overlapping in the image: the composite is, per pixel, the
// nearer of the two separate renders (independent truth: each alone), in
// either draw order.
TEST_F(SceneRendererTest, ObjectsCompositeByCameraZ) {
  const std::string camera =
      R"({"list": [{"name": "v", "width": 80, "height": 60, "fx": 60, "fy": 60, "cx": 40, "cy": 30,)"
      R"( "cam_from_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 6]]}]})";
  const std::string near =
      R"({"name": "near", "type": "mesh", "mesh": {"shape": "sphere"}, "transform": {"translate": [-0.6, 0, -1]}})";
  const std::string far =
      R"({"name": "far", "type": "mesh", "mesh": {"shape": "sphere"}, "transform": {"translate": [0.6, 0, 1], "scale": 1.2}})";
  // The single-object scenes name the other object disabled (it adds nothing).
  const auto off = [](std::string o) { return o.insert(o.size() - 1, R"(, "enabled": false)"), o; };
  const Built a = Build(Parse(near + "," + off(far), camera));
  const Built b = Build(Parse(off(near) + "," + far, camera));
  const Built both = Build(Parse(near + "," + far, camera));
  // One frame target, composited by the depth test: the draw order does not
  // matter (the far object drawn first must not cover the near one).
  const Built reversed = Build(Parse(far + "," + near, camera));
  EXPECT_EQ(reversed.frame.color, both.frame.color);
  EXPECT_EQ(reversed.frame.depth, both.frame.depth);
  int overlap = 0, checked = 0;
  for (int y = 0; y < 60; ++y) {
    for (int x = 0; x < 80; ++x) {
      const float za = a.frame.depth.at(x, y), zb = b.frame.depth.at(x, y),
                  z = both.frame.depth.at(x, y);
      const float want = za > 0 && zb > 0 ? std::min(za, zb) : std::max(za, zb);
      // Clip ranges differ with the scene bounds; camera z is interpolated
      // with w = camera z, independent of them, up to float rounding.
      ASSERT_NEAR(z, want, 1e-5f * want) << x << "," << y;
      if (za > 0 && zb > 0) {
        ++overlap;
        const Built& winner = za < zb ? a : b;
        for (int c = 0; c < 4; ++c)
          ASSERT_NEAR(both.frame.color.at(x, y, c), winner.frame.color.at(x, y, c), 1);
      }
      checked += z > 0;
    }
  }
  EXPECT_GT(overlap, 100) << "the spheres should overlap in the image";
  // The near sphere's front point: camera z = 6 - 1 - 1 = 4 at its centre pixel
  // (x = 40 + 60 * -0.6 / 5 = 32.8, y = 30).
  EXPECT_NEAR(both.frame.depth.at(32, 30), 4.0f, 0.01f);
  // Discs of about 12 and 10.3 px radius (60 px focal length; radius 1 at 5,
  // 1.2 at 7): about 450 + 330 pixels less the overlap.
  EXPECT_GT(checked, 600);
  EXPECT_NO_GL_ERROR();
}

TEST_F(SceneRendererTest, BadObjectsFailNamingThePointer) {
  render::ProgramCache programs;
  const auto error = [&](const std::string& objects) -> std::string {
    try {
      LoadScene(programs, Parse(objects));
    } catch (const core::InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(
      error(
          R"({"type": "depth-object", "images": {"capture": {"shape": "cup"}}, "slicing": "diagonal"})")
          .find("/objects/0/slicing"),
      std::string::npos);
  EXPECT_NE(
      error(R"({"type": "depth-object", "images": {"capture": {"shape": "cup"}}, "slices": 0})")
          .find("/objects/0/slices"),
      std::string::npos);
  EXPECT_NE(error(std::string(kSphere) +
                  R"(, {"type": "displaced-mesh", "enabled": false, "mesh": {"shape": "torus"},)"
                  R"( "height": {"generator": "bumps"}, "method": "warp"})")
                .find("/objects/1/method"),
            std::string::npos)
      << "a disabled object's options are still checked";
  EXPECT_NE(
      error(
          R"({"type": "displaced-mesh", "mesh": {"shape": "cup"}, "height": {"generator": "bumps"}})")
          .find("/objects/0/mesh"),
      std::string::npos)
      << "no uvs on the cup";
  EXPECT_NE(
      error(R"({"type": "mesh", "mesh": {"shape": "cup"}, "transform": {"scale": [1, 2, 1]}})")
          .find("/objects/0/transform"),
      std::string::npos);
  EXPECT_NE(error(R"({"type": "mesh", "mesh": {"shape": "cup"}, "enabled": false})")
                .find("every object is disabled"),
            std::string::npos);
}

}  // namespace
}  // namespace ibr
