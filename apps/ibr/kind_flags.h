// An object kind's command-line flags, made from its settings table
// (scene::ObjectKindSpec, scene/scene_keys.h: each key's `flag`), so a command
// and a scene file read one table: a given flag's value goes straight into
// scene::Settings under the key, as the scene reader puts a scene file's value
// there (the same JSON type: a number for "number" and "integer" keys, a bool
// for "bool" keys, a comma-joined string for the list keys), and the kind's
// options function (e.g. ibr::DeformObjectOptionsFrom) reads both alike.
// A flag not given sets nothing: the key's default applies, as in a scene.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "scene/scene.h"
#include "scene/scene_keys.h"

namespace apps {

// Adds a flag to `cmd` for every key of `kind` that has one; a value refused
// later names `where_prefix` + the flag's first name (e.g. "ibr volume
// --map-size"). `settings` must outlive the parse.
void AddKindFlags(CLI::App* cmd, const scene::ObjectKindSpec& kind, scene::Settings& settings,
                  const std::string& where_prefix = "");

}  // namespace apps
