#include "capture/builtin_scenes.h"

#include <cstdlib>

#include <fmt/format.h>

#include "core/error.h"
#include "datasets/embedded.h"

namespace capture {

std::vector<std::string> BuiltinSceneNames() {
  std::vector<std::string> names;
  for (const auto& f : datasets::EmbeddedFiles()) {
    std::string name(f.name);
    if (name.size() > 5 && name.ends_with(".json")) names.push_back(name.substr(0, name.size() - 5));
  }
  return names;
}

BuiltinScene ParseBuiltinScene(const std::string& name, const std::string& json_text) {
  const std::string where = fmt::format("ParseBuiltinScene: '{}'", name);
  BuiltinScene scene;
  scene.name = name;
  try {
    const nlohmann::json j = nlohmann::json::parse(json_text);
    scene.description = j.value("description", "");
    const nlohmann::json& object = j.at("object");
    scene.shape = object.value("shape", "");
    scene.shared_mesh = object.value("shared_mesh", "");
    if (j.contains("capture")) {
      const nlohmann::json& c = j.at("capture");
      scene.capture.rig = c.value("rig", scene.capture.rig);
      scene.capture.size = c.value("size", scene.capture.size);
    }
    scene.render = j.value("render", nlohmann::json::object());
  } catch (const nlohmann::json::exception& e) {
    core::ThrowInputError(where, "bad definition: {}", e.what());
  }
  if (scene.shape.empty() == scene.shared_mesh.empty()) {
    core::ThrowInputError(where, "the object needs exactly one of \"shape\" or \"shared_mesh\"");
  }
  if (!scene.render.is_object()) core::ThrowInputError(where, "\"render\" must be an object");
  try {
    scene.capture.Check();
  } catch (const core::InputError& e) {
    core::ThrowInputError(where, "{}", e.what());
  }
  return scene;
}

BuiltinScene LoadBuiltinScene(const std::string& name) {
  for (const auto& f : datasets::EmbeddedFiles()) {
    if (f.name == name + ".json") return ParseBuiltinScene(name, std::string(f.source));
  }
  std::string names;
  for (const auto& n : BuiltinSceneNames()) names += (names.empty() ? "" : ", ") + n;
  core::ThrowInputError("LoadBuiltinScene", "no built-in scene '{}' (there are: {})", name, names);
}

SceneMesh LoadBuiltinSceneMesh(const BuiltinScene& scene, const std::filesystem::path& shared_data) {
  if (!scene.shape.empty()) return MakeShapeScene(scene.shape);
  const std::filesystem::path path = shared_data / scene.shared_mesh;
  if (!std::filesystem::exists(path)) {
    core::ThrowFileError("LoadBuiltinSceneMesh", path,
                         "scene '{}' needs this shared data file (set IBR_SHARED_DATA to the data folder)",
                         scene.name);
  }
  return LoadSceneMesh(path);
}

std::filesystem::path DefaultSharedDataDir() {
  if (const char* env = std::getenv("IBR_SHARED_DATA"); env != nullptr && *env != 0) return env;
  return std::filesystem::path(IBR_SOURCE_DIR) / ".." / "shared" / "data";
}

}  // namespace capture
