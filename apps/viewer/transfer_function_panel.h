// The transfer-function editor's ImGui drawing (its model, CPU only, is
// apps/viewer/transfer_function_editor.h): the histogram (log counts) behind
// the opacity curve, the control points (left click: add or pick and drag;
// right click: delete), the selected point's colour, the presets, and
// window/level as two fields.
#pragma once

#include <cstddef>
#include <optional>

#include "apps/viewer/transfer_function_editor.h"

namespace viewer {

struct TransferPanelState {
  std::optional<size_t> selected;  // the point the colour field edits
  bool dragging = false;           // a left drag of `selected` in the canvas
};

// Inside an ImGui window; true when the editor's function changed.
bool DrawTransferFunctionPanel(TransferEditor& editor, const Histogram& histogram,
                               TransferPanelState& state);

}  // namespace viewer
