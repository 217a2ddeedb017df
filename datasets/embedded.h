// The built-in scene definitions (datasets/scenes/*.json), embedded at build
// time so an installed `ibr` needs no source tree.
#pragma once

#include <span>
#include <string_view>

namespace datasets {

struct EmbeddedFile {
  std::string_view name;    // file name, e.g. "spot-cube.json"
  std::string_view source;  // the file's bytes
};

std::span<const EmbeddedFile> EmbeddedFiles();

}  // namespace datasets
