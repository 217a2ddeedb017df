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
#include "bench/sweep.h"
#include "bench/tradeoff.h"
#include "capture/synthetic.h"
#include "core/error.h"
#include "core/metrics.h"
#include "core/timing.h"
#include "ibr/dataset_maps.h"
#include "ibr/depth_object.h"
#include "ibr/jobs/demo_job.h"
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

// `ibr bench first-image` in a child process whose only shader caches are
// under `cache_dir`: ibr's program binaries (IBR_CACHE_DIR) and Mesa's own
// cache (MESA_SHADER_CACHE_DIR; a MESA_SHADER_CACHE_DISABLE of this process
// is dropped, so the child runs as ibr does by default).
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

namespace {

// A depth-object path of the sweep: the paper's slicing families, the ray
// path marching every step (skip grid off), and with empty-space skipping
// (ibr/empty_space.h). ray-skip-subtexel adds sub-texel depth
// (DepthObjectOptions::subtexel_depth). *-fast: the slice families by the
// fast path (SlicePath::kFast, one draw a frame), timed against the exact
// path's row of the same family.
struct Path {
  std::string name;
  ibr::Slicing slicing = ibr::Slicing::kRay;
  int skip_grid = 0;
  bool subtexel = false;
  ibr::SlicePath slice_path = ibr::SlicePath::kExact;
  std::string exact;  // the path its ms_ratio_to_exact divides by ("" = none)
};

// The configuration lists: per object, size x path x slices in that nesting
// order; then the object's profile, accuracy check, Fig. 12 analogues, peer
// and first-image measures (MeasureObject).
struct DepthObjectSweep {
  explicit DepthObjectSweep(const DepthObjectBenchOptions& options)
      : slice_counts(options.quick ? std::vector<int>{16, 64} : std::vector<int>{16, 64, 256}),
        sizes(options.quick ? std::vector<int>{128} : std::vector<int>{128, 256, 512}) {
    if (!options.slices.empty()) slice_counts = options.slices;
    if (!options.sizes.empty()) sizes = options.sizes;
  }
  std::vector<int> slice_counts;
  std::vector<int> sizes;
  std::vector<Path> paths = {
      {"orthogonal", ibr::Slicing::kOrthogonal, 0},
      {"screen", ibr::Slicing::kScreen, 0},
      {"ray", ibr::Slicing::kRay, 0},
      {"ray-skip", ibr::Slicing::kRay, ibr::DepthObjectOptions().skip_grid},
      {"ray-skip-subtexel", ibr::Slicing::kRay, ibr::DepthObjectOptions().skip_grid, true},
      {"orthogonal-fast", ibr::Slicing::kOrthogonal, 0, false, ibr::SlicePath::kFast, "orthogonal"},
      {"screen-fast", ibr::Slicing::kScreen, 0, false, ibr::SlicePath::kFast, "screen"}};
  render::FrameTimerOptions timer{1, 3};
};

// The sweep's objects, restricted to options.objects when given.
std::vector<Object> SweepObjects(const DepthObjectBenchOptions& options) {
  std::vector<Object> objects = Objects(options.quick);
  if (!options.objects.empty()) {
    std::erase_if(objects, [&](const Object& o) {
      return std::find(options.objects.begin(), options.objects.end(), o.name) ==
             options.objects.end();
    });
  }
  return objects;
}

// The result's tables with their columns and no rows.
DepthObjectBenchResult EmptyDepthObjectResult() {
  return {
      Table({"object", "method", "slices", "size", "ms_per_frame", "fill_rate_fraction",
             "time_to_first_image_s", "iou_mean", "iou_min", "mean_depth_error", "p95_depth_error",
             "psnr_db", "slice_pass_ms", "slice_pass_fill_fraction", "ms_ratio_to_exact"}),
      Table({"object", "path", "slices_auto", "views", "size", "iou_min", "p95_depth_error",
             "meets_target"}),
      Table({"family", "slices", "size", "covered_pixels", "ms_per_frame"}),
      Table({"family", "slices", "size", "ms_per_frame"}),
      Table({"object", "method", "size", "cache", "runs", "upload_ms", "first_frame_ms",
             "second_frame_ms", "time_to_first_image_ms", "programs", "programs_loaded", "tsdf_ms",
             "over_tsdf"}),
      MapCountSweepResult{Table({"object"}), Table({"object"})},
      Table({"object", "size", "auto_steps", "variant", "ms_per_frame", "ratio_to_default"}),
      // The goals of issue 36, item 3 (AddGoalRows).
      Table({"object", "size", "measure", "depth_object_ms", "peer", "peer_ms", "ratio",
             "goal_ratio", "depth_object_p95", "peer_p95", "goal_met"})};
}

// What the sweep shares: the context's programs, the options and lists, the
// fill rate calibrated in this run, the scratch folder and the tables.
struct DepthObjectRun {
  render::ProgramCache& programs;
  const DepthObjectBenchOptions& options;
  const DepthObjectSweep& sweep;
  const render::FillRate fill;
  const fs::path work;
  DepthObjectBenchResult result = EmptyDepthObjectResult();
  // Frame ms of each path by (object, path, size, slices): the fast rows' ratios.
  std::map<std::tuple<std::string, std::string, int, int>, double> frame_ms;
};

// The paper's cube rig, unshaded: albedo maps, so colour compares with an
// unshaded truth.
capture::CaptureOptions CubeCapture() {
  capture::CaptureOptions co;
  co.rig = "cube";
  co.size = kMapSize;
  co.shade = false;
  return co;
}

// The object's cube-rig dataset, written to `dir` (the first-image children
// read it there) and read back.
capture::Dataset CaptureCube(render::ProgramCache& programs, const Object& object,
                             const fs::path& dir) {
  capture::CaptureDataset(programs, object.scene, CubeCapture(), dir);
  return capture::ReadDataset(dir);
}

// One object of the sweep: its maps from the cube rig, their bounds, and the
// renderer with the time its construction (the map upload) took.
struct ObjectRun {
  ObjectRun(render::ProgramCache& programs, const Object& o, const fs::path& work)
      : object(o),
        dir(work / o.name),
        cube(CaptureCube(programs, o, dir / "cube")),
        maps(ibr::MapsFromDataset(cube)),
        bounds(*cube.bounds),
        edge(CubeEdge(bounds)),
        upload_watch(),
        renderer(programs, maps),
        upload_ms(upload_watch.ElapsedMs()) {}
  const Object& object;
  const fs::path dir;  // the object's scratch folder
  const capture::Dataset cube;
  const ibr::MapSet maps;
  const capture::Bounds bounds;
  const double edge;
  const core::Stopwatch upload_watch;  // started right before the renderer
  ibr::DepthObjectRenderer renderer;
  const double upload_ms;
};

// The slice passes against the calibrated fill rate; nan for the ray paths.
struct SlicePassFill {
  double fraction = std::nan("");        // the frame's fragments per second / the fill rate
  double slice_ms = std::nan("");        // the slice passes alone
  double slice_fraction = std::nan("");  // their issued fragments per second / the fill rate
};

// Fragments the slice passes shade: slice coverage x maps in the loop. The
// ray variant shades one fragment per pixel that marches many steps: no
// fill-rate fraction is comparable (nan). slice_pass_*: the slice passes
// alone (DrawSlices / DrawSlicesFast into the accumulation target, no
// resolve), against the fragments their draws rasterise: exact, each slice
// once per map and once (robust: twice) more to clear; fast, each slice once.
SlicePassFill MeasureSlicePasses(const DepthObjectRun& run, ObjectRun& obj,
                                 const ibr::ViewCamera& view, const ibr::DepthObjectOptions& o,
                                 double frame_ms) {
  SlicePassFill s;
  if (o.slicing == ibr::Slicing::kRay) return s;
  const ibr::FrameParams params = ibr::PrepareFrame(obj.renderer.maps(), view, o);
  double fragments = 0;
  for (const core::Image8& c : obj.renderer.SliceCoverage(params)) {
    for (uint8_t v : c.values()) fragments += v > 0;
  }
  const double map_count = static_cast<double>(params.active.size());
  s.fraction = fragments * map_count / (frame_ms / 1000.0) / run.fill.fragments_per_second;
  const bool fast = o.slice_path == ibr::SlicePath::kFast;
  const render::RenderTarget accum(
      ibr::DepthObjectRenderer::AccumTargetOptions(view.camera.width, view.camera.height));
  s.slice_ms = render::TimeFrames(
                   [&] {
                     if (fast)
                       obj.renderer.DrawSlicesFast(params, o, accum);
                     else
                       obj.renderer.DrawSlices(params, o, accum);
                   },
                   run.sweep.timer)
                   .median_ms;
  const double issued = fast ? fragments : fragments * (map_count + (params.robust ? 2 : 1));
  s.slice_fraction = issued / (s.slice_ms / 1000.0) / run.fill.fragments_per_second;
  return s;
}

// One path at one slice count and size: a row of the sweep's table. View 0
// is timed (first frame, median frame, slice passes); both views are
// measured against the truth.
void MeasurePath(DepthObjectRun& run, ObjectRun& obj, const Path& path, int slices, int size,
                 const std::vector<ibr::ViewCamera>& views,
                 const std::vector<capture::CapturedView>& truth) {
  const Object& object = obj.object;
  ibr::DepthObjectOptions o;
  o.slicing = path.slicing;
  o.slices = slices;
  o.skip_grid = path.skip_grid;
  o.subtexel_depth = path.subtexel;
  o.slice_path = path.slice_path;
  o.texturing = object.textured ? ibr::Texturing::kViewDependent : ibr::Texturing::kNone;
  core::Stopwatch first;
  render::Frame frame0 = obj.renderer.RenderFrame(views[0], o);
  const double first_ms = first.ElapsedMs();
  const render::RenderTarget target(
      render::FrameTargetOptions(views[0].camera.width, views[0].camera.height));
  const core::TimingStats t =
      render::TimeFrames([&] { obj.renderer.DrawFrame(views[0], o, target); }, run.sweep.timer);
  const SlicePassFill s = MeasureSlicePasses(run, obj, views[0], o, t.median_ms);
  run.frame_ms[{object.name, path.name, size, slices}] = t.median_ms;
  double ratio = std::nan("");
  if (auto it = run.frame_ms.find({object.name, path.exact, size, slices});
      it != run.frame_ms.end())
    ratio = t.median_ms / it->second;
  std::vector<ViewMetrics> acc;
  double psnr = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    const render::Frame f = i == 0 ? std::move(frame0) : obj.renderer.RenderFrame(views[i], o);
    acc.push_back(CompareDepth(f.depth, truth[i].depth, obj.edge));
    if (object.textured)
      psnr += core::Psnr(f.color, truth[i].color,
                         core::BothCovered(core::CoverageFromDepth(f.depth),
                                           core::CoverageFromDepth(truth[i].depth))) /
              double(views.size());
  }
  const PooledMetrics a = Pool(acc);
  const std::string method = fmt::format("depth-object {}", path.name);
  run.result.table.AddRow({object.name, method, std::to_string(slices), std::to_string(size),
                           Num(t.median_ms, 2), Num(s.fraction, 3),
                           Num((obj.upload_ms + first_ms) / 1000.0, 3), Num(a.iou_mean, 4),
                           Num(a.iou_min, 4), Num(a.depth.mean, 5), Num(a.depth.p95, 5),
                           object.textured ? Num(psnr, 2) : "nan", Num(s.slice_ms, 2),
                           Num(s.slice_fraction, 3), Num(ratio, 3)});
  fmt::print(stderr,
             "{:7} {:24} {:4} slices {:5} px: {:9.2f} ms/frame ({:.2f} of fill rate), IoU {:.4f}, "
             "p95 depth {:.5f} edges; slice passes {:.2f} ms ({:.2f} of fill rate for the "
             "fragments they issue), {:.3f} x the exact path's frame\n",
             object.name, method, slices, size, t.median_ms, s.fraction, a.iou_mean, a.depth.p95,
             s.slice_ms, s.slice_fraction, ratio);
}

// Every path x slice count at one size, from two novel views.
void MeasureSize(DepthObjectRun& run, ObjectRun& obj, int size) {
  const std::vector<ibr::ViewCamera> views = Views(obj.maps, 2, size);
  std::vector<capture::CapturedView> truth;
  for (const ibr::ViewCamera& v : views)
    truth.push_back(Truth(run.programs, obj.object.scene, v, obj.bounds));
  using Config = std::tuple<Path, int>;
  Sweep<Config>(Product(run.sweep.paths, run.sweep.slice_counts), {},
                [&](const Config& config, int) {
                  const auto& [path, slices] = config;
                  MeasurePath(run, obj, path, slices, size, views, truth);
                });
}

// Where the default path's time goes (issue 12: what bounds it): the ray
// path at its defaults (skipping, sub-texel depth, slices auto) at the
// largest size, against the same frame with one thing taken away or halved,
// in one run. The march's share scales with the steps and the maps each step
// tests; the rest is the resolve and the readback.
void MeasureProfile(DepthObjectRun& run, ObjectRun& obj) {
  const Object& object = obj.object;
  const int size = run.sweep.sizes.back();
  const ibr::ViewCamera view = Views(obj.maps, 1, size)[0];
  const render::RenderTarget target(render::FrameTargetOptions(size, size));
  ibr::DepthObjectOptions base;
  base.slicing = ibr::Slicing::kRay;
  base.subtexel_depth = true;
  base.texturing = object.textured ? ibr::Texturing::kViewDependent : ibr::Texturing::kNone;
  const int auto_steps = ibr::PrepareFrame(obj.renderer.maps(), view, base).slice_count;
  const auto variant = [&](auto change) {
    ibr::DepthObjectOptions o = base;
    change(o);
    obj.renderer.RenderFrame(view, o);  // programs built before timing
    return render::TimeFrames([&] { obj.renderer.DrawFrame(view, o, target); }, run.sweep.timer)
        .median_ms;
  };
  const double full = variant([](ibr::DepthObjectOptions&) {});
  const std::vector<std::pair<std::string, double>> rows = {
      {"default (ray, skip 64, sub-texel, auto steps)", full},
      {"nearest texels", variant([](auto& o) { o.subtexel_depth = false; })},
      {"no empty-space skipping", variant([](auto& o) { o.skip_grid = 0; })},
      {"no refinement", variant([](auto& o) { o.refine_steps = 0; })},
      {"a quarter of the steps", variant([&](auto& o) { o.slices = std::max(1, auto_steps / 4); })},
      {"3 nearest maps of 6", variant([](auto& o) { o.max_maps = 3; })},
      {"1 nearest map", variant([](auto& o) { o.max_maps = 1; })},
      {"no texturing", variant([](auto& o) { o.texturing = ibr::Texturing::kNone; })},
  };
  for (const auto& [name, ms] : rows) {
    run.result.profile.AddRow({object.name, std::to_string(size), std::to_string(auto_steps), name,
                               Num(ms, 2), Num(ms / full, 3)});
    fmt::print(stderr, "{:7} profile {:5} px, {} steps: {:46} {:9.2f} ms ({:.3f} of default)\n",
               object.name, size, auto_steps, name, ms, ms / full);
  }
}

// The accuracy check (issue 12): every path at its defaults (slices auto),
// 8 novel perspective views at 256 px (quick: 4 at 128) against the true
// mesh from each; IoU and p95 depth error in cube edges.
void MeasureAccuracy(DepthObjectRun& run, ObjectRun& obj) {
  const Object& object = obj.object;
  const int n_views = run.options.quick ? 4 : 8, size = run.options.quick ? 128 : 256;
  const std::vector<ibr::ViewCamera> views = Views(obj.maps, n_views, size);
  std::vector<core::ImageF> truth;
  for (const ibr::ViewCamera& v : views)
    truth.push_back(Truth(run.programs, object.scene, v, obj.bounds).depth);
  Sweep<Path>(run.sweep.paths, {}, [&](const Path& path, int) {
    ibr::DepthObjectOptions o;
    o.slicing = path.slicing;
    o.skip_grid = path.skip_grid;
    o.subtexel_depth = path.subtexel;
    o.slice_path = path.slice_path;
    o.texturing = ibr::Texturing::kNone;
    std::vector<ViewMetrics> acc;
    for (size_t i = 0; i < views.size(); ++i) {
      acc.push_back(CompareDepth(obj.renderer.RenderFrame(views[i], o).depth, truth[i], obj.edge));
    }
    const PooledMetrics a = Pool(acc);
    const int slices = ibr::PrepareFrame(obj.renderer.maps(), views[0], o).slice_count;
    run.result.accuracy.AddRow({object.name, path.name, std::to_string(slices),
                                std::to_string(n_views), std::to_string(size), Num(a.iou_min, 4),
                                Num(a.depth.p95, 5),
                                a.iou_min >= 0.985 && a.depth.p95 <= 0.006 ? "yes" : "no"});
    fmt::print(stderr,
               "{:7} accuracy check {:11} (auto: {} slices): IoU_min {:.4f}, p95 {:.5f} edges\n",
               object.name, path.name, slices, a.iou_min, a.depth.p95);
  });
}

// Figure 12 analogues for one slicing family (the paper: time against
// covered pixels at 128 slices; against slices at 300x300).
void MeasureFig12(DepthObjectRun& run, ObjectRun& obj, ibr::Slicing slicing) {
  const bool quick = run.options.quick;
  const std::vector<int> fig_sizes =
      quick ? std::vector<int>{64, 128} : std::vector<int>{128, 192, 256, 384, 512};
  const std::vector<int> fig_slices =
      quick ? std::vector<int>{16, 32} : std::vector<int>{16, 32, 64, 128, 256, 512};
  ibr::DepthObjectOptions o;
  o.slicing = slicing;
  o.texturing = ibr::Texturing::kNone;
  o.slices = 128;
  for (int size : fig_sizes) {
    const ibr::ViewCamera v = Views(obj.maps, 1, size)[0];
    const render::Frame f = obj.renderer.RenderFrame(v, o);
    const int64_t covered = f.CoveredPixels();
    const render::RenderTarget target(render::FrameTargetOptions(size, size));
    const core::TimingStats t =
        render::TimeFrames([&] { obj.renderer.DrawFrame(v, o, target); }, run.sweep.timer);
    run.result.fig_coverage.AddRow({ibr::SlicingName(slicing), "128", std::to_string(size),
                                    std::to_string(covered), Num(t.median_ms, 2)});
  }
  const int fig_size = quick ? 100 : 300;
  const ibr::ViewCamera v = Views(obj.maps, 1, fig_size)[0];
  const render::RenderTarget target(render::FrameTargetOptions(fig_size, fig_size));
  for (int slices : fig_slices) {
    o.slices = slices;
    const core::TimingStats t =
        render::TimeFrames([&] { obj.renderer.DrawFrame(v, o, target); }, run.sweep.timer);
    run.result.fig_slices.AddRow({ibr::SlicingName(slicing), std::to_string(slices),
                                  std::to_string(fig_size), Num(t.median_ms, 2)});
  }
}

// The peer on a perspective capture of the same object (Open3D takes pinhole
// cameras only), judged from the same novel views at the largest size: its
// rows of the sweep's table, and the goals' still frames (the default path's
// and the TSDF's).
PeerGoals MeasurePeer(DepthObjectRun& run, ObjectRun& obj) {
  const Object& object = obj.object;
  PeerGoals goals;
  capture::CaptureOptions pc = CubeCapture();
  pc.rig = "sphere:6";
  capture::CaptureDataset(run.programs, object.scene, pc, obj.dir / "sphere6");
  Open3dPeerOptions po;
  po.work_dir = obj.dir / "open3d";
  if (run.options.quick) po.methods = {"tsdf:64"};
  try {
    const Open3dRun peer = RunOpen3dPeer(obj.dir / "sphere6", po);
    const int size = run.sweep.sizes.back();
    const std::vector<ibr::ViewCamera> views = Views(obj.maps, run.options.quick ? 2 : 6, size);
    std::vector<core::ImageF> truth;
    for (const ibr::ViewCamera& v : views)
      truth.push_back(Truth(run.programs, object.scene, v, obj.bounds).depth);
    capture::Bounds draw = obj.bounds;
    draw.min -= 0.1 * obj.edge;
    draw.max += 0.1 * obj.edge;
    // The still frame of the default path, timed and judged exactly as the
    // peer's meshes are (TimeViews: the median of the views after the
    // first, each with its depth readback) from the same views.
    goals.ours = EvaluateDepthObject(run.programs, obj.maps, DefaultPathOptions(object), views,
                                     truth, obj.edge, "depth-object default");
    goals.size = size;
    for (const MethodRow& r : EvaluatePeer(run.programs, peer, views, truth, draw, obj.edge)) {
      if (r.method.starts_with("open3d tsdf:") &&
          (goals.peer.method.empty() || r.method == "open3d tsdf:256"))
        goals.peer = r;
      run.result.table.AddRow({object.name, r.method, "0", std::to_string(size),
                               Num(r.median_frame_ms, 2), "nan", Num(r.time_to_first_image_s, 3),
                               Num(r.accuracy.iou_mean, 4), Num(r.accuracy.iou_min, 4),
                               Num(r.accuracy.depth.mean, 5), Num(r.accuracy.depth.p95, 5), "nan",
                               "nan", "nan", "nan"});
      fmt::print(stderr,
                 "{:7} {:24} {:5} px: first image {:.3f} s, IoU {:.4f}, p95 depth {:.5f} edges\n",
                 object.name, r.method, size, r.time_to_first_image_s, r.accuracy.iou_mean,
                 r.accuracy.depth.p95);
    }
  } catch (const core::InputError& e) {
    fmt::print("bench depth-object: the Open3D peer did not run: {}\n", e.what());
  }
  return goals;
}

// The TSDF peer's time to first image from the sweep's table: voxel 1/256,
// else the one TSDF that ran ("" and nan when none did).
struct TsdfFirstImage {
  std::string method;
  double ms = std::nan("");
};

TsdfFirstImage FindTsdfFirstImage(const Table& table, const std::string& object) {
  TsdfFirstImage tsdf;
  for (const auto& row : table.rows()) {
    if (row[0] == object && row[1].starts_with("open3d tsdf:") &&
        (tsdf.method.empty() || row[1] == "open3d tsdf:256")) {
      tsdf.method = row[1];
      tsdf.ms = 1000.0 * CellNumber(row[table.Column("time_to_first_image_s")]);
    }
  }
  return tsdf;
}

// One path's first images, `runs` times each cold, warm and with our
// program binaries only, each run a fresh process (RunFirstImageChild):
// cold = an empty cache folder; warm = the folder the previous run filled;
// binaries only = our program binaries kept and Mesa's cache (the LLVM
// code) emptied. The first-image rows of the medians, against the TSDF.
void MeasureFirstImagePath(DepthObjectRun& run, ObjectRun& obj, const Path& path, int runs,
                           int size, const TsdfFirstImage& tsdf, PeerGoals& goals) {
  const bool default_path = std::string_view(path.name) == "ray-skip-subtexel";
  FirstImageOptions child;
  child.dataset = obj.dir / "cube";
  child.slicing = ibr::SlicingName(path.slicing);
  child.skip_grid = path.skip_grid;
  child.subtexel = path.subtexel;
  child.size = size;
  std::map<std::string, std::vector<FirstImageTimes>> by_cache;
  for (int r = 0; r < runs; ++r) {
    const fs::path dir = obj.dir / "first_image_cache" / fmt::format("{}_{}", path.name, r);
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
      return core::Median(std::move(v));
    };
    const double total = median([](const FirstImageTimes& t) { return t.total_ms(); });
    if (default_path) goals.first_image_ms[cache] = total;
    const std::string method = fmt::format("depth-object {}", path.name);
    run.result.first_image.AddRow(
        {obj.object.name, method, std::to_string(size), cache, std::to_string(runs),
         Num(median([](const FirstImageTimes& t) { return t.upload_ms; }), 1),
         Num(median([](const FirstImageTimes& t) { return t.first_frame_ms; }), 1),
         Num(median([](const FirstImageTimes& t) { return t.second_frame_ms; }), 1), Num(total, 1),
         std::to_string(ts.back().programs), std::to_string(ts.back().programs_loaded),
         Num(tsdf.ms, 1), Num(total / tsdf.ms, 3)});
    fmt::print(stderr, "{:7} {:24} first image {:13}: {:8.1f} ms ({:.3f} of {})\n", obj.object.name,
               method, cache, total, total / tsdf.ms,
               tsdf.method.empty() ? "TSDF (absent)" : tsdf.method);
  }
}

// Time to first image, cold and warm (issue 12, item 4), of every path at the
// largest size (medians of `runs`), against the TSDF peer's time to first
// image at voxel 1/256 (integration + mesh extraction + upload + first
// frame; Open3D keeps nothing between runs: one figure for cold and warm).
void MeasureFirstImages(DepthObjectRun& run, ObjectRun& obj, PeerGoals& goals) {
  const int runs = run.options.quick ? 1 : 3, size = run.sweep.sizes.back();
  const TsdfFirstImage tsdf = FindTsdfFirstImage(run.result.table, obj.object.name);
  if (!tsdf.method.empty()) {
    run.result.first_image.AddRow({obj.object.name, tsdf.method, std::to_string(size),
                                   "none (one run)", "1", "nan", "nan", "nan", Num(tsdf.ms, 1), "0",
                                   "0", Num(tsdf.ms, 1), "1.000"});
  }
  // --quick: the default path only (each run is three processes that compile
  // every program cold at least once).
  std::vector<Path> paths = run.sweep.paths;
  if (run.options.quick)
    std::erase_if(paths, [](const Path& path) { return path.name != "ray-skip-subtexel"; });
  Sweep<Path>(paths, {}, [&](const Path& path, int) {
    MeasureFirstImagePath(run, obj, path, runs, size, tsdf, goals);
  });
}

// Every measure of one object: the sweep (size x path x slices), the profile,
// the accuracy check; on the bunny (and --quick) the Fig. 12 analogues, the
// peer, the first images and the goals against the peer.
void MeasureObject(DepthObjectRun& run, const Object& object) {
  ObjectRun obj(run.programs, object, run.work);
  for (int size : run.sweep.sizes) MeasureSize(run, obj, size);
  MeasureProfile(run, obj);
  MeasureAccuracy(run, obj);
  const bool bunny_or_quick = object.name == "bunny" || run.options.quick;
  if ((object.name == "bunny" && run.options.figures) || run.options.quick) {
    for (ibr::Slicing slicing : {ibr::Slicing::kOrthogonal, ibr::Slicing::kScreen})
      MeasureFig12(run, obj, slicing);
  }
  PeerGoals goals;
  if (bunny_or_quick) goals = MeasurePeer(run, obj);
  // The children are `ibr bench first-image`: only the ibr binary can spawn
  // them (FirstImageBinary).
  const bool can_spawn = !FirstImageBinary().empty();
  if (!can_spawn && bunny_or_quick)
    fmt::print(stderr, "{}: time to first image skipped (no ibr binary; set IBR_BINARY)\n",
               object.name);
  if (can_spawn && bunny_or_quick) MeasureFirstImages(run, obj, goals);
  AddGoalRows(run.result.peer_goals, object.name, goals);
}

// Error against time and the Fig. 12 analogues as PNGs into `out`.
void PlotDepthObjectBench(const DepthObjectBenchResult& result, const fs::path& out) {
  fs::create_directories(out);
  // Error against time: one panel per object and size, a method's points
  // joined only along its slices (a peer's along its resolution).
  PlotTradeoff(DepthObjectTradeoff(result.table), out / "error_vs_time.png");
  PlotTradeoff(DepthObjectSilhouetteTradeoff(result.table), out / "iou_vs_time.png");
  // Fig. 12 analogues: time against covered pixels and against slices.
  for (const auto& [fig, title, x, x_label, png] :
       {std::tuple{&result.fig_coverage,
                   "Fig. 12 analogue: time vs covered pixels, 128 slices (bunny)", "covered_pixels",
                   "object pixels", "fig12_time_vs_coverage.png"},
        std::tuple{&result.fig_slices, "Fig. 12 analogue: time vs slice count (bunny)", "slices",
                   "slices", "fig12_time_vs_slices.png"}}) {
    if (fig->rows().empty()) continue;  // --no-figures, or no bunny in --objects
    PlotPng(*fig,
            {.title = title,
             .x_column = x,
             .y_column = "ms_per_frame",
             .series_column = "family",
             .x_label = x_label,
             .y_label = "ms per frame"},
            out / png);
  }
  fmt::print("wrote plots to {}\n", out.string());
}

// Prints the tables and writes them beside options.csv (and the plots).
void WriteDepthObjectBench(const DepthObjectBenchResult& result,
                           const DepthObjectBenchOptions& options) {
  fmt::print("\n{}\n", result.table.Format());
  result.table.WriteCsv(options.csv);
  const fs::path stem = options.csv.parent_path() / options.csv.stem();
  result.fig_coverage.WriteCsv(stem.string() + "_fig12_coverage.csv");
  result.fig_slices.WriteCsv(stem.string() + "_fig12_slices.csv");
  result.accuracy.WriteCsv(stem.string() + "_accuracy.csv");
  fmt::print("\n{}\n", result.accuracy.Format());
  result.first_image.WriteCsv(stem.string() + "_first_image.csv");
  fmt::print("\n{}\n", result.first_image.Format());
  result.profile.WriteCsv(stem.string() + "_profile.csv");
  fmt::print("\n{}\n", result.profile.Format());
  result.peer_goals.WriteCsv(stem.string() + "_peer_goals.csv");
  fmt::print("\n{}\n", result.peer_goals.Format());
  fmt::print(
      "wrote {} (+ _fig12_coverage.csv, _fig12_slices.csv, _accuracy.csv, _first_image.csv, "
      "_profile.csv, _peer_goals.csv)\n",
      options.csv.string());
  if (!options.out.empty()) PlotDepthObjectBench(result, options.out);
}

}  // namespace

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

  const DepthObjectSweep sweep(options);
  const fs::path work =
      fs::temp_directory_path() / fmt::format("ibr_bench_depth_object_{}", ::getpid());
  fs::remove_all(work);
  DepthObjectRun run{programs, options, sweep, fill, work};
  const std::vector<Object> objects = SweepObjects(options);
  Sweep<Object>(objects, {}, [&](const Object& object, int) { MeasureObject(run, object); });
  fs::remove_all(work);

  // The cost per map (issue 12, item 8) on the sweep's first object.
  if (options.maps_sweep && !objects.empty()) {
    MapCountSweepOptions mo =
        options.quick ? MapCountSweepOptions::Quick() : MapCountSweepOptions{};
    if (!options.map_counts.empty()) mo.counts = options.map_counts;
    run.result.maps = RunMapCountSweep(programs, objects[0].name, objects[0].scene, mo);
    if (!options.out.empty()) fs::create_directories(options.out);
    WriteMapCountSweep(run.result.maps, options.csv.parent_path() / options.csv.stem(),
                       options.out);
  }
  WriteDepthObjectBench(run.result, options);
  return std::move(run.result);
}

}  // namespace bench
