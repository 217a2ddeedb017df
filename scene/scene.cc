#include "scene/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/transfer_function.h"
#include "scene/scene_keys.h"

namespace scene {
namespace fs = std::filesystem;
using nlohmann::json;

void Settings::Set(const std::string& key, json value, std::string where) {
  values_[key] = Setting{std::move(value), std::move(where)};
}

const Setting* Settings::Find(const std::string& key) const {
  const auto it = values_.find(key);
  return it == values_.end() ? nullptr : &it->second;
}

void Settings::Fail(const std::string& key, const std::string& what) const {
  const Setting* s = Find(key);
  throw core::InputError(fmt::format("{}: {}", s ? s->where : key, what));
}

std::string Settings::GetString(const std::string& key, const std::string& fallback) const {
  const Setting* s = Find(key);
  if (s == nullptr) return fallback;
  if (!s->value.is_string()) Fail(key, fmt::format("expected a string, got {}", s->value.dump()));
  return s->value.get<std::string>();
}

int Settings::GetInt(const std::string& key, int fallback) const {
  const Setting* s = Find(key);
  if (s == nullptr) return fallback;
  if (!s->value.is_number_integer() || s->value.get<int64_t>() < -(int64_t{1} << 30) ||
      s->value.get<int64_t>() > (int64_t{1} << 30)) {
    Fail(key, fmt::format("expected an integer, got {}", s->value.dump()));
  }
  return s->value.get<int>();
}

double Settings::GetDouble(const std::string& key, double fallback) const {
  const Setting* s = Find(key);
  if (s == nullptr) return fallback;
  if (!s->value.is_number() || !std::isfinite(s->value.get<double>())) {
    Fail(key, fmt::format("expected a finite number, got {}", s->value.dump()));
  }
  return s->value.get<double>();
}

std::string ObjectTypeName(ObjectType type) {
  switch (type) {
    case ObjectType::kDepthObject:
      return "depth-object";
    case ObjectType::kVisualHull:
      return "visual-hull";
    case ObjectType::kDisplacedMesh:
      return "displaced-mesh";
    case ObjectType::kMesh:
      return "mesh";
    case ObjectType::kVolume:
      return "volume";
    case ObjectType::kDeform:
      return "deform";
  }
  return "?";
}

namespace {

// Walks the document; every error names the file and the JSON pointer.
class Reader {
 public:
  Reader(std::string name, const ReadOptions& options)
      : name_(std::move(name)), options_(options) {}

  std::string Where(const json::json_pointer& p) const {
    return fmt::format("ReadScene: '{}' {}", name_, p.empty() ? "/" : p.to_string());
  }
  [[noreturn]] void Fail(const json::json_pointer& p, const std::string& what) const {
    throw core::InputError(fmt::format("{}: {}", Where(p), what));
  }

  // `j` must be an object whose keys are all in `allowed`.
  void Keys(const json& j, const json::json_pointer& p,
            const std::set<std::string>& allowed) const {
    if (!j.is_object()) Fail(p, fmt::format("expected an object, got {}", TypeOf(j)));
    for (const auto& [key, value] : j.items()) {
      if (!allowed.count(key)) {
        std::string list;
        for (const std::string& k : allowed) list += (list.empty() ? "" : ", ") + k;
        Fail(p / key, fmt::format("unknown key '{}' (allowed here: {})", key, list));
      }
    }
  }
  static std::string TypeOf(const json& j) { return j.type_name(); }

  std::string String(const json& j, const json::json_pointer& p) const {
    if (!j.is_string()) Fail(p, fmt::format("expected a string, got {}", TypeOf(j)));
    return j.get<std::string>();
  }
  int Int(const json& j, const json::json_pointer& p, int lo, int hi) const {
    if (!j.is_number_integer()) Fail(p, fmt::format("expected an integer, got {}", TypeOf(j)));
    const int64_t v = j.get<int64_t>();
    if (v < lo || v > hi) Fail(p, fmt::format("{} outside {}..{}", v, lo, hi));
    return static_cast<int>(v);
  }
  double Number(const json& j, const json::json_pointer& p) const {
    if (!j.is_number()) Fail(p, fmt::format("expected a number, got {}", TypeOf(j)));
    const double v = j.get<double>();
    if (!std::isfinite(v)) Fail(p, "not finite");
    return v;
  }
  bool Bool(const json& j, const json::json_pointer& p) const {
    if (!j.is_boolean()) Fail(p, fmt::format("expected true or false, got {}", TypeOf(j)));
    return j.get<bool>();
  }
  glm::dvec3 Vec3(const json& j, const json::json_pointer& p) const {
    if (!j.is_array() || j.size() != 3) Fail(p, "expected an array of 3 numbers");
    return {Number(j[0], p / 0), Number(j[1], p / 1), Number(j[2], p / 2)};
  }
  // 3 rows of 4 numbers: [R | t].
  glm::dmat4 Rows3x4(const json& j, const json::json_pointer& p) const {
    if (!j.is_array() || j.size() != 3) Fail(p, "expected 3 rows of 4 numbers");
    glm::dmat4 m(1.0);
    for (int r = 0; r < 3; ++r) {
      if (!j[r].is_array() || j[r].size() != 4) Fail(p / r, "expected a row of 4 numbers");
      for (int c = 0; c < 4; ++c) m[c][r] = Number(j[r][c], p / r / c);
    }
    return m;
  }

  fs::path File(const json& j, const json::json_pointer& p, bool directory = false) const {
    const std::string s = String(j, p);
    if (s.empty()) Fail(p, "empty file name");
    fs::path path(s);
    if (path.is_relative()) path = options_.base_dir / path;
    if (options_.check_files) {
      std::error_code ec;
      const bool ok = directory ? fs::is_directory(path, ec) : fs::is_regular_file(path, ec);
      if (!ok)
        Fail(p, fmt::format("no such {} '{}'", directory ? "directory" : "file", path.string()));
    }
    return path;
  }

  // A file under the shared data folder (`rel` relative to it).
  fs::path SharedFile(const json& j, const json::json_pointer& p) const {
    const std::string rel = String(j, p);
    if (rel.empty() || fs::path(rel).is_absolute()) Fail(p, "expected a relative path");
    const fs::path file = options_.shared_data / rel;
    if (options_.check_files && !fs::is_regular_file(file)) {
      Fail(p, fmt::format("no such file '{}' (set IBR_SHARED_DATA to the data folder)",
                          file.string()));
    }
    return file;
  }

  // A capture's mesh: "shape", "mesh" (a file) or "shared_mesh" (with "rig",
  // "size"); a deform object's: "shape", "file" or "shared_mesh"; otherwise
  // "shape" or "file".
  enum class MeshKeys { kPlain, kCapture, kDeform };
  MeshSource Mesh(const json& j, const json::json_pointer& p, MeshKeys kind) const {
    const bool allow_shared = kind != MeshKeys::kPlain;
    if (kind == MeshKeys::kCapture) {
      Keys(j, p, {"shape", "mesh", "shared_mesh", "rig", "size"});
    } else if (kind == MeshKeys::kDeform) {
      Keys(j, p, {"shape", "file", "shared_mesh"});
    } else {
      Keys(j, p, {"shape", "file"});
    }
    MeshSource m;
    m.where = Where(p);
    int given = 0;
    if (j.contains("shape")) {
      m.shape = String(j["shape"], p / "shape");
      static const std::set<std::string> kShapes = {"sphere", "torus", "box",
                                                    "cup",    "mug",   "plane"};
      if (!kShapes.count(m.shape)) {
        Fail(p / "shape",
             fmt::format("unknown shape '{}' (sphere, torus, box, cup, mug, plane)", m.shape));
      }
      ++given;
    }
    const char* file_key = kind == MeshKeys::kCapture ? "mesh" : "file";
    if (j.contains(file_key)) {
      m.file = File(j[file_key], p / file_key);
      ++given;
    }
    if (allow_shared && j.contains("shared_mesh")) {
      m.file = SharedFile(j["shared_mesh"], p / "shared_mesh");
      ++given;
    }
    if (given != 1) {
      Fail(p, allow_shared ? fmt::format("give exactly one of \"shape\", \"{}\" or \"shared_mesh\"",
                                         file_key)
                           : "give exactly one of \"shape\" or \"file\"");
    }
    return m;
  }

  glm::dmat4 Transform(const json& j, const json::json_pointer& p) const {
    Keys(j, p, {"translate", "rotate_deg", "scale", "matrix"});
    if (j.contains("matrix")) {
      if (j.size() != 1) Fail(p / "matrix", "\"matrix\" excludes translate, rotate_deg and scale");
      return Rows3x4(j["matrix"], p / "matrix");
    }
    glm::dmat4 m(1.0);
    if (j.contains("translate")) m = glm::translate(m, Vec3(j["translate"], p / "translate"));
    if (j.contains("rotate_deg")) {
      const glm::dvec3 r = glm::radians(Vec3(j["rotate_deg"], p / "rotate_deg"));
      m = glm::rotate(m, r.z, glm::dvec3(0, 0, 1));
      m = glm::rotate(m, r.y, glm::dvec3(0, 1, 0));
      m = glm::rotate(m, r.x, glm::dvec3(1, 0, 0));
    }
    if (j.contains("scale")) {
      const json& s = j["scale"];
      const glm::dvec3 v = s.is_array() ? Vec3(s, p / "scale") : glm::dvec3(Number(s, p / "scale"));
      if (!(v.x > 0 && v.y > 0 && v.z > 0)) Fail(p / "scale", "scale factors must be > 0");
      m = glm::scale(m, v);
    }
    return m;
  }

  Cameras ReadCameras(const json& j, const json::json_pointer& p) const {
    Keys(j, p, {"orbit", "dataset", "size", "list"});
    Cameras c;
    const int kinds =
        static_cast<int>(j.contains("orbit")) + j.contains("dataset") + j.contains("list");
    if (kinds != 1) Fail(p, "give exactly one of \"orbit\", \"dataset\" or \"list\"");
    if (j.contains("size") && !j.contains("dataset"))
      Fail(p / "size", "\"size\" goes with \"dataset\"");
    if (j.contains("orbit")) {
      const auto q = p / "orbit";
      const json& o = j["orbit"];
      Keys(o, q, {"count", "size", "elevation_deg", "fov_deg", "up"});
      c.kind = Cameras::Kind::kOrbit;
      if (o.contains("count")) c.orbit_count = Int(o["count"], q / "count", 1, 100000);
      if (o.contains("size")) c.orbit_size = Int(o["size"], q / "size", 8, 16384);
      if (o.contains("elevation_deg")) {
        c.orbit_elevation_deg = Number(o["elevation_deg"], q / "elevation_deg");
        if (!(std::abs(c.orbit_elevation_deg) < 89.9))
          Fail(q / "elevation_deg", "outside (-89.9, 89.9)");
      }
      if (o.contains("fov_deg")) {
        c.orbit_fov_deg = Number(o["fov_deg"], q / "fov_deg");
        if (!(c.orbit_fov_deg > 1 && c.orbit_fov_deg < 170))
          Fail(q / "fov_deg", "outside (1, 170)");
      }
      if (o.contains("up")) {
        c.orbit_up = Vec3(o["up"], q / "up");
        if (!(glm::length(c.orbit_up) > 0)) Fail(q / "up", "zero vector");
      }
    } else if (j.contains("dataset")) {
      c.kind = Cameras::Kind::kDataset;
      c.dataset = File(j["dataset"], p / "dataset", /*directory=*/true);
      if (j.contains("size")) c.dataset_size = Int(j["size"], p / "size", 0, 16384);
    } else {
      c.kind = Cameras::Kind::kList;
      const auto q = p / "list";
      const json& list = j["list"];
      if (!list.is_array() || list.empty()) Fail(q, "expected a non-empty array of cameras");
      std::set<std::string> names;
      for (size_t i = 0; i < list.size(); ++i) {
        const auto r = q / i;
        const json& cj = list[i];
        Keys(cj, r,
             {"name", "width", "height", "fx", "fy", "cx", "cy", "orthographic", "cam_from_world"});
        ExplicitCamera cam;
        for (const char* k :
             {"name", "width", "height", "fx", "fy", "cx", "cy", "cam_from_world"}) {
          if (!cj.contains(k)) Fail(r, fmt::format("missing \"{}\"", k));
        }
        cam.name = String(cj["name"], r / "name");
        if (cam.name.empty() || cam.name.find_first_of("/\\") != std::string::npos ||
            cam.name[0] == '.') {
          Fail(r / "name", "camera names are file names: non-empty, no '/', '\\' or leading '.'");
        }
        if (!names.insert(cam.name).second)
          Fail(r / "name", fmt::format("duplicate camera name '{}'", cam.name));
        cam.width = Int(cj["width"], r / "width", 1, 16384);
        cam.height = Int(cj["height"], r / "height", 1, 16384);
        cam.fx = Number(cj["fx"], r / "fx");
        cam.fy = Number(cj["fy"], r / "fy");
        cam.cx = Number(cj["cx"], r / "cx");
        cam.cy = Number(cj["cy"], r / "cy");
        if (!(cam.fx > 0)) Fail(r / "fx", "must be > 0");
        if (!(cam.fy > 0)) Fail(r / "fy", "must be > 0");
        if (cj.contains("orthographic"))
          cam.orthographic = Bool(cj["orthographic"], r / "orthographic");
        cam.cam_from_world = Rows3x4(cj["cam_from_world"], r / "cam_from_world");
        const glm::dmat3 rot(cam.cam_from_world);
        const glm::dmat3 should_be_identity = glm::transpose(rot) * rot;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) {
            if (std::abs(should_be_identity[a][b] - (a == b ? 1.0 : 0.0)) > 1e-4) {
              Fail(r / "cam_from_world", "the 3x3 part is not a rotation");
            }
          }
        }
        if (glm::determinant(rot) < 0) Fail(r / "cam_from_world", "the 3x3 part is a reflection");
        c.list.push_back(cam);
      }
    }
    return c;
  }

  Object ReadObject(const json& j, const json::json_pointer& p, size_t index) const {
    if (!j.is_object()) Fail(p, fmt::format("expected an object, got {}", TypeOf(j)));
    if (!j.contains("type")) Fail(p, "missing \"type\"");
    Object o;
    o.where = Where(p);
    const std::string type = String(j["type"], p / "type");
    // The keys this type takes come from one table (scene/scene_keys.h),
    // which the guide and `ibr info --scene-keys` print.
    const ObjectKindSpec* kind = FindObjectKind(type);
    if (kind == nullptr) {
      std::string names;
      for (const ObjectKindSpec& k : ObjectKinds())
        names += (names.empty() ? "" : ", ") + std::string(k.name);
      Fail(p / "type", fmt::format("unknown object type '{}' ({})", type, names));
    }
    o.type = kind->type;
    std::set<std::string> structural, effect_keys, allowed, list_keys;
    for (const KeySpec& k : CommonObjectKeys()) allowed.insert(std::string(k.key));
    for (const KeySpec& k : kind->keys) {
      (k.effect ? effect_keys : structural).insert(std::string(k.key));
      if (k.type == "list") list_keys.insert(std::string(k.key));
      allowed.insert(std::string(k.key));
    }
    Keys(j, p, allowed);

    o.name = j.contains("name") ? String(j["name"], p / "name") : fmt::format("object_{}", index);
    if (o.name.empty()) Fail(p / "name", "empty name");
    if (j.contains("enabled")) o.enabled = Bool(j["enabled"], p / "enabled");
    if (j.contains("transform")) o.world_from_object = Transform(j["transform"], p / "transform");
    for (const std::string& k : structural) {
      if (k != "texture" && k != "transfer" && k != "volume" && k != "shared_volume" &&
          !j.contains(k))
        Fail(p, fmt::format("missing \"{}\"", k));
    }
    if (o.type == ObjectType::kVolume && j.contains("volume") == j.contains("shared_volume"))
      Fail(p, "give exactly one of \"volume\" or \"shared_volume\"");
    if (j.contains("volume")) o.volume = File(j["volume"], p / "volume");
    if (j.contains("shared_volume")) o.volume = SharedFile(j["shared_volume"], p / "shared_volume");
    if (j.contains("images")) {
      const auto q = p / "images";
      const json& im = j["images"];
      Keys(im, q, {"dataset", "capture"});
      if (im.contains("dataset") == im.contains("capture"))
        Fail(q, "give exactly one of \"dataset\" or \"capture\"");
      if (im.contains("dataset")) {
        o.images.dataset = File(im["dataset"], q / "dataset", /*directory=*/true);
      } else {
        const auto r = q / "capture";
        const json& c = im["capture"];
        o.images.capture_mesh = Mesh(c, r, MeshKeys::kCapture);
        if (c.contains("rig")) o.images.capture_rig = String(c["rig"], r / "rig");
        if (c.contains("size")) o.images.capture_size = Int(c["size"], r / "size", 16, 8192);
      }
    }
    if (j.contains("mesh")) {
      o.mesh = Mesh(j["mesh"], p / "mesh",
                    o.type == ObjectType::kDeform ? MeshKeys::kDeform : MeshKeys::kPlain);
    }
    if (j.contains("height")) {
      const auto q = p / "height";
      const json& h = j["height"];
      Keys(h, q, {"file", "generator", "texels"});
      o.height.where = Where(q);
      if (h.contains("file") == h.contains("generator"))
        Fail(q, "give exactly one of \"file\" or \"generator\"");
      if (h.contains("texels") && !h.contains("generator"))
        Fail(q / "texels", "\"texels\" goes with \"generator\"");
      if (h.contains("file")) {
        o.height.file = File(h["file"], q / "file");
      } else {
        o.height.generator = String(h["generator"], q / "generator");
        static const std::set<std::string> kPatterns = {"bumps", "noise",  "bricks",
                                                        "steps", "spikes", "constant"};
        if (!kPatterns.count(o.height.generator)) {
          Fail(q / "generator",
               fmt::format("unknown generator '{}' (bumps, noise, bricks, steps, spikes, constant)",
                           o.height.generator));
        }
        if (h.contains("texels")) o.height.texels = Int(h["texels"], q / "texels", 4, 4096);
      }
    }
    if (j.contains("texture")) o.texture = File(j["texture"], p / "texture");
    for (const std::string& k : effect_keys) {
      if (!j.contains(k)) continue;
      const json& v = j[k];
      // Keys of type "list" ("deformations") take a JSON list, which the
      // kind's options reader checks.
      if (list_keys.count(k) > 0 ? !v.is_array() : (!v.is_primitive() || v.is_null()))
        Fail(p / k,
             fmt::format("expected {}, got {}",
                         list_keys.count(k) > 0 ? "a list" : "a string or a number", TypeOf(v)));
      o.settings.Set(k, v, Where(p / k));
    }
    if (o.type == ObjectType::kDepthObject || o.type == ObjectType::kVisualHull) {
      o.settings.Set("method", type, Where(p / "type"));
    }
    if (o.type == ObjectType::kVolume && j.contains("transfer") && j["transfer"].is_object()) {
      // An inline transfer function, the JSON of a transfer-function file
      // (what `ibr view --save-scene` writes for an edited one): checked
      // here, kept as the object.
      std::istringstream text(j["transfer"].dump());
      try {
        core::ReadTransferFunction(text, "inline object");
      } catch (const core::InputError& e) {
        Fail(p / "transfer", e.what());
      }
      o.settings.Set("transfer", j["transfer"], Where(p / "transfer"));
    } else if (o.type == ObjectType::kVolume && j.contains("transfer")) {
      // A preset name (core::TransferPresetNames), else a JSON file.
      const std::string t = String(j["transfer"], p / "transfer");
      const std::vector<std::string> presets = core::TransferPresetNames();
      const bool preset = std::find(presets.begin(), presets.end(), t) != presets.end();
      o.settings.Set("transfer", preset ? t : File(j["transfer"], p / "transfer").string(),
                     Where(p / "transfer"));
    }
    return o;
  }

  Scene Read(std::istream& in) const {
    json doc;
    try {
      doc = json::parse(in);
    } catch (const json::exception& e) {
      throw core::InputError(fmt::format("ReadScene: '{}': not JSON: {}", name_, e.what()));
    }
    const json::json_pointer root;
    Keys(doc, root, {"version", "description", "cameras", "lights", "objects"});
    if (!doc.contains("version")) Fail(root, "missing \"version\"");
    const int version = Int(doc["version"], root / "version", 0, 1000000);
    if (version != kSceneVersion) {
      Fail(root / "version", fmt::format("version {} is not supported (this build reads {})",
                                         version, kSceneVersion));
    }
    Scene s;
    s.name = name_;
    if (doc.contains("description"))
      s.description = String(doc["description"], root / "description");
    if (!doc.contains("cameras")) Fail(root, "missing \"cameras\"");
    s.cameras = ReadCameras(doc["cameras"], root / "cameras");
    if (doc.contains("lights")) {
      const auto q = root / "lights";
      if (!doc["lights"].is_array()) Fail(q, "expected an array");
      for (size_t i = 0; i < doc["lights"].size(); ++i) {
        const json& l = doc["lights"][i];
        Keys(l, q / i, {"type"});
        if (!l.contains("type")) Fail(q / i, "missing \"type\"");
        Light light;
        light.type = String(l["type"], q / i / "type");
        if (light.type != "head") {
          Fail(q / i / "type",
               fmt::format("light type '{}' is not built in this version (head)", light.type));
        }
        s.lights.push_back(light);
      }
    } else {
      s.lights.push_back(Light{});
    }
    if (!doc.contains("objects")) Fail(root, "missing \"objects\"");
    const auto q = root / "objects";
    if (!doc["objects"].is_array() || doc["objects"].empty())
      Fail(q, "expected a non-empty array of objects");
    std::set<std::string> names;
    for (size_t i = 0; i < doc["objects"].size(); ++i) {
      s.objects.push_back(ReadObject(doc["objects"][i], q / i, i));
      if (!names.insert(s.objects.back().name).second) {
        Fail(q / i / "name", fmt::format("duplicate object name '{}'", s.objects.back().name));
      }
    }
    return s;
  }

 private:
  std::string name_;
  ReadOptions options_;
};

}  // namespace

Scene ReadScene(std::istream& in, const std::string& name, const ReadOptions& options) {
  return Reader(name, options).Read(in);
}

Scene ReadScene(const fs::path& path, const fs::path& shared_data) {
  std::ifstream in(path, std::ios::binary);
  if (!in) core::ThrowFileError("ReadScene", path, "cannot open");
  ReadOptions options;
  options.base_dir = path.parent_path();
  options.shared_data = shared_data;
  return ReadScene(in, path.string(), options);
}

}  // namespace scene
