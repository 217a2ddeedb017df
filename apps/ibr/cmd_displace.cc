// `ibr displace`: one displacement-mapped base mesh (torus, plane, sphere, or
// the user's --mesh with --height-map and --texture) rendered by one method
// (ibr/displaced_mesh.h, the one method table) into a PNG (colour) and an EXR
// beside it (camera z). `tessellated` is the ground truth every other method
// is compared with (--compare); it is planned within the memory budget
// before anything is allocated (fewer subdivisions, said, or one error line).
// The job: ibr::RunDisplaceJob (ibr/jobs/displace_job.h).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <string>

#include "apps/ibr/commands.h"
#include "ibr/jobs/displace_job.h"
#include "render/gl/context.h"

namespace apps {
namespace {

std::string MethodNames() {
  std::string names;
  for (const std::string& n : ibr::DisplacementMethodNames())
    names += (names.empty() ? "" : "|") + n;
  return names;
}

void AddDisplaceCommand(CLI::App& app) {
  static ibr::DisplaceJob o;
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
                  "colour texture (any image) at the mesh's uvs, lit, for every method");
  cmd->add_option("--max-displacement", o.max_displacement, "scene units for height 1")
      ->capture_default_str();
  cmd->add_option("--tiling", o.tiling, "height map repeats across uv [0,1]")
      ->capture_default_str();
  cmd->add_option("--texture-tiling", o.texture_tiling,
                  "colour texture repeats across uv [0,1] (1: where the mesh's uvs put it)")
      ->capture_default_str();
  cmd->add_option("--texels", o.texels, "height map size")->capture_default_str();
  cmd->add_option("--slices", o.slices, "slices per face volume")->capture_default_str();
  cmd->add_option("--size", o.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--elevation", o.elevation,
                  "degrees above the plane perpendicular to --up (90 = top view)")
      ->capture_default_str();
  cmd->add_option("--azimuth", o.azimuth, "degrees around --up")->capture_default_str();
  cmd->add_option("--distance", o.distance,
                  "camera distance from the mesh's centre in its units (0 = frame the mesh)")
      ->capture_default_str();
  cmd->add_option("--fov", o.fov, "field of view, degrees")->capture_default_str();
  cmd->add_option("--up", o.up, "the mesh's up axis: x, y, z, -x, -y, -z")->capture_default_str();
  cmd->add_option("--background", o.background,
                  "opaque background colour R,G,B (0-255); default transparent");
  cmd->add_flag("--unlit", o.unlit, "show the colour texture's plain colour (default: lit)");
  cmd->add_option("--frames", o.frames, "timed frames (median); 0 = draw once, untimed")
      ->capture_default_str();
  cmd->add_option("--out", o.out, "colour PNG; camera-z EXR written beside it (.depth.exr)")
      ->capture_default_str();
  cmd->add_flag("--compare", o.compare,
                "also render the tessellated ground truth and print the error");
  cmd->callback([] {
    o.Check();  // every flag before a context exists
    auto context = render::HeadlessContext::Create();
    spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
    render::ProgramCache programs;
    ibr::RunDisplaceJob(programs, o, [](const std::string& line) { fmt::print("{}\n", line); });
  });
}

}  // namespace

IBR_REGISTER_COMMAND("displace", AddDisplaceCommand);

}  // namespace apps
