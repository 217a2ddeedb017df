// `ibr render SCENE.json`: every camera of a scene file (scene/scene.h).
// `ibr render DATASET`: the dataset's depth object or visual hull
// (Kautz-Seidel 2001, sec. 4-5) as a one-object scene from novel cameras
// (another dataset's, or a turntable orbit, or an arc of it around the input
// views; its up the dataset's, printed). Both through ibr::RenderToDataset
// (ibr/jobs/render_job.h): output DIR is itself a dataset (color/NAME.png,
// depth/NAME.exr camera z of the first surface, 0 where empty, mask/NAME.png,
// dataset.json with the cameras), staged, so a failure leaves nothing behind.
#include <fmt/format.h>

#include <filesystem>
#include <optional>

#include "apps/ibr/commands.h"
#include "ibr/jobs/render_job.h"
#include "ibr/scene_options.h"
#include "ibr/views.h"
#include "render/gl/context.h"

namespace apps {
namespace {

struct RenderCommandOptions {
  std::filesystem::path dataset;  // or a scene file (*.json)
  ibr::DepthObjectFlags flags;
  std::string up;  // empty: the dataset's (capture::DefaultUp)
  ibr::DatasetRenderJob job;
  std::filesystem::path out;
};

void RunRender(RenderCommandOptions& o) {
  ibr::DatasetRenderJob& job = o.job;
  job.dataset = o.dataset;
  const bool scene_file = o.dataset.extension() == ".json";
  // A scene file refuses --up whatever it says (ibr::RenderToDataset).
  if (!o.up.empty()) job.up = scene_file ? glm::dvec3(0, 0, 1) : ibr::ParseUp(o.up, "--up");
  if (!scene_file) {
    job.options = ibr::DepthObjectOptionsFrom(ibr::SettingsFromFlags(o.flags));
    job.outside_auto = o.flags.outside.empty();
    job.Check();
  }
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  for (const std::string& line :
       ibr::RenderToDataset(programs, job, o.out,
                            [](const std::string& line) { fmt::print("render: {}\n", line); })) {
    fmt::print("{}\n", line);
  }
}

void AddRenderCommand(CLI::App& app) {
  static RenderCommandOptions o;
  auto* cmd = app.add_subcommand("render",
                                 "Render a scene file, or a dataset's depth object or visual hull "
                                 "from novel cameras (Kautz-Seidel 2001, sec. 4-5)");
  cmd->add_option("DATASET", o.dataset, "input dataset directory, or a scene file SCENE.json")
      ->required();
  AddDepthObjectFlags(cmd, o.flags);
  cmd->add_option("--cameras", o.job.cameras,
                  "render from these cameras: a dataset (its images not needed), a cameras-only "
                  "dataset.json, or a scene file's \"cameras\"");
  cmd->add_option("--orbit", o.job.orbit, "render N views on a turntable orbit");
  cmd->add_option("--up", o.up,
                  "orbit axis: x, y, z, -x, -y, -z or three numbers 'X,Y,Z' (default: the "
                  "dataset's \"up\", else its cameras' mean up)");
  cmd->add_option("--arc", o.job.arc_deg,
                  "orbit: span this many degrees centred on the input views' mean direction")
      ->capture_default_str();
  cmd->add_option("--size", o.job.size,
                  "output width in pixels (default: the cameras' own, orbit 512)");
  cmd->add_option("--truth-mesh", o.job.truth_mesh,
                  "also print silhouette IoU and depth error against this mesh");
  cmd->add_option("--out", o.out, "output directory (a dataset of the rendered views)")->required();
  cmd->callback([] { RunRender(o); });
}

}  // namespace

IBR_REGISTER_COMMAND("render", AddRenderCommand);

}  // namespace apps
