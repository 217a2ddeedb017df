// The `ibr view` flags that set viewer::ViewerOptions directly.
#pragma once

#include <CLI/CLI.hpp>

#include "apps/viewer/viewer.h"

namespace apps {

void AddViewerFlags(CLI::App* cmd, viewer::ViewerOptions& v);

}  // namespace apps
