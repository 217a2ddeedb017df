// Rendering options from a built-in scene's "render" object
// (datasets/scenes/*.json): the same names as `ibr render`'s options.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "ibr/depth_object.h"

namespace ibr {

// Keys: method, slicing, slices (a count or "auto"), texturing, robust (all optional; defaults are
// DepthObjectOptions'). InputError naming `where` and the key on a bad value.
DepthObjectOptions DepthObjectOptionsFromJson(const nlohmann::json& render,
                                              const std::string& where);

}  // namespace ibr
