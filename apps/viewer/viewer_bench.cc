#include "apps/viewer/viewer_bench.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "apps/viewer/scenes.h"
#include "apps/viewer/viewer.h"
#include "capture/builtin_scenes.h"
#include "core/check.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/timing.h"
#include "ibr/scene_renderer.h"
#include "scene/scene.h"

namespace viewer {
namespace {

// The three object kinds the issue names: a depth object of a cube capture,
// a deform object, a volume (each the demo scenes' object, alone).
struct BenchScene {
  const char* name;
  const char* json;
};
constexpr BenchScene kScenes[] = {
    {"spot depth object (cube capture)",
     R"({"version": 1, "cameras": {"orbit": {"count": 1, "size": 64}}, "objects": [
        {"name": "spot", "type": "depth-object", "images": {"capture": {"shared_mesh":
        "meshes/spot.obj", "rig": "cube", "size": 512}}, "slicing": "ray", "slices": "auto",
        "texturing": "vdt"}]})"},
    {"spot knife cut (deform)",
     R"({"version": 1, "cameras": {"orbit": {"count": 1, "size": 64}}, "lights": [{"type": "head"}],
        "objects": [{"name": "spot", "type": "deform", "mesh": {"shared_mesh": "meshes/spot.obj"},
        "deformation": "knife", "cut": "solid", "resolution": 128}]})"},
    {"tooth peel (volume)",
     R"({"version": 1, "cameras": {"orbit": {"count": 1, "size": 64}}, "lights": [{"type": "head"}],
        "objects": [{"name": "tooth", "type": "volume", "transform": {"rotate_deg": [-90, 0, 0],
        "scale": 0.0065}, "shared_volume": "volumes/tooth_103x94x161_uint8.dat",
        "effect": "peel"}]})"},
};

constexpr float kElevation = 20.0f;
constexpr float kAzimuth0 = 30.0f;
// Degrees per moving frame: a steady mouse drag.
constexpr float kOrbitStep = 1.5f;

// `coarse` (RGBA8) scaled to width x height as the window shows it: bilinear
// between texel centres, clamped at the edges (GL_LINEAR, CLAMP_TO_EDGE).
core::Image8 ScaledUp(const core::Image8& coarse, int width, int height) {
  core::Image8 out(width, height, 4);
  const double sx = static_cast<double>(coarse.width()) / width;
  const double sy = static_cast<double>(coarse.height()) / height;
  for (int y = 0; y < height; ++y) {
    const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, coarse.height() - 1.0);
    const int y0 = static_cast<int>(fy);
    const int y1 = std::min(y0 + 1, coarse.height() - 1);
    const double wy = fy - y0;
    for (int x = 0; x < width; ++x) {
      const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, coarse.width() - 1.0);
      const int x0 = static_cast<int>(fx);
      const int x1 = std::min(x0 + 1, coarse.width() - 1);
      const double wx = fx - x0;
      for (int c = 0; c < 4; ++c) {
        const double top = (1 - wx) * coarse.at(x0, y0, c) + wx * coarse.at(x1, y0, c);
        const double bottom = (1 - wx) * coarse.at(x0, y1, c) + wx * coarse.at(x1, y1, c);
        out.at(x, y, c) =
            static_cast<uint8_t>(std::clamp(std::lround((1 - wy) * top + wy * bottom), 0L, 255L));
      }
    }
  }
  return out;
}

// Sum of squared RGB differences (8-bit) and the sample count.
struct SquaredError {
  double sum = 0;
  int64_t samples = 0;
  void Add(const core::Image8& a, const core::Image8& b) {
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x)
        for (int c = 0; c < 3; ++c) {
          const double d = static_cast<double>(a.at(x, y, c)) - b.at(x, y, c);
          sum += d * d;
          ++samples;
        }
  }
  double PsnrDb() const {
    if (samples == 0) return std::numeric_limits<double>::quiet_NaN();
    const double mse = sum / static_cast<double>(samples);
    return mse == 0 ? std::numeric_limits<double>::infinity()
                    : 10.0 * std::log10(255.0 * 255.0 / mse);
  }
};

// Pixels where the viewer's exact frame (RGBA, the frame target) and the
// dataset `ibr render` wrote (color/exact.png RGB, mask/exact.png) differ in
// colour or coverage.
int64_t DifferingPixels(const core::Image8& frame, const std::filesystem::path& rendered) {
  const core::Image8 color = core::ReadImage<uint8_t>(rendered / "color" / "exact.png", 3);
  const core::Image8 mask = core::ReadImage<uint8_t>(rendered / "mask" / "exact.png", 1);
  if (color.width() != frame.width() || color.height() != frame.height())
    return static_cast<int64_t>(frame.width()) * frame.height();
  int64_t differing = 0;
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < frame.width(); ++x) {
      bool same = (frame.at(x, y, 3) == 255) == (mask.at(x, y, 0) > 127);
      for (int c = 0; c < 3; ++c) same = same && frame.at(x, y, c) == color.at(x, y, c);
      differing += !same;
    }
  return differing;
}

// One motion (orbit or drag) and the rest after it, as measured.
struct MotionResult {
  std::string motion;
  std::vector<double> frame_ms;  // moving frames, whole frame
  std::vector<double> divisors;
  double seconds_to_exact = std::numeric_limits<double>::quiet_NaN();
  double exact_render_ms = 0;
  int64_t differing_pixels = -1;
  SquaredError motion_error;  // moving frames scaled up vs the exact frames of their cameras
};

// A moving frame kept for the PSNR: what the window showed and its pose.
struct Sample {
  core::Image8 coarse;
  FrameCamera full_camera;
  std::optional<double> drag;
};

enum class Phase { kWarm, kOrbit, kOrbitRest, kDragStart, kDrag, kDragRest, kDone };

// The script of one scene: rest (shaders compile, the first exact frame),
// orbit, rest, drag (when the scene has a parameter), rest.
class Session {
 public:
  Session(const ViewerBenchOptions& options, std::filesystem::path scratch)
      : options_(options), scratch_(std::move(scratch)) {}

  std::optional<ScriptedInput> Input(int /*frame*/) {
    if (phase_ == Phase::kDone) return std::nullopt;
    ScriptedInput in;
    in.elevation_degrees = kElevation;
    in.azimuth_degrees = azimuth_;
    if (phase_ == Phase::kOrbit) {
      azimuth_ += kOrbitStep;
      in.azimuth_degrees = azimuth_;
    } else if (phase_ == Phase::kDragStart) {
      drag_ = 0.0;
    } else if (phase_ == Phase::kDrag) {
      drag_ = static_cast<double>(step_ + 1) / options_.motion_frames;
    }
    in.drag = drag_;
    return in;
  }

  void OnFrame(const FrameReport& r) {
    switch (phase_) {
      case Phase::kWarm:
        if (r.exact) Start(Phase::kOrbit, "orbit");
        break;
      case Phase::kDragStart:
        // The drag's first value moved the scene only if it has a parameter.
        if (!r.moving) {
          phase_ = Phase::kDone;
          break;
        }
        Start(Phase::kDrag, "drag");
        Moving(r);
        break;
      case Phase::kOrbit:
      case Phase::kDrag:
        Moving(r);
        break;
      case Phase::kOrbitRest:
      case Phase::kDragRest:
        if (r.exact) Rested(r);
        break;
      case Phase::kDone:
        break;
    }
  }

  std::vector<MotionResult> results;

 private:
  void Start(Phase phase, const std::string& motion) {
    phase_ = phase;
    step_ = 0;
    results.push_back({});
    results.back().motion = motion;
  }

  void Moving(const FrameReport& r) {
    MotionResult& m = results.back();
    if (r.drawn) {
      m.frame_ms.push_back(r.frame_ms);
      m.divisors.push_back(r.divisor);
    }
    // Every sixth moving frame goes to the PSNR (its readback is not timed).
    if (r.drawn && r.target && step_ % 6 == 3) {
      samples_.push_back({r.target->ReadColor8(), r.full_camera, drag_});
    }
    if (++step_ >= options_.motion_frames) {
      phase_ = phase_ == Phase::kOrbit ? Phase::kOrbitRest : Phase::kDragRest;
      rest_watch_ = core::Stopwatch();
    }
  }

  void Rested(const FrameReport& r) {
    MotionResult& m = results.back();
    m.seconds_to_exact = rest_watch_.ElapsedMs() / 1000.0;
    m.exact_render_ms = r.render_ms;
    auto* scene = dynamic_cast<SceneFileScene*>(r.scene);
    IBR_CHECK(scene != nullptr && r.target != nullptr);
    const core::Image8 exact = r.target->ReadColor8();
    // What `ibr render SCENE.json` writes for the scene as edited, from this camera.
    ibr::LoadedScene copy = scene->loaded();
    copy.views = {ibr::NamedView{"exact", ViewCameraOf(r.full_camera)}};
    const std::filesystem::path rendered = scratch_ / m.motion;
    ibr::RenderSceneToDataset(scene->programs(), copy, rendered);
    m.differing_pixels = DifferingPixels(exact, rendered);
    // The moving frames against the exact frames of their cameras (and
    // parameter values), drawn now by the same scene.
    for (const Sample& s : samples_) {
      if (s.drag) scene->DragParameter(*s.drag);
      const core::Image8 truth = scene->Render(s.full_camera).ReadColor8();
      m.motion_error.Add(ScaledUp(s.coarse, truth.width(), truth.height()), truth);
    }
    if (drag_) scene->DragParameter(*drag_);
    samples_.clear();
    phase_ = phase_ == Phase::kOrbitRest ? Phase::kDragStart : Phase::kDone;
  }

  const ViewerBenchOptions& options_;
  std::filesystem::path scratch_;
  Phase phase_ = Phase::kWarm;
  int step_ = 0;
  float azimuth_ = kAzimuth0;
  std::optional<double> drag_;
  std::vector<Sample> samples_;
  core::Stopwatch rest_watch_;
};

double LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one_minute = std::numeric_limits<double>::quiet_NaN();
  in >> one_minute;
  return one_minute;
}

}  // namespace

void ViewerBenchOptions::Check() const {
  if (csv.empty()) core::ThrowInputError("ibr bench viewer", "--csv FILE is required");
  if (width < 64 || height < 64 || width > 8192 || height > 8192)
    core::ThrowInputError("ibr bench viewer", "--window {}x{} outside 64..8192", width, height);
  if (motion_frames < 6 || motion_frames > 10000)
    core::ThrowInputError("ibr bench viewer", "--frames {} outside 6..10000", motion_frames);
}

bench::Table RunViewerBench(const ViewerBenchOptions& options) {
  options.Check();
  const std::filesystem::path shared =
      options.shared_data.empty() ? capture::DefaultSharedDataDir() : options.shared_data;
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path() / fmt::format("ibr-bench-viewer-{}", ::getpid());
  // The renders `exact_equals_render` compares with, removed on every exit.
  struct RemovedOnExit {
    std::filesystem::path path;
    ~RemovedOnExit() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  } scratch_guard{scratch};
  bench::Table table({"scene", "motion", "width", "height", "motion_fps", "motion_frame_ms_p95",
                      "mean_divisor", "seconds_to_exact", "exact_render_ms", "exact_equals_render",
                      "differing_pixels", "psnr_motion_db", "load_avg_1min"});
  for (const BenchScene& bench_scene : kScenes) {
    std::istringstream json(bench_scene.json);
    const scene::Scene file =
        scene::ReadScene(json, bench_scene.name, {.base_dir = shared, .shared_data = shared});
    ViewerOptions viewer;
    viewer.width = options.width;
    viewer.height = options.height;
    viewer.azimuth_degrees = kAzimuth0;
    viewer.elevation_degrees = kElevation;
    viewer.motion_frame_ms = options.motion_frame_ms;
    const double load = LoadAverage();
    Session session(options, scratch / fmt::format("{}", &bench_scene - kScenes));
    ViewerScript script;
    script.input = [&](int frame) { return session.Input(frame); };
    script.on_frame = [&](const FrameReport& r) { session.OnFrame(r); };
    Run([&] { return std::make_unique<SceneFileScene>(file); }, viewer, &script);
    for (const MotionResult& m : session.results) {
      if (m.frame_ms.empty()) continue;
      double total_ms = 0, divisors = 0;
      for (double ms : m.frame_ms) total_ms += ms;
      for (double d : m.divisors) divisors += d;
      std::vector<double> sorted = m.frame_ms;
      std::sort(sorted.begin(), sorted.end());
      const double p95 = sorted[std::min(sorted.size() - 1, sorted.size() * 95 / 100)];
      table.AddRow({bench_scene.name, m.motion, std::to_string(options.width),
                    std::to_string(options.height),
                    bench::Num(1000.0 * m.frame_ms.size() / total_ms, 1), bench::Num(p95, 1),
                    bench::Num(divisors / m.divisors.size(), 2), bench::Num(m.seconds_to_exact, 3),
                    bench::Num(m.exact_render_ms, 1), m.differing_pixels == 0 ? "true" : "false",
                    std::to_string(m.differing_pixels), bench::Num(m.motion_error.PsnrDb(), 2),
                    bench::Num(load, 2)});
    }
  }
  fmt::print("{}", table.Format());
  table.WriteCsv(options.csv);
  const std::filesystem::path out =
      options.out.empty() ? std::filesystem::absolute(options.csv).parent_path() : options.out;
  bench::PlotOptions plot;
  plot.title = fmt::format("ibr view at {}x{}: moving frames against the exact ones", options.width,
                           options.height);
  plot.x_column = "motion_fps";
  plot.y_column = "psnr_motion_db";
  plot.series_column = "scene";
  plot.panel_column = "motion";
  plot.x_label = "frames per second while moving";
  plot.y_label = "PSNR of the moving frames (dB)";
  bench::PlotPng(table, plot, out / "viewer_motion.png");
  return table;
}

}  // namespace viewer
