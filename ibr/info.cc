#include "ibr/info.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>

#include "capture/dataset.h"
#include "capture/depth_scale.h"
#include "core/error.h"
#include "core/volume_io.h"
#include "render/gl/context.h"
#include "render/gl/shader_program.h"

namespace ibr {
namespace {

// A volume file or a DICOM folder (a dataset folder holds a manifest).
bool IsVolumePath(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  for (const char* ext : {".dat", ".nrrd", ".nhdr", ".nii", ".nii.gz"}) {
    const std::string e = ext;
    if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0)
      return true;
  }
  return std::filesystem::is_directory(path) && !std::filesystem::exists(path / "dataset.json");
}

}  // namespace

std::string GlInfoText() {
  std::string s;
  auto context = render::HeadlessContext::Create();
  const render::GlInfo& gl = context->info();
  s += fmt::format("OpenGL    {}.{} ({})\n", gl.major, gl.minor, gl.version);
  s += fmt::format("renderer  {}\nvendor    {}\nGLSL      {}\nplatform  EGL {}\n", gl.renderer,
                   gl.vendor, gl.glsl_version, gl.platform);
  s += fmt::format("shaders   {} embedded files\n",
                   render::ShaderSources::Embedded().Names().size());
  return s;
}

std::string DatasetInfoText(const std::filesystem::path& dir) {
  std::string s;
  const capture::Dataset d = capture::ReadDataset(dir);
  s += fmt::format("dataset   {}\n", std::filesystem::absolute(dir).string());
  int with_depth = 0, with_mask = 0, with_normal = 0;
  for (const auto& v : d.views) {
    with_depth += !v.depth.empty();
    with_mask += !v.mask.empty();
    with_normal += !v.normal.empty();
  }
  s += fmt::format("views     {} (depth {}, mask {}, normals {})\n", d.views.size(), with_depth,
                   with_mask, with_normal);
  std::map<std::string, int> models;
  for (const auto& [id, c] : d.cameras)
    models[fmt::format("{} {}x{}", capture::CameraModelName(c.model), c.width, c.height)]++;
  s += fmt::format("cameras   {}:", d.cameras.size());
  for (const auto& [m, n] : models) s += fmt::format(" {} x {};", n, m);
  s += "\n";
  s += fmt::format("depth     camera z, units: {}, invalid = 0 or non-finite\n", d.depth_units);
  s += fmt::format("noise     {}\n", d.depth_noise ? d.depth_noise->Describe()
                                                   : std::string("not stated by the dataset"));
  if (d.bounds) {
    s += fmt::format("bounds    min ({:.4g}, {:.4g}, {:.4g})  max ({:.4g}, {:.4g}, {:.4g})\n",
                     d.bounds->min.x, d.bounds->min.y, d.bounds->min.z, d.bounds->max.x,
                     d.bounds->max.y, d.bounds->max.z);
  } else {
    s += fmt::format("bounds    unknown\n");
  }
  const capture::UpChoice up = capture::DefaultUp(d);
  s += fmt::format("up        ({:.3f}, {:.3f}, {:.3f}) from {}\n", up.up.x, up.up.y, up.up.z,
                   up.source);
  if (with_depth > 0) {
    const capture::DepthScaleReport scale = capture::CheckDepthScale(d);
    s += fmt::format(
        "depth     median {:.4g} {} over {} view(s){}\n", scale.median, d.depth_units, scale.views,
        scale.agreement >= 0 ? fmt::format("; {:.0f} % of samples agree between {} pair(s)",
                                           100 * scale.agreement, scale.pairs)
                             : "");
    if (scale.noise_sigma >= 0) {
      s += fmt::format(
          "noise     the views agree to a depth deviation of {:.3g} {} per map ({} "
          "reprojected samples)\n",
          scale.noise_sigma, d.depth_units, scale.noise_samples);
    }
    if (!scale.warning.empty()) s += fmt::format("warning   {}\n", scale.warning);
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
    s += fmt::format("view 0    '{}': depth {:.4g}..{:.4g}, {:.1f} % valid\n", d.views[i].name,
                     valid ? lo : 0.0f, hi, 100.0 * valid / depth.pixel_count());
    break;
  }
  s += fmt::format("{:<14} {:<8} {:<28} {}\n", "view", "camera", "centre (world)", "files");
  for (const auto& v : d.views) {
    const glm::dvec3 c = v.cam_from_world.Centre();
    s += fmt::format("{:<14} {:<8} ({:8.4f},{:8.4f},{:8.4f})  {}{}{}{}\n", v.name, v.camera_id, c.x,
                     c.y, c.z, "color", v.depth.empty() ? "" : " depth",
                     v.mask.empty() ? "" : " mask", v.normal.empty() ? "" : " normal");
  }
  return s;
}

std::string VolumeInfoText(const std::filesystem::path& path) {
  std::string s;
  const core::Volume v = core::ReadVolume(path);
  const core::VolumeStats st = core::ComputeVolumeStats(v);
  const glm::dvec3 extent = v.Extent();
  s += fmt::format("volume    {}\n", std::filesystem::absolute(path).string());
  s += fmt::format("type      {}\n", core::ScalarTypeName(v.type));
  s += fmt::format("size      {} x {} x {} voxels ({} bytes)\n", v.dims.x, v.dims.y, v.dims.z,
                   v.bytes.size());
  s += fmt::format("spacing   {:.6g} x {:.6g} x {:.6g} (file units, e.g. mm)\n", v.spacing.x,
                   v.spacing.y, v.spacing.z);
  s += fmt::format("extent    {:.6g} x {:.6g} x {:.6g}\n", extent.x, extent.y, extent.z);
  s += fmt::format("range     {:.6g} .. {:.6g} ({} finite voxels, {} NaN/Inf)\n", st.min, st.max,
                   st.finite, st.non_finite);
  s += fmt::format("percentiles 1 / 50 / 99: {:.6g} / {:.6g} / {:.6g}\n", st.p1, st.p50, st.p99);
  const glm::dvec2 n = v.NormalizationRange();
  s += fmt::format("texture   stored values {:.6g} .. {:.6g} map to 0 .. 1\n", n.x, n.y);
  return s;
}

std::string PathInfoText(const std::filesystem::path& path) {
  if (!IsVolumePath(path)) return DatasetInfoText(path);
  if (!std::filesystem::is_directory(path)) return VolumeInfoText(path);
  // A folder without a manifest: a DICOM series, or a dataset missing its dataset.json.
  try {
    return VolumeInfoText(path);
  } catch (const core::InputError& e) {
    core::ThrowFileError("ibr info", path,
                         "no dataset.json (not a dataset) and not a DICOM series ({})", e.what());
  }
}

}  // namespace ibr
