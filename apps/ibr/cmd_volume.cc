// `ibr volume VOLUME`: a QVis/NRRD/NIfTI/DICOM volume deformed and cut (Correa, Silver, Chen
// 2006; the deformation names of `ibr deform`), rendered by DVR or as an isosurface.
// Flags (the volume kind's table) -> settings, as a scene's volume object -> ibr::RenderVolume
// -> one line.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <optional>
#include <string>
#include <vector>

#include "apps/ibr/commands.h"
#include "apps/ibr/kind_flags.h"
#include "ibr/jobs/volume_job.h"
#include "ibr/views.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

struct VolumeFlags {
  ibr::VolumeRenderRequest request;
  scene::Settings settings;  // the volume kind's flags (apps/ibr/kind_flags.h)
  std::string up = "z";
  int brick_texels = 3;  // the pass's default
  bool support_skip = true;
  std::optional<double> window, level;  // the volume's stored units (e.g. HU)
};

void RunVolume(VolumeFlags& f) {
  ibr::VolumeRenderRequest& r = f.request;
  r.object = ibr::VolumeObjectOptionsFrom(f.settings);  // as a scene's volume object
  r.object.pass.support_skip = f.support_skip;
  r.object.pass.brick_texels = f.brick_texels;
  r.orbit.up = ibr::UpAxisFromName(f.up, "ibr volume --up");
  r.orbit.Check();
  if (f.window) r.window_level = glm::dvec2(*f.window, *f.level);
  r.object.Check();
  auto context = render::HeadlessContext::Create();
  render::CheckFrameSize("ibr volume", "--size", r.size, r.size);  // --cameras: view by view
  spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
  fmt::print("{}\n", ibr::VolumeReportText(r, ibr::RenderVolume(r)));
}

void AddVolumeCommand(CLI::App& app) {
  static VolumeFlags f;
  auto* cmd = app.add_subcommand("volume", "Render a volume deformed and cut (Correa et al. 2006)");
  auto& r = f.request;
  cmd->add_option("volume", r.volume, "QVis, NRRD, NIfTI file or DICOM dir")->required();
  AddKindFlags(cmd, *scene::FindObjectKind("volume"), f.settings, "ibr volume ");
  auto* transfer = cmd->add_option("--transfer", r.transfer,
                                   "preset (tooth, neghip, bucky, ramp, empty) or JSON file; "
                                   "default: the preset named like the volume, else a ramp");
  auto* window = cmd->add_option("--window", f.window, "DVR window width, the volume's units");
  auto* level = cmd->add_option("--level", f.level, "DVR window centre, the volume's units");
  window->needs(level)->excludes(transfer), level->needs(window)->excludes(transfer);
  cmd->add_flag("!--no-support-skip", f.support_skip, "DVR: no split at the maps' support box");
  cmd->add_option("--brick-texels", f.brick_texels, "DVR, one map: split by bricks (0: off)");
  cmd->add_option("--size", r.size, "image width = height, pixels (orbit view)");
  cmd->add_option("--azimuth", r.orbit.azimuth_deg, "degrees around --up");
  cmd->add_option("--elevation", r.orbit.elevation_deg, "degrees above the plane normal to --up");
  cmd->add_option("--distance", r.orbit.distance, "from the centre, volume units (0: frame it)");
  cmd->add_option("--fov", r.orbit.fov_deg, "field of view, degrees");
  cmd->add_option("--up", f.up, "volume axis at the image's top: x, y, z, -x, -y, -z");
  cmd->add_option("--cameras", r.cameras, "render from this dataset's cameras (--out DIR)");
  cmd->add_option("--out", r.out, "FILE.png or DIR")->required();
  cmd->callback([] { RunVolume(f); });
}

}  // namespace

IBR_REGISTER_COMMAND("volume", AddVolumeCommand);

}  // namespace apps
