// `ibr displace`: one displacement-mapped base mesh (torus, plane, sphere)
// rendered by one method into a PNG (colour) and an EXR beside it (camera z).
//
// Methods are rows of a table, name -> render function, all fed the same
// DisplaceScene; `tessellated` is the shared ground truth every other method
// is compared with (--compare). A new method is one function plus one row in
// Methods().
#include <filesystem>
#include <functional>
#include <map>
#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "apps/ibr/commands.h"
#include "bench/displacement_bench.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/image_io.h"
#include "core/timing.h"
#include "render/gl/context.h"
#include "core/displacement_error.h"
#include "render/passes/displacement_pass.h"
#include "render/gl/frame_timer.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/relief_surface_pass.h"

namespace apps {
namespace {
namespace fs = std::filesystem;

// Everything a method needs; built once per run.
struct DisplaceScene {
  render::ProgramCache* programs = nullptr;
  core::TriangleMesh base;          // object = world space, normals + uvs
  core::ImageF height;              // 1 channel, [0, 1] (1 = max_displacement)
  core::ImageF texels;              // RGBA: colour + height in alpha (render::MakeDisplacementTexels)
  const render::Texture* texture;   // `texels` on the GPU: RGBA8, LINEAR, REPEAT
  float max_displacement = 0.1f;    // scene units for height 1
  float tiling = 1.0f;              // texture repeats across uv [0, 1]
  int slices = 64;                  // slices per volume (slicing methods)
  render::ViewSetup view;
  int size = 512;                   // pixels, square
};

struct DisplaceResult {
  render::Frame frame;              // colour RGBA8 + camera z (0 = empty)
  core::TimingStats timing;         // per frame, after warm-up
  std::string detail;               // one line for the log (counts)
};

using DisplaceMethod = std::function<DisplaceResult(const DisplaceScene&)>;

// Times whole frames of `pass` (after warm-up), then keeps one.
DisplaceResult TimePass(const DisplaceScene& scene, render::Pass& pass) {
  render::RenderTarget target(render::FrameTargetOptions(scene.size, scene.size));
  DisplaceResult result;
  result.timing = render::TimeFrames([&] { render::DrawFrame(target, pass, scene.view); });
  render::DrawFrame(target, pass, scene.view);
  result.frame = render::ReadFrame(target);
  return result;
}

DisplaceResult RenderSlices(const DisplaceScene& scene, render::SliceFamily family) {
  render::DisplacementPassOptions options;
  options.slicing.family = family;
  options.slicing.count = scene.slices;
  options.max_displacement = scene.max_displacement;
  options.tiling = scene.tiling;
  render::DisplacementPass pass(*scene.programs, scene.base, *scene.texture, options);
  DisplaceResult result = TimePass(scene, pass);
  const auto& s = pass.last_stats();
  result.detail = fmt::format("{} volumes, {} slices, {} triangles", s.volumes, s.slices, s.triangles);
  return result;
}

// The ground truth: the base tessellated at texture resolution and displaced.
DisplaceResult RenderTessellated(const DisplaceScene& scene) {
  const core::TriangleMesh mesh =
      render::MakeDisplacedGroundTruth(scene.base, scene.height, scene.max_displacement, scene.tiling);
  const render::GpuMesh gpu(mesh);
  render::MeshPassOptions options;
  options.texture = scene.texture;
  options.shade = false;  // the texture's colour, as the slicing passes show it
  render::MeshPass pass(*scene.programs, gpu, options);
  DisplaceResult result = TimePass(scene, pass);
  result.detail = fmt::format("{} triangles", mesh.triangle_count());
  return result;
}

// Per-pixel ray marching through the ray core (render/passes/relief_surface_pass.h):
// NCS (Chen-Chang, curved silhouettes), relief mapping, POM; defaults: 32
// steps, c = 2.5.
DisplaceResult RenderRelief(const DisplaceScene& scene, render::ReliefMethod method) {
  render::ReliefGeometryOptions geometry;
  geometry.max_displacement = scene.max_displacement;
  render::DetectPeriodicAxes(scene.base, geometry.tangent_maps.wrap_u, geometry.tangent_maps.wrap_v);
  render::ReliefSurfaceOptions options;
  options.method = method;
  options.tiling = scene.tiling;
  render::ReliefSurface surface(*scene.programs, scene.base, scene.height, geometry, options);
  DisplaceResult result = TimePass(scene, surface);
  result.detail = fmt::format("{} steps, c = {}, {} early-terminated pixels", options.steps, options.step_enlargement,
                              result.frame.CountOutcome(render::OutcomeBit(render::RayOutcome::kEarlyTermination)));
  return result;
}

const std::map<std::string, DisplaceMethod>& Methods() {
  static const std::map<std::string, DisplaceMethod> methods = {
      {"slices-surface", [](const DisplaceScene& s) { return RenderSlices(s, render::SliceFamily::kSurfaceAligned); }},
      {"slices-orthogonal", [](const DisplaceScene& s) { return RenderSlices(s, render::SliceFamily::kOrthogonal); }},
      {"slices-screen", [](const DisplaceScene& s) { return RenderSlices(s, render::SliceFamily::kScreen); }},
      {"tessellated", RenderTessellated},
      {"ncs", [](const DisplaceScene& s) { return RenderRelief(s, render::ReliefMethod::kNcs); }},
      {"relief", [](const DisplaceScene& s) { return RenderRelief(s, render::ReliefMethod::kRelief); }},
      {"pom", [](const DisplaceScene& s) { return RenderRelief(s, render::ReliefMethod::kPom); }},
  };
  return methods;
}

std::string MethodNames() {
  std::string names;
  for (const auto& [name, method] : Methods()) names += (names.empty() ? "" : "|") + name;
  return names;
}

struct DisplaceOptions {
  std::string method = "slices-orthogonal";
  std::string base = "torus";
  std::string height = "bumps";
  float max_displacement = 0.15f;  // scene units (the torus tube radius is 0.4)
  float tiling = 2.0f;
  int texels = 256;       // height map size
  int slices = 64;        // per volume
  int size = 512;         // pixels
  double elevation = 35;  // degrees above the z = 0 plane
  double azimuth = -60;   // degrees around +z
  fs::path out = "displace.png";
  bool compare = false;   // also render `tessellated` and print the error
};

void RunDisplace(const DisplaceOptions& o) {
  const auto method = Methods().find(o.method);
  if (method == Methods().end()) {
    core::ThrowInputError("ibr displace", "--method '{}' is not one of {}", o.method, MethodNames());
  }
  if (o.size < 16 || o.size > 8192) core::ThrowInputError("ibr displace", "--size {} outside 16..8192", o.size);
  if (o.slices < 1 || o.slices > 4096) core::ThrowInputError("ibr displace", "--slices {} outside 1..4096", o.slices);
  if (o.texels < 4 || o.texels > 4096) core::ThrowInputError("ibr displace", "--texels {} outside 4..4096", o.texels);
  if (!(o.max_displacement > 0 && o.max_displacement <= 10)) {
    core::ThrowInputError("ibr displace", "--max-displacement {} outside (0, 10]", o.max_displacement);
  }
  if (!(o.tiling > 0 && o.tiling <= 1024)) core::ThrowInputError("ibr displace", "--tiling {} outside (0, 1024]", o.tiling);
  if (o.out.extension() != ".png") core::ThrowInputError("ibr displace", "--out '{}' must end in .png", o.out.string());
  if (o.out.has_parent_path() && !fs::is_directory(o.out.parent_path())) {
    core::ThrowInputError("ibr displace", "--out '{}': no such directory", o.out.string());
  }
  const core::HeightPattern pattern = core::HeightPatternFromName(o.height);

  auto context = render::HeadlessContext::Create();
  spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
  render::ProgramCache programs;
  DisplaceScene scene;
  scene.programs = &programs;
  scene.base = bench::DisplacementBaseMesh(o.base);
  scene.height = bench::DisplacementHeightMap(pattern, o.texels);
  scene.texels = render::MakeDisplacementTexels(scene.height);
  const render::Texture texture = render::UploadDisplacementTexture(scene.texels);
  scene.texture = &texture;
  scene.max_displacement = o.max_displacement;
  scene.tiling = o.tiling;
  scene.slices = o.slices;
  scene.size = o.size;
  scene.view = bench::OrbitView(scene.base, o.max_displacement, o.elevation, o.azimuth, o.size);

  const DisplaceResult result = method->second(scene);
  fmt::print("displace: {} on {} ({}), {}x{} px, {:.2f} ms/frame (median of {}), {}\n", o.method, o.base, o.height,
             o.size, o.size, result.timing.median_ms, result.timing.samples, result.detail);
  if (o.compare && o.method != "tessellated") {
    const DisplaceResult truth = RenderTessellated(scene);
    core::DisplacementErrorOptions error_options;
    error_options.depth_unit = core::HeightTexelWorldSize(scene.base, o.texels, o.tiling);
    const core::DisplacementError e = core::CompareToGroundTruth(
        result.frame.color, result.frame.depth, truth.frame.color, truth.frame.depth, error_options);
    fmt::print("displace: vs tessellated ({:.2f} ms/frame): coverage IoU {:.4f}, depth error mean {:.3f} / p95 {:.3f} "
               "texels, {} see-through pixels\n", truth.timing.median_ms, e.coverage_iou, e.mean_depth_error,
               e.p95_depth_error, e.see_through_pixels);
  }
  fs::path depth_path = o.out;
  depth_path.replace_extension(".depth.exr");
  core::WriteImage(depth_path, result.frame.depth);
  core::WriteImage(o.out, result.frame.color);
  fmt::print("displace: wrote {} and {}\n", o.out.string(), depth_path.string());
}

void AddDisplaceCommand(CLI::App& app) {
  static DisplaceOptions o;
  auto* cmd = app.add_subcommand("displace", "Render a displacement-mapped torus/plane/sphere by one method");
  cmd->add_option("--method", o.method, MethodNames())->capture_default_str();
  cmd->add_option("--base", o.base, "torus|plane|sphere")->capture_default_str();
  cmd->add_option("--height", o.height, "bumps|noise|bricks|steps|spikes|constant")->capture_default_str();
  cmd->add_option("--max-displacement", o.max_displacement, "scene units for height 1")->capture_default_str();
  cmd->add_option("--tiling", o.tiling, "height map repeats across uv [0,1]")->capture_default_str();
  cmd->add_option("--texels", o.texels, "height map size")->capture_default_str();
  cmd->add_option("--slices", o.slices, "slices per face volume")->capture_default_str();
  cmd->add_option("--size", o.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--elevation", o.elevation, "degrees above the base plane (90 = top view)")->capture_default_str();
  cmd->add_option("--azimuth", o.azimuth, "degrees around +z")->capture_default_str();
  cmd->add_option("--out", o.out, "colour PNG; camera-z EXR written beside it (.depth.exr)")->capture_default_str();
  cmd->add_flag("--compare", o.compare, "also render the tessellated ground truth and print the error");
  cmd->callback([] { RunDisplace(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("displace", AddDisplaceCommand);

}  // namespace apps
