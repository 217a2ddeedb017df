// `ibr volume VOLUME`: a QVis/NRRD/NIfTI/DICOM volume with one discontinuous displacement
// effect (Correa, Silver, Chen 2006) rendered by DVR or as an isosurface.
// Flags -> ibr::VolumeRenderRequest -> ibr::RenderVolume -> one line.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <optional>
#include <string>
#include <vector>

#include "apps/ibr/commands.h"
#include "core/error.h"
#include "ibr/views.h"
#include "ibr/volume_render.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

struct VolumeCommandOptions {
  ibr::VolumeRenderRequest request;
  std::string effect = "none";
  std::string mode = "dvr";
  std::string lighting = "blended";
  std::vector<double> placement;  // tx ty tz sx sy sz
  core::EffectOptions params;
  std::string up = "z";
  std::optional<double> window, level;  // the volume's stored units (e.g. HU)
};

void RunVolume(VolumeCommandOptions& o) {
  constexpr const char* kWhere = "ibr volume";
  ibr::VolumeRenderRequest& r = o.request;
  if (o.effect != "none") {
    o.params.effect = core::ParseEffect(o.effect);
    o.params.Check();
    r.effect = o.params;
  }
  r.iso_value = ibr::ApplyVolumeMode(o.mode, r.pass, std::string(kWhere) + " --mode");
  r.pass.lighting = render::VolumeLightingFromName(o.lighting);
  if (!o.placement.empty()) {
    if (o.placement.size() != 6)
      core::ThrowInputError(kWhere, "--placement takes 6 numbers: tx ty tz sx sy sz");
    r.placement_offset = {o.placement[0], o.placement[1], o.placement[2]};
    r.placement_scale = {o.placement[3], o.placement[4], o.placement[5]};
  }
  r.orbit.up = ibr::UpAxisFromName(o.up, std::string(kWhere) + " --up");
  r.orbit.Check();
  if (o.window) r.window_level = glm::dvec2(*o.window, *o.level);
  r.pass.Check();
  auto context = render::HeadlessContext::Create();
  // --size is the orbit view's; --cameras views are checked view by view.
  render::CheckFrameSize(kWhere, "--size", r.size, r.size);
  spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
  const ibr::VolumeRenderResult result = ibr::RenderVolume(r);
  fmt::print(
      "volume: {} effect {} mode {} -> {} image(s) in {}; {:.1f} ms/frame (median), {} slices, "
      "proxy box "
      "[{:.2f} {:.2f} {:.2f}]-[{:.2f} {:.2f} {:.2f}]\n",
      r.volume.string(), o.effect, o.mode, result.images, r.out.string(), result.median_ms,
      result.slices, result.proxy_lo.x, result.proxy_lo.y, result.proxy_lo.z, result.proxy_hi.x,
      result.proxy_hi.y, result.proxy_hi.z);
}

void AddVolumeCommand(CLI::App& app) {
  static VolumeCommandOptions o;
  auto* cmd = app.add_subcommand(
      "volume", "Render a volume with a discontinuous displacement (Correa et al. 2006)");
  auto& r = o.request;
  cmd->add_option("volume", r.volume,
                  "QVis .dat, NRRD .nrrd/.nhdr, NIfTI .nii/.nii.gz or a DICOM folder")
      ->required();
  cmd->add_option("--deformation,--effect", o.effect,
                  "none|peel|slices|seam|pull|wave|clip|cutaway|wedge (clip, cutaway and wedge "
                  "cut meshes too: ibr deform --deformation)")
      ->capture_default_str();
  cmd->add_option("--peel-angle", o.params.peel_angle_deg, "peel: degrees")->capture_default_str();
  cmd->add_option("--peel-thickness", o.params.peel_thickness, "peel: layer thickness, map units")
      ->capture_default_str();
  cmd->add_option("--peel-top", o.params.peel_top, "peel: layer top, map units")
      ->capture_default_str();
  cmd->add_option("--peel-hinge", o.params.peel_hinge_x, "peel: hinge x, map units")
      ->capture_default_str();
  cmd->add_option("--slices-period", o.params.slices_period, "slices: period, map units")
      ->capture_default_str();
  cmd->add_option("--slices-gap", o.params.slices_gap, "slices: gap, map units")
      ->capture_default_str();
  cmd->add_option("--seam-z", o.params.seam_z, "seam: opening starts at this z, map units")
      ->capture_default_str();
  cmd->add_option("--seam-width", o.params.seam_width, "seam: opening at the top, map units")
      ->capture_default_str();
  cmd->add_option("--pull-sigma", o.params.pull_sigma, "pull: Gaussian width, map units")
      ->capture_default_str();
  cmd->add_option("--wave-amplitude", o.params.wave_amplitude, "wave: amplitude, map units")
      ->capture_default_str();
  cmd->add_option("--wave-frequency", o.params.wave_frequency, "wave: periods across the map")
      ->capture_default_str();
  cmd->add_option("--clip-height", o.params.clip_height,
                  "clip: z above which is removed, map units")
      ->capture_default_str();
  cmd->add_option("--cutaway-corner", o.params.cutaway_corner,
                  "cutaway: the corner x, y, z above this is removed, map units")
      ->capture_default_str();
  cmd->add_option("--wedge-angle", o.params.wedge_angle_deg,
                  "wedge: opening in degrees about the map's vertical axis, centred on +x")
      ->capture_default_str();
  cmd->add_option("--wedge-bottom", o.params.wedge_bottom, "wedge: its lowest z, map units")
      ->capture_default_str();
  cmd->add_option("--map-size", r.map_size, "displacement map texels per axis")
      ->capture_default_str();
  cmd->add_option("--placement", o.placement, "map cube in volume texture space: tx ty tz sx sy sz")
      ->expected(6);
  cmd->add_option("--mode", o.mode, "dvr | iso:VALUE (in the volume's own units, e.g. HU)")
      ->capture_default_str();
  cmd->add_option("--lighting", o.lighting, "none|gradient|transformed|blended (Fig. 4 a-d)")
      ->capture_default_str();
  cmd->add_option("--spacing", r.pass.sampling_distance_voxels, "sampling distance, voxels")
      ->capture_default_str();
  auto* transfer = cmd->add_option(
      "--transfer", r.transfer,
      "preset (tooth, neghip, bucky, ramp, empty) or JSON file (\"units\": \"data\" for "
      "points in the volume's units); default: the preset named like the volume, else a white "
      "ramp transparent at its 50th and opaque at its 99th percentile");
  auto* window = cmd->add_option("--window", o.window,
                                 "DVR window width in the volume's units (e.g. 400 HU): a white "
                                 "ramp over [level - width/2, level + width/2], transparent "
                                 "below, opaque above (instead of --transfer)");
  auto* level =
      cmd->add_option("--level", o.level, "DVR window centre in the volume's units (e.g. 40 HU)");
  window->needs(level)->excludes(transfer);
  level->needs(window)->excludes(transfer);
  cmd->add_option("--displacement-bits", r.pass.displacement_bits, "8 | 16 | 32")
      ->capture_default_str();
  cmd->add_flag("!--no-support-skip", r.pass.support_skip,
                "DVR: every slice fragment runs the displaced shader (no split of the slices "
                "at the maps' support box; same image, the baseline of ibr bench volume)");
  cmd->add_option("--brick-texels", r.pass.brick_texels,
                  "DVR, one map: split the support box further by map bricks of this many "
                  "texels (identity bricks drawn without maps, cut-away ones not drawn); 0: the "
                  "support box only")
      ->capture_default_str();
  cmd->add_option("--size", r.size, "image width = height, pixels (orbit view)")
      ->capture_default_str();
  cmd->add_option("--azimuth", r.orbit.azimuth_deg, "degrees around --up")->capture_default_str();
  cmd->add_option("--elevation", r.orbit.elevation_deg,
                  "degrees above the plane perpendicular to --up (90 = top view)")
      ->capture_default_str();
  cmd->add_option("--distance", r.orbit.distance,
                  "camera distance from the volume's centre in its units, e.g. mm (0 = frame "
                  "the volume)")
      ->capture_default_str();
  cmd->add_option("--fov", r.orbit.fov_deg, "field of view, degrees")->capture_default_str();
  cmd->add_option("--up", o.up,
                  "the volume axis at the top of the image: x, y, z, -x, -y, -z (z, the slice "
                  "axis: head up for an axial CT or MRI series)")
      ->capture_default_str();
  cmd->add_option("--cameras", r.cameras,
                  "render from this dataset's cameras (one PNG per view into --out DIR)");
  cmd->add_option("--out", r.out, "FILE.png or DIR")->required();
  cmd->callback([] { RunVolume(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("volume", AddVolumeCommand);

}  // namespace apps
