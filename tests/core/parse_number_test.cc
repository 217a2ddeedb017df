// core::ParseFiniteNumber: the whole text is one finite number, or nothing.
#include "core/parse_number.h"

#include <gtest/gtest.h>

namespace core {
namespace {

TEST(ParseFiniteNumber, WholeFiniteNumbersOnly) {
  EXPECT_EQ(ParseFiniteNumber("1.5"), 1.5);
  EXPECT_EQ(ParseFiniteNumber("-2e3"), -2000);
  EXPECT_EQ(ParseFiniteNumber("1341841278.8427"), 1341841278.8427);
  for (const char* bad : {"", "x", "1.5x", "1,5", "nan", "inf", "-inf", "1e999", "0x"}) {
    EXPECT_FALSE(ParseFiniteNumber(bad).has_value()) << bad;
  }
}

TEST(ParseNumberList, FiniteNumbersBetweenSeparatorsOnly) {
  EXPECT_EQ(ParseNumberList("1,2.5,-3"), (std::vector<double>{1, 2.5, -3}));
  EXPECT_EQ(ParseNumberList("7"), (std::vector<double>{7}));
  EXPECT_EQ(ParseNumberList("1;2", ';'), (std::vector<double>{1, 2}));
  for (const char* bad : {"", ",", "1,", ",1", "1,,2", "1,x", "1,nan"}) {
    EXPECT_FALSE(ParseNumberList(bad).has_value()) << bad;
  }
}

}  // namespace
}  // namespace core
