// `ibr displace`: one displacement-mapped base mesh (torus, plane, sphere, or
// the user's --mesh with --height-map and --texture) rendered by one method
// (ibr/displaced_mesh.h, the one method table) into a PNG (colour) and an EXR
// beside it (camera z). `tessellated` is the ground truth every other method
// is compared with (--compare); it is planned within the memory budget
// before anything is allocated (fewer subdivisions, said, or one error line).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "apps/ibr/commands.h"
#include "core/displacement_error.h"
#include "core/error.h"
#include "core/heightfield.h"
#include "core/image_io.h"
#include "core/timing.h"
#include "ibr/displaced_mesh.h"
#include "render/gl/context.h"
#include "render/gl/frame_timer.h"
#include "render/passes/pass.h"
#include "render/passes/relief_surface_pass.h"

namespace apps {
namespace {
namespace fs = std::filesystem;

std::string MethodNames() {
  std::string names;
  for (const std::string& n : ibr::DisplacementMethodNames())
    names += (names.empty() ? "" : "|") + n;
  return names;
}

struct DisplaceOptions {
  std::string method = "slices-orthogonal";
  std::string base = "torus";
  std::string height = "bumps";
  fs::path mesh;        // the user's OBJ/PLY with uvs (instead of --base)
  fs::path height_map;  // the user's 8/16-bit PNG or EXR height map (instead of --height)
  fs::path texture;     // optional colour texture
  float max_displacement = 0.15f;  // scene units (the torus tube radius is 0.4)
  float tiling = 2.0f;             // the height map's repeats across uv [0, 1]
  float texture_tiling = 1.0f;     // the colour texture's: 1 = where the mesh's uvs put it
  int texels = 256;                // generated height map size
  int slices = 64;                 // per volume
  int size = 512;                  // pixels
  double elevation = 35;           // degrees above the plane perpendicular to --up
  double azimuth = -60;            // degrees around --up
  double distance = 0;  // camera distance from the bounds' centre, scene units (0 = framed)
  double fov = 40;      // field of view, degrees
  std::string up = "z";
  std::string background;  // "R,G,B" (0-255): composite onto an opaque colour
  int frames = 7;          // timed frames (median); 0 = draw once, untimed
  bool unlit = false;      // the colour texture's plain colour, not lit
  fs::path out = "displace.png";
  bool compare = false;  // also render `tessellated` and print the error
};

// "R,G,B", each an integer 0..255.
std::array<uint8_t, 3> ParseBackground(const std::string& text) {
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
      core::ThrowInputError("ibr displace", "--background '{}' is not R,G,B with each in 0..255",
                            text);
    }
    rgb[k] = static_cast<uint8_t>(value);
    start = comma + 1;
  }
  return rgb;
}

// Straight alpha over an opaque colour: alpha 255 everywhere after.
void Composite(core::Image8& color, const std::array<uint8_t, 3>& background) {
  for (size_t p = 0; p < color.pixel_count(); ++p) {
    uint8_t* px = color.data() + p * color.channels();
    const int a = px[3];
    for (int k = 0; k < 3; ++k)
      px[k] = static_cast<uint8_t>((px[k] * a + background[k] * (255 - a) + 127) / 255);
    px[3] = 255;
  }
}

// One method drawn and timed; the frame read back.
struct Drawn {
  render::Frame frame;
  core::TimingStats timing;
  std::string detail;
};
Drawn Draw(render::ProgramCache& programs, const ibr::DisplacedMeshData& data,
           const ibr::DisplacedMeshOptions& o, const render::ViewSetup& view, int size,
           int frames) {
  ibr::DisplacedMeshRenderer renderer(programs, data, o);
  if (const render::GroundTruthPlan* plan = renderer.truth_plan()) {
    fmt::print("displace: tessellated truth: {}\n", plan->Describe());
  }
  Drawn d;
  if (frames > 0) {
    render::FrameTimerOptions timer;
    timer.timed_frames = frames;
    d.timing = render::TimeFrames([&] { renderer.Draw(view, size, size); }, timer);
  }
  renderer.Draw(view, size, size);
  d.frame = renderer.Read();
  d.detail = renderer.Detail();
  if (const int64_t early =
          d.frame.CountOutcome(render::OutcomeBit(render::RayOutcome::kEarlyTermination))) {
    d.detail += fmt::format(", {} early-terminated pixels", early);
  }
  return d;
}

void RunDisplace(const DisplaceOptions& o) {
  constexpr const char* kWhere = "ibr displace";
  if (o.texels < 4 || o.texels > 4096)
    core::ThrowInputError(kWhere, "--texels {} outside 4..4096", o.texels);
  if (o.out.extension() != ".png")
    core::ThrowInputError(kWhere, "--out '{}' must end in .png", o.out.string());
  if (o.out.has_parent_path() && !fs::is_directory(o.out.parent_path())) {
    core::ThrowInputError(kWhere, "--out '{}': no such directory", o.out.string());
  }
  if (o.frames < 0 || o.frames > 1000)
    core::ThrowInputError(kWhere, "--frames {} outside 0..1000", o.frames);
  std::optional<std::array<uint8_t, 3>> background;
  if (!o.background.empty()) background = ParseBackground(o.background);
  ibr::DisplacedMeshOptions options;
  options.method = ibr::DisplacementMethodFromName(o.method);
  options.max_displacement = o.max_displacement;
  options.tiling = o.tiling;
  options.texture_tiling = o.texture_tiling;
  options.shade = !o.unlit;
  options.slices = o.slices;
  options.Check();
  ibr::OrbitCamera orbit;
  orbit.elevation_deg = o.elevation;
  orbit.azimuth_deg = o.azimuth;
  orbit.distance = o.distance;
  orbit.fov_deg = o.fov;
  orbit.up = ibr::UpAxisFromName(o.up, "ibr displace --up");
  orbit.Check();
  auto context = render::HeadlessContext::Create();
  render::CheckFrameSize(kWhere, "--size", o.size, o.size, /*min_side=*/16);

  // Parse -> plain CPU data -> GPU -> passes.
  ibr::DisplacedMeshData data;
  data.base =
      o.mesh.empty() ? ibr::DisplacementBaseMesh(o.base) : ibr::ReadDisplacementBase(o.mesh);
  data.height = o.height_map.empty()
                    ? ibr::DisplacementHeightMap(core::HeightPatternFromName(o.height), o.texels)
                    : ibr::ReadHeightMap(o.height_map);
  if (!o.texture.empty()) data.color = core::ReadImage<uint8_t>(o.texture);
  const std::string base = o.mesh.empty() ? o.base : o.mesh.filename().string();
  const std::string height = o.height_map.empty() ? o.height : o.height_map.filename().string();

  spdlog::info("GL: {} | {}", context->info().version, context->info().renderer);
  render::ProgramCache programs;
  const render::ViewSetup view =
      ibr::DisplacementOrbitView(data.base, o.max_displacement, orbit, o.size);
  const Drawn result = Draw(programs, data, options, view, o.size, o.frames);
  const std::string timing = o.frames > 0
                                 ? fmt::format("{:.2f} ms/frame (median of {})",
                                               result.timing.median_ms, result.timing.samples)
                                 : std::string("untimed");
  fmt::print("displace: {} on {} ({}), {}x{} px, {}, {}\n", o.method, base, height, o.size, o.size,
             timing, result.detail);
  // An empty frame is a camera that misses the mesh, never a result.
  const auto covered = [](const core::Image8& c) {
    for (size_t p = 0; p < c.pixel_count(); ++p)
      if (c.data()[p * c.channels() + 3] == 255) return true;
    return false;
  };
  const auto refuse_empty = [&](const std::string& what) {
    core::ThrowInputError(kWhere,
                          "{} covers no pixel: the camera misses the mesh (check --distance, "
                          "--fov, --up, --elevation)",
                          what);
  };
  if (!covered(result.frame.color)) refuse_empty("the " + o.method + " image");
  if (o.compare && options.method != ibr::DisplacementMethod::kTessellated) {
    ibr::DisplacedMeshOptions truth_options = options;
    truth_options.method = ibr::DisplacementMethod::kTessellated;
    const Drawn truth = Draw(programs, data, truth_options, view, o.size, o.frames);
    if (!covered(truth.frame.color)) refuse_empty("the tessellated truth");
    core::DisplacementErrorOptions error_options;
    error_options.depth_unit = core::HeightTexelWorldSize(data.base, data.height.width(), o.tiling);
    const core::DisplacementError e =
        core::CompareToGroundTruth(result.frame.color, result.frame.depth, truth.frame.color,
                                   truth.frame.depth, error_options);
    const std::string depth =
        e.both_pixels > 0 ? fmt::format("depth error mean {:.3f} / p95 {:.3f} / max {:.3f} texels",
                                        e.mean_depth_error, e.p95_depth_error, e.max_depth_error)
                          : std::string("no pixel covered by both, so no depth error");
    fmt::print("displace: vs tessellated ({}): coverage IoU {:.4f}, {}, {} see-through pixels\n",
               o.frames > 0 ? fmt::format("{:.2f} ms/frame", truth.timing.median_ms)
                            : std::string("untimed"),
               e.coverage_iou, depth, e.see_through_pixels);
  }
  fs::path depth_path = o.out;
  depth_path.replace_extension(".depth.exr");
  core::Image8 color = result.frame.color;
  if (background) Composite(color, *background);
  core::WriteImage(depth_path, result.frame.depth);
  core::WriteImage(o.out, color);
  fmt::print("displace: wrote {} and {}\n", o.out.string(), depth_path.string());
}

void AddDisplaceCommand(CLI::App& app) {
  static DisplaceOptions o;
  auto* cmd = app.add_subcommand(
      "displace", "Render a displacement-mapped mesh (torus/plane/sphere or --mesh) by one method");
  cmd->add_option("--method", o.method, MethodNames())->capture_default_str();
  cmd->add_option("--base", o.base, "torus|plane|sphere")->capture_default_str();
  cmd->add_option("--height", o.height, "bumps|noise|bricks|steps|spikes|constant")
      ->capture_default_str();
  cmd->add_option("--mesh", o.mesh,
                  "your own base mesh (OBJ/PLY with texture coordinates) instead of --base");
  cmd->add_option("--height-map", o.height_map,
                  "your own height map (8/16-bit PNG or EXR, [0, 1]) instead of --height");
  cmd->add_option("--texture", o.texture,
                  "colour texture (any image) at the mesh's uvs, lit, for every method");
  cmd->add_option("--max-displacement", o.max_displacement, "scene units for height 1")
      ->capture_default_str();
  cmd->add_option("--tiling", o.tiling, "height map repeats across uv [0,1]")
      ->capture_default_str();
  cmd->add_option("--texture-tiling", o.texture_tiling,
                  "colour texture repeats across uv [0,1] (1: where the mesh's uvs put it)")
      ->capture_default_str();
  cmd->add_option("--texels", o.texels, "height map size")->capture_default_str();
  cmd->add_option("--slices", o.slices, "slices per face volume")->capture_default_str();
  cmd->add_option("--size", o.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--elevation", o.elevation,
                  "degrees above the plane perpendicular to --up (90 = top view)")
      ->capture_default_str();
  cmd->add_option("--azimuth", o.azimuth, "degrees around --up")->capture_default_str();
  cmd->add_option("--distance", o.distance,
                  "camera distance from the mesh's centre in its units (0 = frame the mesh)")
      ->capture_default_str();
  cmd->add_option("--fov", o.fov, "field of view, degrees")->capture_default_str();
  cmd->add_option("--up", o.up, "the mesh's up axis: x, y, z, -x, -y, -z")->capture_default_str();
  cmd->add_option("--background", o.background,
                  "opaque background colour R,G,B (0-255); default transparent");
  cmd->add_flag("--unlit", o.unlit, "show the colour texture's plain colour (default: lit)");
  cmd->add_option("--frames", o.frames, "timed frames (median); 0 = draw once, untimed")
      ->capture_default_str();
  cmd->add_option("--out", o.out, "colour PNG; camera-z EXR written beside it (.depth.exr)")
      ->capture_default_str();
  cmd->add_flag("--compare", o.compare,
                "also render the tessellated ground truth and print the error");
  cmd->callback([] { RunDisplace(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("displace", AddDisplaceCommand);

}  // namespace apps
