#include "ibr/scene_options.h"

#include "core/error.h"

namespace ibr {

DepthObjectOptions DepthObjectOptionsFromJson(const nlohmann::json& render,
                                              const std::string& where) {
  DepthObjectOptions o;
  try {
    if (render.contains("method"))
      o.method = MethodFromName(render.at("method").get<std::string>());
    if (render.contains("slicing"))
      o.slicing = SlicingFromName(render.at("slicing").get<std::string>());
    if (render.contains("texturing"))
      o.texturing = TexturingFromName(render.at("texturing").get<std::string>());
    if (render.contains("slices")) {
      // "auto" or a count >= 1 (a literal 0 is not a spelling of auto).
      const nlohmann::json& v = render.at("slices");
      o.slices = v.is_string() ? SliceCountFromName(v.get<std::string>())
                               : SliceCountFromName(std::to_string(v.get<int>()));
    }
    if (render.contains("robust")) o.robust_k = render.at("robust").get<int>();
  } catch (const nlohmann::json::exception& e) {
    core::ThrowInputError(where, "bad render options: {}", e.what());
  } catch (const core::InputError& e) {
    core::ThrowInputError(where, "{}", e.what());
  }
  o.Check();
  return o;
}

}  // namespace ibr
