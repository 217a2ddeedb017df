// The one mapping from option names to options structs, shared by the
// command line (`ibr render`, `ibr view`: flags -> scene::Settings with
// where = "--flag") and scene files (scene/scene.h: where = the file and the
// JSON pointer). Errors name `where`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "scene/scene.h"

namespace ibr {

// Keys: method (depth-object | visual-hull), slicing (orthogonal | screen |
// ray), slice_path (exact | fast), slices (a count or "auto"), texturing (vdt | vdt-paper |
// visibility | none), robust (k), outside (pass | fail), invalid_depth (empty | no-constraint),
// refine_steps, max_maps (0 = every map, else the nearest that many:
// DepthObjectOptions::max_maps), depth_lookup (nearest | subtexel:
// DepthObjectOptions::subtexel_depth; missing: subtexel for ray-path depth
// objects, nearest elsewhere, where only nearest applies). Missing
// keys keep DepthObjectOptions' defaults.
DepthObjectOptions DepthObjectOptionsFrom(const scene::Settings& settings);

// Keys: method (DisplacementMethodNames()), max_displacement, tiling, slices, steps.
DisplacedMeshOptions DisplacedMeshOptionsFrom(const scene::Settings& settings);

// The command line's depth-object flags as settings (where = "--flag").
struct DepthObjectFlags {
  std::string method = "depth-object";
  // The ray path (one pass per pixel, empty-space skipping, sub-texel
  // depth): the fastest and smoothest, for `ibr render` and `ibr view` alike.
  std::string slicing = "ray";
  std::string slices = "auto";       // "auto" (sec. 3.4: one slice per depth texel) or a count
  std::string slice_path = "exact";  // "exact" (the stencil passes) or "fast" (one draw)
  int robust = 0;
  std::string texturing = "vdt";
  // Empty: the command chooses from the cameras' coverage
  // (ibr::ChooseOutsidePolicy); "pass" or "fail" as given.
  std::string outside;
  std::string invalid_depth = "empty";
  int max_maps = 0;          // 0 = every map
  std::string depth_lookup;  // "nearest", "subtexel", or empty: subtexel where it applies
};
scene::Settings SettingsFromFlags(const DepthObjectFlags& flags);

// A built-in scene's render options as a JSON object (the keys above); where
// = `where` + the key.
DepthObjectOptions DepthObjectOptionsFromJson(const nlohmann::json& render,
                                              const std::string& where);

}  // namespace ibr
