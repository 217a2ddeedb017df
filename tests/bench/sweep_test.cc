// The sweep helper: Product enumerates in loop-nesting order, Sweep visits
// every configuration once per round, rounds interleaved.
#include "bench/sweep.h"

#include <gtest/gtest.h>

#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace bench {
namespace {

TEST(Sweep, ProductIsTheNestedLoopOrder) {
  const std::vector<int> a = {1, 2};
  const std::vector<std::string> b = {"x", "y", "z"};
  std::vector<std::tuple<int, std::string>> loops;
  for (int i : a) {
    for (const std::string& s : b) loops.emplace_back(i, s);
  }
  EXPECT_EQ(Product(a, b), loops);
  EXPECT_TRUE(Product(a, std::vector<float>{}).empty());
  EXPECT_EQ(Product(a).size(), 2u);
}

TEST(Sweep, RoundsInterleaveEveryConfiguration) {
  const std::vector<int> configs = {10, 20, 30};
  std::vector<std::pair<int, int>> visits;
  Sweep<int>(configs, {.rounds = 2},
             [&](const int& c, int round) { visits.emplace_back(round, c); });
  const std::vector<std::pair<int, int>> expected = {{0, 10}, {0, 20}, {0, 30},
                                                     {1, 10}, {1, 20}, {1, 30}};
  EXPECT_EQ(visits, expected);
}

TEST(Sweep, ZeroRoundsMeasureNothing) {
  int calls = 0;
  Sweep<int>({1, 2}, {.rounds = 0}, [&](const int&, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace bench
