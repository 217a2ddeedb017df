// `ibr deform MESH`: a mesh deformed and cut by the deform pass (Correa, Silver, Chen 2007);
// flags -> settings (as a scene's deform object) -> ibr::RenderDeform -> print.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "apps/ibr/commands.h"
#include "ibr/deform_render.h"
#include "render/gl/context.h"

namespace apps {
namespace {

struct DeformFlags {
  ibr::DeformRenderOptions o;
  bool cap_holes = false, skip = false, skip_object = true;
  DeformationFlags deformations{{"twist"}, {}, {}, ""};
  std::string cut = "none", region, step = "fixed", implicit = "sdf", solid = "csg";
  float step_voxels = 1.0f;
  int resolution = 128;
};

void RunDeformCommand(DeformFlags& f) {
  scene::Settings s;  // read as a scene's deform object is (ibr::DeformObjectOptionsFrom)
  SetDeformationSettings(f.deformations, "", s);
  if (!f.region.empty()) s.Set("region", f.region, "--region");
  s.Set("cut", f.cut, "--cut");
  s.Set("step", f.step, "--step");
  s.Set("step_voxels", f.step_voxels, "--step-voxels");
  s.Set("skip", f.skip, "--skip");
  s.Set("skip_object", f.skip_object, "--skip-object");
  s.Set("solid", f.solid, "--solid");
  s.Set("resolution", f.resolution, "--resolution");
  s.Set("cap_holes", f.cap_holes, "--cap-holes");
  s.Set("implicit", f.implicit, "--implicit");
  f.o.object = ibr::DeformObjectOptionsFrom(s);
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  // Checks the options and every frame size (--size, --cameras' views) first.
  const ibr::DeformRenderReport r = ibr::RenderDeform(programs, f.o);
  fmt::print("{}", ibr::DeformReportText(r, f.o.out.string()));
}

void AddDeformCommand(CLI::App& app) {
  static DeformFlags f;
  auto* cmd = app.add_subcommand("deform", "Render a mesh deformed and cut (Correa 2007)");
  cmd->add_option("mesh", f.o.mesh, "mesh file (OBJ/PLY/...), normalised to the unit cube")
      ->required();
  cmd->add_flag("--cap-holes", f.cap_holes, "fill the boundary loops of an open mesh");
  AddDeformationFlags(cmd, f.deformations, "--deformation",
                      "twist|bend|pull|knife|peel|slices|seam|wave|clip|cutaway|wedge (repeat or "
                      "comma list to sum; docs/guide/deformations.md)",
                      "tx,ty,tz[,rx,ry,rz[,scale]] about region centre");
  cmd->add_option("--cut", f.cut, "none|hollow|solid|thick:T")->capture_default_str();
  cmd->add_option("--region", f.region, "x0,y0,z0,x1,y1,z1 (normalised; default: mesh + 0.05)");
  cmd->add_option("--step", f.step, "fixed|threshold:T|jacobian")->capture_default_str();
  cmd->add_option("--step-voxels", f.step_voxels, "base step, field voxels")->capture_default_str();
  cmd->add_flag("--skip", f.skip, "empty-space skipping in the cut (sec. 6.2)");
  cmd->add_option("--skip-object", f.skip_object, "skip by the object's distance field (sdf)");
  cmd->add_option("--solid", f.solid, "solid/thick cuts: csg | search (sec. 5.1.2)");
  cmd->add_option("--implicit", f.implicit, "sdf|depth-cube (sec. 6.1)")->capture_default_str();
  cmd->add_option("--resolution", f.resolution, "field samples, longest axis (cube: pixels)");
  cmd->add_option("--size", f.o.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--azimuth", f.o.azimuth_deg, "degrees about +y")->capture_default_str();
  cmd->add_option("--elevation", f.o.elevation_deg, "degrees above the horizon");
  cmd->add_option("--cameras", f.o.cameras, "render from this dataset's cameras (mesh frame)");
  cmd->add_option("--out", f.o.out, "FILE.png (camera-z EXR beside it) or DIR (a dataset)")
      ->required();
  cmd->callback([] { RunDeformCommand(f); });
}

}  // namespace

IBR_REGISTER_COMMAND("deform", AddDeformCommand);

}  // namespace apps
