#include "bench/deform_bench.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/projection.h"
#include "ibr/dataset_maps.h"
#include "ibr/views.h"
#include "render/gl/frame_timer.h"

namespace bench {

void DeformRunOptions::Check() const {
  deformation.Check();
  pass.Check();
  if (size < 16 || size > 4096)
    core::ThrowInputError("ibr deform", "--size {} outside 16..4096", size);
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
  if (out.empty()) core::ThrowInputError("ibr deform", "--out FILE.png|DIR is required");
  if (!cameras.empty() && !WritesDataset()) {
    core::ThrowInputError("ibr deform",
                          "--cameras {} renders several views: --out must be a folder",
                          cameras.string());
  }
}

void DeformOutcomes::Add(const DeformOutcomes& o) {
  const double samples = mean_samples * rays + o.mean_samples * o.rays;
  mesh_pixels += o.mesh_pixels;
  hit_pixels += o.hit_pixels;
  cut_face_pixels += o.cut_face_pixels;
  exited_pixels += o.exited_pixels;
  early_pixels += o.early_pixels;
  rays += o.rays;
  mean_samples = rays > 0 ? samples / static_cast<double>(rays) : 0.0;
}

DeformOutcomes CountDeformOutcomes(const render::Frame& frame) {
  DeformOutcomes r;
  double samples = 0;
  auto has = [](uint32_t bits, render::RayOutcome o) {
    return (bits & (1u << static_cast<int>(o))) != 0;
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
    }
  }
  r.mean_samples = r.rays > 0 ? samples / static_cast<double>(r.rays) : 0.0;
  return r;
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
  // Every input is read and checked before anything is built or written.
  std::optional<capture::Dataset> cameras;
  if (!options.cameras.empty()) cameras = capture::ReadDataset(options.cameras);
  capture::SceneMesh scene = capture::LoadSceneMesh(options.mesh);
  core::TriangleMesh& mesh = scene.mesh;
  // world (the mesh file's frame) = centre + longest * normalised.
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const glm::dvec3 centre = 0.5 * (glm::dvec3(lo) + glm::dvec3(hi));
  const double longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  Normalise(mesh);
  const glm::dmat4 world_from_norm =
      glm::scale(glm::translate(glm::dmat4(1.0), centre), glm::dvec3(longest));
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
  report.distance_queries = sdf.distance_queries;
  const core::DeformationTexture texture =
      core::SampleDeformation(options.deformation, options.deformation_resolution);
  render::DeformPass pass(programs, {&mesh, &sdf, &texture, placement}, options.pass);

  // The views, in world units (rigid cam_from_world): the dataset's, or one
  // orbit view (azimuth about +y, 34 degree field of view, 2.6 longest sides
  // from the centre).
  std::vector<ibr::NamedView> views;
  if (cameras) {
    const std::vector<ibr::ViewCamera> cams = ibr::ViewsFromDataset(*cameras);
    for (size_t i = 0; i < cams.size(); ++i) views.push_back({cameras->views[i].name, cams[i]});
  } else {
    const double az = glm::radians(options.azimuth_deg), el = glm::radians(options.elevation_deg);
    const glm::dvec3 eye_norm =
        2.6 * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    const double focal = 0.5 * options.size / std::tan(glm::radians(17.0));
    ibr::ViewCamera view;
    view.camera = ibr::MapCamera::Pinhole(options.size, options.size, focal, focal,
                                          options.size / 2.0, options.size / 2.0);
    view.cam_from_world = glm::dmat4(core::CamFromWorldLookAt(
        glm::vec3(centre + longest * eye_norm), glm::vec3(centre), {0, 1, 0}));
    views.push_back({"deform", view});
  }
  // Clip range: the mesh and the deformation box (grown by the displacement), in world units.
  const core::Box3d norm_bounds{glm::min(glm::dvec3(lo), box.lo) - report.max_displacement,
                                glm::max(glm::dvec3(hi), box.hi) + report.max_displacement};
  capture::Bounds world_bounds;
  world_bounds.min = glm::dvec3(world_from_norm * glm::dvec4(norm_bounds.lo, 1.0));
  world_bounds.max = glm::dvec3(world_from_norm * glm::dvec4(norm_bounds.hi, 1.0));

  std::optional<capture::DatasetWriter> writer;
  if (options.WritesDataset()) writer.emplace(options.out);
  render::Frame first;
  for (size_t v = 0; v < views.size(); ++v) {
    const ibr::ViewCamera& camera = views[v].view;
    render::ViewSetup view = ibr::ViewSetupFor(camera, world_bounds);
    // The pass works in normalised units: cam_from_norm is a similarity, so
    // camera z (and the depth written) stays in world units.
    view.cam_from_world = glm::mat4(camera.cam_from_world * world_from_norm);
    render::RenderTarget target(
        render::FrameTargetOptions(camera.camera.width, camera.camera.height));
    if (v == 0) {
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
    }
    render::BeginFrame(target);
    pass.Draw(target, view);
    render::Frame frame = render::ReadFrame(target);
    report.views.push_back({views[v].name, CountDeformOutcomes(frame)});
    report.total.Add(report.views.back().outcomes);
    std::fprintf(stderr, "deform: view %zu/%zu %s rendered\n", v + 1, views.size(),
                 views[v].name.c_str());
    if (writer) {
      core::Image8 mask(frame.color.width(), frame.color.height(), 1, 0);
      for (int y = 0; y < mask.height(); ++y)
        for (int x = 0; x < mask.width(); ++x) mask.at(x, y) = frame.Covered(x, y) ? 255 : 0;
      const int cam = writer->AddCamera(ibr::CaptureCamera(camera.camera));
      writer->AddView(views[v].name, cam, ibr::RigidFromMat4(camera.cam_from_world), frame.color,
                      frame.depth, mask, frame.normal);
    } else {
      first = std::move(frame);
    }
  }
  if (writer) {
    writer->SetBounds(world_bounds);
    writer->Commit();
  } else {
    std::filesystem::path depth_path = options.out;
    depth_path.replace_extension(".depth.exr");
    core::WriteImage(depth_path, first.depth);
    core::WriteImage(options.out, first.color);
  }
  return report;
}

}  // namespace bench
