// `ibr info`: what this machine's GL gives us. `ibr info DIR`: a readable
// summary of a dataset (cameras, views, depth, bounds). `ibr info VOLUME`: a
// volume file's type, size, spacing, data range and percentiles.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include "apps/ibr/commands.h"
#include "capture/dataset.h"
#include "capture/depth_scale.h"
#include "core/error.h"
#include "core/volume_io.h"
#include "render/gl/context.h"
#include "render/gl/shader_program.h"
#include "scene/scene_keys.h"

namespace apps {

namespace {

void PrintGlInfo() {
  auto context = render::HeadlessContext::Create();
  const render::GlInfo& gl = context->info();
  fmt::print("OpenGL    {}.{} ({})\n", gl.major, gl.minor, gl.version);
  fmt::print("renderer  {}\nvendor    {}\nGLSL      {}\nplatform  EGL {}\n", gl.renderer, gl.vendor,
             gl.glsl_version, gl.platform);
  fmt::print("shaders   {} embedded files\n", render::ShaderSources::Embedded().Names().size());
}

void PrintDataset(const std::filesystem::path& dir) {
  const capture::Dataset d = capture::ReadDataset(dir);
  fmt::print("dataset   {}\n", std::filesystem::absolute(dir).string());
  int with_depth = 0, with_mask = 0, with_normal = 0;
  for (const auto& v : d.views) {
    with_depth += !v.depth.empty();
    with_mask += !v.mask.empty();
    with_normal += !v.normal.empty();
  }
  fmt::print("views     {} (depth {}, mask {}, normals {})\n", d.views.size(), with_depth,
             with_mask, with_normal);
  std::map<std::string, int> models;
  for (const auto& [id, c] : d.cameras)
    models[fmt::format("{} {}x{}", capture::CameraModelName(c.model), c.width, c.height)]++;
  fmt::print("cameras   {}:", d.cameras.size());
  for (const auto& [m, n] : models) fmt::print(" {} x {};", n, m);
  fmt::print("\n");
  fmt::print("depth     camera z, units: {}, invalid = 0 or non-finite\n", d.depth_units);
  if (d.bounds) {
    fmt::print("bounds    min ({:.4g}, {:.4g}, {:.4g})  max ({:.4g}, {:.4g}, {:.4g})\n",
               d.bounds->min.x, d.bounds->min.y, d.bounds->min.z, d.bounds->max.x, d.bounds->max.y,
               d.bounds->max.z);
  } else {
    fmt::print("bounds    unknown\n");
  }
  const capture::UpChoice up = capture::DefaultUp(d);
  fmt::print("up        ({:.3f}, {:.3f}, {:.3f}) from {}\n", up.up.x, up.up.y, up.up.z, up.source);
  if (with_depth > 0) {
    const capture::DepthScaleReport scale = capture::CheckDepthScale(d);
    fmt::print("depth     median {:.4g} {} over {} view(s){}\n", scale.median, d.depth_units,
               scale.views,
               scale.agreement >= 0 ? fmt::format("; {:.0f} % of samples agree between {} pair(s)",
                                                  100 * scale.agreement, scale.pairs)
                                    : "");
    if (!scale.warning.empty()) fmt::print("warning   {}\n", scale.warning);
  }
  // Depth range and coverage of the first view with depth, as a sanity figure.
  for (size_t i = 0; i < d.views.size(); ++i) {
    if (d.views[i].depth.empty()) continue;
    const core::ImageF depth = d.LoadDepth(i);
    float lo = std::numeric_limits<float>::max(), hi = 0;
    size_t valid = 0;
    for (float z : depth.values()) {
      if (!(std::isfinite(z) && z > 0)) continue;
      lo = std::min(lo, z);
      hi = std::max(hi, z);
      ++valid;
    }
    fmt::print("view 0    '{}': depth {:.4g}..{:.4g}, {:.1f} % valid\n", d.views[i].name,
               valid ? lo : 0.0f, hi, 100.0 * valid / depth.pixel_count());
    break;
  }
  fmt::print("{:<14} {:<8} {:<28} {}\n", "view", "camera", "centre (world)", "files");
  for (const auto& v : d.views) {
    const glm::dvec3 c = v.cam_from_world.Centre();
    fmt::print("{:<14} {:<8} ({:8.4f},{:8.4f},{:8.4f})  {}{}{}{}\n", v.name, v.camera_id, c.x, c.y,
               c.z, "color", v.depth.empty() ? "" : " depth", v.mask.empty() ? "" : " mask",
               v.normal.empty() ? "" : " normal");
  }
}

// A volume file or a DICOM folder (a dataset folder holds a manifest).
bool IsVolume(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  for (const char* ext : {".dat", ".nrrd", ".nhdr", ".nii", ".nii.gz"}) {
    const std::string e = ext;
    if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0)
      return true;
  }
  return std::filesystem::is_directory(path) && !std::filesystem::exists(path / "dataset.json");
}

void PrintVolume(const std::filesystem::path& path) {
  const core::Volume v = core::ReadVolume(path);
  const core::VolumeStats st = core::ComputeVolumeStats(v);
  const glm::dvec3 extent = v.Extent();
  fmt::print("volume    {}\n", std::filesystem::absolute(path).string());
  fmt::print("type      {}\n", core::ScalarTypeName(v.type));
  fmt::print("size      {} x {} x {} voxels ({} bytes)\n", v.dims.x, v.dims.y, v.dims.z,
             v.bytes.size());
  fmt::print("spacing   {:.6g} x {:.6g} x {:.6g} (file units, e.g. mm)\n", v.spacing.x, v.spacing.y,
             v.spacing.z);
  fmt::print("extent    {:.6g} x {:.6g} x {:.6g}\n", extent.x, extent.y, extent.z);
  fmt::print("range     {:.6g} .. {:.6g} ({} finite voxels, {} NaN/Inf)\n", st.min, st.max,
             st.finite, st.non_finite);
  fmt::print("percentiles 1 / 50 / 99: {:.6g} / {:.6g} / {:.6g}\n", st.p1, st.p50, st.p99);
  const glm::dvec2 n = v.NormalizationRange();
  fmt::print("texture   stored values {:.6g} .. {:.6g} map to 0 .. 1\n", n.x, n.y);
}

void AddInfoCommand(CLI::App& app) {
  static std::filesystem::path dir;
  auto* cmd =
      app.add_subcommand("info",
                         "Without DIR: the OpenGL context this machine gives (headless EGL); "
                         "with DIR: a summary of the dataset there; with a volume (.dat, .nrrd, "
                         ".nhdr, .nii, .nii.gz or a DICOM folder): its type, size, spacing, data "
                         "range and percentiles");
  cmd->add_option("DIR", dir, "dataset directory or volume (optional)");
  static bool scene_keys = false;
  cmd->add_flag("--scene-keys", scene_keys,
                "print every key a scene object takes, per object type (Markdown)");
  cmd->callback([] {
    if (scene_keys) {
      fmt::print("{}", scene::ObjectKeysMarkdown());
    } else if (dir.empty()) {
      PrintGlInfo();
    } else if (IsVolume(dir) && std::filesystem::is_directory(dir)) {
      // A folder without a manifest: a DICOM series, or a dataset missing its dataset.json.
      try {
        PrintVolume(dir);
      } catch (const core::InputError& e) {
        core::ThrowFileError("ibr info", dir,
                             "no dataset.json (not a dataset) and not a DICOM series ({})",
                             e.what());
      }
    } else if (IsVolume(dir)) {
      PrintVolume(dir);
    } else {
      PrintDataset(dir);
    }
  });
}
}  // namespace

IBR_REGISTER_COMMAND("info", AddInfoCommand);

}  // namespace apps
