#include "bench/deform_bench.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "capture/synthetic.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "render/gl/frame_timer.h"

namespace bench {

void DeformRunOptions::Check() const {
  deformation.Check();
  pass.Check();
  // The frame budget and the GL limits: render::CheckFrameSize (ibr deform).
  if (size < 16 || size > 16384)
    core::ThrowInputError("ibr deform", "--size {} outside 16..16384", size);
  if (sdf_resolution < 8 || sdf_resolution > 512) {
    core::ThrowInputError("ibr deform", "--resolution {} outside 8..512", sdf_resolution);
  }
  if (!std::isfinite(azimuth_deg) || !std::isfinite(elevation_deg) ||
      std::abs(elevation_deg) > 89) {
    core::ThrowInputError("ibr deform",
                          "--azimuth {} / --elevation {} not finite or |elevation| > 89",
                          azimuth_deg, elevation_deg);
  }
  if (region) {
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(region->lo[a]) || !std::isfinite(region->hi[a]) ||
          !(region->hi[a] > region->lo[a])) {
        core::ThrowInputError("ibr deform",
                              "--region must be x0,y0,z0,x1,y1,z1 with x0 < x1, y0 < y1, z0 < z1");
      }
    }
  }
  if (!std::isfinite(scale) || !(scale > 0))
    core::ThrowInputError("ibr deform", "placement scale {} must be > 0", scale);
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(rotation_deg[a]) || !std::isfinite(translation[a])) {
      core::ThrowInputError("ibr deform", "--placement values must be finite");
    }
  }
  if (out.extension() != ".png")
    core::ThrowInputError("ibr deform", "--out {} must be a .png file", out.string());
}

core::Placement DeformPlacement(const DeformRunOptions& options, const core::Box3d& mesh_bounds) {
  core::Box3d region = options.region ? *options.region : mesh_bounds.Grown(0.05);
  return core::Placement::FromRegion(region, options.rotation_deg, options.scale,
                                     options.translation);
}

namespace {

// Normalises into the unit cube centred at the origin (longest side 1).
void Normalise(core::TriangleMesh& mesh) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const float longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  if (!(longest > 0)) core::ThrowInputError("ibr deform", "the mesh has no extent");
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (glm::vec3& p : mesh.positions) p = (p - centre) / longest;
}

}  // namespace

DeformRunReport RunDeform(render::ProgramCache& programs, const DeformRunOptions& options) {
  options.Check();
  capture::SceneMesh scene = capture::LoadSceneMesh(options.mesh);
  core::TriangleMesh& mesh = scene.mesh;
  Normalise(mesh);
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const core::Placement placement = DeformPlacement(options, {glm::dvec3(lo), glm::dvec3(hi)});

  DeformRunReport report;
  report.max_displacement =
      core::MaxObjectDisplacement(options.deformation, placement, options.deformation_resolution);
  std::fprintf(stderr,
               "deform: %zu triangles, max displacement %.4f; building the distance field\n",
               mesh.triangle_count(), report.max_displacement);
  const auto start = std::chrono::steady_clock::now();
  core::MeshDistance distance(mesh, options.cap_holes, options.mesh.string());
  core::DistanceFieldOptions sdf_options;
  sdf_options.resolution = options.sdf_resolution;
  sdf_options.progress = true;
  // Grown by the largest displacement (samples land up to that far out) and
  // two voxels for the normals' central differences.
  const core::Box3d box = placement.ObjectBounds();
  const double voxel =
      std::max({box.size().x, box.size().y, box.size().z}) / (options.sdf_resolution - 1);
  const core::DistanceField sdf = core::BuildDistanceField(
      distance, box.Grown(report.max_displacement + 2 * voxel), sdf_options);
  report.sdf_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.sdf_size = sdf.size;
  const core::DeformationTexture texture =
      core::SampleDeformation(options.deformation, options.deformation_resolution);

  render::DeformPass pass(programs, {&mesh, &sdf, &texture, placement}, options.pass);
  const double az = glm::radians(options.azimuth_deg), el = glm::radians(options.elevation_deg);
  const float distance_to_centre = 2.6f;
  const glm::vec3 eye = distance_to_centre * glm::vec3(std::cos(el) * std::sin(az), std::sin(el),
                                                       std::cos(el) * std::cos(az));
  render::ViewSetup view;
  view.cam_from_world = core::CamFromWorldLookAt(eye, {0, 0, 0}, {0, 1, 0});
  const double focal =
      0.5 * options.size / std::tan(glm::radians(17.0));  // 34 degree field of view
  view.clip_from_cam = core::ClipFromCamPerspective(
      focal, focal, options.size / 2.0, options.size / 2.0, options.size, options.size, 0.05, 10.0);
  render::RenderTarget target(render::FrameTargetOptions(options.size, options.size));
  render::FrameTimerOptions timer;
  timer.warmup_frames = 1;
  timer.timed_frames = 3;
  report.frame_ms = render::TimeFrames(
                        [&] {
                          render::BeginFrame(target);
                          pass.Draw(target, view);
                        },
                        timer)
                        .median_ms;
  render::BeginFrame(target);
  pass.Draw(target, view);
  const render::Frame frame = render::ReadFrame(target);

  double samples = 0;
  int64_t rays = 0;
  for (int y = 0; y < options.size; ++y)
    for (int x = 0; x < options.size; ++x) {
      const uint32_t bits = frame.outcome.at(x, y);
      if (bits & render::kDeformMeshBit) ++report.mesh_pixels;
      if (bits & (1u << static_cast<int>(render::RayOutcome::kHit))) ++report.hit_pixels;
      if (bits & render::kDeformCutFaceBit) ++report.cut_face_pixels;
      if (bits & (1u << static_cast<int>(render::RayOutcome::kExited))) ++report.exited_pixels;
      if (bits & (1u << static_cast<int>(render::RayOutcome::kEarlyTermination)))
        ++report.early_pixels;
      const uint32_t n = bits >> render::kDeformSamplesShift;
      if (n > 0) {
        samples += n;
        ++rays;
      }
    }
  report.mean_samples = rays > 0 ? samples / static_cast<double>(rays) : 0.0;

  std::filesystem::path depth_path = options.out;
  depth_path.replace_extension(".depth.exr");
  core::WriteImage(depth_path, frame.depth);
  core::WriteImage(options.out, frame.color);
  return report;
}

}  // namespace bench
