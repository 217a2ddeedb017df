// libFuzzer target: the PLY mesh reader (core/ply_io.h) on arbitrary bytes:
// ascii and binary bodies, triangle strips, lists whose lengths lie. It has no
// writer, so only a clean rejection (core::InputError) or a mesh that passes
// its own validation are acceptable outcomes.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/memory_budget.h"
#include "core/ply_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A budget below -rss_limit_mb: a header claiming a huge mesh is refused by
  // the budget check, which is part of what is tested.
  core::SetMemoryBudget(uint64_t{512} << 20);
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const core::PlyMesh mesh = core::ReadPly(in, "fuzz.ply");
    mesh.mesh.Validate("fuzz.ply");
  } catch (const core::InputError&) {
  }
  return 0;
}
