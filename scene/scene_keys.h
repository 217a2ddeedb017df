// The keys a scene object takes, per object kind: one table that the scene
// reader checks objects against (a key outside it is an error naming the
// allowed ones), that `ibr info --scene-keys` prints and that
// docs/guide/scene-format.md includes (tests/scene/scene_keys_test.cc keeps
// the guide equal to it), and that makes the kinds' command-line flags
// (apps/ibr/kind_flags.h), so the documented, read and flagged keys cannot
// drift apart. It lives here, below ibr/, so the reader needs no GL library;
// each kind of ibr/kinds/ reaches its table by its type
// (docs/decisions/object-kinds.md). The values are checked where they become
// options structs (the kind's Options); tests/ibr/scene_keys_defaults_test.cc
// and tests/ibr/object_kind_registry_test.cc check the defaults and ranges
// written here against them.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace scene {

// An inclusive numeric range (the bounds themselves are accepted unless open).
struct KeyRange {
  double lo = 0, hi = 0;
  bool lo_open = false, hi_open = false;
};

struct KeySpec {
  std::string_view key;
  std::string_view type;           // "string", "integer", "number", "bool", "object", ...
  std::string_view default_value;  // as a user would write it; "" = required or none
  std::string_view help;           // meaning, unit and allowed values
  bool effect = true;              // an effect option (kept as scene::Settings) or a structural key
  // The command-line flag that sets this key (CLI11 names, "--a,--b" for an
  // alias), empty when no command takes it; apps/ibr/kind_flags.h adds it.
  // A "bool" key whose default is "false" is a switch, any other key takes a
  // value; "list" types take repeated or comma-separated values.
  std::string_view flag = {};
  // The values the options function accepts, when numeric (the registry test
  // checks both ends against it).
  std::optional<KeyRange> range = std::nullopt;
};

struct ObjectKindSpec {
  std::string_view name;  // the "type" value
  ObjectType type;
  std::string_view source;  // the paper section it implements, or what it is
  std::vector<KeySpec> keys;
};

// Keys every object takes.
const std::vector<KeySpec>& CommonObjectKeys();
// Every object type, in the order the guide lists them.
const std::vector<ObjectKindSpec>& ObjectKinds();
// The kind named `name`, or nullptr.
const ObjectKindSpec* FindObjectKind(std::string_view name);

// "[lo, hi]", with "(" / ")" for an open end.
std::string RangeText(const KeyRange& range);

// The tables as Markdown (one section per kind), for the scene-format guide.
std::string ObjectKeysMarkdown();

}  // namespace scene
