#include "apps/viewer/transfer_function_panel.h"

#include <imgui.h>

#include <algorithm>
#include <string>

namespace viewer {
namespace {

ImU32 Colour(const glm::dvec4& rgba, float alpha = 1.0f) {
  return ImGui::ColorConvertFloat4ToU32(ImVec4(
      static_cast<float>(rgba.r), static_cast<float>(rgba.g), static_cast<float>(rgba.b), alpha));
}

}  // namespace

bool DrawTransferFunctionPanel(TransferEditor& editor, const Histogram& h,
                               TransferPanelState& state) {
  bool changed = false;
  const std::vector<std::string> presets = EditorPresetNames();
  if (ImGui::BeginCombo("preset", "choose...")) {
    for (const std::string& name : presets) {
      if (ImGui::Selectable(name.c_str())) {
        editor.ApplyPreset(name);
        state = {};
        changed = true;
      }
    }
    ImGui::EndCombo();
  }
  // The canvas: x the stored value over the histogram's range, y opacity.
  const float width = std::max(ImGui::GetContentRegionAvail().x, 100.0f), height = 110;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("tf_canvas", ImVec2(width, height),
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight);
  const auto x_of = [&](double v) {
    return origin.x + static_cast<float>((v - h.lo) / (h.hi - h.lo)) * width;
  };
  const auto y_of = [&](double a) { return origin.y + static_cast<float>(1 - a) * height; };
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  const double mouse_value = h.lo + (mouse.x - origin.x) / width * (h.hi - h.lo);
  const double mouse_opacity = 1.0 - (mouse.y - origin.y) / height;
  // Picking within 6 pixels.
  const glm::dvec2 scale((h.hi - h.lo) / width, 1.0 / height);
  if (ImGui::IsItemClicked(ImGuiMouseButton_Left)) {
    state.selected = editor.Pick(mouse_value, mouse_opacity, scale, 6.0);
    if (!state.selected) {
      state.selected = editor.AddPoint(mouse_value, mouse_opacity);
      changed = true;
    }
    state.dragging = true;
  }
  if (state.dragging && state.selected && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
    const core::TransferPoint before = editor.transfer().points[*state.selected];
    editor.MovePoint(*state.selected, mouse_value, mouse_opacity);
    changed |= !(editor.transfer().points[*state.selected] == before);
  } else {
    state.dragging = false;
  }
  if (ImGui::IsItemClicked(ImGuiMouseButton_Right)) {
    if (const auto i = editor.Pick(mouse_value, mouse_opacity, scale, 6.0)) {
      changed |= editor.DeletePoint(*i);
      state = {};
    }
  }

  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->AddRectFilled(origin, ImVec2(origin.x + width, origin.y + height),
                      IM_COL32(20, 20, 24, 255));
  const float bin_w = width / static_cast<float>(h.counts.size());
  for (size_t i = 0; i < h.counts.size(); ++i) {
    const float x = origin.x + static_cast<float>(i) * bin_w;
    const float top = y_of(h.LogHeight(i));
    draw->AddRectFilled(ImVec2(x, top), ImVec2(x + std::max(bin_w, 1.0f), origin.y + height),
                        IM_COL32(90, 90, 100, 255));
  }
  const core::TransferFunction& tf = editor.transfer();
  draw->PushClipRect(origin, ImVec2(origin.x + width, origin.y + height), true);
  // The opacity curve, constant beyond the ends.
  ImVec2 last(origin.x, y_of(tf.points.front().rgba.a));
  for (const core::TransferPoint& p : tf.points) {
    const ImVec2 q(x_of(p.s), y_of(p.rgba.a));
    draw->AddLine(last, q, IM_COL32(230, 230, 230, 255), 1.5f);
    last = q;
  }
  draw->AddLine(last, ImVec2(origin.x + width, last.y), IM_COL32(230, 230, 230, 255), 1.5f);
  for (size_t i = 0; i < tf.points.size(); ++i) {
    const ImVec2 q(x_of(tf.points[i].s), y_of(tf.points[i].rgba.a));
    draw->AddCircleFilled(q, 5, Colour(tf.points[i].rgba));
    draw->AddCircle(q, 5,
                    state.selected == i ? IM_COL32(255, 220, 0, 255) : IM_COL32(255, 255, 255, 255),
                    0, state.selected == i ? 2.0f : 1.0f);
  }
  draw->PopClipRect();
  // The colour the function gives each value (opacity as brightness of the
  // band's lower half would hide the colour: the band shows colour alone).
  const ImVec2 band(origin.x, origin.y + height + 2);
  for (int i = 0; i < static_cast<int>(width); ++i) {
    const double v = h.lo + (i + 0.5) / width * (h.hi - h.lo);
    draw->AddRectFilled(ImVec2(band.x + static_cast<float>(i), band.y),
                        ImVec2(band.x + static_cast<float>(i) + 1, band.y + 8),
                        Colour(tf.Evaluate(v)));
  }
  ImGui::Dummy(ImVec2(width, 12));
  ImGui::Text("data %.5g .. %.5g (histogram: log counts)", h.lo, h.hi);

  if (state.selected && *state.selected < tf.points.size()) {
    const core::TransferPoint& p = tf.points[*state.selected];
    float rgb[3] = {static_cast<float>(p.rgba.r), static_cast<float>(p.rgba.g),
                    static_cast<float>(p.rgba.b)};
    ImGui::Text("point %zu: value %.5g, opacity %.3f", *state.selected, p.s, p.rgba.a);
    if (ImGui::ColorEdit3("colour", rgb)) {
      editor.SetColour(*state.selected, glm::dvec3(rgb[0], rgb[1], rgb[2]));
      changed = true;
    }
  }
  // Window/level in stored units (also Ctrl + left drag over the frame).
  const WindowLevel wl = editor.window();
  float level = static_cast<float>(wl.centre), window = static_cast<float>(wl.width);
  const float speed = static_cast<float>((h.hi - h.lo) / 500);
  const bool level_moved = ImGui::DragFloat("level", &level, speed, 0, 0, "%.5g");
  const bool window_moved = ImGui::DragFloat("window", &window, speed, speed, 0, "%.5g");
  if ((level_moved || window_moved) && tf.points.size() > 1) {
    editor.SetWindow(
        {level_moved ? level : wl.centre, window_moved ? std::max(window, speed) : wl.width});
    changed = true;
  }
  return changed;
}

}  // namespace viewer
