// GL error reporting: the KHR_debug callback (debug builds) routes driver
// messages to spdlog; DrainGlErrors() is what tests call at the end
// (ExpectNoGlError in tests/support).
#pragma once

#include <string>

namespace render {

// Installs the KHR_debug callback on the current context. Returns false when
// the context offers no KHR_debug.
bool InstallDebugCallback();

// Pops every pending glGetError() and returns their names, comma-separated
// ("" when there were none).
std::string DrainGlErrors();

}  // namespace render
