#pragma once
// The sampling rate from a time base: one rule for every reader that finds
// one (a CSV or .lvm time column, an HDF5 `time` dataset, a MATLAB time
// vector). Not installed; the readers' own.
//
// The rule (METHOD.md section 2 speaks of evenly sampled recordings; this is
// how a reader holds a file's clock to it):
//  - the values are seconds, finite and strictly increasing;
//  - the sampling interval is the mean step, (last - first) / (n - 1): as
//    exact as the first and last values allow, whatever happened between;
//  - every step lies within kTimeBaseTolerance of the mean step (relative),
//    widened by the values' resolution q (how finely they are stored: the
//    last printed digit of a text column, one count of an integer type, the
//    float spacing at the largest value): rounding moves a step by up to q,
//    and is no fault of the clock. A step outside is refused naming the file,
//    the time base and the first bad step: samples missing, runs joined, or a
//    column that is not a clock;
//  - a rate stated beside it (the user's sampling rate, a rate attribute, an
//    .lvm Delta_X) agrees with 1 / the mean step within the same tolerance,
//    widened by q / (last - first) (the rounding of the two end values),
//    unless the user forces the stated rate, which sets the time base aside.
//
// The tolerance, 0.1 %: time bases written by software (t = i / fs, in
// float64 or printed to fixed decimals) meet it exactly once q is counted,
// and so does every test file (the tightest, a 300 kHz column printed to
// 1 us: steps of 3 and 4 us about a mean of 3.33 us, within q); a missing
// sample is a step 100 % off, a joined run more. A rate 0.1 % off moves a
// velocity by 0.1 %, a tenth of the spread of AWCC's window velocities on the
// real recordings. It replaces three rules (CSV: the median step within 1 %
// of the mean; HDF5 and MATLAB: the first step within 0.1 %): the median let
// jitter of up to 1 % through, the first step saw none after it.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>

namespace awcc::detail {

/// Relative: of every step against the mean step, of a stated rate against the time base's.
inline constexpr double kTimeBaseTolerance = 1e-3;

/// What a pass over a time base found besides its values.
struct TimeBaseScan {
  std::uint64_t values = 0;  ///< how many were handed
  /// s; how finely the values are stored, beyond the float spacing the rule
  /// adds itself: one count of an integer type, the finest printed digit of
  /// a text column (resolution_of_text); 0: exactly.
  double resolution = 0.0;
};

/// A time base as a reader presents it to the rule.
struct TimeBase {
  using Sink = std::function<void(std::uint64_t first, std::span<const double> values)>;
  std::filesystem::path path;  ///< the file, for messages
  std::string name;            ///< what messages call it: "dataset '/time'", "time column 'Time [s]'"
  /// Hands every value (seconds) in order to the sink, block by block, with
  /// the index of the block's first value; called a second time only to find
  /// the first bad step of a time base being refused.
  std::function<TimeBaseScan(const Sink&)> scan;
  /// Where value `index` is, as a message says it: "value 601", "line 12".
  std::function<std::string(std::uint64_t index)> where;
  /// Stored as floating point of this many mantissa bits (24: float32, 53:
  /// float64; 0: not floating): the rule adds their spacing at the largest value.
  int float_bits = 0;
  std::string fix;       ///< what the user can do, ending a refusal: "correct it, or force the rate"
  std::string quantity;  ///< InputError::quantity of a refusal (the setting that fixes it)
};

/// What the rule finds.
struct TimeBaseRate {
  double fs = 0.0;         ///< Hz: 1 / the mean step
  double tolerance = 0.0;  ///< relative: a stated rate within it agrees
  std::uint64_t values = 0;
};

/// The rate of a time base of at least two values, or InputError naming the
/// file, the time base, the first value or step that breaks the rule, and the fix.
TimeBaseRate time_base_rate(const TimeBase& time_base);

/// True when a stated rate agrees with the time base's.
[[nodiscard]] bool agrees(const TimeBaseRate& rate, double stated);

/// The resolution of a number printed as `text` (decimal point '.', an
/// exponent allowed): one unit of its last digit ("0.000123" 1e-6,
/// "1.5e-05" 1e-6, "12" 1). Exact zeros ("0", "0.0") say nothing: 0.
[[nodiscard]] double resolution_of_text(std::string_view text);

}  // namespace awcc::detail
