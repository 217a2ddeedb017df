#include "ibr/jobs/volume_job.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <glm/gtc/matrix_transform.hpp>
#include <utility>

#include "capture/dataset.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_compose.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "core/volume_io.h"
#include "ibr/dataset_maps.h"
#include "ibr/kinds/volume_kind.h"
#include "ibr/scene_renderer.h"
#include "render/gl/frame_timer.h"
#include "render/passes/pass.h"

namespace ibr {

render::ViewSetup VolumeOrbitView(double azimuth_deg, double elevation_deg, double distance,
                                  int size, double radius) {
  OrbitCamera orbit{.elevation_deg = elevation_deg,
                    .azimuth_deg = azimuth_deg,
                    .distance = distance,
                    .fov_deg = glm::degrees(2 * std::atan(1 / 2.4))};  // focal 1.2 size
  return OrbitViewSetup(glm::dvec3(0.0), radius, orbit, size);
}

std::string VolumeReportText(const VolumeRenderRequest& r, const VolumeRenderResult& v) {
  std::vector<std::string> names;
  for (const core::Deformation& d : r.object.deformations)
    names.push_back(core::DeformationKindName(d.kind));
  return fmt::format(
      "volume: {} deformation {} mode {} -> {} image(s) in {}; {:.1f} ms/frame (median), {} "
      "slices, proxy box [{:.2f} {:.2f} {:.2f}]-[{:.2f} {:.2f} {:.2f}]",
      r.volume.string(), names.empty() ? "none" : fmt::format("{}", fmt::join(names, ",")),
      r.object.pass.mode == render::VolumeMode::kIso ? "iso" : "dvr", v.images, r.out.string(),
      v.median_ms, v.slices, v.proxy_lo.x, v.proxy_lo.y, v.proxy_lo.z, v.proxy_hi.x, v.proxy_hi.y,
      v.proxy_hi.z);
}

core::ImageF DrawVolumeFloat(render::VolumePass& pass, const render::ViewSetup& view, int size) {
  render::RenderTargetOptions options = render::FrameTargetOptions(size, size);
  options.color_formats[render::kFrameColor] = GL_RGBA32F;
  render::RenderTarget target(options);
  render::BeginFrame(target);
  pass.Draw(target, view);
  return target.ReadColorF(render::kFrameColor);
}

VolumeRenderResult RenderVolume(const VolumeRenderRequest& r) {
  core::Volume volume = core::ReadVolume(r.volume);
  try {
    render::CheckVolumeFits(volume.dims, {}, render::Max3dTextureSize());
  } catch (const core::InputError& e) {
    core::ThrowFileError("ibr volume", r.volume, "{}", e.what());
  }
  const core::TransferFunction transfer =
      r.window_level
          ? WindowLevelTransfer(r.window_level->x, r.window_level->y,
                                core::ComputeVolumeStats(volume), "ibr volume --window/--level")
          : TransferForVolume(r.transfer, r.volume, &volume);
  r.object.Check();
  LoadedVolume loaded{
      MakeVolumeObject(std::move(volume), transfer, r.object.deformations, r.object.map_size),
      r.object};
  if (r.object.iso_value) {
    SetIsoValue(loaded.data, *r.object.iso_value, loaded.options.pass, "ibr volume --mode");
  }
  // The frame budget and the GL limits: render::CheckFrameSize (ibr volume).
  if (r.size < 16 || r.size > 16384)
    core::ThrowInputError("ibr volume", "--size {} not in [16, 16384]", r.size);
  // The one-object scene of a scene file's volume object.
  LoadedScene scene = OneObjectScene(LoadedVolumeObject("volume", std::move(loaded)));
  std::vector<NamedView>& views = scene.views;
  if (r.cameras.empty()) {
    // The orbit frames the proxy box, not the volume's: material the maps
    // move out of the volume's box (core::VolumeMapBox) stays in the picture.
    const glm::dmat4 world_from_proxy = WorldFromProxy(*VolumeOf(scene.objects.front()).data);
    const glm::dvec3 centre(world_from_proxy * glm::dvec4(0.5, 0.5, 0.5, 1.0));
    const double radius = 0.5 * glm::length(glm::dvec3(world_from_proxy * glm::dvec4(1, 1, 1, 0)));
    views.push_back({"volume", OrbitCameraView(centre, radius, r.orbit, r.size)});
  } else {
    views = NamedViewsFromDataset(capture::ReadCameras(r.cameras));
    if (views.empty()) core::ThrowFileError("ibr volume", r.cameras, "the dataset has no views");
    for (const NamedView& v : views) {
      render::CheckFrameSize("ibr volume",
                             fmt::format("--cameras '{}': view '{}'", r.cameras.string(), v.name),
                             v.view.camera.width, v.view.camera.height);
    }
  }
  const bool to_dir = !r.cameras.empty() || r.out.extension() != ".png";
  if (!to_dir && r.out.has_parent_path() && !std::filesystem::is_directory(r.out.parent_path())) {
    core::ThrowFileError("ibr volume", r.out, "no such directory");
  }
  render::ProgramCache programs;
  SceneRenderer renderer(programs, scene);
  const render::VolumePass& pass = VolumePassOf(renderer.object_pass(0));
  VolumeRenderResult result;
  result.proxy_lo = pass.proxy_box().lo;
  result.proxy_hi = pass.proxy_box().hi;
  std::optional<core::StagedDirectory> staged;
  if (to_dir) staged.emplace(r.out);
  const glm::vec3 background(0.08f, 0.08f, 0.1f);
  for (size_t i = 0; i < views.size(); ++i) {
    const NamedView& v = views[i];
    if (i == 0) {
      result.median_ms = render::TimeFrames([&] { renderer.Draw(v.view); }, {1, 3}).median_ms;
      result.slices = pass.last_stats().slices;
    }
    // View 0's last timed frame is read, not drawn again.
    const render::Frame frame = i == 0 ? renderer.ReadLast() : renderer.Render(v.view);
    const core::Image8 image = core::OverBackground(frame.color, background);
    core::WriteImage(to_dir ? staged->path() / (v.name + ".png") : r.out, image);
    ++result.images;
    spdlog::info("ibr volume: view {}/{}", i + 1, views.size());
  }
  if (staged) staged->Commit();
  return result;
}

}  // namespace ibr
