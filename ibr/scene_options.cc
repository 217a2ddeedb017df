#include "ibr/scene_options.h"

#include "core/error.h"
#include "render/cores/ray_core.h"

namespace ibr {
namespace {

// A parser's message without its leading "Function: " (the caller names where).
std::string WithoutWhere(const core::InputError& e) {
  const std::string what = e.what();
  const size_t colon = what.find(": ");
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

// Runs `parse` on the setting's string; its InputError is re-thrown naming where.
template <typename Parse>
auto Named(const scene::Settings& s, const std::string& key, const std::string& fallback,
           Parse parse) {
  const std::string text = s.GetString(key, fallback);
  try {
    return parse(text);
  } catch (const core::InputError& e) {
    s.Fail(key, WithoutWhere(e));
  }
}

// `check` throws InputError naming the option struct; re-thrown naming the first key given.
template <typename Options>
void CheckNamed(const Options& o, const scene::Settings& s) {
  try {
    o.Check();
  } catch (const core::InputError& e) {
    const std::string where =
        s.values().empty() ? std::string("options") : s.values().begin()->second.where;
    throw core::InputError(fmt::format("{}: {}", where, e.what()));
  }
}

}  // namespace

DepthObjectOptions DepthObjectOptionsFrom(const scene::Settings& s) {
  DepthObjectOptions o;
  o.method = Named(s, "method", MethodName(o.method), MethodFromName);
  o.slicing = Named(s, "slicing", SlicingName(o.slicing), SlicingFromName);
  o.slice_path = Named(s, "slice_path", SlicePathName(o.slice_path), SlicePathFromName);
  o.texturing = Named(s, "texturing", TexturingName(o.texturing), TexturingFromName);
  // "auto" or a count (a literal 0 is not a spelling of auto).
  if (const scene::Setting* v = s.Find("slices"); v != nullptr && v->value.is_string()) {
    o.slices = Named(s, "slices", "auto", SliceCountFromName);
  } else if (v != nullptr) {
    const int n = s.GetInt("slices", 0);
    try {
      o.slices = SliceCountFromName(std::to_string(n));
    } catch (const core::InputError& e) {
      s.Fail("slices", WithoutWhere(e));
    }
  }
  o.robust_k = s.GetInt("robust", o.robust_k);
  if (o.robust_k < 0) s.Fail("robust", fmt::format("robust k {} must be >= 0", o.robust_k));
  o.max_maps = s.GetInt("max_maps", o.max_maps);
  if (o.max_maps < 0 || o.max_maps > kMaxMaps) {
    s.Fail("max_maps", fmt::format("{} maps outside 0..{} (0 = all)", o.max_maps, kMaxMaps));
  }
  o.refine_steps = s.GetInt("refine_steps", o.refine_steps);
  if (o.refine_steps < 0 || o.refine_steps > render::kMaxRayRefineSteps) {
    s.Fail("refine_steps", fmt::format("{} refine steps outside 0..{}", o.refine_steps,
                                       render::kMaxRayRefineSteps));
  }
  // Sub-texel depth where it applies (ray-path depth objects): nearest texels
  // leave a staircase a texel deep along slopes, which `ibr bench
  // depth-object` shows in p95 depth error and silhouette IoU; the sub-texel
  // lookup removes it at the price of more work a sample, which accuracy is
  // worth as the default (docs/decisions/subtexel-depth.md). The slice passes
  // test nearest texels only.
  const bool subtexel_applies = o.method == Method::kDepthObject && o.slicing == Slicing::kRay;
  const std::string lookup =
      Named(s, "depth_lookup", subtexel_applies ? "subtexel" : "nearest", [](const std::string& t) {
        if (t != "nearest" && t != "subtexel")
          core::ThrowInputError("depth_lookup", "unknown lookup '{}' (nearest, subtexel)", t);
        return t;
      });
  if (lookup == "subtexel" && !subtexel_applies) {
    s.Fail("depth_lookup",
           "subtexel needs a depth object on the ray path (slicing ray); the slice passes and "
           "visual hulls test nearest texels");
  }
  o.subtexel_depth = lookup == "subtexel";
  o.outside = Named(s, "outside", "pass", [](const std::string& t) {
    return core::EnumFromName(kOutsidePolicyNames, t, "outside", "policy");
  });
  o.invalid_depth = Named(s, "invalid_depth", "empty", [](const std::string& t) {
    return core::EnumFromName(kInvalidDepthPolicyNames, t, "invalid_depth", "policy");
  });
  CheckNamed(o, s);
  return o;
}

DisplacedMeshOptions DisplacedMeshOptionsFrom(const scene::Settings& s) {
  DisplacedMeshOptions o;
  o.method = Named(s, "method", DisplacementMethodName(o.method), DisplacementMethodFromName);
  o.max_displacement = static_cast<float>(s.GetDouble("max_displacement", o.max_displacement));
  if (!(o.max_displacement > 0 && o.max_displacement <= 10)) {
    s.Fail("max_displacement", fmt::format("{} outside (0, 10]", o.max_displacement));
  }
  o.tiling = static_cast<float>(s.GetDouble("tiling", o.tiling));
  if (!(o.tiling > 0 && o.tiling <= 1024))
    s.Fail("tiling", fmt::format("{} outside (0, 1024]", o.tiling));
  o.slices = s.GetInt("slices", o.slices);
  if (o.slices < 1 || o.slices > 4096)
    s.Fail("slices", fmt::format("{} outside 1..4096", o.slices));
  o.steps = s.GetInt("steps", o.steps);
  if (o.steps < 1 || o.steps > 4096) s.Fail("steps", fmt::format("{} outside 1..4096", o.steps));
  CheckNamed(o, s);
  return o;
}

scene::Settings SettingsFromFlags(const DepthObjectFlags& f) {
  scene::Settings s;
  s.Set("method", f.method, "--method");
  s.Set("slicing", f.slicing, "--slicing");
  s.Set("slices", f.slices, "--slices");
  s.Set("slice_path", f.slice_path, "--slice-path");
  s.Set("robust", f.robust, "--robust");
  s.Set("texturing", f.texturing, "--texturing");
  if (!f.outside.empty()) s.Set("outside", f.outside, "--outside");
  s.Set("invalid_depth", f.invalid_depth, "--invalid-depth");
  s.Set("max_maps", f.max_maps, "--max-maps");
  if (!f.depth_lookup.empty()) s.Set("depth_lookup", f.depth_lookup, "--depth-lookup");
  return s;
}

DepthObjectOptions DepthObjectOptionsFromJson(const nlohmann::json& render,
                                              const std::string& where) {
  if (!render.is_object()) core::ThrowInputError(where, "render options must be an object");
  scene::Settings s;
  for (const auto& [key, value] : render.items()) s.Set(key, value, where + " /" + key);
  return DepthObjectOptionsFrom(s);
}

}  // namespace ibr
