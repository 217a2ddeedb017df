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

}  // namespace
}  // namespace core
