// The readers' shared helpers (awcc/detail/columns.hpp, time_base.hpp), each
// against a reference computed here, and through a reader on a written file.
#include <gtest/gtest.h>

#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "awcc/detail/columns.hpp"
#include "awcc/detail/time_base.hpp"
#include "awcc/errors.hpp"
#include "awcc/recording.hpp"
#include "test_paths.hpp"
#include "declared_quantity.hpp"

namespace {

namespace fs = std::filesystem;
using awcc::detail::kTimeBaseTolerance;
using awcc::detail::TimeBase;
using awcc::detail::TimeBaseScan;

fs::path scratch(const std::string& name) { return pdp_test::temp_dir() / ("helpers_" + name); }

// ---------------------------------------------------------------------------
// Column layout and interleaving.

TEST(ColumnLayout, OrientationAtTheBoundaries) {
  using awcc::detail::column_layout;
  // As many rows as columns: samples x channels.
  auto l = column_layout(2, 2);
  ASSERT_TRUE(l);
  EXPECT_FALSE(l->transposed);
  EXPECT_EQ(l->frames, 2u);
  // 16 rows under 17 columns: 16 stacked channels of 17 samples.
  l = column_layout(16, 17);
  ASSERT_TRUE(l);
  EXPECT_TRUE(l->transposed);
  EXPECT_EQ(l->frames, 17u);
  EXPECT_EQ(l->channels, 16u);
  // 17 rows under 18 columns: neither.
  EXPECT_FALSE(column_layout(17, 18));
  EXPECT_EQ(column_layout(100000, 3)->channels, 3u);
}

// Both storage orders into a wider output from channel 2 on, against the
// frame/channel each value was made from; convert sees the right (i, c).
TEST(Interleave, BothStorageOrdersLandEachValueInItsFrameAndChannel) {
  const std::size_t frames = 37, channels = 3, out_channels = 6, first = 2;
  auto code = [](std::size_t i, std::size_t c) { return static_cast<int>(1000 * i + c); };
  for (bool channels_first : {false, true}) {
    std::vector<int> block(frames * channels);
    for (std::size_t i = 0; i < frames; ++i) {
      for (std::size_t c = 0; c < channels; ++c) {
        block[channels_first ? c * frames + i : i * channels + c] = code(i, c);
      }
    }
    std::vector<double> out(frames * out_channels, -1.0);
    awcc::detail::interleave(
        frames, channels, channels_first, [&](std::size_t k) { return block[k]; }, std::span<double>(out),
        out_channels, first, [&](int v, std::size_t i, std::size_t c) {
          EXPECT_EQ(v, code(i, c));
          return 0.5 * v;
        });
    for (std::size_t i = 0; i < frames; ++i) {
      for (std::size_t c = 0; c < out_channels; ++c) {
        const double expected = c >= first && c < first + channels ? 0.5 * code(i, c - first) : -1.0;
        ASSERT_EQ(out[i * out_channels + c], expected) << "frame " << i << " channel " << c << " " << channels_first;
      }
    }
  }
}

// ---------------------------------------------------------------------------
// The time-base rule.

// A time base over `values` as a reader would present it (blocks of 5).
TimeBase base_of(const std::vector<double>& values, double resolution = 0.0) {
  TimeBase b;
  b.path = "clock.h5";
  b.name = "dataset '/time'";
  b.where = [](std::uint64_t i) { return fmt::format("value {}", i); };
  b.float_bits = 53;
  b.fix = "correct it";
  b.quantity = "override-fs";
  b.scan = [values, resolution](const TimeBase::Sink& sink) {
    for (std::size_t at = 0; at < values.size(); at += 5) {
      sink(at, std::span<const double>(values).subspan(at, std::min<std::size_t>(5, values.size() - at)));
    }
    return TimeBaseScan{values.size(), resolution};
  };
  return b;
}

std::string refusal(const TimeBase& b, std::string* quantity = nullptr) {
  try {
    (void)awcc::detail::time_base_rate(b);
  } catch (const awcc::InputError& e) {
    EXPECT_TRUE(declared_reader_quantity(e.quantity())) << e.quantity();
    if (quantity) *quantity = e.quantity();
    return e.what();
  }
  return "accepted";
}

// A clock of 1/1024 s (exact in binary) with value k moved by `shift` steps:
// step k longer, step k + 1 shorter by as much, the ends (and the mean) kept.
std::vector<double> clock_with_shift(std::size_t n, std::size_t k, double shift) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / 1024.0;
  t[k] += shift / 1024.0;
  return t;
}

TEST(TimeBaseRule, TheRateIsTheMeanStepsAndEveryStepIsHeldToTheTolerance) {
  const auto rate = awcc::detail::time_base_rate(base_of(clock_with_shift(1000, 400, 0.0)));
  EXPECT_EQ(rate.fs, 1024.0);
  EXPECT_EQ(rate.values, 1000u);
  // Just inside the tolerance: read, at the same mean rate.
  EXPECT_EQ(awcc::detail::time_base_rate(base_of(clock_with_shift(1000, 400, 0.99 * kTimeBaseTolerance))).fs, 1024.0);
  // Just outside: refused, naming the first bad step (to value 400) and the fix.
  std::string quantity;
  const auto message = refusal(base_of(clock_with_shift(1000, 400, 1.01 * kTimeBaseTolerance)), &quantity);
  EXPECT_NE(message.find("clock.h5: dataset '/time' is not evenly spaced: its step to value 400 is"),
            std::string::npos) << message;
  EXPECT_NE(message.find("0.101 % off its mean step"), std::string::npos) << message;
  EXPECT_NE(message.find("; correct it"), std::string::npos) << message;
  EXPECT_EQ(quantity, "override-fs");
}

// A jittered clock (each stamp moved by up to 0.3 % of a step, uniformly):
// refused at the first step outside 0.1 %, found here by brute force.
TEST(TimeBaseRule, AJitteredClockIsRefusedAtItsFirstBadStep) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> jitter(-0.003, 0.003);
  std::vector<double> t(2000);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = (static_cast<double>(i) + (i == 0 || i + 1 == t.size() ? 0.0 : jitter(gen))) * 1e-5;
  const double mean = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  std::size_t first_bad = 0;
  for (std::size_t i = 1; i < t.size() && first_bad == 0; ++i) {
    if (std::fabs((t[i] - t[i - 1]) - mean) > kTimeBaseTolerance * mean) first_bad = i;
  }
  ASSERT_GT(first_bad, 0u);
  const auto message = refusal(base_of(t));
  EXPECT_NE(message.find(fmt::format("its step to value {} is", first_bad)), std::string::npos) << message;
  // Irregular (a missing sample): the first step is named, and the long one.
  auto gap = clock_with_shift(1000, 0, 0.0);
  gap.erase(gap.begin() + 600);
  const auto missing = refusal(base_of(gap));
  EXPECT_NE(missing.find("its step to value 1 is"), std::string::npos) << missing;
  EXPECT_NE(missing.find("the longest step, 0.00195312 s, is to value 600"), std::string::npos) << missing;
}

// Stamps printed to 1 us at 300 kHz step by 3 and 4 us: within the values'
// resolution, so read; the same steps said to be exact are refused.
TEST(TimeBaseRule, TheValuesResolutionWidensTheAllowance) {
  std::vector<double> t(3000);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = std::round(static_cast<double>(i) / 300e3 * 1e6) * 1e-6;
  const auto rate = awcc::detail::time_base_rate(base_of(t, 1e-6));
  EXPECT_NEAR(rate.fs, 300e3, 300e3 * 1e-4);
  EXPECT_DOUBLE_EQ(rate.tolerance, kTimeBaseTolerance + 1e-6 / (t.back() - t.front()));
  EXPECT_NE(refusal(base_of(t)).find("not evenly spaced"), std::string::npos);
}

// A stated rate agrees within the same tolerance (widened by the rounding of the two end values).
TEST(TimeBaseRule, AStatedRateAgreesWithinTheSameTolerance) {
  const auto rate = awcc::detail::time_base_rate(base_of(clock_with_shift(1000, 1, 0.0)));
  EXPECT_TRUE(awcc::detail::agrees(rate, 1024.0 * (1.0 + 0.99 * kTimeBaseTolerance)));
  EXPECT_TRUE(awcc::detail::agrees(rate, 1024.0 * (1.0 - 0.99 * kTimeBaseTolerance)));
  EXPECT_FALSE(awcc::detail::agrees(rate, 1024.0 * (1.0 + 1.01 * kTimeBaseTolerance)));
  EXPECT_FALSE(awcc::detail::agrees(rate, 1024.0 * (1.0 - 1.01 * kTimeBaseTolerance)));
}

TEST(TimeBaseRule, ValuesThatDoNotIncreaseOrAreNotFiniteAreNamed) {
  auto back = clock_with_shift(100, 0, 0.0);
  std::swap(back[60], back[61]);
  EXPECT_NE(refusal(base_of(back)).find("does not increase at value 61"), std::string::npos) << refusal(base_of(back));
  auto nan = back;
  nan[30] = std::nan("");
  EXPECT_NE(refusal(base_of(nan)).find("is not finite at value 30"), std::string::npos);
  EXPECT_NE(refusal(base_of({0.5})).find("fewer than two values"), std::string::npos);
}

TEST(TimeBaseRule, ResolutionOfPrintedNumbers) {
  using awcc::detail::resolution_of_text;
  EXPECT_DOUBLE_EQ(resolution_of_text("0.000123"), 1e-6);
  EXPECT_DOUBLE_EQ(resolution_of_text("-12.50"), 1e-2);
  EXPECT_DOUBLE_EQ(resolution_of_text("1.5e-05"), 1e-6);
  EXPECT_DOUBLE_EQ(resolution_of_text("3E2"), 100.0);
  EXPECT_DOUBLE_EQ(resolution_of_text("12"), 1.0);
  EXPECT_EQ(resolution_of_text("0.000"), 0.0);
  EXPECT_EQ(resolution_of_text("0"), 0.0);
}

// Through a reader: a CSV time column with one sample missing is refused
// naming its line (the header is line 1), with the setting that fixes it.
TEST(TimeBaseRule, ACsvTimeColumnIsHeldToTheRuleWithItsLineNamed) {
  std::string text = "time,a,b\n";
  for (int i = 0; i < 500; ++i) {
    if (i == 321) continue;  // a sample lost
    text += fmt::format("{:.6f},{},{}\n", i * 5e-5, i % 7 < 3 ? 0 : 4, i % 5 < 2 ? 0 : 4);
  }
  const auto p = scratch("lost_sample.csv");
  std::ofstream(p, std::ios::binary) << text;
  try {
    (void)awcc::open_recording(p, {});
    ADD_FAILURE() << "read";
  } catch (const awcc::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("the time column 'time' is not evenly spaced"), std::string::npos) << message;
    // Row i at line i + 2; the row after the lost one (i = 322) is line 323.
    EXPECT_NE(message.find("its step to line 323 is 0.0001 s"), std::string::npos) << message;
    EXPECT_EQ(e.quantity(), "time-column");
    EXPECT_EQ(message.find("--"), std::string::npos) << message;
  }
  // Forced, the stated rate sets the time column aside.
  awcc::ReaderOptions forced;
  forced.fs = 20e3;
  forced.override_fs = true;
  EXPECT_EQ(awcc::open_recording(p, forced)->info().fs, 20e3);
}

}  // namespace
