// Voltage PDFs (awcc/voltage_pdf.hpp) from a histogram of known samples.
#include <gtest/gtest.h>

#include <cmath>

#include "awcc/voltage_pdf.hpp"

namespace {

TEST(VoltagePdf, CountsPerBinOverTheObservedRange) {
  awcc::VoltageHistogram h(5.0 / 32768.0);
  const std::vector<float> v{0.31f, 0.35f, 0.36f, 4.1f, 4.12f, 4.15f, 4.15f, 2.0f};
  h.add(v, 0, 1);
  const auto p = awcc::voltage_pdf(h, 0.1);
  ASSERT_FALSE(p.fraction.empty());
  EXPECT_NEAR(p.lower.front(), 0.3, 1e-12);
  EXPECT_NEAR(p.upper.back(), 4.2, 1e-12);
  double total = 0.0;
  for (double f : p.fraction) total += f;
  EXPECT_NEAR(total, 1.0, 1e-15);
  EXPECT_DOUBLE_EQ(p.fraction.front(), 3.0 / 8.0);  // [0.3, 0.4)
  EXPECT_DOUBLE_EQ(p.fraction.back(), 4.0 / 8.0);   // [4.1, 4.2)
}

TEST(VoltagePdf, FeldersBinsAreLabelledByTheirFloat32UpperEdge) {
  // Volts of int16 counts c * 5 / 32768. Code 26870 = 4.1000977 V lies below
  // e_52 = fl32(-1 + fl32(5.2)) = 4.2000003 and at or above e_51 = 4.1: bin 52.
  // Code 6554 = 1.0000610 V: bin 21 ([1.0, 1.1)). Everything below -0.9 V: bin 1.
  awcc::VoltageHistogram h(5.0 / 32768.0);
  const std::vector<float> v{static_cast<float>(26870 * 5.0 / 32768.0), static_cast<float>(6554 * 5.0 / 32768.0), -3.0f,
                             -3.0f};
  h.add(v, 0, 1);
  const auto p = awcc::felder_voltage_pdf(h);
  ASSERT_EQ(p.fraction.size(), 60u);
  EXPECT_FLOAT_EQ(static_cast<float>(p.upper[51]), 4.2000003f);
  EXPECT_EQ(static_cast<float>(p.upper[34]), 2.5f);
  EXPECT_DOUBLE_EQ(p.fraction[51], 0.25);
  EXPECT_DOUBLE_EQ(p.fraction[20], 0.25);
  EXPECT_DOUBLE_EQ(p.fraction[0], 0.5);
  EXPECT_TRUE(std::isinf(p.lower[0]));
}

}  // namespace
