// `ibr info`: what this machine's GL gives us. `ibr info DIR`: a readable
// summary of a dataset (cameras, views, depth, bounds). `ibr info VOLUME`: a
// volume file's type, size, spacing, data range and percentiles. The text:
// ibr/info.h.
#include <fmt/format.h>

#include <filesystem>

#include "apps/ibr/commands.h"
#include "ibr/info.h"
#include "scene/scene_keys.h"

namespace apps {

namespace {

void AddInfoCommand(CLI::App& app) {
  static std::filesystem::path dir;
  auto* cmd =
      app.add_subcommand("info",
                         "Without DIR: the OpenGL context this machine gives (headless EGL); "
                         "with DIR: a summary of the dataset there; with a volume (.dat, .nrrd, "
                         ".nhdr, .nii, .nii.gz or a DICOM folder): its type, size, spacing, data "
                         "range and percentiles");
  cmd->add_option("DIR", dir, "dataset directory or volume (optional)");
  static bool scene_keys = false;
  cmd->add_flag("--scene-keys", scene_keys,
                "print every key a scene object takes, per object type (Markdown)");
  cmd->callback([] {
    if (scene_keys) {
      fmt::print("{}", scene::ObjectKeysMarkdown());
    } else {
      fmt::print("{}", dir.empty() ? ibr::GlInfoText() : ibr::PathInfoText(dir));
    }
  });
}
}  // namespace

IBR_REGISTER_COMMAND("info", AddInfoCommand);

}  // namespace apps
