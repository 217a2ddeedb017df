#include "ibr/volume_render.h"

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
#include "render/gl/frame_timer.h"
#include "render/passes/pass.h"

namespace ibr {

render::ViewSetup VolumeOrbitView(double azimuth_deg, double elevation_deg, double distance,
                                  int size, double radius) {
  OrbitCamera orbit{.elevation_deg = elevation_deg,
                    .azimuth_deg = azimuth_deg,
                    .distance = distance,
                    .fov_deg = glm::degrees(2 * std::atan(1 / 2.4))};  // focal 1.2 size
  return OrbitCameraView(glm::vec3(0), static_cast<float>(radius), orbit, size);
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
  const VolumeObjectData scene =
      MakeVolumeObject(std::move(volume), transfer, r.object.deformations, r.object.map_size);
  render::VolumePassOptions pass_options = r.object.pass;
  if (r.object.iso_value) {
    SetIsoValue(scene, *r.object.iso_value, pass_options, "ibr volume --mode");
  }
  // The frame budget and the GL limits: render::CheckFrameSize (ibr volume).
  if (r.size < 16 || r.size > 16384)
    core::ThrowInputError("ibr volume", "--size {} not in [16, 16384]", r.size);
  struct Shot {
    std::string name;
    render::ViewSetup view;
    int width, height;
  };
  // The orbit frames the proxy box, not the volume's: material the maps move
  // out of the volume's box (core::VolumeMapBox) stays in the picture.
  const glm::dmat4 world_from_proxy = WorldFromProxy(scene);
  const glm::vec3 centre(world_from_proxy * glm::dvec4(0.5, 0.5, 0.5, 1.0));
  const double radius = 0.5 * glm::length(glm::dvec3(world_from_proxy * glm::dvec4(1, 1, 1, 0)));
  std::vector<Shot> shots;
  if (r.cameras.empty()) {
    shots.push_back(
        {"", OrbitCameraView(centre, static_cast<float>(radius), r.orbit, r.size), r.size, r.size});
  } else {
    const capture::Dataset dataset = capture::ReadDataset(r.cameras);
    for (const auto& v : dataset.views) {
      const capture::Camera& cam = dataset.cameras.at(v.camera_id);
      const double d = glm::length(v.cam_from_world.Centre());
      const double near = std::max(d - 2 * radius, 1e-3 * radius), far = d + 2 * radius;
      render::ViewSetup view;
      view.cam_from_world = v.cam_from_world.ToMat4();
      view.orthographic = cam.orthographic();
      view.clip_from_cam =
          cam.orthographic() ? core::ClipFromCamOrthographic(cam.fx(), cam.fy(), cam.cx(), cam.cy(),
                                                             cam.width, cam.height, 0, far)
                             : core::ClipFromCamPerspective(cam.fx(), cam.fy(), cam.cx(), cam.cy(),
                                                            cam.width, cam.height, near, far);
      shots.push_back({v.name, view, cam.width, cam.height});
    }
    for (const Shot& shot : shots) {
      render::CheckFrameSize(
          "ibr volume", fmt::format("--cameras '{}': view '{}'", r.cameras.string(), shot.name),
          shot.width, shot.height);
    }
    if (shots.empty()) core::ThrowFileError("ibr volume", r.cameras, "the dataset has no views");
  }
  const bool to_dir = !r.cameras.empty() || r.out.extension() != ".png";
  if (!to_dir && r.out.has_parent_path() && !std::filesystem::is_directory(r.out.parent_path())) {
    core::ThrowFileError("ibr volume", r.out, "no such directory");
  }
  render::ProgramCache programs;
  render::VolumePass pass(programs, scene.volume, scene.transfer, scene.maps,
                          scene.world_from_volume, pass_options);
  VolumeRenderResult result;
  result.proxy_lo = pass.proxy_box().lo;
  result.proxy_hi = pass.proxy_box().hi;
  std::optional<core::StagedDirectory> staged;
  if (to_dir) staged.emplace(r.out);
  const glm::vec3 background(0.08f, 0.08f, 0.1f);
  for (size_t i = 0; i < shots.size(); ++i) {
    const Shot& shot = shots[i];
    render::RenderTarget target(render::FrameTargetOptions(shot.width, shot.height));
    auto frame = [&] {
      render::BeginFrame(target);
      pass.Draw(target, shot.view);
    };
    if (i == 0) {
      result.median_ms = render::TimeFrames(frame, {1, 3}).median_ms;
      result.slices = pass.last_stats().slices;
    }
    frame();
    const core::Image8 image = core::OverBackground(render::ReadFrame(target).color, background);
    if (to_dir) {
      core::WriteImage(
          staged->path() / ((shot.name.empty() ? std::string("volume") : shot.name) + ".png"),
          image);
    } else {
      core::WriteImage(r.out, image);
    }
    ++result.images;
    spdlog::info("ibr volume: view {}/{}", i + 1, shots.size());
  }
  if (staged) staged->Commit();
  return result;
}

}  // namespace ibr
