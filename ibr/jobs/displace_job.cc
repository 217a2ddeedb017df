#include "ibr/jobs/displace_job.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <exception>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/image_io.h"
#include "ibr/kinds/displaced_mesh_kind.h"
#include "ibr/scene_renderer.h"
#include "render/cores/ray_core.h"

namespace ibr {
namespace fs = std::filesystem;

DisplacedDraw DrawDisplaced(render::ProgramCache& programs, const DisplacedMeshData& data,
                            const DisplacedMeshOptions& options, const ViewCamera& view,
                            const std::optional<render::FrameTimerOptions>& timer,
                            const std::function<void(const std::string&)>& say) {
  // The one-object scene of a scene file's displaced mesh.
  const LoadedScene scene = OneObjectScene(LoadedDisplacedMesh("displaced mesh", data, options));
  SceneRenderer renderer(programs, scene);
  const DisplacedMeshRenderer& method = DisplacedRendererOf(renderer.object_pass(0));
  if (const render::GroundTruthPlan* plan = method.truth_plan(); plan && say) {
    say(fmt::format("displace: tessellated truth: {}", plan->Describe()));
  }
  DisplacedDraw d;
  if (timer) d.timing = render::TimeFrames([&] { renderer.Draw(view); }, *timer);
  d.frame = timer ? renderer.ReadLast() : renderer.Render(view);  // a timed frame is not redrawn
  d.detail = method.Detail();
  if (const int64_t early =
          d.frame.CountOutcome(render::OutcomeBit(render::RayOutcome::kEarlyTermination))) {
    d.detail += fmt::format(", {} early-terminated pixels", early);
  }
  return d;
}

core::DisplacementError DisplacedError(const render::Frame& method, const render::Frame& truth,
                                       const DisplacedMeshData& data, float tiling) {
  core::DisplacementErrorOptions o;
  o.depth_unit = core::HeightTexelWorldSize(data.base, data.height.width(), tiling);
  return core::CompareToGroundTruth(method.color, method.depth, truth.color, truth.depth, o);
}

std::array<uint8_t, 3> ParseBackgroundRgb(const std::string& text, std::string_view where) {
  std::array<uint8_t, 3> rgb{};
  size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? comma : comma - start);
    const bool last = k == 2;
    int value = -1;
    size_t used = 0;
    try {
      value = std::stoi(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || value < 0 || value > 255 ||
        (comma == std::string::npos) != last) {
      core::ThrowInputError(where, "--background '{}' is not R,G,B with each in 0..255", text);
    }
    rgb[k] = static_cast<uint8_t>(value);
    start = comma + 1;
  }
  return rgb;
}

void CompositeOver(core::Image8& color, const std::array<uint8_t, 3>& background) {
  for (size_t p = 0; p < color.pixel_count(); ++p) {
    uint8_t* px = color.data() + p * color.channels();
    const int a = px[3];
    for (int k = 0; k < 3; ++k)
      px[k] = static_cast<uint8_t>((px[k] * a + background[k] * (255 - a) + 127) / 255);
    px[3] = 255;
  }
}

namespace {
constexpr const char* kWhere = "ibr displace";
}  // namespace

void DisplaceJob::Check() const {
  if (texels < 4 || texels > 4096)
    core::ThrowInputError(kWhere, "--texels {} outside 4..4096", texels);
  if (out.extension() != ".png")
    core::ThrowInputError(kWhere, "--out '{}' must end in .png", out.string());
  if (out.has_parent_path() && !fs::is_directory(out.parent_path())) {
    core::ThrowInputError(kWhere, "--out '{}': no such directory", out.string());
  }
  // The camera-z image beside it, refused before any work as --out is.
  fs::path depth_path = out;
  core::CheckReplaceableFile("--out", depth_path.replace_extension(".depth.exr"));
  if (frames < 0 || frames > 1000)
    core::ThrowInputError(kWhere, "--frames {} outside 0..1000", frames);
  if (!background.empty()) ParseBackgroundRgb(background, kWhere);
  PassOptions().Check();
  Orbit().Check();
}

DisplacedMeshOptions DisplaceJob::PassOptions() const {
  DisplacedMeshOptions o;
  o.method = DisplacementMethodFromName(method);
  o.max_displacement = max_displacement;
  o.tiling = tiling;
  o.texture_tiling = texture_tiling;
  o.shade = !unlit;
  o.slices = slices;
  return o;
}

OrbitCamera DisplaceJob::Orbit() const {
  return {.elevation_deg = elevation,
          .azimuth_deg = azimuth,
          .distance = distance,
          .fov_deg = fov,
          .up = UpAxisFromName(up, "ibr displace --up")};
}

void RunDisplaceJob(render::ProgramCache& programs, const DisplaceJob& job,
                    const std::function<void(const std::string&)>& say) {
  job.Check();
  const DisplacedMeshOptions options = job.PassOptions();
  render::CheckFrameSize(kWhere, "--size", job.size, job.size, /*min_side=*/16);

  // Parse -> plain CPU data -> GPU -> passes.
  DisplacedMeshData data;
  data.base = job.mesh.empty() ? DisplacementBaseMesh(job.base) : ReadDisplacementBase(job.mesh);
  data.height = job.height_map.empty()
                    ? DisplacementHeightMap(core::HeightPatternFromName(job.height), job.texels)
                    : ReadHeightMap(job.height_map);
  if (!job.texture.empty()) data.color = core::ReadImage<uint8_t>(job.texture);
  const std::string base = job.mesh.empty() ? job.base : job.mesh.filename().string();
  {
    // A displacement of the order of the mesh itself turns the surface inside
    // out into spikes: said with the numbers, in the mesh's units.
    glm::vec3 lo, hi;
    data.base.Bounds(lo, hi);
    const double diagonal = glm::length(glm::dvec3(hi - lo));
    if (diagonal > 0 && job.max_displacement > 0.25 * diagonal) {
      spdlog::warn(
          "{}: --max-displacement {} is {:.0f} % of the mesh's diagonal ({:.3g} units, '{}'): the "
          "surface will fold over itself; a displacement map's relief is usually a few percent "
          "of the mesh (the default 0.15 is for the built-in unit-sized bases)",
          kWhere, job.max_displacement, 100.0 * job.max_displacement / diagonal, diagonal, base);
    }
  }
  const std::string height =
      job.height_map.empty() ? job.height : job.height_map.filename().string();

  const ViewCamera view =
      DisplacementOrbitCamera(data.base, job.max_displacement, job.Orbit(), job.size);
  std::optional<render::FrameTimerOptions> timer;
  if (job.frames > 0) timer = render::FrameTimerOptions{.timed_frames = job.frames};
  const DisplacedDraw result = DrawDisplaced(programs, data, options, view, timer, say);
  const auto timing = [&](const DisplacedDraw& d, bool samples) {
    if (!timer) return std::string("untimed");
    return samples
               ? fmt::format("{:.2f} ms/frame (median of {})", d.timing.median_ms, d.timing.samples)
               : fmt::format("{:.2f} ms/frame", d.timing.median_ms);
  };
  say(fmt::format("displace: {} on {} ({}), {}x{} px, {}, {}", job.method, base, height, job.size,
                  job.size, timing(result, true), result.detail));
  // An empty frame is a camera that misses the mesh, never a result.
  const auto refuse_empty = [&](const render::Frame& frame, const std::string& what) {
    if (frame.CoveredPixels() > 0) return;
    core::ThrowInputError(kWhere,
                          "{} covers no pixel: the camera misses the mesh (check --distance, "
                          "--fov, --up, --elevation)",
                          what);
  };
  refuse_empty(result.frame, "the " + job.method + " image");
  if (job.compare && options.method != DisplacementMethod::kTessellated) {
    DisplacedMeshOptions truth_options = options;
    truth_options.method = DisplacementMethod::kTessellated;
    const DisplacedDraw truth = DrawDisplaced(programs, data, truth_options, view, timer, say);
    refuse_empty(truth.frame, "the tessellated truth");
    const core::DisplacementError e = DisplacedError(result.frame, truth.frame, data, job.tiling);
    const std::string depth =
        e.both_pixels > 0 ? fmt::format("depth error mean {:.3f} / p95 {:.3f} / max {:.3f} texels",
                                        e.mean_depth_error, e.p95_depth_error, e.max_depth_error)
                          : std::string("no pixel covered by both, so no depth error");
    say(fmt::format("displace: vs tessellated ({}): coverage IoU {:.4f}, {}, {} see-through pixels",
                    timing(truth, false), e.coverage_iou, depth, e.see_through_pixels));
  }
  fs::path depth_path = job.out;
  depth_path.replace_extension(".depth.exr");
  core::Image8 color = result.frame.color;
  if (!job.background.empty()) CompositeOver(color, ParseBackgroundRgb(job.background, kWhere));
  core::WriteImage(depth_path, result.frame.depth);
  core::WriteImage(job.out, color);
  say(fmt::format("displace: wrote {} and {}", job.out.string(), depth_path.string()));
}

}  // namespace ibr
