#include "scene/scene_write.h"

#include <algorithm>
#include <set>
#include <string>

#include "core/atomic_file.h"
#include "core/transfer_function.h"
#include "scene/scene_keys.h"

namespace scene {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

class Writer {
 public:
  explicit Writer(const WriteOptions& options) : options_(options) {}

  // Relative to base_dir when the file lies under it (no ".." step), else
  // absolute: a file beside the scene moves with it, others stay put.
  std::string File(const fs::path& path) const {
    const fs::path absolute = fs::absolute(path).lexically_normal();
    if (!options_.base_dir.empty()) {
      const fs::path rel =
          absolute.lexically_relative(fs::absolute(options_.base_dir).lexically_normal());
      if (!rel.empty() && *rel.begin() != "..") return rel.generic_string();
    }
    return absolute.string();
  }

  // 3 rows of 4: [R | t] of an affine matrix (the reader's Rows3x4).
  static json Rows3x4(const glm::dmat4& m) {
    json rows = json::array();
    for (int r = 0; r < 3; ++r) rows.push_back({m[0][r], m[1][r], m[2][r], m[3][r]});
    return rows;
  }

  json Mesh(const MeshSource& m, const char* file_key) const {
    if (!m.shape.empty()) return {{"shape", m.shape}};
    return {{file_key, File(m.file)}};
  }

  json Cameras(const scene::Cameras& c) const {
    switch (c.kind) {
      case Cameras::Kind::kOrbit:
        return {{"orbit",
                 {{"count", c.orbit_count},
                  {"size", c.orbit_size},
                  {"elevation_deg", c.orbit_elevation_deg},
                  {"fov_deg", c.orbit_fov_deg},
                  {"up", {c.orbit_up.x, c.orbit_up.y, c.orbit_up.z}}}}};
      case Cameras::Kind::kDataset:
        return {{"dataset", File(c.dataset)}, {"size", c.dataset_size}};
      case Cameras::Kind::kList: {
        json list = json::array();
        for (const ExplicitCamera& e : c.list) {
          list.push_back({{"name", e.name},
                          {"width", e.width},
                          {"height", e.height},
                          {"fx", e.fx},
                          {"fy", e.fy},
                          {"cx", e.cx},
                          {"cy", e.cy},
                          {"orthographic", e.orthographic},
                          {"cam_from_world", Rows3x4(e.cam_from_world)}});
        }
        return {{"list", list}};
      }
    }
    return {};
  }

  json Object(const scene::Object& o) const {
    const ObjectKindSpec* kind = FindObjectKind(ObjectTypeName(o.type));
    json j = {{"type", ObjectTypeName(o.type)},
              {"name", o.name},
              {"enabled", o.enabled},
              {"transform", {{"matrix", Rows3x4(o.world_from_object)}}}};
    std::set<std::string> keys;
    for (const KeySpec& k : kind->keys) keys.insert(std::string(k.key));
    if (keys.count("images")) {
      const ImageSource& im = o.images;
      if (!im.dataset.empty()) {
        j["images"] = {{"dataset", File(im.dataset)}};
      } else {
        json capture = Mesh(im.capture_mesh, "mesh");
        capture["rig"] = im.capture_rig;
        capture["size"] = im.capture_size;
        j["images"] = {{"capture", capture}};
      }
    }
    if (keys.count("mesh")) j["mesh"] = Mesh(o.mesh, "file");
    if (keys.count("height")) {
      const HeightSource& h = o.height;
      j["height"] = h.file.empty() ? json{{"generator", h.generator}, {"texels", h.texels}}
                                   : json{{"file", File(h.file)}};
    }
    if (!o.texture.empty()) j["texture"] = File(o.texture);
    if (!o.volume.empty()) j["volume"] = File(o.volume);
    // The settings under their keys. A setting outside the kind's table was
    // derived by the reader from a structural key (a depth object's "method"
    // from its "type") and is not written.
    const std::vector<std::string> presets = core::TransferPresetNames();
    for (const auto& [key, setting] : o.settings.values()) {
      if (!keys.count(key) || j.contains(key)) continue;
      json value = setting.value;
      if (key == "transfer" && value.is_string() &&
          std::find(presets.begin(), presets.end(), value.get<std::string>()) == presets.end()) {
        value = File(value.get<std::string>());  // a transfer-function file
      }
      j[key] = value;
    }
    return j;
  }

  json Scene(const scene::Scene& s) const {
    json doc = {{"version", kSceneVersion}, {"cameras", Cameras(s.cameras)}};
    if (!s.description.empty()) doc["description"] = s.description;
    json lights = json::array();
    for (const Light& l : s.lights) lights.push_back({{"type", l.type}});
    doc["lights"] = lights;
    json objects = json::array();
    for (const scene::Object& o : s.objects) objects.push_back(Object(o));
    doc["objects"] = objects;
    return doc;
  }

 private:
  WriteOptions options_;
};

}  // namespace

json SceneToJson(const Scene& scene, const WriteOptions& options) {
  return Writer(options).Scene(scene);
}

void WriteScene(std::ostream& out, const Scene& scene, const WriteOptions& options) {
  out << SceneToJson(scene, options).dump(2) << "\n";
}

void WriteScene(const fs::path& path, const Scene& scene) {
  WriteOptions options;
  options.base_dir = fs::absolute(path).parent_path();
  core::AtomicWriteStream(path, [&](std::ostream& out) { WriteScene(out, scene, options); });
}

}  // namespace scene
