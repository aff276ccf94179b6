#include "awcc/units.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace {

using awcc::Dimension;
using awcc::format_quantity;
using awcc::parse_quantity;

TEST(ParseQuantity, ConvertsEachUnitToSI) {
  EXPECT_DOUBLE_EQ(parse_quantity("5mm", Dimension::length), 0.005);
  EXPECT_DOUBLE_EQ(parse_quantity("7.15 mm", Dimension::length), 0.00715);
  EXPECT_DOUBLE_EQ(parse_quantity("250um", Dimension::length), 250e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("2cm", Dimension::length), 0.02);
  EXPECT_DOUBLE_EQ(parse_quantity("0.003m", Dimension::length), 0.003);
  EXPECT_DOUBLE_EQ(parse_quantity("0", Dimension::length), 0.0);  // zero is zero in any unit
  EXPECT_DOUBLE_EQ(parse_quantity("500kHz", Dimension::frequency), 500e3);
  EXPECT_DOUBLE_EQ(parse_quantity("2MHz", Dimension::frequency), 2e6);
  EXPECT_DOUBLE_EQ(parse_quantity("20000Hz", Dimension::frequency), 20000.0);
  EXPECT_DOUBLE_EQ(parse_quantity("300s", Dimension::time), 300.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1ms", Dimension::time), 1e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("5min", Dimension::time), 300.0);
  EXPECT_DOUBLE_EQ(parse_quantity("10m/s", Dimension::velocity), 10.0);
  EXPECT_DOUBLE_EQ(parse_quantity("36km/h", Dimension::velocity), 10.0);
  EXPECT_DOUBLE_EQ(parse_quantity("-0.45", Dimension::dimensionless), -0.45);
  EXPECT_DOUBLE_EQ(parse_quantity("25%", Dimension::dimensionless), 0.25);
  EXPECT_DOUBLE_EQ(parse_quantity("+4.2V", Dimension::voltage), 4.2);
  EXPECT_DOUBLE_EQ(parse_quantity("20mV", Dimension::voltage), 0.02);
  EXPECT_DOUBLE_EQ(parse_quantity("1e-3s", Dimension::time), 1e-3);
}

// Issue 12: "--dx 7.15" meant millimetres and was taken as 7.15 m. A bare
// number of a dimensional quantity is refused with the fix; dimensionless
// quantities take bare numbers.
TEST(ParseQuantity, DimensionalQuantitiesNeedTheirUnit) {
  try {
    (void)parse_quantity("7.15", Dimension::length);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "7.15 has no unit: write 7.15mm (or the same as 0.00715m)");
  }
  for (auto d : {Dimension::time, Dimension::frequency, Dimension::velocity, Dimension::voltage}) {
    EXPECT_THROW((void)parse_quantity("2.5", d), std::invalid_argument);
    EXPECT_THROW((void)parse_quantity("-1e-3", d), std::invalid_argument);
  }
  EXPECT_DOUBLE_EQ(parse_quantity("0.25", Dimension::dimensionless), 0.25);
  EXPECT_DOUBLE_EQ(parse_quantity("0.0", Dimension::velocity), 0.0);
}

// A ratio given a unit (--calibration-tu-bands 0.1m/s, a Tu written as a
// velocity) is refused, not read as 0.1.
TEST(ParseQuantity, DimensionlessQuantitiesRefuseAUnit) {
  for (const char* text : {"0.1m/s", "0.1mm", "0.1Hz"}) {
    try {
      (void)parse_quantity(text, Dimension::dimensionless);
      FAIL() << text << " accepted as a plain number";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("is not a plain number"), std::string::npos) << e.what();
    }
  }
}

TEST(ParseQuantity, RefusesWrongUnitsWithAMessageNamingThem) {
  try {
    parse_quantity("5kg", Dimension::length);
    FAIL() << "5kg accepted as a length";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'5kg'"), std::string::npos) << m;
    EXPECT_NE(m.find("a length"), std::string::npos) << m;
    EXPECT_NE(m.find("mm"), std::string::npos) << m;
  }
  EXPECT_THROW(parse_quantity("5Hz", Dimension::time), std::invalid_argument);
  EXPECT_THROW(parse_quantity("mm", Dimension::length), std::invalid_argument);
  EXPECT_THROW(parse_quantity("", Dimension::length), std::invalid_argument);
  EXPECT_THROW(parse_quantity("nan", Dimension::length), std::invalid_argument);
  EXPECT_THROW(parse_quantity("inf", Dimension::time), std::invalid_argument);
  EXPECT_THROW(parse_quantity("5 m m", Dimension::length), std::invalid_argument);
}

TEST(FormatQuantity, RoundTripsThroughParse) {
  for (double v : {0.005, 0.00715, 2.5e-4, 1.0, 0.0}) {
    EXPECT_DOUBLE_EQ(parse_quantity(format_quantity(v, Dimension::length), Dimension::length), v);
  }
  for (double v : {500e3, 2e6, 20.0}) {
    EXPECT_DOUBLE_EQ(parse_quantity(format_quantity(v, Dimension::frequency), Dimension::frequency), v);
  }
  for (double v : {300.0, 0.1, 2e-6}) {
    EXPECT_DOUBLE_EQ(parse_quantity(format_quantity(v, Dimension::time), Dimension::time), v);
  }
  EXPECT_EQ(format_quantity(0.005, Dimension::length), "5mm");
  EXPECT_EQ(format_quantity(500e3, Dimension::frequency), "500kHz");
  EXPECT_EQ(format_quantity(300.0, Dimension::time), "300s");
  EXPECT_EQ(format_quantity(10.0, Dimension::velocity), "10m/s");
}

}  // namespace
