// `ibr bench ...`: measured figures, printed (never asserted).
#include <fmt/format.h>

#include "apps/ibr/bench_gl.h"
#include "apps/ibr/commands.h"
#include "render/gl/context.h"
#include "render/gl/fill_rate.h"
#include "render/passes/pass.h"

namespace apps {

namespace {

void AddFillRateBench(CLI::App& app) {
  auto* fill = BenchGroup(app)->add_subcommand(
      "fillrate",
      "Calibrate fragment throughput: a trivial textured, alpha-tested full-screen pass (2D "
      "NEAREST, 2D LINEAR), and the floors of a DVR fragment: one 3D LINEAR lookup classified by a "
      "transfer function and blended, and a displacement map's lookup before it");
  static render::FillRateOptions options;
  fill->add_option("--size", options.width, "target width = height in pixels")
      ->capture_default_str();
  fill->add_option("--layers", options.layers_per_frame, "full-screen passes per frame")
      ->capture_default_str();
  fill->add_option("--frames", options.timer.timed_frames, "timed frames (median reported)")
      ->capture_default_str();
  fill->callback([] {
    options.height = options.width;
    const auto gl = StartBenchGl("ibr bench fillrate", options.width);
    // 2D NEAREST and LINEAR with the alpha test, then the DVR floors (one 3D
    // LINEAR lookup classified and blended; a map's lookup before it).
    using Work = render::FillRateOptions::Work;
    struct Variant {
      const char* name;
      bool linear;
      Work work;
    };
    for (const Variant& v : {Variant{"NEAREST", false, Work::kTexture2DAlphaTest},
                             Variant{"LINEAR", true, Work::kTexture2DAlphaTest},
                             Variant{"3D+TF+blend", true, Work::kVolumeBlend},
                             Variant{"map, 3D+TF+blend", true, Work::kDisplacedVolumeBlend}}) {
      render::FillRateOptions o = options;
      o.linear_filter = v.linear;
      o.work = v.work;
      const render::FillRate rate = render::MeasureFillRate(gl->programs, o);
      fmt::print("fill rate ({:15}) {}x{} x {} layers: {:8.2f} ms/frame  {:7.1f} M fragments/s\n",
                 v.name, o.width, o.height, o.layers_per_frame, rate.ms_per_frame,
                 rate.fragments_per_second * 1e-6);
    }
  });
}

}  // namespace

IBR_REGISTER_COMMAND("bench fillrate", AddFillRateBench);

}  // namespace apps
