#include "bench/depth_object_bench.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "bench/peer.h"
#include "bench/report.h"
#include "bench/tradeoff.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/demo_scene.h"
#include "ibr/depth_object.h"
#include "ibr/views.h"
#include "render/gl/context.h"
#include "render/gl/fill_rate.h"
#include "render/gl/frame_timer.h"
#include "render/gl/program_binary_cache.h"
#include "render/passes/pass.h"

namespace bench {
namespace {

namespace fs = std::filesystem;

constexpr int kMapSize = 256;  // cube-rig maps, pixels

struct Object {
  std::string name;
  capture::SceneMesh scene;
  bool textured = false;
};

// The true mesh from `view`, unshaded (the maps are captured unshaded too, so
// colours compare): camera z and RGBA.
capture::CapturedView Truth(render::ProgramCache& programs, const capture::SceneMesh& scene,
                            const ibr::ViewCamera& view, const capture::Bounds& bounds) {
  const capture::RigView rv = ibr::RigViewFor(view, bounds, "truth");
  const ibr::MapCamera& c = view.camera;
  capture::CaptureOptions co;
  co.size = std::max(c.width, 16);
  co.shade = false;
  return capture::RenderView(programs, scene, rv, co);
}

std::vector<Object> Objects(bool quick) {
  std::vector<Object> objects;
  objects.push_back({"cup", capture::MakeShapeScene("cup"), false});
  if (quick) return objects;
  // The mug (core::MakeMug): a concave cavity and a handle's hole, which a
  // depth object from the six cube maps sees only where some map does.
  objects.push_back({"mug", capture::MakeShapeScene("mug"), false});
  const fs::path meshes = ibr::SharedDataDir() / "meshes";
  for (const auto& [name, file] :
       std::vector<std::pair<std::string, std::string>>{{"bunny", "stanford-bunny.obj"},
                                                        {"cow", "cow.obj"},
                                                        {"spot", "spot.obj"},
                                                        {"teapot", "teapot.obj"}}) {
    if (!fs::exists(meshes / file)) {
      fmt::print("bench depth-object: {} skipped: {} is absent\n", name, (meshes / file).string());
      continue;
    }
    capture::SceneMesh scene = capture::LoadSceneMesh(meshes / file);
    const bool textured = !scene.texture.empty();
    objects.push_back({name, std::move(scene), textured});
  }
  // Bunny first: the Fig. 12 analogues and the peer use it.
  std::stable_sort(objects.begin(), objects.end(), [](const Object& a, const Object& b) {
    return (a.name == "bunny") > (b.name == "bunny");
  });
  return objects;
}

std::vector<ibr::ViewCamera> Views(const ibr::MapSet& maps, int count, int size) {
  ibr::OrbitOptions orbit;
  orbit.count = count;
  orbit.size = size;
  orbit.elevation_deg = 25;
  std::vector<ibr::ViewCamera> out;
  for (const ibr::NamedView& v : ibr::OrbitViews(maps, orbit)) out.push_back(v.view);
  return out;
}

// `ibr bench first-image` in a child process whose only shader caches are
// under `cache_dir`: ibr's program binaries (IBR_CACHE_DIR) and Mesa's own
// cache (MESA_SHADER_CACHE_DIR; a MESA_SHADER_CACHE_DISABLE of this process
// is dropped, so the child runs as ibr does by default).
// The executable the first-image children run: this one when it is `ibr`,
// else $IBR_BINARY (tests set it; a test executable would run itself again);
// empty when neither.
fs::path FirstImageBinary() {
  const fs::path self = fs::read_symlink("/proc/self/exe");
  if (self.filename() == "ibr") return self;
  const char* env = std::getenv("IBR_BINARY");
  if (env != nullptr && fs::is_regular_file(env)) return env;
  return {};
}

FirstImageTimes RunFirstImageChild(const FirstImageOptions& options, const fs::path& cache_dir) {
  constexpr const char* kWhere = "bench depth-object: first image";
  const fs::path self = FirstImageBinary();
  fs::create_directories(cache_dir / "mesa");  // Mesa makes only the last folder
  const std::string command = fmt::format(
      "env -u MESA_SHADER_CACHE_DISABLE MESA_SHADER_CACHE_DIR={} IBR_CACHE_DIR={} {} "
      "--log-level warn bench first-image --dataset {} --slicing {} --skip-grid {} {} --size {} "
      "2>&1",
      ShellQuote((cache_dir / "mesa").string()), ShellQuote(cache_dir.string()),
      ShellQuote(self.string()), ShellQuote(options.dataset.string()), options.slicing,
      options.skip_grid, options.subtexel ? "--subtexel" : "", options.size);
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) core::ThrowInputError(kWhere, "cannot run '{}'", command);
  std::string output, line;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe.get())) output += buffer;
  const int status = pclose(pipe.release());
  FirstImageTimes t;
  for (size_t at = 0; at < output.size();) {
    const size_t end = std::min(output.find('\n', at), output.size());
    line = output.substr(at, end - at);
    if (std::sscanf(line.c_str(),
                    "first_image upload_ms %lf first_frame_ms %lf second_frame_ms %lf programs %d "
                    "loaded %d",
                    &t.upload_ms, &t.first_frame_ms, &t.second_frame_ms, &t.programs,
                    &t.programs_loaded) == 5 &&
        status == 0)
      return t;
    at = end + 1;
  }
  core::ThrowInputError(kWhere, "'{}' failed (status {}): {}", command, status, output);
}

// The default depth-object path (what `ibr render` and `ibr view` draw
// unless a scene says otherwise): the ray march with empty-space skipping,
// sub-texel depth and the automatic step count.
ibr::DepthObjectOptions DefaultPathOptions(const Object& object) {
  ibr::DepthObjectOptions o;
  o.slicing = ibr::Slicing::kRay;
  o.subtexel_depth = true;
  o.texturing = object.textured ? ibr::Texturing::kViewDependent : ibr::Texturing::kNone;
  return o;
}

// Issue 36, item 3: the default path against the TSDF peer (1/256; --quick:
// the one TSDF it runs) at the sweep's largest size, in one run.
struct PeerGoals {
  int size = 0;
  MethodRow ours;                                // the default path from the peer's views
  MethodRow peer;                                // the TSDF row
  std::map<std::string, double> first_image_ms;  // "cold" / "warm": the default path's medians
};

constexpr double kStillFrameGoal = 1.0;  // ours / TSDF still frame, at a better p95
constexpr double kFirstImageGoal = 0.1;  // ours / TSDF time to first image

// Rows still frame, first image cold and warm: our figure, the peer's, the
// ratio, the goal and whether it is met. A measure not taken is nan (not met).
void AddGoalRows(Table& table, const std::string& object, const PeerGoals& g) {
  if (g.peer.method.empty()) return;
  const double nan = std::nan("");
  const double p95 = g.ours.accuracy.depth.p95, peer_p95 = g.peer.accuracy.depth.p95;
  const auto add = [&](const std::string& measure, double ours, double peer, double goal,
                       bool better_p95) {
    const double ratio = ours / peer;
    const bool met = std::isfinite(ratio) && ratio <= goal && (!better_p95 || p95 < peer_p95);
    table.AddRow({object, std::to_string(g.size), measure, Num(ours, 1), g.peer.method,
                  Num(peer, 1), Num(ratio, 3), Num(goal, 2), Num(p95, 5), Num(peer_p95, 5),
                  met ? "yes" : "no"});
    fmt::print(stderr, "{:7} {:18} {:9.1f} ms against {} {:9.1f} ms: {:.3f} (goal <= {}{}): {}\n",
               object, measure, ours, g.peer.method, peer, ratio, goal,
               better_p95 ? ", better p95" : "", met ? "met" : "not met");
  };
  add("still_frame", g.ours.median_frame_ms, g.peer.median_frame_ms, kStillFrameGoal, true);
  const double peer_first = 1000.0 * g.peer.time_to_first_image_s;
  for (const char* cache : {"cold", "warm"}) {
    const auto it = g.first_image_ms.find(cache);
    add(fmt::format("first_image_{}", cache), it == g.first_image_ms.end() ? nan : it->second,
        peer_first, kFirstImageGoal, false);
  }
}

}  // namespace

void FirstImageOptions::Check() const {
  constexpr const char* kWhere = "bench first-image";
  if (!fs::is_directory(dataset))
    core::ThrowInputError(kWhere, "--dataset '{}': no such folder", dataset.string());
  ibr::SlicingFromName(slicing);
  if (skip_grid < 0 || skip_grid > 512)
    core::ThrowInputError(kWhere, "--skip-grid {} is outside 0..512", skip_grid);
  if (size < 16 || size > 8192)
    core::ThrowInputError(kWhere, "--size {} is outside 16..8192", size);
}

FirstImageTimes MeasureFirstImage(const FirstImageOptions& options) {
  options.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  const ibr::MapSet maps = ibr::MapsFromDataset(capture::ReadDataset(options.dataset));
  const ibr::ViewCamera view = Views(maps, 2, options.size)[0];
  ibr::DepthObjectOptions o;
  o.slicing = ibr::SlicingFromName(options.slicing);
  o.skip_grid = options.skip_grid;
  o.subtexel_depth = options.subtexel;
  o.texturing = ibr::Texturing::kNone;
  FirstImageTimes t;
  core::Stopwatch upload;
  ibr::DepthObjectRenderer renderer(programs, maps);
  t.upload_ms = upload.ElapsedMs();
  core::Stopwatch first;
  const render::Frame frame = renderer.RenderFrame(view, o);
  t.first_frame_ms = first.ElapsedMs();
  core::Stopwatch second;
  renderer.RenderFrame(view, o);
  t.second_frame_ms = second.ElapsedMs();
  t.programs = static_cast<int>(programs.size());
  t.programs_loaded = programs.disk() ? programs.disk()->stats().hits : 0;
  if (frame.CoveredPixels() == 0)
    core::ThrowInputError("bench first-image", "'{}': the first image shows nothing",
                          options.dataset.string());
  return t;
}

std::string FormatFirstImageLine(const FirstImageTimes& t) {
  return fmt::format(
      "first_image upload_ms {:.3f} first_frame_ms {:.3f} second_frame_ms {:.3f} programs {} "
      "loaded {}",
      t.upload_ms, t.first_frame_ms, t.second_frame_ms, t.programs, t.programs_loaded);
}

void DepthObjectBenchOptions::Check() const {
  constexpr const char* kWhere = "bench depth-object";
  if (csv.empty()) core::ThrowInputError(kWhere, "--csv FILE is required");
  const fs::path folder = fs::absolute(csv).parent_path();
  if (!fs::is_directory(folder))
    core::ThrowInputError(kWhere, "--csv '{}': no folder '{}'", csv.string(), folder.string());
}

DepthObjectBenchResult RunDepthObjectBench(const DepthObjectBenchOptions& options) {
  options.Check();
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  fmt::print("{} | {}\n", context->info().renderer, context->info().version);
  for (int size : options.sizes)
    render::CheckFrameSize("ibr bench depth-object", "--sizes", size, size);

  // Fill-rate calibration in this run (trivial alpha-tested full-screen layers).
  render::FillRateOptions fo;
  fo.width = fo.height = 512;
  fo.layers_per_frame = options.quick ? 8 : 32;
  fo.timer = {1, options.quick ? 3 : 5};
  const render::FillRate fill = render::MeasureFillRate(programs, fo);
  fmt::print(stderr, "fill rate: {:.1f} M fragments/s\n", fill.fragments_per_second * 1e-6);

  std::vector<int> slice_counts =
      options.quick ? std::vector<int>{16, 64} : std::vector<int>{16, 64, 256};
  std::vector<int> sizes = options.quick ? std::vector<int>{128} : std::vector<int>{128, 256, 512};
  if (!options.slices.empty()) slice_counts = options.slices;
  if (!options.sizes.empty()) sizes = options.sizes;
  const render::FrameTimerOptions timer{1, 3};
  const fs::path work =
      fs::temp_directory_path() / fmt::format("ibr_bench_depth_object_{}", ::getpid());
  fs::remove_all(work);

  Table table({"object", "method", "slices", "size", "ms_per_frame", "fill_rate_fraction",
               "time_to_first_image_s", "iou_mean", "iou_min", "mean_depth_error",
               "p95_depth_error", "psnr_db", "slice_pass_ms", "slice_pass_fill_fraction",
               "ms_ratio_to_exact"});
  Table accuracy({"object", "path", "slices_auto", "views", "size", "iou_min", "p95_depth_error",
                  "meets_target"});
  Table profile({"object", "size", "auto_steps", "variant", "ms_per_frame", "ratio_to_default"});
  Table fig_coverage({"family", "slices", "size", "covered_pixels", "ms_per_frame"});
  Table fig_slices({"family", "slices", "size", "ms_per_frame"});
  Table first_image({"object", "method", "size", "cache", "runs", "upload_ms", "first_frame_ms",
                     "second_frame_ms", "time_to_first_image_ms", "programs", "programs_loaded",
                     "tsdf_ms", "over_tsdf"});
  // The goals of issue 36, item 3 (AddGoalRows).
  Table peer_goals({"object", "size", "measure", "depth_object_ms", "peer", "peer_ms", "ratio",
                    "goal_ratio", "depth_object_p95", "peer_p95", "goal_met"});

  std::vector<Object> objects = Objects(options.quick);
  if (!options.objects.empty()) {
    std::erase_if(objects, [&](const Object& o) {
      return std::find(options.objects.begin(), options.objects.end(), o.name) ==
             options.objects.end();
    });
  }
  // The paths: the paper's slicing families, the ray path marching every step
  // (skip grid off), and with empty-space skipping (ibr/empty_space.h).
  // ray-skip-subtexel adds sub-texel depth (DepthObjectOptions::subtexel_depth).
  // *-fast: the slice families by the fast path (SlicePath::kFast, one draw a
  // frame), timed against the exact path's row of the same family.
  struct Path {
    std::string name;
    ibr::Slicing slicing;
    int skip_grid;
    bool subtexel = false;
    ibr::SlicePath slice_path = ibr::SlicePath::kExact;
    std::string exact;  // the path its ms_ratio_to_exact divides by ("" = none)
  };
  const ibr::DepthObjectOptions defaults;
  const std::vector<Path> paths = {
      {"orthogonal", ibr::Slicing::kOrthogonal, 0},
      {"screen", ibr::Slicing::kScreen, 0},
      {"ray", ibr::Slicing::kRay, 0},
      {"ray-skip", ibr::Slicing::kRay, defaults.skip_grid},
      {"ray-skip-subtexel", ibr::Slicing::kRay, defaults.skip_grid, true},
      {"orthogonal-fast", ibr::Slicing::kOrthogonal, 0, false, ibr::SlicePath::kFast, "orthogonal"},
      {"screen-fast", ibr::Slicing::kScreen, 0, false, ibr::SlicePath::kFast, "screen"}};
  // Frame ms of each path by (object, size, slices): the fast rows' ratios.
  std::map<std::tuple<std::string, std::string, int, int>, double> frame_ms;
  for (const Object& object : objects) {
    capture::CaptureOptions co;
    co.rig = "cube";
    co.size = kMapSize;
    co.shade = false;  // albedo maps: colour compares with an unshaded truth
    const capture::Dataset cube =
        capture::CaptureDataset(programs, object.scene, co, work / object.name / "cube");
    const capture::Dataset cube_read = capture::ReadDataset(work / object.name / "cube");
    const ibr::MapSet maps = ibr::MapsFromDataset(cube_read);
    const capture::Bounds bounds = *cube_read.bounds;
    const double edge = CubeEdge(bounds);
    core::Stopwatch upload_watch;
    ibr::DepthObjectRenderer renderer(programs, maps);
    const double upload_ms = upload_watch.ElapsedMs();

    for (int size : sizes) {
      // Two novel views per size: view 0 is timed, both are measured.
      const std::vector<ibr::ViewCamera> views = Views(maps, 2, size);
      std::vector<capture::CapturedView> truth;
      for (const ibr::ViewCamera& v : views)
        truth.push_back(Truth(programs, object.scene, v, bounds));
      for (const Path& path : paths) {
        const ibr::Slicing slicing = path.slicing;
        for (int slices : slice_counts) {
          ibr::DepthObjectOptions o;
          o.slicing = slicing;
          o.slices = slices;
          o.skip_grid = path.skip_grid;
          o.subtexel_depth = path.subtexel;
          o.slice_path = path.slice_path;
          o.texturing = object.textured ? ibr::Texturing::kViewDependent : ibr::Texturing::kNone;
          core::Stopwatch first;
          render::Frame frame0 = renderer.RenderFrame(views[0], o);
          const double first_ms = first.ElapsedMs();
          const render::RenderTarget target(
              render::FrameTargetOptions(views[0].camera.width, views[0].camera.height));
          const core::TimingStats t =
              render::TimeFrames([&] { renderer.DrawFrame(views[0], o, target); }, timer);
          // Fragments the slice passes shade: slice coverage x maps in the loop.
          // The ray variant shades one fragment per pixel that marches many
          // steps: no fill-rate fraction is comparable (nan).
          // slice_pass_*: the slice passes alone (DrawSlices / DrawSlicesFast
          // into the accumulation target, no resolve), against the fragments
          // their draws rasterise: exact, each slice once per map and once
          // (robust: twice) more to clear; fast, each slice once.
          double fraction = std::nan(""), slice_ms = std::nan(""), slice_fraction = std::nan("");
          if (slicing != ibr::Slicing::kRay) {
            const ibr::FrameParams params = ibr::PrepareFrame(renderer.maps(), views[0], o);
            double fragments = 0;
            for (const core::Image8& c : renderer.SliceCoverage(params)) {
              for (uint8_t v : c.values()) fragments += v > 0;
            }
            const double map_count = static_cast<double>(params.active.size());
            fraction = fragments * map_count / (t.median_ms / 1000.0) / fill.fragments_per_second;
            const bool fast = path.slice_path == ibr::SlicePath::kFast;
            const render::RenderTarget accum(ibr::DepthObjectRenderer::AccumTargetOptions(
                views[0].camera.width, views[0].camera.height));
            slice_ms = render::TimeFrames(
                           [&] {
                             if (fast)
                               renderer.DrawSlicesFast(params, o, accum);
                             else
                               renderer.DrawSlices(params, o, accum);
                           },
                           timer)
                           .median_ms;
            const double issued =
                fast ? fragments : fragments * (map_count + (params.robust ? 2 : 1));
            slice_fraction = issued / (slice_ms / 1000.0) / fill.fragments_per_second;
          }
          frame_ms[{object.name, path.name, size, slices}] = t.median_ms;
          double ratio = std::nan("");
          if (auto it = frame_ms.find({object.name, path.exact, size, slices});
              it != frame_ms.end())
            ratio = t.median_ms / it->second;
          std::vector<ViewMetrics> acc;
          double psnr = 0;
          for (size_t i = 0; i < views.size(); ++i) {
            const render::Frame f = i == 0 ? std::move(frame0) : renderer.RenderFrame(views[i], o);
            acc.push_back(CompareDepth(f.depth, truth[i].depth, edge));
            if (object.textured)
              psnr += core::Psnr(f.color, truth[i].color,
                                 core::BothCovered(core::CoverageFromDepth(f.depth),
                                                   core::CoverageFromDepth(truth[i].depth))) /
                      double(views.size());
          }
          const PooledMetrics a = Pool(acc);
          const std::string method = fmt::format("depth-object {}", path.name);
          table.AddRow({object.name, method, std::to_string(slices), std::to_string(size),
                        Num(t.median_ms, 2), Num(fraction, 3),
                        Num((upload_ms + first_ms) / 1000.0, 3), Num(a.iou_mean, 4),
                        Num(a.iou_min, 4), Num(a.depth.mean, 5), Num(a.depth.p95, 5),
                        object.textured ? Num(psnr, 2) : "nan", Num(slice_ms, 2),
                        Num(slice_fraction, 3), Num(ratio, 3)});
          fmt::print(
              stderr,
              "{:7} {:24} {:4} slices {:5} px: {:9.2f} ms/frame ({:.2f} of fill rate), IoU {:.4f}, "
              "p95 depth {:.5f} edges; slice passes {:.2f} ms ({:.2f} of fill rate for the "
              "fragments they issue), {:.3f} x the exact path's frame\n",
              object.name, method, slices, size, t.median_ms, fraction, a.iou_mean, a.depth.p95,
              slice_ms, slice_fraction, ratio);
        }
      }
    }

    {
      // Where the default path's time goes (issue 12: what bounds it): the
      // ray path at its defaults (skipping, sub-texel depth, slices auto) at
      // the largest size, against the same frame with one thing taken away
      // or halved, in one run. The march's share scales with the steps and
      // the maps each step tests; the rest is the resolve and the readback.
      const int size = sizes.back();
      const ibr::ViewCamera view = Views(maps, 1, size)[0];
      const render::RenderTarget target(render::FrameTargetOptions(size, size));
      ibr::DepthObjectOptions base;
      base.slicing = ibr::Slicing::kRay;
      base.subtexel_depth = true;
      base.texturing = object.textured ? ibr::Texturing::kViewDependent : ibr::Texturing::kNone;
      const int auto_steps = ibr::PrepareFrame(renderer.maps(), view, base).slice_count;
      const auto variant = [&](auto change) {
        ibr::DepthObjectOptions o = base;
        change(o);
        renderer.RenderFrame(view, o);  // programs built before timing
        return render::TimeFrames([&] { renderer.DrawFrame(view, o, target); }, timer).median_ms;
      };
      const double full = variant([](ibr::DepthObjectOptions&) {});
      const std::vector<std::pair<std::string, double>> rows = {
          {"default (ray, skip 64, sub-texel, auto steps)", full},
          {"nearest texels", variant([](auto& o) { o.subtexel_depth = false; })},
          {"no empty-space skipping", variant([](auto& o) { o.skip_grid = 0; })},
          {"no refinement", variant([](auto& o) { o.refine_steps = 0; })},
          {"a quarter of the steps",
           variant([&](auto& o) { o.slices = std::max(1, auto_steps / 4); })},
          {"3 nearest maps of 6", variant([](auto& o) { o.max_maps = 3; })},
          {"1 nearest map", variant([](auto& o) { o.max_maps = 1; })},
          {"no texturing", variant([](auto& o) { o.texturing = ibr::Texturing::kNone; })},
      };
      for (const auto& [name, ms] : rows) {
        profile.AddRow({object.name, std::to_string(size), std::to_string(auto_steps), name,
                        Num(ms, 2), Num(ms / full, 3)});
        fmt::print(stderr, "{:7} profile {:5} px, {} steps: {:46} {:9.2f} ms ({:.3f} of default)\n",
                   object.name, size, auto_steps, name, ms, ms / full);
      }
    }

    {
      // The accuracy check (issue 12): every path at its defaults (slices
      // auto), 8 novel perspective views at 256 px (quick: 4 at 128) against
      // the true mesh from each; IoU and p95 depth error in cube edges.
      const int n_views = options.quick ? 4 : 8, size = options.quick ? 128 : 256;
      const std::vector<ibr::ViewCamera> views = Views(maps, n_views, size);
      std::vector<core::ImageF> truth;
      for (const ibr::ViewCamera& v : views)
        truth.push_back(Truth(programs, object.scene, v, bounds).depth);
      for (const Path& path : paths) {
        ibr::DepthObjectOptions o;
        o.slicing = path.slicing;
        o.skip_grid = path.skip_grid;
        o.subtexel_depth = path.subtexel;
        o.slice_path = path.slice_path;
        o.texturing = ibr::Texturing::kNone;
        std::vector<ViewMetrics> acc;
        for (size_t i = 0; i < views.size(); ++i) {
          acc.push_back(CompareDepth(renderer.RenderFrame(views[i], o).depth, truth[i], edge));
        }
        const PooledMetrics a = Pool(acc);
        const int slices = ibr::PrepareFrame(renderer.maps(), views[0], o).slice_count;
        accuracy.AddRow({object.name, path.name, std::to_string(slices), std::to_string(n_views),
                         std::to_string(size), Num(a.iou_min, 4), Num(a.depth.p95, 5),
                         a.iou_min >= 0.985 && a.depth.p95 <= 0.006 ? "yes" : "no"});
        fmt::print(
            stderr,
            "{:7} accuracy check {:11} (auto: {} slices): IoU_min {:.4f}, p95 {:.5f} edges\n",
            object.name, path.name, slices, a.iou_min, a.depth.p95);
      }
    }

    if ((object.name == "bunny" && options.figures) || options.quick) {
      // Figure 12 analogues (the paper: time against covered pixels at 128
      // slices; against slices at 300x300).
      const std::vector<int> fig_sizes =
          options.quick ? std::vector<int>{64, 128} : std::vector<int>{128, 192, 256, 384, 512};
      const std::vector<int> fig_slices_n =
          options.quick ? std::vector<int>{16, 32} : std::vector<int>{16, 32, 64, 128, 256, 512};
      for (ibr::Slicing slicing : {ibr::Slicing::kOrthogonal, ibr::Slicing::kScreen}) {
        ibr::DepthObjectOptions o;
        o.slicing = slicing;
        o.texturing = ibr::Texturing::kNone;
        o.slices = 128;
        for (int size : fig_sizes) {
          const ibr::ViewCamera v = Views(maps, 1, size)[0];
          const render::Frame f = renderer.RenderFrame(v, o);
          const int64_t covered = f.CoveredPixels();
          const render::RenderTarget target(render::FrameTargetOptions(size, size));
          const core::TimingStats t =
              render::TimeFrames([&] { renderer.DrawFrame(v, o, target); }, timer);
          fig_coverage.AddRow({ibr::SlicingName(slicing), "128", std::to_string(size),
                               std::to_string(covered), Num(t.median_ms, 2)});
        }
        const int fig_size = options.quick ? 100 : 300;
        const ibr::ViewCamera v = Views(maps, 1, fig_size)[0];
        const render::RenderTarget target(render::FrameTargetOptions(fig_size, fig_size));
        for (int slices : fig_slices_n) {
          o.slices = slices;
          const core::TimingStats t =
              render::TimeFrames([&] { renderer.DrawFrame(v, o, target); }, timer);
          fig_slices.AddRow({ibr::SlicingName(slicing), std::to_string(slices),
                             std::to_string(fig_size), Num(t.median_ms, 2)});
        }
      }
    }

    PeerGoals goals;
    if (object.name == "bunny" || options.quick) {
      // The peer on a perspective capture of the same object (Open3D takes
      // pinhole cameras only), judged from the same novel views.
      capture::CaptureOptions pc = co;
      pc.rig = "sphere:6";
      capture::CaptureDataset(programs, object.scene, pc, work / object.name / "sphere6");
      Open3dPeerOptions po;
      po.work_dir = work / object.name / "open3d";
      if (options.quick) po.methods = {"tsdf:64"};
      try {
        const Open3dRun run = RunOpen3dPeer(work / object.name / "sphere6", po);
        const int size = sizes.back();
        const std::vector<ibr::ViewCamera> views = Views(maps, options.quick ? 2 : 6, size);
        std::vector<core::ImageF> truth;
        for (const ibr::ViewCamera& v : views)
          truth.push_back(Truth(programs, object.scene, v, bounds).depth);
        capture::Bounds draw = bounds;
        draw.min -= 0.1 * edge;
        draw.max += 0.1 * edge;
        // The still frame of the default path, timed and judged exactly as the
        // peer's meshes are (TimeViews: the median of the views after the
        // first, each with its depth readback) from the same views.
        goals.ours = EvaluateDepthObject(programs, maps, DefaultPathOptions(object), views, truth,
                                         edge, "depth-object default");
        goals.size = size;
        for (const MethodRow& r : EvaluatePeer(programs, run, views, truth, draw, edge)) {
          if (r.method.starts_with("open3d tsdf:") &&
              (goals.peer.method.empty() || r.method == "open3d tsdf:256"))
            goals.peer = r;
          table.AddRow({object.name, r.method, "0", std::to_string(size), Num(r.median_frame_ms, 2),
                        "nan", Num(r.time_to_first_image_s, 3), Num(r.accuracy.iou_mean, 4),
                        Num(r.accuracy.iou_min, 4), Num(r.accuracy.depth.mean, 5),
                        Num(r.accuracy.depth.p95, 5), "nan", "nan", "nan", "nan"});
          fmt::print(
              stderr,
              "{:7} {:24} {:5} px: first image {:.3f} s, IoU {:.4f}, p95 depth {:.5f} edges\n",
              object.name, r.method, size, r.time_to_first_image_s, r.accuracy.iou_mean,
              r.accuracy.depth.p95);
        }
      } catch (const core::InputError& e) {
        fmt::print("bench depth-object: the Open3D peer did not run: {}\n", e.what());
      }
    }

    // The children are `ibr bench first-image`: only the ibr binary can
    // spawn them (FirstImageBinary).
    const bool can_spawn = !FirstImageBinary().empty();
    if (!can_spawn && (object.name == "bunny" || options.quick))
      fmt::print(stderr, "{}: time to first image skipped (no ibr binary; set IBR_BINARY)\n",
                 object.name);
    if (can_spawn && (object.name == "bunny" || options.quick)) {
      // Time to first image, cold and warm (issue 12, item 4), each run a
      // fresh process (RunFirstImageChild): cold = an empty cache folder;
      // warm = the folder the previous run filled; binaries only = our
      // program binaries kept and Mesa's cache (the LLVM code) emptied.
      // Medians of `runs`; against the TSDF peer's time to first image at
      // voxel 1/256 (integration + mesh extraction + upload + first frame;
      // Open3D keeps nothing between runs: one figure for cold and warm).
      const int runs = options.quick ? 1 : 3, size = sizes.back();
      double tsdf_ms = std::nan("");
      std::string tsdf_method;
      for (const auto& row : table.rows()) {
        if (row[0] == object.name && row[1].starts_with("open3d tsdf:") &&
            (tsdf_method.empty() || row[1] == "open3d tsdf:256")) {
          tsdf_method = row[1];
          tsdf_ms = 1000.0 * CellNumber(row[table.Column("time_to_first_image_s")]);
        }
      }
      if (!tsdf_method.empty()) {
        first_image.AddRow({object.name, tsdf_method, std::to_string(size), "none (one run)", "1",
                            "nan", "nan", "nan", Num(tsdf_ms, 1), "0", "0", Num(tsdf_ms, 1),
                            "1.000"});
      }
      const fs::path caches = work / object.name / "first_image_cache";
      for (const Path& path : paths) {
        // --quick: the default path only (each run is three processes that
        // compile every program cold at least once).
        const bool default_path = std::string_view(path.name) == "ray-skip-subtexel";
        if (options.quick && !default_path) continue;
        FirstImageOptions child;
        child.dataset = work / object.name / "cube";
        child.slicing = ibr::SlicingName(path.slicing);
        child.skip_grid = path.skip_grid;
        child.subtexel = path.subtexel;
        child.size = size;
        std::map<std::string, std::vector<FirstImageTimes>> by_cache;
        for (int r = 0; r < runs; ++r) {
          const fs::path dir = caches / fmt::format("{}_{}", path.name, r);
          fs::remove_all(dir);
          by_cache["cold"].push_back(RunFirstImageChild(child, dir));
          by_cache["warm"].push_back(RunFirstImageChild(child, dir));
          fs::remove_all(dir / "mesa");
          by_cache["binaries only"].push_back(RunFirstImageChild(child, dir));
          fs::remove_all(dir);
        }
        for (const char* cache : {"cold", "warm", "binaries only"}) {
          const std::vector<FirstImageTimes>& ts = by_cache[cache];
          auto median = [&](auto get) {
            std::vector<double> v;
            for (const FirstImageTimes& t : ts) v.push_back(get(t));
            std::sort(v.begin(), v.end());
            return v[v.size() / 2];
          };
          const double total = median([](const FirstImageTimes& t) { return t.total_ms(); });
          if (default_path) goals.first_image_ms[cache] = total;
          const std::string method = fmt::format("depth-object {}", path.name);
          first_image.AddRow(
              {object.name, method, std::to_string(size), cache, std::to_string(runs),
               Num(median([](const FirstImageTimes& t) { return t.upload_ms; }), 1),
               Num(median([](const FirstImageTimes& t) { return t.first_frame_ms; }), 1),
               Num(median([](const FirstImageTimes& t) { return t.second_frame_ms; }), 1),
               Num(total, 1), std::to_string(ts.back().programs),
               std::to_string(ts.back().programs_loaded), Num(tsdf_ms, 1),
               Num(total / tsdf_ms, 3)});
          fmt::print(stderr, "{:7} {:24} first image {:13}: {:8.1f} ms ({:.3f} of {})\n",
                     object.name, method, cache, total, total / tsdf_ms,
                     tsdf_method.empty() ? "TSDF (absent)" : tsdf_method);
        }
      }
    }
    AddGoalRows(peer_goals, object.name, goals);
  }
  fs::remove_all(work);

  // The cost per map (issue 12, item 8) on the sweep's first object.
  MapCountSweepResult map_sweep{Table({"object"}), Table({"object"})};
  if (options.maps_sweep && !objects.empty()) {
    MapCountSweepOptions mo =
        options.quick ? MapCountSweepOptions::Quick() : MapCountSweepOptions{};
    if (!options.map_counts.empty()) mo.counts = options.map_counts;
    map_sweep = RunMapCountSweep(programs, objects[0].name, objects[0].scene, mo);
    if (!options.out.empty()) fs::create_directories(options.out);
    WriteMapCountSweep(map_sweep, options.csv.parent_path() / options.csv.stem(), options.out);
  }

  fmt::print("\n{}\n", table.Format());
  table.WriteCsv(options.csv);
  const fs::path stem = options.csv.parent_path() / options.csv.stem();
  fig_coverage.WriteCsv(stem.string() + "_fig12_coverage.csv");
  fig_slices.WriteCsv(stem.string() + "_fig12_slices.csv");
  accuracy.WriteCsv(stem.string() + "_accuracy.csv");
  fmt::print("\n{}\n", accuracy.Format());
  first_image.WriteCsv(stem.string() + "_first_image.csv");
  fmt::print("\n{}\n", first_image.Format());
  profile.WriteCsv(stem.string() + "_profile.csv");
  fmt::print("\n{}\n", profile.Format());
  peer_goals.WriteCsv(stem.string() + "_peer_goals.csv");
  fmt::print("\n{}\n", peer_goals.Format());
  fmt::print(
      "wrote {} (+ _fig12_coverage.csv, _fig12_slices.csv, _accuracy.csv, _first_image.csv, "
      "_profile.csv, _peer_goals.csv)\n",
      options.csv.string());
  if (!options.out.empty()) {
    fs::create_directories(options.out);
    // Error against time: one panel per object and size, a method's points
    // joined only along its slices (a peer's along its resolution).
    PlotTradeoff(DepthObjectTradeoff(table), options.out / "error_vs_time.png");
    PlotTradeoff(DepthObjectSilhouetteTradeoff(table), options.out / "iou_vs_time.png");
    // Fig. 12 analogues: time against covered pixels and against slices.
    for (const auto& [fig, title, x, x_label, png] :
         {std::tuple{&fig_coverage, "Fig. 12 analogue: time vs covered pixels, 128 slices (bunny)",
                     "covered_pixels", "object pixels", "fig12_time_vs_coverage.png"},
          std::tuple{&fig_slices, "Fig. 12 analogue: time vs slice count (bunny)", "slices",
                     "slices", "fig12_time_vs_slices.png"}}) {
      if (fig->rows().empty()) continue;  // --no-figures, or no bunny in --objects
      PlotPng(*fig,
              {.title = title,
               .x_column = x,
               .y_column = "ms_per_frame",
               .series_column = "family",
               .x_label = x_label,
               .y_label = "ms per frame"},
              options.out / png);
    }
    fmt::print("wrote plots to {}\n", options.out.string());
  }
  return {std::move(table),      std::move(accuracy),    std::move(fig_coverage),
          std::move(fig_slices), std::move(first_image), std::move(map_sweep),
          std::move(profile),    std::move(peer_goals)};
}

}  // namespace bench
