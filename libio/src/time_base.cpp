// The one time-base rule (awcc/detail/time_base.hpp).
#include "awcc/detail/time_base.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "reader_support.hpp"

namespace awcc::detail {

TimeBaseRate time_base_rate(const TimeBase& time_base) {
  const auto refuse = [&](const std::string& what) {
    reader_fail(time_base.path, fmt::format("{} {}; {}", time_base.name, what, time_base.fix), time_base.quantity);
  };
  // One pass: finite, increasing, the ends and the extreme steps.
  double first = 0.0, previous = 0.0;
  double least = std::numeric_limits<double>::infinity(), most = 0.0;
  std::uint64_t least_at = 0, most_at = 0;
  const TimeBaseScan scan = time_base.scan([&](std::uint64_t at, std::span<const double> values) {
    for (std::size_t i = 0; i < values.size(); ++i) {
      const double t = values[i];
      const std::uint64_t index = at + i;
      if (!std::isfinite(t)) refuse(fmt::format("is not finite at {}", time_base.where(index)));
      if (index == 0) {
        first = t;
      } else {
        if (!(t > previous)) {
          refuse(fmt::format("does not increase at {} ({} s after {} s): it is not the time base of one recording",
                             time_base.where(index), t, previous));
        }
        if (t - previous < least) least = t - previous, least_at = index;
        if (t - previous > most) most = t - previous, most_at = index;
      }
      previous = t;
    }
  });
  if (scan.values < 2) refuse("holds fewer than two values: no step to take the sampling rate from");
  const double last = previous, span = last - first;
  const double mean = span / static_cast<double>(scan.values - 1);
  double resolution = scan.resolution;
  if (time_base.float_bits > 0) {
    // Each value is rounded by half the spacing at its magnitude: a step by up to one spacing.
    resolution = std::max(resolution, std::ldexp(std::max(std::fabs(first), std::fabs(last)), 1 - time_base.float_bits));
  }
  const double allowed = kTimeBaseTolerance * mean + resolution;
  if (most - mean > allowed || mean - least > allowed) {
    // A second pass names the first step outside.
    std::uint64_t bad = 0;
    double bad_step = 0.0, before = 0.0;
    (void)time_base.scan([&](std::uint64_t at, std::span<const double> values) {
      for (std::size_t i = 0; i < values.size(); ++i) {
        const std::uint64_t index = at + i;
        if (bad == 0 && index > 0 && std::fabs((values[i] - before) - mean) > allowed) {
          bad = index;
          bad_step = values[i] - before;
        }
        before = values[i];
      }
    });
    // The first bad step may be an honest one beside a gap that moved the
    // mean: the step farthest from the mean is named too.
    const bool long_worst = most - mean >= mean - least;
    const std::string worst =
        (long_worst ? most_at : least_at) == bad
            ? std::string()
            : fmt::format("; the {} step, {:.6g} s, is to {}", long_worst ? "longest" : "shortest",
                          long_worst ? most : least, time_base.where(long_worst ? most_at : least_at));
    // The resolution is named when it widened the allowance noticeably.
    const std::string widened = resolution > 0.01 * kTimeBaseTolerance * mean
                                    ? fmt::format(" and the values' resolution of {:.3g} s", resolution)
                                    : std::string();
    refuse(fmt::format("is not evenly spaced: its step to {} is {:.6g} s, {:.3g} % off its mean step of {:.6g} s{}, "
                       "beyond the {:g} %{} a sampling clock keeps to (samples missing, runs joined, or not a clock)",
                       time_base.where(bad), bad_step, 100.0 * std::fabs(bad_step - mean) / mean, mean, worst,
                       100.0 * kTimeBaseTolerance, widened));
  }
  return {1.0 / mean, kTimeBaseTolerance + resolution / span, scan.values};
}

bool agrees(const TimeBaseRate& rate, double stated) {
  return std::fabs(stated - rate.fs) <= rate.tolerance * rate.fs;
}

double resolution_of_text(std::string_view text) {
  int decimals = 0, exponent = 0;
  bool point = false, nonzero = false;
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '.') {
      point = true;
    } else if (c >= '0' && c <= '9') {
      nonzero = nonzero || c != '0';
      decimals += point ? 1 : 0;
    } else {
      break;
    }
  }
  if (!nonzero) return 0.0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    const std::string digits(text.substr(i + 1));
    exponent = std::atoi(digits.c_str());
  }
  return std::pow(10.0, exponent - decimals);
}

}  // namespace awcc::detail
