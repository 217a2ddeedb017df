// `ibr capture`: render a mesh or an analytic shape from a rig into a dataset.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <optional>

#include "apps/ibr/commands.h"
#include "capture/builtin_scenes.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "ibr/views.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

struct CaptureCommandOptions {
  std::filesystem::path mesh;     // OBJ/PLY/... (assimp); exclusive with shape
  std::string shape;              // sphere | torus | box | cup
  std::filesystem::path texture;  // optional texture override
  std::string scene;              // a built-in scene (datasets/scenes/NAME.json)
  std::filesystem::path out;      // dataset directory, replaced atomically
  std::string up;                 // --up: the mesh's up axis (x, y, z, -x, -y, -z)
  capture::CaptureOptions capture;
};

void RunCapture(CaptureCommandOptions o, bool rig_given, bool size_given) {
  if (!o.scene.empty()) {
    if (!o.mesh.empty() || !o.shape.empty()) {
      core::ThrowInputError("ibr capture", "give --scene NAME alone, without --mesh or --shape");
    }
    // The scene's object, rig and size; --rig / --size given on the command line win.
    const capture::BuiltinScene scene = capture::LoadBuiltinScene(o.scene);
    o.shape = scene.shape;
    if (!scene.shared_mesh.empty()) o.mesh = capture::DefaultSharedDataDir() / scene.shared_mesh;
    if (!rig_given) o.capture.rig = scene.capture.rig;
    if (!size_given) o.capture.size = scene.capture.size;
  }
  if (o.mesh.empty() == o.shape.empty()) {
    core::ThrowInputError("ibr capture",
                          "give exactly one of --mesh PATH, --shape NAME or --scene NAME");
  }
  if (o.out.empty()) core::ThrowInputError("ibr capture", "--out DIR is required");
  if (!o.texture.empty() && o.mesh.empty())
    core::ThrowInputError("ibr capture", "--texture applies to --mesh only");
  auto context = render::HeadlessContext::Create();
  render::CheckFrameSize("ibr capture", "--size", o.capture.size, o.capture.size,
                         /*min_side=*/16);
  if (!o.up.empty()) o.capture.up = ibr::ParseUp(o.up, "--up");
  o.capture.Check();
  const auto start = std::chrono::steady_clock::now();
  const capture::SceneMesh scene =
      o.mesh.empty() ? capture::MakeShapeScene(o.shape) : capture::LoadSceneMesh(o.mesh, o.texture);
  render::ProgramCache programs;
  spdlog::info("capture: {} ({} triangles{}), rig {}, {} px, up ({:g}, {:g}, {:g}){}", scene.source,
               scene.mesh.triangle_count(), scene.texture.empty() ? "" : ", textured",
               o.capture.rig, o.capture.size, o.capture.up.x, o.capture.up.y, o.capture.up.z,
               o.up.empty() ? " (the OBJ convention; --up z for a z-up mesh)" : "");
  const capture::Dataset dataset = capture::CaptureDataset(
      programs, scene, o.capture, o.out, [](int i, int n, const std::string& name) {
        spdlog::info("capture: view {}/{} {}", i, n, name);
      });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("capture: {} views of {} at {}x{} px in {:.2f} s -> {}\n", dataset.views.size(),
             scene.source, o.capture.size, o.capture.size, seconds,
             std::filesystem::absolute(o.out).string());
}

void AddCaptureCommand(CLI::App& app) {
  static CaptureCommandOptions o;
  auto* cmd = app.add_subcommand(
      "capture", "Render a mesh or analytic shape from a camera rig into a dataset");
  cmd->add_option("--mesh", o.mesh, "mesh file (OBJ, PLY, ... through assimp)");
  cmd->add_option("--shape", o.shape, "analytic shape: sphere, torus, box, cup or mug");
  std::string names;
  for (const auto& n : capture::BuiltinSceneNames()) names += (names.empty() ? "" : ", ") + n;
  cmd->add_option("--scene", o.scene, "built-in scene (object, rig, size): " + names);
  cmd->add_option("--texture", o.texture,
                  "texture image (default: the material's, or <stem>_texture.png)");
  cmd->add_option("--rig", o.capture.rig, "cube | ring:N | sphere:N")->capture_default_str();
  cmd->add_option("--size", o.capture.size, "image width = height in pixels")
      ->capture_default_str();
  cmd->add_option("--fov", o.capture.fov_deg, "perspective field of view, degrees")
      ->capture_default_str();
  cmd->add_option("--background", o.capture.background,
                  "black, or noise: a fixed textured backdrop sphere (gives SfM features)")
      ->check(CLI::IsMember({"black", "noise"}))
      ->capture_default_str();
  cmd->add_option("--up", o.up,
                  "the mesh's up axis x, y, z, -x, -y or -z (default y): the rigs turn about it "
                  "and the dataset records it");
  cmd->add_option("--noise", o.capture.noise,
                  "depth sensor model, key=value,...: sigma=L, model=constant|quadratic, "
                  "quantize=L, edge=N, grazing=DEG, holes=F, hole-radius=N, flying=F, "
                  "outliers=F, mask=exact|depth, seed=N (L: scene units, or % of the "
                  "object's diagonal)");
  cmd->add_option("--out", o.out, "output dataset directory")->required();
  cmd->callback([cmd] { RunCapture(o, cmd->count("--rig") > 0, cmd->count("--size") > 0); });
}

}  // namespace

IBR_REGISTER_COMMAND("capture", AddCaptureCommand);

}  // namespace apps
