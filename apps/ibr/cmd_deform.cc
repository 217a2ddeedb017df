// `ibr deform MESH`: a mesh deformed and cut by the deform pass (Correa, Silver, Chen 2007);
// flags (the deform kind's table) -> settings, as a scene's deform object -> ibr::RenderDeform
// -> print.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "apps/ibr/commands.h"
#include "apps/ibr/kind_flags.h"
#include "ibr/jobs/deform_job.h"
#include "render/gl/context.h"

namespace apps {
namespace {

struct DeformFlags {
  ibr::DeformRenderOptions o;
  scene::Settings settings;  // the deform kind's flags (apps/ibr/kind_flags.h)
};

void RunDeformCommand(DeformFlags& f) {
  f.o.object = ibr::DeformObjectOptionsFrom(f.settings);
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
  AddKindFlags(cmd, *scene::FindObjectKind("deform"), f.settings);
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
