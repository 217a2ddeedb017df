// `ibr displace`: one displacement-mapped base mesh (torus, plane, sphere, or
// the user's --mesh with --height-map and --texture) rendered by one method
// (ibr/displaced_mesh.h, the one method table) into a PNG (colour) and an EXR
// beside it (camera z). `tessellated` is the ground truth every other method
// is compared with (--compare).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "apps/ibr/commands.h"
#include "bench/displacement_bench.h"
#include "core/displacement_error.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/image_io.h"
#include "core/timing.h"
#include "ibr/displaced_mesh.h"
#include "render/gl/context.h"
#include "render/gl/frame_timer.h"
#include "render/passes/pass.h"
#include "render/passes/relief_surface_pass.h"

namespace apps {
namespace {
namespace fs = std::filesystem;

std::string MethodNames() {
  std::string names;
  for (const std::string& n : ibr::DisplacementMethodNames())
    names += (names.empty() ? "" : "|") + n;
  return names;
}

struct DisplaceOptions {
  std::string method = "slices-orthogonal";
  std::string base = "torus";
  std::string height = "bumps";
  fs::path mesh;        // the user's OBJ/PLY with uvs (instead of --base)
  fs::path height_map;  // the user's 8/16-bit PNG or EXR height map (instead of --height)
  fs::path texture;     // optional colour texture
  float max_displacement = 0.15f;  // scene units (the torus tube radius is 0.4)
  float tiling = 2.0f;
  int texels = 256;       // generated height map size
  int slices = 64;        // per volume
  int size = 512;         // pixels
  double elevation = 35;  // degrees above the z = 0 plane
  double azimuth = -60;   // degrees around +z
  fs::path out = "displace.png";
  bool compare = false;  // also render `tessellated` and print the error
};

// One method drawn and timed; the frame read back.
struct Drawn {
  render::Frame frame;
  core::TimingStats timing;
  std::string detail;
};
Drawn Draw(render::ProgramCache& programs, const ibr::DisplacedMeshData& data,
           const ibr::DisplacedMeshOptions& o, const render::ViewSetup& view, int size) {
  ibr::DisplacedMeshRenderer renderer(programs, data, o);
  Drawn d;
  d.timing = render::TimeFrames([&] { renderer.Draw(view, size, size); });
  renderer.Draw(view, size, size);
  d.frame = renderer.Read();
  d.detail = renderer.Detail();
  if (const int64_t early =
          d.frame.CountOutcome(render::OutcomeBit(render::RayOutcome::kEarlyTermination))) {
    d.detail += fmt::format(", {} early-terminated pixels", early);
  }
  return d;
}

void RunDisplace(const DisplaceOptions& o) {
  constexpr const char* kWhere = "ibr displace";
  if (o.texels < 4 || o.texels > 4096)
    core::ThrowInputError(kWhere, "--texels {} outside 4..4096", o.texels);
  if (o.out.extension() != ".png")
    core::ThrowInputError(kWhere, "--out '{}' must end in .png", o.out.string());
  if (o.out.has_parent_path() && !fs::is_directory(o.out.parent_path())) {
    core::ThrowInputError(kWhere, "--out '{}': no such directory", o.out.string());
  }
  ibr::DisplacedMeshOptions options;
  options.method = ibr::DisplacementMethodFromName(o.method);
  options.max_displacement = o.max_displacement;
  options.tiling = o.tiling;
  options.slices = o.slices;
  options.Check();
  auto context = render::HeadlessContext::Create();
  render::CheckFrameSize(kWhere, "--size", o.size, o.size, /*min_side=*/16);

  // Parse -> plain CPU data -> GPU -> passes.
  ibr::DisplacedMeshData data;
  data.base =
      o.mesh.empty() ? ibr::DisplacementBaseMesh(o.base) : ibr::ReadDisplacementBase(o.mesh);
  data.height = o.height_map.empty()
                    ? ibr::DisplacementHeightMap(core::HeightPatternFromName(o.height), o.texels)
                    : ibr::ReadHeightMap(o.height_map);
  if (!o.texture.empty()) data.color = core::ReadImage<uint8_t>(o.texture);
  const std::string base = o.mesh.empty() ? o.base : o.mesh.filename().string();
  const std::string height = o.height_map.empty() ? o.height : o.height_map.filename().string();

  spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
  render::ProgramCache programs;
  const render::ViewSetup view =
      bench::OrbitView(data.base, o.max_displacement, o.elevation, o.azimuth, o.size);
  const Drawn result = Draw(programs, data, options, view, o.size);
  fmt::print("displace: {} on {} ({}), {}x{} px, {:.2f} ms/frame (median of {}), {}\n", o.method,
             base, height, o.size, o.size, result.timing.median_ms, result.timing.samples,
             result.detail);
  if (o.compare && options.method != ibr::DisplacementMethod::kTessellated) {
    ibr::DisplacedMeshOptions truth_options = options;
    truth_options.method = ibr::DisplacementMethod::kTessellated;
    const Drawn truth = Draw(programs, data, truth_options, view, o.size);
    core::DisplacementErrorOptions error_options;
    error_options.depth_unit = core::HeightTexelWorldSize(data.base, data.height.width(), o.tiling);
    const core::DisplacementError e =
        core::CompareToGroundTruth(result.frame.color, result.frame.depth, truth.frame.color,
                                   truth.frame.depth, error_options);
    fmt::print(
        "displace: vs tessellated ({:.2f} ms/frame): coverage IoU {:.4f}, depth error mean {:.3f} "
        "/ p95 {:.3f} "
        "texels, {} see-through pixels\n",
        truth.timing.median_ms, e.coverage_iou, e.mean_depth_error, e.p95_depth_error,
        e.see_through_pixels);
  }
  fs::path depth_path = o.out;
  depth_path.replace_extension(".depth.exr");
  core::WriteImage(depth_path, result.frame.depth);
  core::WriteImage(o.out, result.frame.color);
  fmt::print("displace: wrote {} and {}\n", o.out.string(), depth_path.string());
}

void AddDisplaceCommand(CLI::App& app) {
  static DisplaceOptions o;
  auto* cmd = app.add_subcommand(
      "displace", "Render a displacement-mapped mesh (torus/plane/sphere or --mesh) by one method");
  cmd->add_option("--method", o.method, MethodNames())->capture_default_str();
  cmd->add_option("--base", o.base, "torus|plane|sphere")->capture_default_str();
  cmd->add_option("--height", o.height, "bumps|noise|bricks|steps|spikes|constant")
      ->capture_default_str();
  cmd->add_option("--mesh", o.mesh,
                  "your own base mesh (OBJ/PLY with texture coordinates) instead of --base");
  cmd->add_option("--height-map", o.height_map,
                  "your own height map (8/16-bit PNG or EXR, [0, 1]) instead of --height");
  cmd->add_option("--texture", o.texture,
                  "colour texture (any image) for the slicing and tessellated methods");
  cmd->add_option("--max-displacement", o.max_displacement, "scene units for height 1")
      ->capture_default_str();
  cmd->add_option("--tiling", o.tiling, "height map repeats across uv [0,1]")
      ->capture_default_str();
  cmd->add_option("--texels", o.texels, "height map size")->capture_default_str();
  cmd->add_option("--slices", o.slices, "slices per face volume")->capture_default_str();
  cmd->add_option("--size", o.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--elevation", o.elevation, "degrees above the base plane (90 = top view)")
      ->capture_default_str();
  cmd->add_option("--azimuth", o.azimuth, "degrees around +z")->capture_default_str();
  cmd->add_option("--out", o.out, "colour PNG; camera-z EXR written beside it (.depth.exr)")
      ->capture_default_str();
  cmd->add_flag("--compare", o.compare,
                "also render the tessellated ground truth and print the error");
  cmd->callback([] { RunDisplace(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("displace", AddDisplaceCommand);

}  // namespace apps
