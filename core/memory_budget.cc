#include "core/memory_budget.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdlib>

#include "core/error.h"

namespace core {
namespace {

// 0 = no override.
std::atomic<std::uint64_t> g_override{0};

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::uint64_t ParseMemorySize(const std::string& text, std::string_view where) {
  const std::string t = Lower(text);
  size_t end = 0;
  double value = 0;
  try {
    value = std::stod(t, &end);
  } catch (const std::exception&) {
    ThrowInputError(where, "'{}' is not a memory size (e.g. 8G, 512M, 25%)", text);
  }
  std::string unit = t.substr(end);
  while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
  double scale = 1;
  if (unit.empty() || unit == "b") {
    scale = 1;
  } else if (unit == "%") {
    const std::uint64_t physical = PhysicalMemoryBytes();
    if (physical == 0) ThrowInputError(where, "'{}': physical memory unknown here", text);
    scale = static_cast<double>(physical) / 100.0;
  } else if (unit == "k" || unit == "kb" || unit == "kib") {
    scale = 1024.0;
  } else if (unit == "m" || unit == "mb" || unit == "mib") {
    scale = 1024.0 * 1024.0;
  } else if (unit == "g" || unit == "gb" || unit == "gib") {
    scale = 1024.0 * 1024.0 * 1024.0;
  } else if (unit == "t" || unit == "tb" || unit == "tib") {
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  } else {
    ThrowInputError(where, "'{}': unknown unit '{}' (B, K, M, G, T or %)", text, unit);
  }
  const double bytes = value * scale;
  if (!std::isfinite(bytes) || bytes < 1.0 || bytes > 1.8e19) {
    ThrowInputError(where, "'{}' is not a positive memory size", text);
  }
  return static_cast<std::uint64_t>(bytes);
}

std::string FormatBytes(std::uint64_t bytes) {
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024.0 * 1024.0 * 1024.0)
    return fmt::format("{:.2f} TiB", b / (1024.0 * 1024.0 * 1024.0 * 1024.0));
  if (b >= 1024.0 * 1024.0 * 1024.0)
    return fmt::format("{:.2f} GiB", b / (1024.0 * 1024.0 * 1024.0));
  if (b >= 1024.0 * 1024.0) return fmt::format("{:.1f} MiB", b / (1024.0 * 1024.0));
  if (b >= 1024.0) return fmt::format("{:.1f} KiB", b / 1024.0);
  return fmt::format("{} B", bytes);
}

std::uint64_t PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 0;
  return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
}

std::uint64_t MemoryBudgetBytes() {
  std::uint64_t budget = g_override.load();
  if (budget == 0) {
    if (const char* env = std::getenv("IBR_MEMORY_BUDGET"); env != nullptr && *env != '\0') {
      budget = ParseMemorySize(env, "IBR_MEMORY_BUDGET");
    }
  }
  if (budget == 0) {
    const std::uint64_t physical = PhysicalMemoryBytes();
    // Unknown physical memory: a budget that refuses nothing a 64-bit
    // allocator could serve is still bounded by RLIMIT_AS below.
    budget =
        physical > 0
            ? static_cast<std::uint64_t>(kDefaultMemoryFraction * static_cast<double>(physical))
            : (std::uint64_t{1} << 40);
  }
  // An address-space limit (ulimit -v) counts mappings, not residency: the
  // binary, its libraries and the GL driver already take some of it, so keep
  // a quarter of the limit for them.
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const auto usable = static_cast<std::uint64_t>(0.75 * static_cast<double>(limit.rlim_cur));
    if (usable < budget) budget = usable;
  }
  return budget;
}

void SetMemoryBudget(std::optional<std::uint64_t> bytes) { g_override.store(bytes.value_or(0)); }

bool FitsMemory(std::uint64_t bytes) { return bytes <= MemoryBudgetBytes(); }

void CheckMemory(std::uint64_t bytes, std::string_view where, std::string_view what) {
  const std::uint64_t budget = MemoryBudgetBytes();
  if (bytes <= budget) return;
  ThrowInputError(where,
                  "{} needs {}, over the memory budget of {} (set --memory-budget or "
                  "IBR_MEMORY_BUDGET to change it)",
                  what, FormatBytes(bytes), FormatBytes(budget));
}

}  // namespace core
