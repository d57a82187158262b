// the reports' number formatter: printf's "%.*f", digit for digit.
#include "autonomy/common/format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace paddock {
namespace {

TEST(Format, FixedIsPrintfFixedPoint) {
  EXPECT_EQ(fixed(2.5, 2), "2.50");
  EXPECT_EQ(fixed(2.675, 2), "2.67");  // the binary value rounded: 2.67499999...
  EXPECT_EQ(fixed(-1.25, 1), "-1.2");  // an exact half rounds to even (glibc)
  EXPECT_EQ(fixed(10.775, 0), "11");
  EXPECT_EQ(fixed(1.0 / 3.0, 3), "0.333");
  EXPECT_EQ(fixed(-0.0004, 3), "-0.000");  // the sign of a value that rounds to zero stays
  EXPECT_EQ(fixed(123456.0, 1), "123456.0");
  EXPECT_EQ(fixed(std::numeric_limits<double>::infinity(), 2), "inf");
  EXPECT_EQ(fixed(std::nan(""), 2), "nan");
}

TEST(Format, FixedCutsVeryLongText) {
  // 1e80 has 81 digits before the point: the text stops at 63 characters
  EXPECT_EQ(fixed(1e80, 0).size(), 63u);
}

}  // namespace
}  // namespace paddock
