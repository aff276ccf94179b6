#pragma once
// From voltage to air/water (METHOD.md 2). Binary convention everywhere:
// 1 = air, 0 = water.
//
// Threshold rules, with V_air and V_water the modes of the voltage histogram
// on the air and water sides:
//  - histogram: bins of width w (0.1 V; or 100 bins over the range), modes at
//    bin centres, searched below / above the middle of the observed range;
//    threshold = V_air + theta (V_water - V_air), theta = 0.5.
//  - felder: Felder's program: 0.1 V bins labelled by their upper edge, the
//    air mode searched at or below 3.0 V and the water mode at or above,
//    threshold = V_air + theta (V_water - V_air), and a sample is air when
//    V - threshold < 1e-5. Its threshold sits 0.05 V above the histogram
//    rule's; offered so that a lab can reproduce its past results exactly.
//  - kramer: Kramer's toolbox (thres.m): MATLAB's hist with 100 equal bins
//    from the channel's minimum to its maximum (bins (e_k, e_k+1], the first
//    closed, identified by their centres); a first split at half the
//    largest centre; the air mode is the mean of the centres of every bin
//    whose count equals the largest count below the split (a bin on the
//    other side with the same count is averaged in: the toolbox's quirk,
//    noted when it happens), the water mode likewise above; threshold =
//    V_air + theta (V_water - V_air) (thres.m: theta = 0.5); air when V is
//    below it. Exact for integer recordings (floating ones are histogrammed
//    at 0.1 mV).
//  - fixed: a stated voltage (the trailing tip may have its own).
//  - hysteresis: two thresholds at fractions theta_low and theta_high (0.4,
//    0.6) between the modes; the state changes only when the signal crosses
//    the far one, which suppresses chatter on noisy signals.
// Conductivity probes see air as the low level, optical probes as the high
// one. A channel holding at most two distinct values is binary input: it is
// not thresholded again, its higher value is air.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/validation.hpp"

namespace awcc {

enum class ProbeType { conductivity, optical };
enum class ThresholdRule { histogram, felder, kramer, fixed, hysteresis };

std::string_view to_string(ThresholdRule rule);
std::string_view to_string(ProbeType probe);

struct BinarisationOptions {
  ThresholdRule rule = ThresholdRule::histogram;
  ProbeType probe = ProbeType::conductivity;
  double theta = 0.5;                ///< histogram/felder: fraction from air mode to water mode, -
  std::optional<double> fixed_threshold;  ///< fixed: threshold, V (required by the fixed rule)
  std::optional<double> fixed_threshold_trailing;  ///< fixed: the trailing tip's own threshold, V (else fixed_threshold)
  double hysteresis_low = 0.4;       ///< hysteresis: fraction of the nearer-to-air threshold, -
  double hysteresis_high = 0.6;      ///< hysteresis: fraction of the nearer-to-water threshold, -
  double bin_width = 0.1;            ///< histogram: bin width, V; 0 = 100 bins over the observed range
  double felder_split = 3.0;         ///< felder: mode search boundary, V

  [[nodiscard]] Validation validate() const;
  /// The options of the trailing tip (its own fixed threshold, when given).
  [[nodiscard]] BinarisationOptions for_trailing_tip() const;
};

/// Voltage histogram of one channel at the resolution of the data (one bin
/// per count for integer samples, 0.1 mV for floating samples), gathered
/// block by block, plus the distinct values seen (up to three) to recognise
/// binary input.
class VoltageHistogram {
 public:
  explicit VoltageHistogram(double quantum);
  /// Adds every `stride`-th value starting at `first`.
  void add(std::span<const float> values, std::size_t first, std::size_t stride);
  /// Adds counts[i] samples of value (first_index + i) * quantum, for
  /// histograms of integer data gathered elsewhere (same quantum).
  void add_counts(std::span<const std::int64_t> counts, std::int64_t first_index);
  [[nodiscard]] std::int64_t total() const { return total_; }
  /// The resolution of the histogram (the quantum it was built with), V.
  [[nodiscard]] double resolution() const { return width_; }
  /// Distinct values seen, when there were at most two (binary input).
  [[nodiscard]] std::optional<std::vector<double>> binary_levels() const;
  /// Counts regrouped into bins [k w, (k+1) w): (k, count) for nonempty bins.
  [[nodiscard]] std::vector<std::pair<std::int64_t, std::int64_t>> regroup(double width) const;
  /// The values seen (at the histogram's resolution) with their counts, in increasing order.
  [[nodiscard]] std::vector<std::pair<double, std::int64_t>> values() const;
  [[nodiscard]] double min_value() const;
  [[nodiscard]] double max_value() const;

 private:
  void grow(std::int64_t index);
  double width_;
  std::int64_t offset_ = 0;               // fine index of counts_[0]
  std::vector<std::int64_t> counts_;
  std::int64_t total_ = 0;
  std::vector<float> distinct_;           // up to 3
};

/// The threshold chosen for one channel.
struct Threshold {
  ThresholdRule rule = ThresholdRule::histogram;
  ProbeType probe = ProbeType::conductivity;
  bool binary_input = false;   ///< two levels at most: taken as is
  bool constant = false;       ///< one level only: no interface
  double air_level = 0.0;      ///< V: air mode (bin centre, or Felder's label)
  double water_level = 0.0;    ///< V
  double threshold = 0.0;      ///< V (the middle of the two for hysteresis)
  double lower = 0.0;          ///< V: hysteresis threshold nearer the low level
  double upper = 0.0;          ///< V: hysteresis threshold nearer the high level
  double tolerance = 0.0;      ///< V: Felder's 1e-5 comparison tolerance
  std::string note;            ///< anything the user should know
};

/// Applies the rule to a channel's histogram. Throws InputError when
/// no threshold can be found (e.g. no bin on one side for the felder rule).
Threshold choose_threshold(const VoltageHistogram& histogram, const BinarisationOptions& options);

/// Turns one channel's voltages into air intervals, block by block.
class Binariser {
 public:
  Binariser(const Threshold& threshold, double fs);
  /// Feeds every `stride`-th value from `first` (consecutive samples).
  void feed(std::span<const float> values, std::size_t first, std::size_t stride);
  /// Feeds `length` consecutive samples that all take the same decision as
  /// `value` would (a run known to lie on one side of every threshold).
  void feed_run(float value, std::int64_t length);
  /// The air intervals of everything fed.
  AirIntervals finish();
  /// Room for `intervals` air intervals, where the caller knows a bound: the
  /// array is not grown by doubling (a 300 s record's is 20 MB at its peak).
  void reserve(std::size_t intervals) { out_.intervals.reserve(intervals); }

 private:
  Threshold t_;
  std::int64_t position_ = 0;
  bool in_air_ = false;
  bool started_ = false;
  std::int64_t air_start_ = 0;
  AirIntervals out_;
};

}  // namespace awcc
