#include "core/memory_budget.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include "core/error.h"

namespace core {
namespace {

TEST(MemoryBudget, ParsesSizesInTheirUnits) {
  EXPECT_EQ(ParseMemorySize("512"), 512u);
  EXPECT_EQ(ParseMemorySize("2K"), 2048u);
  EXPECT_EQ(ParseMemorySize("512M"), 512ull << 20);
  EXPECT_EQ(ParseMemorySize("1.5GiB"), 3ull << 29);
  EXPECT_EQ(ParseMemorySize("8g"), 8ull << 30);
  const std::uint64_t physical = PhysicalMemoryBytes();
  ASSERT_GT(physical, 0u);
  EXPECT_NEAR(static_cast<double>(ParseMemorySize("25%")), 0.25 * static_cast<double>(physical),
              1.0);
  for (const char* bad : {"", "abc", "-1G", "0", "5 parsecs", "nan", "1e30T"}) {
    EXPECT_THROW(ParseMemorySize(bad), InputError) << bad;
  }
}

TEST(MemoryBudget, RefusesPastTheBudgetNamingNeedBudgetAndFlag) {
  SetMemoryBudget(64ull << 20);
  EXPECT_EQ(MemoryBudgetBytes(), 64ull << 20);
  EXPECT_NO_THROW(CheckMemory(64ull << 20, "Test", "a thing"));
  EXPECT_TRUE(FitsMemory(1));
  EXPECT_FALSE(FitsMemory((64ull << 20) + 1));
  try {
    CheckMemory(3ull << 30, "Test", "the tessellated truth of 'x.obj'");
    FAIL() << "no refusal";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("Test: the tessellated truth of 'x.obj' needs 3.00 GiB"), std::string::npos)
        << what;
    EXPECT_NE(what.find("64.0 MiB"), std::string::npos) << what;
    EXPECT_NE(what.find("--memory-budget"), std::string::npos) << what;
  }
  SetMemoryBudget(std::nullopt);
}

TEST(MemoryBudget, DefaultIsAFractionOfPhysicalMemoryCappedByTheAddressSpaceLimit) {
  SetMemoryBudget(std::nullopt);
  const std::uint64_t physical = PhysicalMemoryBytes();
  rlimit limit{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &limit), 0);
  if (limit.rlim_cur == RLIM_INFINITY && std::getenv("IBR_MEMORY_BUDGET") == nullptr) {
    EXPECT_NEAR(static_cast<double>(MemoryBudgetBytes()),
                kDefaultMemoryFraction * static_cast<double>(physical), 4096.0);
  }
  // A lower address-space limit caps the budget (restored afterwards).
  const rlimit saved = limit;
  rlimit lower = limit;
  lower.rlim_cur = 8ull << 30;
  if (saved.rlim_max != RLIM_INFINITY && saved.rlim_max < lower.rlim_cur) GTEST_SKIP();
  ASSERT_EQ(setrlimit(RLIMIT_AS, &lower), 0);
  const std::uint64_t capped = MemoryBudgetBytes();
  ASSERT_EQ(setrlimit(RLIMIT_AS, &saved), 0);
  EXPECT_LE(capped, 6ull << 30);
}

}  // namespace
}  // namespace core
