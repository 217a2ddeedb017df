// The object-kind registry (ibr/object_kind.h) and the one settings table per
// kind (scene/scene_keys.h): the command-line flags made from a kind's table
// (apps/ibr/kind_flags.h) and the same keys in a scene file give identical
// options, the table's defaults are the options' defaults, and a value outside
// a key's range is refused by both roads with the same message, each naming
// its flag or key.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <any>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "apps/ibr/kind_flags.h"
#include "core/error.h"
#include "ibr/deform_object.h"
#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "ibr/object_kind.h"
#include "ibr/volume_object.h"
#include "scene/scene.h"
#include "scene/scene_keys.h"

namespace ibr {
namespace {

// A non-default value for every key that has a flag, as a scene file writes
// it (the command line gets the same text; a switch is given bare). A flag
// added to a table without a sample here fails the test.
const std::map<std::string, nlohmann::json>& Samples(std::string_view kind) {
  static const std::map<std::string, std::map<std::string, nlohmann::json>> samples = {
      {"deform",
       {{"deformation", "bend,knife"},
        {"amount", "0.3"},
        {"width", "0.4"},
        {"cut", "thick:0.05"},
        {"region", "-0.5,-0.4,-0.5,0.5,0.4,0.5"},
        {"placement", "0.1,0,0,0,30,0,0.9"},
        {"step", "threshold:0.5"},
        {"step_voxels", 0.5},
        {"skip", true},
        {"skip_object", false},
        {"solid", "search"},
        {"resolution", 64},
        {"cap_holes", true},
        {"implicit", "depth-cube"}}},
      {"volume",
       {{"deformation", "peel,twist"},
        {"amount", "0.5,0.25"},
        {"width", "0.2"},
        {"placement", "0.1,0.2,0.3"},
        {"map_size", 32},
        {"mode", "iso:0.5"},
        {"spacing", 0.5},
        {"displacement_bits", 8},
        {"lighting", "gradient"},
        {"jacobian", "differences"}}},
  };
  static const std::map<std::string, nlohmann::json> none;
  const auto it = samples.find(std::string(kind));
  return it == samples.end() ? none : it->second;
}

// The structural keys a kind needs to be read at all.
std::string Skeleton(std::string_view kind) {
  static const std::map<std::string, std::string, std::less<>> skeletons = {
      {"depth-object", R"("images": {"dataset": "maps"})"},
      {"visual-hull", R"("images": {"dataset": "maps"})"},
      {"displaced-mesh", R"("mesh": {"shape": "torus"}, "height": {"generator": "bumps"})"},
      {"mesh", R"("mesh": {"shape": "sphere"})"},
      {"volume", R"("volume": "ball.dat")"},
      {"deform", R"("mesh": {"shape": "sphere"})"},
  };
  return skeletons.find(kind)->second;
}

// The scene road: one object of `kind` with `keys`, read by the scene reader.
scene::Settings FromScene(std::string_view kind, const nlohmann::json& keys) {
  std::string extra;
  for (const auto& [key, value] : keys.items()) extra += ", \"" + key + "\": " + value.dump();
  std::istringstream in(R"({"version": 1, "cameras": {"orbit": {}}, "objects": [{"type": ")" +
                        std::string(kind) + "\", " + Skeleton(kind) + extra + "}]}");
  scene::ReadOptions options;
  options.check_files = false;
  return scene::ReadScene(in, "test.json", options).objects.at(0).settings;
}

// The command-line road: the kind's flags parsed from `line`.
scene::Settings FromFlags(const scene::ObjectKindSpec& kind, const std::string& line) {
  CLI::App app;
  scene::Settings settings;
  apps::AddKindFlags(&app, kind, settings, "cli ");
  app.parse(line, /*program_name_included=*/false);
  return settings;
}

// `value` as a flag on the command line.
std::string Flag(const scene::KeySpec& k, const nlohmann::json& value) {
  const std::string name(k.flag.substr(0, k.flag.find(',')));
  if (k.type == "bool" && k.default_value == "false") return value.get<bool>() ? name : "";
  return name + " " + (value.is_string() ? value.get<std::string>() : value.dump());
}

template <typename... T>
bool SameOptions(const std::any& a, const std::any& b) {
  bool known = !a.has_value() && !b.has_value(), same = known;
  (
      [&] {
        if (a.type() == typeid(T) && b.type() == typeid(T)) {
          known = true;
          same = std::any_cast<const T&>(a) == std::any_cast<const T&>(b);
        }
      }(),
      ...);
  EXPECT_TRUE(known) << "options of an unknown type " << a.type().name();
  return same;
}

bool Same(const std::any& a, const std::any& b) {
  return SameOptions<DeformObjectOptions, VolumeObjectOptions, DisplacedMeshOptions,
                     DepthObjectOptions>(a, b);
}

// The message of the InputError `f` throws ("" and a failure when none).
template <typename F>
std::string Refusal(F&& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "not refused";
  return "";
}

TEST(ObjectKindRegistry, EveryTableHasOneKind) {
  std::set<scene::ObjectType> types;
  for (const ObjectKind* kind : ObjectKinds()) {
    EXPECT_TRUE(types.insert(kind->type()).second) << kind->spec().name << " registered twice";
    EXPECT_EQ(&KindOf(kind->type()), kind);
    EXPECT_EQ(kind->spec().type, kind->type());
  }
  for (const scene::ObjectKindSpec& spec : scene::ObjectKinds()) {
    EXPECT_EQ(types.count(spec.type), 1u) << spec.name << " has no registered kind";
    EXPECT_EQ(&KindOf(spec.type).spec(), &spec);
  }
}

// Keys a kind's other keys need (a volume's amounts need a deformation),
// given on both roads when another key is tested.
nlohmann::json Base(std::string_view kind) {
  if (kind == "volume") return {{"deformation", "twist,peel"}};
  return nlohmann::json::object();
}

const scene::KeySpec& KeyOf(const scene::ObjectKindSpec& spec, const std::string& key) {
  for (const scene::KeySpec& k : spec.keys) {
    if (k.key == key) return k;
  }
  throw std::logic_error("no key " + key);
}

TEST(ObjectKindRegistry, FlagsAndSceneKeysGiveTheSameOptions) {
  for (const ObjectKind* kind : ObjectKinds()) {
    const scene::ObjectKindSpec& spec = kind->spec();
    nlohmann::json all = nlohmann::json::object();
    std::string all_flags;
    for (const scene::KeySpec& k : spec.keys) {
      if (k.flag.empty()) continue;
      const std::string key(k.key);
      SCOPED_TRACE(std::string(spec.name) + " " + key);
      const auto sample = Samples(spec.name).find(key);
      ASSERT_NE(sample, Samples(spec.name).end()) << "no sample value for a flagged key";
      nlohmann::json keys = Base(spec.name);
      std::string flags;
      if (keys.contains(key)) keys = nlohmann::json::object();
      for (const auto& [base_key, value] : keys.items())
        flags += Flag(KeyOf(spec, base_key), value) + " ";
      const std::any base = kind->Options(FromScene(spec.name, keys));
      keys[key] = sample->second;
      flags += Flag(k, sample->second);
      const scene::Settings from_flags = FromFlags(spec, flags);
      const scene::Settings from_scene = FromScene(spec.name, keys);
      ASSERT_TRUE(from_flags.Has(key)) << flags;
      EXPECT_EQ(from_flags.Find(key)->value, from_scene.Find(key)->value);
      const std::any options = kind->Options(from_flags);
      EXPECT_TRUE(Same(options, kind->Options(from_scene))) << flags;
      EXPECT_FALSE(Same(options, base)) << flags << ": the sample changes nothing";
      // Every alias of the flag sets the same key.
      for (size_t at = k.flag.find(','); at != std::string_view::npos;
           at = k.flag.find(',', at + 1)) {
        const std::string alias(k.flag.substr(at + 1, k.flag.find(',', at + 1) - at - 1));
        const std::string line = alias + " " + sample->second.get<std::string>();
        EXPECT_TRUE(Same(kind->Options(FromFlags(spec, line)), options)) << line;
      }
      all[key] = sample->second;
      all_flags += " " + Flag(k, sample->second);
    }
    // All at once.
    if (!all.empty()) {
      SCOPED_TRACE(std::string(spec.name) + all_flags);
      EXPECT_TRUE(Same(kind->Options(FromFlags(spec, all_flags)),
                       kind->Options(FromScene(spec.name, all))));
    }
  }
}

// The written defaults, given as flags and as scene keys, are the options'
// defaults (no key at all), and those are the options struct's own except
// where the kind documents otherwise.
TEST(ObjectKindRegistry, TableDefaultsAreTheOptionsDefaults) {
  for (const ObjectKind* kind : ObjectKinds()) {
    const scene::ObjectKindSpec& spec = kind->spec();
    const std::any defaults = kind->Options({});
    for (const scene::KeySpec& k : spec.keys) {
      // Defaults a user could type (not a description such as "per deformation").
      if (!k.effect || k.default_value.find(' ') != std::string_view::npos ||
          k.default_value == "auto") {
        continue;
      }
      SCOPED_TRACE(std::string(spec.name) + " " + std::string(k.key));
      nlohmann::json value =
          nlohmann::json::parse(k.default_value, nullptr, /*allow_exceptions=*/false);
      if (value.is_discarded()) value = std::string(k.default_value);
      EXPECT_TRUE(
          Same(kind->Options(FromScene(spec.name, {{std::string(k.key), value}})), defaults));
      if (!k.flag.empty()) {
        EXPECT_TRUE(Same(kind->Options(FromFlags(spec, Flag(k, value))), defaults));
      }
    }
  }
  EXPECT_EQ(std::any_cast<VolumeObjectOptions>(KindOf(scene::ObjectType::kVolume).Options({})),
            VolumeObjectOptions{});
  EXPECT_EQ(
      std::any_cast<DisplacedMeshOptions>(KindOf(scene::ObjectType::kDisplacedMesh).Options({})),
      DisplacedMeshOptions{});
  EXPECT_EQ(std::any_cast<DepthObjectOptions>(KindOf(scene::ObjectType::kDepthObject).Options({})),
            DepthObjectOptions{});
  // A deform object's one difference: the documented default deformation, one twist.
  DeformObjectOptions deform;
  core::Deformation twist;
  twist.kind = core::DeformationKindFromName("twist");
  SetDeformationDefaults(twist);
  deform.deformation.terms = {twist};
  EXPECT_EQ(std::any_cast<DeformObjectOptions>(KindOf(scene::ObjectType::kDeform).Options({})),
            deform);
}

// Each end of a key's range is accepted, a value just outside refused: by
// both roads with the same message after the flag or the key's JSON pointer.
TEST(ObjectKindRegistry, OutOfRangeIsRefusedAlikeByBothRoads) {
  int ranged = 0;
  for (const ObjectKind* kind : ObjectKinds()) {
    const scene::ObjectKindSpec& spec = kind->spec();
    for (const scene::KeySpec& k : spec.keys) {
      if (!k.range) continue;
      ++ranged;
      const scene::KeyRange& r = *k.range;
      const bool integer = k.type == "integer";
      const double step = integer ? 1.0 : (r.hi - r.lo) / 1000;
      auto json = [&](double v) {
        return integer ? nlohmann::json(static_cast<int>(v)) : nlohmann::json(v);
      };
      const std::string key(k.key);
      for (const auto& [value, accepted] :
           {std::pair{r.lo, !r.lo_open}, std::pair{r.hi, !r.hi_open}, std::pair{r.lo - step, false},
            std::pair{r.hi + step, false}}) {
        SCOPED_TRACE(fmt::format("{} {} = {}", spec.name, key, json(value).dump()));
        const scene::Settings scene_settings = FromScene(spec.name, {{key, json(value)}});
        if (accepted) {
          EXPECT_NO_THROW(kind->Options(scene_settings));
          if (!k.flag.empty()) {
            EXPECT_NO_THROW(kind->Options(FromFlags(spec, Flag(k, json(value)))));
          }
          continue;
        }
        const std::string scene_where = scene_settings.Find(key)->where;
        const std::string scene_message = Refusal([&] { kind->Options(scene_settings); });
        ASSERT_EQ(scene_message.rfind(scene_where + ": ", 0), 0u) << scene_message;
        EXPECT_NE(scene_where.find("/objects/0/" + key), std::string::npos);
        if (k.flag.empty()) continue;
        const scene::Settings flag_settings = FromFlags(spec, Flag(k, json(value)));
        const std::string flag_where = flag_settings.Find(key)->where;
        EXPECT_EQ(flag_where, "cli " + std::string(k.flag.substr(0, k.flag.find(','))));
        const std::string flag_message = Refusal([&] { kind->Options(flag_settings); });
        ASSERT_EQ(flag_message.rfind(flag_where + ": ", 0), 0u) << flag_message;
        EXPECT_EQ(flag_message.substr(flag_where.size()), scene_message.substr(scene_where.size()));
      }
    }
  }
  EXPECT_GT(ranged, 0);
}

}  // namespace
}  // namespace ibr
