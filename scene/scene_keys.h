// The keys a scene object takes, per object type: one table that the scene
// reader checks objects against (a key outside it is an error naming the
// allowed ones), that `ibr info --scene-keys` prints and that
// docs/guide/scene-format.md includes (tests/scene/scene_keys_test.cc keeps
// the guide equal to it), so the documented keys cannot drift from the read
// ones. The effect keys' values are checked where they become options
// structs (ibr/scene_options.h, ibr/volume_object.h, ibr/deform_object.h);
// tests/ibr/scene_keys_defaults_test.cc checks the defaults written here
// against what those parsers do without the key.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace scene {

struct KeySpec {
  std::string_view key;
  std::string_view type;           // "string", "integer", "number", "bool", "object", ...
  std::string_view default_value;  // as a user would write it; "" = required or none
  std::string_view help;           // meaning, unit and allowed values
  bool effect = true;              // an effect option (kept as scene::Settings) or a structural key
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

// The tables as Markdown (one section per kind), for the scene-format guide.
std::string ObjectKeysMarkdown();

}  // namespace scene
