#include "ibr/jobs/deform_job.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_io.h"
#include "ibr/dataset_maps.h"
#include "ibr/kinds/deform_kind.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "render/gl/frame_timer.h"

namespace ibr {

void DeformRenderOptions::Check() const {
  object.deformation.Check();
  object.pass.Check();
  // The frame budget and the GL limits: render::CheckFrameSize (ibr deform).
  if (size < 16 || size > 16384)
    core::ThrowInputError("ibr deform", "--size {} outside 16..16384", size);
  if (!std::isfinite(azimuth_deg) || !std::isfinite(elevation_deg) ||
      std::abs(elevation_deg) > 89) {
    core::ThrowInputError("ibr deform",
                          "--azimuth {} / --elevation {} not finite or |elevation| > 89",
                          azimuth_deg, elevation_deg);
  }
  if (out.empty()) core::ThrowInputError("ibr deform", "--out FILE.png|DIR is required");
  if (!cameras.empty() && !WritesDataset()) {
    core::ThrowInputError("ibr deform",
                          "--cameras {} renders several views: --out must be a folder",
                          cameras.string());
  }
  // The camera-z image beside FILE.png, refused before any work as --out is.
  if (!WritesDataset()) {
    std::filesystem::path depth_path = out;
    core::CheckReplaceableFile("--out", depth_path.replace_extension(".depth.exr"));
  }
}

void DeformOutcomes::Add(const DeformOutcomes& o) {
  const double samples = mean_samples * rays + o.mean_samples * o.rays;
  const double rejected = mean_rejected * rays + o.mean_rejected * o.rays;
  rejecting_rays += o.rejecting_rays;
  mesh_pixels += o.mesh_pixels;
  hit_pixels += o.hit_pixels;
  cut_face_pixels += o.cut_face_pixels;
  exited_pixels += o.exited_pixels;
  early_pixels += o.early_pixels;
  rays += o.rays;
  mean_samples = rays > 0 ? samples / static_cast<double>(rays) : 0.0;
  mean_rejected = rays > 0 ? rejected / static_cast<double>(rays) : 0.0;
}

DeformOutcomes CountDeformOutcomes(const render::Frame& frame) {
  DeformOutcomes r;
  double samples = 0, rejected = 0;
  auto has = [](uint32_t bits, render::RayOutcome o) {
    return (bits & render::OutcomeBit(o)) != 0;
  };
  for (const uint32_t bits : frame.outcome.values()) {
    r.mesh_pixels += (bits & render::kDeformMeshBit) != 0;
    r.hit_pixels += has(bits, render::RayOutcome::kHit);
    r.cut_face_pixels += (bits & render::kDeformCutFaceBit) != 0;
    r.exited_pixels += has(bits, render::RayOutcome::kExited);
    r.early_pixels += has(bits, render::RayOutcome::kEarlyTermination);
    const uint32_t n = bits >> render::kDeformSamplesShift;
    if (n > 0) {
      samples += n;
      ++r.rays;
      const uint32_t k = (bits >> render::kDeformRejectedShift) & render::kDeformRejectedMax;
      rejected += k;
      r.rejecting_rays += k > 0;
    }
  }
  r.mean_samples = r.rays > 0 ? samples / static_cast<double>(r.rays) : 0.0;
  r.mean_rejected = r.rays > 0 ? rejected / static_cast<double>(r.rays) : 0.0;
  return r;
}

OrbitCamera DeformOrbit(double azimuth_deg, double elevation_deg, double distance) {
  return {.elevation_deg = elevation_deg,
          .azimuth_deg = azimuth_deg,
          .distance = distance,
          .fov_deg = 34.0,
          .up = {0, 1, 0}};
}

DeformRenderReport RenderDeform(render::ProgramCache& programs,
                                const DeformRenderOptions& options) {
  // Every input is read and checked before anything is built or written; the
  // frame sizes first (the budget's message before the range of Check()).
  render::CheckFrameSize("ibr deform", "--size", options.size, options.size);
  options.Check();
  // The views, in world units (rigid cam_from_world): the dataset's, or (once
  // the mesh is known) one orbit view.
  std::vector<NamedView> views;
  if (!options.cameras.empty()) {
    views = NamedViewsFromDataset(capture::ReadCameras(options.cameras));
    for (const NamedView& v : views) {
      render::CheckFrameSize(
          "ibr deform", fmt::format("--cameras '{}': view '{}'", options.cameras.string(), v.name),
          v.view.camera.width, v.view.camera.height);
    }
  }
  // The one path from options to the pass's inputs (ibr/deform_object.h),
  // shared with deform objects in scene files; world = the mesh file's frame.
  LoadedScene scene = OneObjectScene(
      LoadedDeformObject("deform",
                         MakeDeformObject(capture::LoadSceneMesh(options.mesh).mesh, options.object,
                                          options.mesh.string(), /*progress=*/true, &programs),
                         options.object));
  const DeformObjectData& object = *DeformOf(scene.objects.front()).data;
  DeformRenderReport report;
  report.max_displacement = object.max_displacement;
  report.sdf_seconds = object.sdf_seconds;
  report.sdf_size = object.sdf.size;
  report.cube_size = object.depth_cube.faces.empty() ? 0 : object.depth_cube.faces[0].depth.width();
  report.implicit_bytes = object.ImplicitBytes();
  report.distance_queries = object.sdf.distance_queries;
  if (views.empty()) {
    // The normalised mesh (longest side 1) carried to the file's frame.
    const glm::dmat4& world_from_norm = scene.objects.front().world_from_object;
    const double longest = world_from_norm[0][0];
    views.push_back({"deform", OrbitCameraView(glm::dvec3(world_from_norm[3]), longest,
                                               DeformOrbit(options.azimuth_deg,
                                                           options.elevation_deg, 2.6 * longest),
                                               options.size)});
  }
  SceneRenderer renderer(programs, scene);
  render::FrameTimerOptions timer;
  timer.warmup_frames = 1;
  timer.timed_frames = 3;
  report.frame_ms = render::TimeFrames([&] { renderer.Draw(views.front().view); }, timer).median_ms;
  const auto count = [&](const NamedView& v, const render::Frame& frame) {
    report.views.push_back({v.name, CountDeformOutcomes(frame)});
    report.total.Add(report.views.back().outcomes);
    return std::string();
  };
  if (options.WritesDataset()) {
    RenderViewsToDataset(
        renderer, views, options.out, {.bounds = scene.bounds, .normals = true},
        [](const std::string& line) { std::fprintf(stderr, "deform: %s\n", line.c_str()); }, count);
  } else {
    const render::Frame frame = renderer.ReadLast();  // the last timed frame, view 0's
    count(views.front(), frame);
    std::filesystem::path depth_path = options.out;
    depth_path.replace_extension(".depth.exr");
    core::WriteImage(depth_path, frame.depth);
    core::WriteImage(options.out, frame.color);
  }
  return report;
}

std::string DeformReportText(const DeformRenderReport& r, const std::string& out) {
  std::string text;
  if (r.cube_size > 0) {
    text += fmt::format("deform: implicit depth-cube 6 x {}x{} R32F, {} bytes, built in {:.2f} s\n",
                        r.cube_size, r.cube_size, r.implicit_bytes, r.sdf_seconds);
  } else {
    text += fmt::format(
        "deform: implicit sdf {}x{}x{} R32F, {} bytes, built in {:.2f} s ({} exact distance "
        "queries)\n",
        r.sdf_size.x, r.sdf_size.y, r.sdf_size.z, r.implicit_bytes, r.sdf_seconds,
        r.distance_queries);
  }
  text += fmt::format("deform: max displacement {:.4f}\n", r.max_displacement);
  auto outcomes = [&](const std::string& what, const DeformOutcomes& c) {
    text += fmt::format(
        "deform: {}: pixels mesh {} ray-hit {} cut-face {} exited {} early-termination {}; {} "
        "rays, {:.1f} samples per ray\n",
        what, c.mesh_pixels, c.hit_pixels, c.cut_face_pixels, c.exited_pixels, c.early_pixels,
        c.rays, c.mean_samples);
  };
  for (const DeformViewReport& v : r.views) outcomes("view " + v.name, v.outcomes);
  if (r.views.size() > 1) outcomes(fmt::format("all {} views", r.views.size()), r.total);
  text += fmt::format("deform: {:.1f} ms per frame (first view); wrote {}\n", r.frame_ms, out);
  return text;
}

}  // namespace ibr
