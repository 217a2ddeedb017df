// `ibr deform MESH`: a mesh deformed and cut by the deform pass (Correa,
// Silver, Chen 2007); flags -> ibr::DeformObjectOptionsFrom (as a scene's
// deform object) -> bench::DeformRunOptions -> bench::RunDeform.
#include <fmt/format.h>

#include <sstream>
#include <string>
#include <vector>

#include "apps/ibr/commands.h"
#include "bench/deform_bench.h"
#include "core/error.h"
#include "ibr/deform_object.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

struct DeformFlags {
  std::string mesh;
  bool cap_holes = false;
  std::vector<std::string> deformations = {"twist"};
  std::vector<double> amounts, widths;
  std::string cut = "none";
  std::string region, placement;
  std::string step = "fixed";
  std::string implicit = "sdf";
  float step_voxels = 1.0f;
  bool skip = false;
  bool skip_object = true;
  std::string solid = "csg";
  int resolution = 128;
  int size = 512;
  double azimuth = 30, elevation = 20;
  std::string cameras;
  std::string out;
};

// The flags as settings (where = "--flag"), read by the one function that
// turns deform options into the pass's (ibr::DeformObjectOptionsFrom).
scene::Settings SettingsFromFlags(const DeformFlags& f) {
  auto join = [](const auto& values) {
    std::string text;
    for (const auto& v : values) text += (text.empty() ? "" : ",") + fmt::format("{}", v);
    return text;
  };
  scene::Settings s;
  s.Set("deformation", join(f.deformations), "--deformation");
  if (!f.amounts.empty()) s.Set("amount", join(f.amounts), "--amount");
  if (!f.widths.empty()) s.Set("width", join(f.widths), "--width");
  s.Set("cut", f.cut, "--cut");
  if (!f.region.empty()) s.Set("region", f.region, "--region");
  if (!f.placement.empty()) s.Set("placement", f.placement, "--placement");
  s.Set("step", f.step, "--step");
  s.Set("step_voxels", f.step_voxels, "--step-voxels");
  s.Set("skip", f.skip, "--skip");
  s.Set("skip_object", f.skip_object, "--skip-object");
  s.Set("solid", f.solid, "--solid");
  s.Set("resolution", f.resolution, "--resolution");
  s.Set("cap_holes", f.cap_holes, "--cap-holes");
  s.Set("implicit", f.implicit, "--implicit");
  return s;
}

void RunDeformCommand(const DeformFlags& f) {
  bench::DeformRunOptions o;
  o.mesh = f.mesh;
  o.object = ibr::DeformObjectOptionsFrom(SettingsFromFlags(f));
  o.size = f.size;
  o.azimuth_deg = f.azimuth;
  o.elevation_deg = f.elevation;
  o.cameras = f.cameras;
  o.out = f.out;
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  // Checks the options and every frame size (--size, --cameras' views) first.
  const bench::DeformRunReport r = bench::RunDeform(programs, o);
  if (r.cube_size > 0) {
    fmt::print("deform: implicit depth-cube 6 x {}x{} R32F, {} bytes, built in {:.2f} s\n",
               r.cube_size, r.cube_size, r.implicit_bytes, r.sdf_seconds);
  } else {
    fmt::print(
        "deform: implicit sdf {}x{}x{} R32F, {} bytes, built in {:.2f} s ({} exact distance "
        "queries)\n",
        r.sdf_size.x, r.sdf_size.y, r.sdf_size.z, r.implicit_bytes, r.sdf_seconds,
        r.distance_queries);
  }
  fmt::print("deform: max displacement {:.4f}\n", r.max_displacement);
  auto print = [](const std::string& what, const bench::DeformOutcomes& c) {
    fmt::print(
        "deform: {}: pixels mesh {} ray-hit {} cut-face {} exited {} early-termination {}; {} "
        "rays, "
        "{:.1f} samples per ray\n",
        what, c.mesh_pixels, c.hit_pixels, c.cut_face_pixels, c.exited_pixels, c.early_pixels,
        c.rays, c.mean_samples);
  };
  for (const bench::DeformViewReport& v : r.views) print("view " + v.name, v.outcomes);
  if (r.views.size() > 1) print(fmt::format("all {} views", r.views.size()), r.total);
  fmt::print("deform: {:.1f} ms per frame (first view); wrote {}\n", r.frame_ms, f.out);
}

void AddDeformCommand(CLI::App& app) {
  static DeformFlags f;
  auto* cmd = app.add_subcommand(
      "deform", "Render a mesh deformed and cut in the pixel shader (Correa 2007)");
  cmd->add_option("mesh", f.mesh, "mesh file (OBJ/PLY/...), normalised to the unit cube")
      ->required();
  cmd->add_flag("--cap-holes", f.cap_holes, "fill the boundary loops of an open mesh");
  cmd->add_option("--deformation", f.deformations,
                  "twist|bend|pull|knife|peel|clip|cutaway|wedge (repeat to sum)")
      ->delimiter(',');
  cmd->add_option("--amount", f.amounts,
                  "per deformation: twist/bend/peel/wedge angle (rad), pull amplitude, knife "
                  "opening, clip plane height, cutaway corner (box units)")
      ->delimiter(',');
  cmd->add_option("--width", f.widths,
                  "per deformation: twist rigid radius, pull sigma, knife depth, peel thickness, "
                  "wedge bottom (box units)")
      ->delimiter(',');
  cmd->add_option("--cut", f.cut, "none|hollow|solid|thick:T")->capture_default_str();
  cmd->add_option("--region", f.region,
                  "x0,y0,z0,x1,y1,z1 (normalised units; default: mesh bounds + 0.05)");
  cmd->add_option("--placement", f.placement,
                  "tx,ty,tz[,rx,ry,rz[,scale]] about the region's centre");
  cmd->add_option("--step", f.step, "fixed|threshold:T|jacobian")->capture_default_str();
  cmd->add_option("--step-voxels", f.step_voxels, "base step in distance-field voxels")
      ->capture_default_str();
  cmd->add_flag("--skip", f.skip, "empty-space skipping in the cut (sec. 6.2)");
  cmd->add_option("--skip-object", f.skip_object,
                  "empty-space skipping by the object's distance field (sdf implicit)")
      ->capture_default_str();
  cmd->add_option("--solid", f.solid,
                  "solid/thick cuts: csg (the field max(body, A)) or search (sec. 5.1.2: "
                  "reject surface hits in the cut, then find the cut's boundary)")
      ->capture_default_str();
  cmd->add_option("--implicit", f.implicit,
                  "sdf|depth-cube: the distance field, or six depth maps (sec. 6.1)")
      ->capture_default_str();
  cmd->add_option("--resolution", f.resolution,
                  "distance-field samples along the longest axis (depth cube: map pixels)")
      ->capture_default_str();
  cmd->add_option("--size", f.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--azimuth", f.azimuth, "degrees about +y")->capture_default_str();
  cmd->add_option("--elevation", f.elevation, "degrees above the horizon")->capture_default_str();
  cmd->add_option("--cameras", f.cameras,
                  "render from this dataset's cameras (world = the mesh file's frame)");
  cmd->add_option("--out", f.out,
                  "FILE.png (colour; camera-z EXR beside it) or DIR (a dataset folder as ibr "
                  "render writes)")
      ->required();
  cmd->callback([] { RunDeformCommand(f); });
}

}  // namespace

IBR_REGISTER_COMMAND("deform", AddDeformCommand);

}  // namespace apps
