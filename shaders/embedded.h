// The shader sources embedded at build time (see shaders/CMakeLists.txt).
#pragma once

#include <span>
#include <string_view>

namespace shaders {

struct EmbeddedFile {
  std::string_view name;    // path relative to shaders/, e.g. "passes/mesh.frag.glsl"
  std::string_view source;  // the file's bytes
};

std::span<const EmbeddedFile> EmbeddedFiles();

}  // namespace shaders
