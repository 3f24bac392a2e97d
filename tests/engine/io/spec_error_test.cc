// Numbers in SpecError messages (spec_error.h, ValueText): the shortest text that reads back to the
// same double, in fixed notation for decimal exponents -4 to 15 and scientific beyond.
#include "driftlab/spec_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

namespace driftlab {
namespace {

TEST(ValueText, ShortestTextThatReadsBackToTheSameDouble) {
  // 51 x 0.01 is the double nearest 0.51, which 17 significant digits print as 0.51000000000000001.
  EXPECT_EQ(ValueText(51 * 0.01), "0.51");
  EXPECT_EQ(ValueText(0.1), "0.1");
  EXPECT_EQ(ValueText(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(ValueText(0.0), "0");
  EXPECT_EQ(ValueText(-0.0), "-0");
  EXPECT_EQ(ValueText(-2.5), "-2.5");
  EXPECT_EQ(ValueText(100000.0), "100000");
  EXPECT_EQ(ValueText(123456.789), "123456.789");
  EXPECT_EQ(ValueText(1e15), "1000000000000000");
  EXPECT_EQ(ValueText(1e16), "1e+16");
  EXPECT_EQ(ValueText(1e300), "1e+300");
  EXPECT_EQ(ValueText(0.0001), "0.0001");
  EXPECT_EQ(ValueText(0.00015), "0.00015");
  EXPECT_EQ(ValueText(1.5e-7), "1.5e-07");
  EXPECT_EQ(ValueText(std::numeric_limits<double>::max()), "1.7976931348623157e+308");
  EXPECT_EQ(ValueText(std::numeric_limits<double>::denorm_min()), "5e-324");
  EXPECT_EQ(ValueText(std::nan("")), "nan");
  EXPECT_EQ(ValueText(-std::numeric_limits<double>::infinity()), "-inf");
  // Every one reads back to the same bits.
  for (const double v : {51 * 0.01, 1.0 / 3.0, 123456.789, 1e15 + 1.0, 2.0 / 3.0 * 1e-5,
                         std::numeric_limits<double>::max(), 6.02214076e23}) {
    EXPECT_EQ(std::strtod(ValueText(v).c_str(), nullptr), v) << ValueText(v);
  }
}

}  // namespace
}  // namespace driftlab
