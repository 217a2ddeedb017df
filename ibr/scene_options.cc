#include "ibr/scene_options.h"

#include "core/error.h"

namespace ibr {

DepthObjectOptions DepthObjectOptionsFromJson(const nlohmann::json& render, const std::string& where) {
  DepthObjectOptions o;
  try {
    if (render.contains("method")) o.method = MethodFromName(render.at("method").get<std::string>());
    if (render.contains("slicing")) o.slicing = SlicingFromName(render.at("slicing").get<std::string>());
    if (render.contains("texturing")) o.texturing = TexturingFromName(render.at("texturing").get<std::string>());
    if (render.contains("slices")) o.slices = render.at("slices").get<int>();
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
