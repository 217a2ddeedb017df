#include "capture/builtin_scenes.h"

#include <fmt/format.h>

#include <cstdlib>
#include <sstream>

#include "core/error.h"
#include "datasets/embedded.h"
#include "scene/scene.h"

namespace capture {

namespace {

// Whether a scene file's first object is image-based (a capture scene);
// scenes of other objects (e.g. cut-and-volume.json) are for `ibr render` /
// `ibr view` only. Text that is not such JSON counts as one, so
// ParseBuiltinScene reports what is wrong with it.
bool FirstObjectImageBased(std::string_view text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("objects") || !j["objects"].is_array() ||
      j["objects"].empty() || !j["objects"][0].is_object() || !j["objects"][0].contains("type")) {
    return true;
  }
  const nlohmann::json& type = j["objects"][0]["type"];
  return !type.is_string() || type == "depth-object" || type == "visual-hull";
}

}  // namespace

std::vector<std::string> BuiltinSceneNames() {
  std::vector<std::string> names;
  for (const auto& f : datasets::EmbeddedFiles()) {
    std::string name(f.name);
    if (name.size() > 5 && name.ends_with(".json") && FirstObjectImageBased(f.source))
      names.push_back(name.substr(0, name.size() - 5));
  }
  return names;
}

BuiltinScene ParseBuiltinScene(const std::string& name, const std::string& json_text) {
  // A scene file (scene/scene.h) whose first object is a depth object or a
  // visual hull captured from a shape or a shared mesh.
  const std::string where = fmt::format("ParseBuiltinScene: '{}'", name);
  scene::ReadOptions read;
  read.check_files = false;  // shared data may be absent until the object is loaded
  std::istringstream in(json_text);
  scene::Scene file;
  try {
    file = scene::ReadScene(in, name, read);
  } catch (const core::InputError& e) {
    core::ThrowInputError(where, "{}", e.what());
  }
  const scene::Object& object = file.objects.front();
  if ((object.type != scene::ObjectType::kDepthObject &&
       object.type != scene::ObjectType::kVisualHull) ||
      !object.images.dataset.empty()) {
    core::ThrowInputError(where,
                          "the first object must be a depth object or visual hull with \"images\": "
                          "{{\"capture\": ...}}");
  }
  BuiltinScene scene;
  scene.name = name;
  scene.description = file.description;
  scene.shape = object.images.capture_mesh.shape;
  scene.shared_mesh = object.images.capture_mesh.file.string();
  scene.capture.rig = object.images.capture_rig;
  scene.capture.size = object.images.capture_size;
  scene.render = nlohmann::json::object();
  for (const auto& [key, setting] : object.settings.values()) scene.render[key] = setting.value;
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

SceneMesh LoadBuiltinSceneMesh(const BuiltinScene& scene,
                               const std::filesystem::path& shared_data) {
  if (!scene.shape.empty()) return MakeShapeScene(scene.shape);
  const std::filesystem::path path = shared_data / scene.shared_mesh;
  if (!std::filesystem::exists(path)) {
    core::ThrowFileError(
        "LoadBuiltinSceneMesh", path,
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
