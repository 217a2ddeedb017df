// The built-in scenes (datasets/scenes/*.json, embedded): an object, how to
// capture it, and how to render it by default. Used by `ibr capture --scene`
// and `ibr demo`; meshes come from ../shared/data (third-party data is never
// copied into the repository).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/synthetic.h"

namespace capture {

struct BuiltinScene {
  std::string name;  // file stem, e.g. "spot-cube"
  std::string description;
  std::string shape;        // analytic shape name (sphere, torus, box, cup), or empty
  std::string shared_mesh;  // path relative to the shared data folder, or empty
  CaptureOptions capture;   // rig and size from the definition, defaults otherwise
  nlohmann::json render;    // default rendering options (parsed by ibr/)
};

// The embedded scenes whose first object is a depth object or visual hull
// (scene files of other objects, e.g. cut-and-volume.json, are not capture
// scenes: `ibr render` / `ibr view` read them as files).
std::vector<std::string> BuiltinSceneNames();

// Parses and validates a definition (InputError naming the scene and the problem).
BuiltinScene ParseBuiltinScene(const std::string& name, const std::string& json_text);
// The embedded scene `name` (InputError listing the names if unknown).
BuiltinScene LoadBuiltinScene(const std::string& name);

// The scene's object: the analytic shape, or the mesh under `shared_data`
// (InputError naming the missing file when the data folder is absent).
SceneMesh LoadBuiltinSceneMesh(const BuiltinScene& scene, const std::filesystem::path& shared_data);

// The shared data folder: $IBR_SHARED_DATA, else ../shared/data beside the
// source tree this binary was built from.
std::filesystem::path DefaultSharedDataDir();

}  // namespace capture
