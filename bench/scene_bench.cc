#include "bench/scene_bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <memory>
#include <sstream>

#include "core/error.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "core/timing.h"
#include "ibr/scene_renderer.h"
#include "render/gl/gl.h"
#include "scene/scene.h"

namespace bench {
namespace {

struct Effect {
  std::string name;
  std::string object;  // JSON of the object, without "enabled"
};

std::vector<Effect> Effects(bool quick) {
  const std::string at = R"("name": "effect", "transform": {"translate": [2.6, 0, 0]})";
  const std::string displaced =
      at +
      R"(, "type": "displaced-mesh", "mesh": {"shape": "torus"},)"
      R"( "height": {"generator": "bumps", "texels": 128}, "max_displacement": 0.15, "tiling": 2, )";
  const std::string image =
      at + R"(, "images": {"capture": {"shape": "cup", "rig": "cube", "size": 128}}, )";
  std::vector<Effect> effects = {
      {"displacement slices-orthogonal",
       displaced + R"("method": "slices-orthogonal", "slices": 32)"},
      {"depth-object orthogonal",
       image + R"("type": "depth-object", "slicing": "orthogonal", "slices": 96)"},
  };
  if (quick) return effects;
  effects.push_back(
      {"displacement slices-screen", displaced + R"("method": "slices-screen", "slices": 32)"});
  effects.push_back({"displacement ncs", displaced + R"("method": "ncs")"});
  effects.push_back({"displacement relief", displaced + R"("method": "relief")"});
  effects.push_back({"displacement pom", displaced + R"("method": "pom")"});
  effects.push_back({"displacement crm", displaced + R"("method": "crm")"});
  effects.push_back({"displacement tessellated", displaced + R"("method": "tessellated")"});
  effects.push_back(
      {"depth-object ray", image + R"("type": "depth-object", "slicing": "ray", "slices": 96)"});
  effects.push_back({"visual-hull screen",
                     image + R"("type": "visual-hull", "slicing": "screen", "slices": 96)"});
  return effects;
}

// One fixed camera for every configuration (so the base object covers the
// same pixels whether the effect is there or not), looking at both objects.
std::string Camera(int size) {
  const glm::mat4 m =
      core::CamFromWorldLookAt({1.3f, 2.0f, 7.5f}, {1.3f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f});
  std::string rows;
  for (int r = 0; r < 3; ++r) {
    rows += fmt::format("{}[{}, {}, {}, {}]", r ? ", " : "", m[0][r], m[1][r], m[2][r], m[3][r]);
  }
  const double f = 0.5 * size / std::tan(glm::radians(22.0));
  return fmt::format(
      R"({{"list": [{{"name": "bench", "width": {0}, "height": {0}, "fx": {1}, "fy": {1}, "cx": {2}, )"
      R"("cy": {2}, "cam_from_world": [{3}]}}]}})",
      size, f, size / 2.0, rows);
}

// The base scene: a plain mesh sphere, always present.
scene::Scene Scene(const std::string& camera, const std::string& extra_object) {
  std::string text =
      R"({"version": 1, "cameras": )" + camera +
      R"(, "objects": [{"name": "base", "type": "mesh", "mesh": {"shape": "sphere"}})";
  if (!extra_object.empty()) text += ", {" + extra_object + "}";
  text += "]}";
  std::istringstream in(text);
  scene::ReadOptions read;
  read.check_files = false;
  return scene::ReadScene(in, "bench-scene", read);
}

// A configuration: its scene, renderer and frame times. The four
// configurations of an effect share one program cache, built in the order
// absent, disabled, absent again, on: each compiles only what the ones before
// it did not, so a scene's programs are the absent scene's plus its own
// additions (every scene holds the base sphere). Shared, because separate
// caches gave identical scenes separately JIT-compiled copies of the same
// shader, and those ran up to 5 % apart for the same work (the noise floor
// absent again / absent read 0.95-1.09 with one cache each).
struct Config {
  ibr::LoadedScene loaded;
  std::unique_ptr<ibr::SceneRenderer> renderer;
  std::vector<double> ms;
  std::vector<double> cpu_ms;  // the process's CPU time per frame (every thread)
  int programs_compiled = 0;
};

// `base_programs`: what the absent scene compiled (0 when building it).
void Build(Config& c, render::ProgramCache& programs, const scene::Scene& s, int base_programs) {
  const size_t before = programs.size();
  c.loaded = ibr::LoadScene(programs, s);
  c.renderer = std::make_unique<ibr::SceneRenderer>(programs, c.loaded);
  c.renderer->Render(c.loaded.views.front().view);  // warm-up: shader compilation
  c.programs_compiled = base_programs + static_cast<int>(programs.size() - before);
}

void Time(Config& c, int frames) {
  for (int i = 0; i < frames; ++i) {
    glFinish();
    core::Stopwatch watch;
    core::CpuStopwatch cpu;
    c.renderer->Render(c.loaded.views.front().view);  // ends with readback: the GPU work is done
    c.ms.push_back(watch.ElapsedMs());
    c.cpu_ms.push_back(cpu.ElapsedMs());
  }
}

// Median over rounds of numerator / denominator, each round's figure the
// median of that round's frames: a ratio of frames timed side by side, so a
// change of load between rounds cancels (a ratio of whole-run medians does
// not: the first full run read 0.90-1.05 for identical work).
double PairedRatio(const std::vector<double>& numerator, const std::vector<double>& denominator,
                   int frames) {
  std::vector<double> ratios;
  for (size_t r = 0; r + frames <= numerator.size() && r + frames <= denominator.size();
       r += frames) {
    const auto round = [&](const std::vector<double>& ms) {
      return core::Percentile(std::vector<double>(ms.begin() + r, ms.begin() + r + frames), 0.5);
    };
    ratios.push_back(round(numerator) / round(denominator));
  }
  return core::Percentile(ratios, 0.5);
}

}  // namespace

void SceneBenchOptions::Check() const {
  // The frame budget and the GL limits: render::CheckFrameSize (ibr bench scene).
  if (size < 32 || size > 16384)
    core::ThrowInputError("SceneBenchOptions", "size {} outside 32..16384", size);
  if (rounds < 1 || rounds > 1000)
    core::ThrowInputError("SceneBenchOptions", "rounds {} outside 1..1000", rounds);
  if (frames < 1 || frames > 1000)
    core::ThrowInputError("SceneBenchOptions", "frames {} outside 1..1000", frames);
}

SceneBenchResult RunSceneBench(const SceneBenchOptions& options) {
  options.Check();
  const int size = options.quick ? std::min(options.size, 128) : options.size;
  const int rounds = options.quick ? 1 : options.rounds;
  const std::string camera = Camera(size);
  // Ratios of wall time, and of the process's CPU time (llvmpipe renders in
  // this process's threads: the work done, which other processes' load
  // changes far less than the wall clock; `_cpu` columns).
  SceneBenchResult result{Table(
      {"effect", "on_ms", "disabled_ms", "absent_ms", "on_over_absent", "disabled_over_absent",
       "absent_again_over_absent", "on_over_absent_cpu", "disabled_over_absent_cpu",
       "absent_again_over_absent_cpu", "programs_on", "programs_disabled", "programs_absent"})};
  const std::vector<Effect> effects = Effects(options.quick);
  for (size_t e = 0; e < effects.size(); ++e) {
    const Effect& effect = effects[e];
    fmt::print(stderr, "bench scene: {}/{} {}: building\n", e + 1, effects.size(), effect.name);
    // `again`: a second scene without the effect, built and timed like the
    // others: its ratio to `absent` is what identical work measures as, the
    // noise floor the disabled ratio is read against.
    Config absent, disabled, on, again;
    render::ProgramCache programs;
    Build(absent, programs, Scene(camera, ""), 0);
    const int base = absent.programs_compiled;
    Build(disabled, programs, Scene(camera, effect.object + R"(, "enabled": false)"), base);
    Build(again, programs, Scene(camera, ""), base);
    Build(on, programs, Scene(camera, effect.object), base);
    // Interleaved so that load changes on the machine hit all four alike,
    // the order rotated each round so that none always follows the costly
    // `on` frames (with a fixed order, the scene after them measured about
    // 1.4 % slower: disabled and absent again both read 0.986 in the median).
    Config* order[] = {&absent, &disabled, &again, &on};
    for (int r = 0; r < rounds; ++r) {
      for (int i = 0; i < 4; ++i) Time(*order[(i + r) % 4], options.frames);
    }
    const double a = core::Summarize(absent.ms).median_ms,
                 d = core::Summarize(disabled.ms).median_ms, o = core::Summarize(on.ms).median_ms;
    const double on_ratio = PairedRatio(on.ms, absent.ms, options.frames),
                 disabled_ratio = PairedRatio(disabled.ms, absent.ms, options.frames),
                 noise = PairedRatio(again.ms, absent.ms, options.frames);
    const double on_cpu = PairedRatio(on.cpu_ms, absent.cpu_ms, options.frames),
                 disabled_cpu = PairedRatio(disabled.cpu_ms, absent.cpu_ms, options.frames),
                 noise_cpu = PairedRatio(again.cpu_ms, absent.cpu_ms, options.frames);
    result.table.AddRow(
        {effect.name, Num(o, 2), Num(d, 2), Num(a, 2), Num(on_ratio, 3), Num(disabled_ratio, 3),
         Num(noise, 3), Num(on_cpu, 3), Num(disabled_cpu, 3), Num(noise_cpu, 3),
         std::to_string(on.programs_compiled), std::to_string(disabled.programs_compiled),
         std::to_string(absent.programs_compiled)});
    fmt::print(stderr,
               "bench scene: {}: on {:.2f} ms, disabled {:.2f} ms, absent {:.2f} ms; per-round "
               "ratios to absent: on {:.3f}, disabled {:.3f}, absent again {:.3f}; of CPU time: "
               "on {:.3f}, disabled {:.3f}, absent again {:.3f}\n",
               effect.name, o, d, a, on_ratio, disabled_ratio, noise, on_cpu, disabled_cpu,
               noise_cpu);
  }
  return result;
}

void WriteSceneBench(const SceneBenchResult& result, const std::filesystem::path& csv,
                     const std::filesystem::path& out_dir) {
  result.table.WriteCsv(csv);
  // Ratios per effect (x = effect number, in table order).
  Table plot({"series", "effect_index", "ratio"});
  const Table& t = result.table;
  for (size_t i = 0; i < t.rows().size(); ++i) {
    plot.AddRow({"on / absent", std::to_string(i + 1), t.rows()[i][t.Column("on_over_absent")]});
    plot.AddRow({"disabled / absent", std::to_string(i + 1),
                 t.rows()[i][t.Column("disabled_over_absent")]});
    plot.AddRow({"absent again / absent (noise)", std::to_string(i + 1),
                 t.rows()[i][t.Column("absent_again_over_absent")]});
    plot.AddRow({"disabled / absent, CPU time", std::to_string(i + 1),
                 t.rows()[i][t.Column("disabled_over_absent_cpu")]});
    plot.AddRow({"absent again / absent, CPU time (noise)", std::to_string(i + 1),
                 t.rows()[i][t.Column("absent_again_over_absent_cpu")]});
  }
  std::filesystem::create_directories(out_dir);
  PlotPng(
      plot,
      {.title =
           "frame time relative to the scene without the effect (effects numbered as in the CSV)",
       .x_column = "effect_index",
       .y_column = "ratio",
       .series_column = "series",
       .x_label = "effect (row of the CSV)",
       .y_label = "frame time / absent",
       .log_y = true},
      out_dir / "scene_bench.png");
}

}  // namespace bench
