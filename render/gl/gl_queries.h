// Small questions to the current GL context and its queue, for code outside
// render/ that measures or reports (benches, the viewer, `ibr verify`): they
// keep raw GL calls inside render/.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace render {

// glFinish: returns once every GL command issued so far has run, so a wall
// clock started or stopped here measures GPU work, not queued commands.
void WaitForGpu();

// The GL work `draw` issues, counted by queries around it (untimed): what
// time ratios of equal work should agree with.
struct DrawWork {
  uint64_t samples_passed = 0;        // GL_SAMPLES_PASSED: fragments past every test
  uint64_t primitives_generated = 0;  // GL_PRIMITIVES_GENERATED
};
DrawWork CountDrawWork(const std::function<void()>& draw);

// "RENDERER / VERSION" of the current context, as reports name the driver.
std::string CurrentDriverName();
// GL_SUBPIXEL_BITS of the current context: the rasteriser's vertex snapping.
int CurrentSubpixelBits();

}  // namespace render
