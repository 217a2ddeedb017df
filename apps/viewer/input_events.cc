#include "apps/viewer/input_events.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/atomic_file.h"
#include "core/enum_names.h"
#include "core/error.h"

namespace viewer {
namespace {
using nlohmann::json;

constexpr int kVersion = 1;

constexpr core::EnumName<InputEvent::Type> kTypeNames[] = {
    {InputEvent::Type::kMove, "move"},
    {InputEvent::Type::kButton, "button"},
    {InputEvent::Type::kScroll, "scroll"},
    {InputEvent::Type::kKey, "key"},
};
constexpr core::EnumName<InputEvent::Action> kActionNames[] = {
    {InputEvent::Action::kRelease, "release"},
    {InputEvent::Action::kPress, "press"},
    {InputEvent::Action::kRepeat, "repeat"},
};

// Walks the document; errors name the file and the JSON pointer.
class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void Fail(const json::json_pointer& p, const std::string& what) const {
    throw core::InputError(
        fmt::format("ReadRecording: '{}' {}: {}", name_, p.empty() ? "/" : p.to_string(), what));
  }
  const json& Get(const json& j, const json::json_pointer& p, const char* key) const {
    if (!j.contains(key)) Fail(p, fmt::format("missing \"{}\"", key));
    return j[key];
  }
  double Number(const json& j, const json::json_pointer& p) const {
    if (!j.is_number() || !std::isfinite(j.get<double>())) Fail(p, "expected a finite number");
    return j.get<double>();
  }
  int Int(const json& j, const json::json_pointer& p, int lo, int hi) const {
    if (!j.is_number_integer() || j.get<int64_t>() < lo || j.get<int64_t>() > hi)
      Fail(p, fmt::format("expected an integer in {}..{}", lo, hi));
    return j.get<int>();
  }

  InputRecording Read(std::istream& in) const {
    json doc;
    try {
      doc = json::parse(in);
    } catch (const json::exception& e) {
      throw core::InputError(fmt::format("ReadRecording: '{}': not JSON: {}", name_, e.what()));
    }
    const json::json_pointer root;
    if (!doc.is_object()) Fail(root, "expected an object");
    if (Int(Get(doc, root, "version"), root / "version", 0, 1 << 30) != kVersion)
      Fail(root / "version", fmt::format("this build reads version {}", kVersion));
    InputRecording r;
    const json& window = Get(doc, root, "window");
    if (!window.is_array() || window.size() != 2) Fail(root / "window", "expected [W, H]");
    r.width = Int(window[0], root / "window" / 0, 64, 8192);
    r.height = Int(window[1], root / "window" / 1, 64, 8192);
    r.azimuth_deg = static_cast<float>(Number(Get(doc, root, "azimuth_deg"), root / "azimuth_deg"));
    r.elevation_deg =
        static_cast<float>(Number(Get(doc, root, "elevation_deg"), root / "elevation_deg"));
    if (doc.contains("panel")) {
      if (!doc["panel"].is_boolean()) Fail(root / "panel", "expected true or false");
      r.panel = doc["panel"].get<bool>();
    }
    const json& events = Get(doc, root, "events");
    if (!events.is_array()) Fail(root / "events", "expected an array");
    for (size_t i = 0; i < events.size(); ++i) {
      const json::json_pointer p = root / "events" / i;
      const json& e = events[i];
      if (!e.is_object()) Fail(p, "expected an object");
      InputEvent event;
      event.frame = Int(Get(e, p, "frame"), p / "frame", 0, 1 << 30);
      if (!r.events.empty() && event.frame < r.events.back().frame)
        Fail(p / "frame", "frames must not decrease");
      if (e.contains("t")) event.t = Number(e["t"], p / "t");
      const json& type = Get(e, p, "type");
      const std::string t = type.is_string() ? type.get<std::string>() : "";
      if (t == "move" || t == "scroll") {
        event.type = t == "move" ? InputEvent::Type::kMove : InputEvent::Type::kScroll;
        const char* kx = t == "move" ? "x" : "dx";
        const char* ky = t == "move" ? "y" : "dy";
        event.x = Number(Get(e, p, kx), p / kx);
        event.y = Number(Get(e, p, ky), p / ky);
      } else if (t == "button" || t == "key") {
        event.type = t == "button" ? InputEvent::Type::kButton : InputEvent::Type::kKey;
        const char* kc = t == "button" ? "button" : "key";
        event.code = Int(Get(e, p, kc), p / kc, t == "button" ? 0 : 32,
                         t == "button" ? 7 : 348);  // GLFW's ranges
        const json& action = Get(e, p, "action");
        const std::optional<InputEvent::Action> a =
            action.is_string() ? core::FindEnum(kActionNames, action.get<std::string>())
                               : std::nullopt;
        if (!a || (*a == InputEvent::Action::kRepeat && t != "key")) {
          Fail(p / "action",
               t == "key" ? "expected press, release or repeat" : "expected press or release");
        }
        event.action = *a;
        if (e.contains("mods")) event.mods = Int(e["mods"], p / "mods", 0, 63);
      } else {
        Fail(p / "type", "expected move, button, scroll or key");
      }
      r.events.push_back(event);
    }
    return r;
  }

 private:
  std::string name_;
};

}  // namespace

void WriteRecording(std::ostream& out, const InputRecording& r) {
  json events = json::array();
  for (const InputEvent& e : r.events) {
    json j = {{"frame", e.frame}, {"t", e.t}, {"type", core::EnumToName(kTypeNames, e.type)}};
    switch (e.type) {
      case InputEvent::Type::kMove:
        j["x"] = e.x, j["y"] = e.y;
        break;
      case InputEvent::Type::kScroll:
        j["dx"] = e.x, j["dy"] = e.y;
        break;
      case InputEvent::Type::kButton:
      case InputEvent::Type::kKey:
        j[e.type == InputEvent::Type::kButton ? "button" : "key"] = e.code;
        j["action"] = core::EnumToName(kActionNames, e.action);
        j["mods"] = e.mods;
        break;
    }
    events.push_back(j);
  }
  const json doc = {{"version", kVersion},
                    {"window", {r.width, r.height}},
                    {"azimuth_deg", r.azimuth_deg},
                    {"elevation_deg", r.elevation_deg},
                    {"panel", r.panel},
                    {"events", events}};
  // One event a line: a recording stays readable and diffable.
  out << "{\n";
  for (const char* key : {"version", "window", "azimuth_deg", "elevation_deg", "panel"})
    out << fmt::format("  \"{}\": {},\n", key, doc[key].dump());
  out << "  \"events\": [";
  for (size_t i = 0; i < events.size(); ++i) out << (i ? ",\n    " : "\n    ") << events[i].dump();
  out << (events.empty() ? "]\n}\n" : "\n  ]\n}\n");
}

void WriteRecording(const std::filesystem::path& path, const InputRecording& recording) {
  core::AtomicWriteStream(path, [&](std::ostream& out) { WriteRecording(out, recording); });
}

InputRecording ReadRecording(std::istream& in, const std::string& name) {
  return Reader(name).Read(in);
}

InputRecording ReadRecording(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) core::ThrowFileError("ReadRecording", path, "cannot open");
  return ReadRecording(in, path.string());
}

}  // namespace viewer
