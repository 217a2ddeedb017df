// The memory budget: every step whose allocation grows with the input
// (tessellated truths, distance fields, volumes and their maps, captures,
// textures uploaded for a render) estimates its need before allocating and
// asks here. Past the budget it is refused with one line naming the need, the
// budget and the flag that changes it, so a large input never ends in
// std::bad_alloc, a segfault or the kernel's OOM killer.
//
// The budget is a fraction of physical memory (kDefaultFraction) unless the
// command line's `--memory-budget` or the environment's IBR_MEMORY_BUDGET sets
// it. The process's address-space limit (`ulimit -v`) caps it as well: a need
// that fits the machine but not the limit would still fail to allocate.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace core {

// Half of physical memory: leaves room for the GL driver's own copies
// (llvmpipe keeps textures in system memory) and for the rest of the machine.
inline constexpr double kDefaultMemoryFraction = 0.5;

// "8G", "512M", "1.5GiB", "2000000000" (bytes) or "25%" (of physical memory).
// InputError naming `where` on anything else or on a value <= 0.
std::uint64_t ParseMemorySize(const std::string& text, std::string_view where = "--memory-budget");

// "1.50 GiB", "12.0 MiB", "512 B".
std::string FormatBytes(std::uint64_t bytes);

// Physical memory in bytes (sysconf), 0 where it cannot be read.
std::uint64_t PhysicalMemoryBytes();

// The budget in force: the override if set, else the default fraction of
// physical memory; never above the address-space limit (RLIMIT_AS) less a
// margin for what the process already holds.
std::uint64_t MemoryBudgetBytes();

// Sets (or with nullopt clears) the process-wide override.
void SetMemoryBudget(std::optional<std::uint64_t> bytes);

// Throws InputError "WHERE: WHAT needs N, over the memory budget of B (set
// --memory-budget or IBR_MEMORY_BUDGET to change it)" when `bytes` exceeds
// the budget. `what` names the allocation in the user's terms ("the
// tessellated truth of 'x.obj' (2.1e8 triangles)").
void CheckMemory(std::uint64_t bytes, std::string_view where, std::string_view what);

// True if `bytes` fits the budget (for code that adapts instead of refusing).
bool FitsMemory(std::uint64_t bytes);

}  // namespace core
