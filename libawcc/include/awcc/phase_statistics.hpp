#pragma once
// Phase statistics of one tip from its air intervals (METHOD.md 2).
//
// Void fraction c = air samples / samples. Bubble count rate F = complete air
// chords / duration (a chord cut by the record's start or end is not
// complete). Chord times are chord samples / fs; chord lengths chord time x u;
// Sauter mean diameter d32 = 1.5 u c / F.
//
// 95 % confidence intervals. The record is an alternating renewal process of
// n cycles (air chord a, water chord w, cycle m = E[a + w]):
//   c is a ratio estimator: Var(c) = ((1 - c)^2 Var(a) + c^2 Var(w)) / (n m^2);
//   F = n / T: Var(F) / F^2 = CV_cycle^2 / n with CV_cycle^2 = (Var(a) + Var(w)) / m^2;
//   a mean: +/- 1.96 s / sqrt(n);
//   a median: the order statistics of ranks n/2 -/+ 1.96 sqrt(n)/2 (binomial).
// They assume chords independent, which clustering of bubbles breaks; they are
// then too narrow.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/air_intervals.hpp"

namespace awcc {

struct Interval95 {
  double lower = 0.0;
  double upper = 0.0;
};

/// Summary of a sample of durations or lengths.
struct Summary {
  std::int64_t count = 0;
  double mean = 0.0, median = 0.0, std = 0.0, min = 0.0, max = 0.0;
  /// Percentiles 5, 10, 25, 50, 75, 90, 95 (linear interpolation between order statistics).
  std::array<double, 7> percentiles{};
  Interval95 mean_ci95, median_ci95;
  static constexpr std::array<double, 7> levels{5, 10, 25, 50, 75, 90, 95};
};

/// Counts in bins [k w, (k+1) w), k = 0..size-1; the last bin also holds larger values.
struct Histogram {
  double bin_width = 0.0;
  std::vector<std::int64_t> counts;
};

struct PhaseStatisticsOptions {
  int histogram_bins = 50;            ///< bins of the chord-time histograms, up to their 99th percentile
  std::optional<double> velocity;     ///< m/s: adds chord lengths and d32 when given
};

/// Whether the statistics of a tip hold everything, and if not why.
enum class PhaseStatus {
  ok,
  no_air,           ///< the tip never saw air: c = 0, no chords
  all_air,          ///< the tip saw only air: c = 1, no chords
  too_few_chords,   ///< fewer than 2 complete air and water chords: no confidence intervals (given as the point)
};
std::string_view to_string(PhaseStatus status);

struct PhaseStatistics {
  PhaseStatus status = PhaseStatus::ok;
  std::string message;                 ///< why not ok (empty when ok)
  double duration = 0.0;               ///< s
  double void_fraction = 0.0;          ///< -
  Interval95 void_fraction_ci95;
  double bubble_count_rate = 0.0;      ///< complete air chords per second, 1/s
  Interval95 bubble_count_rate_ci95;
  Summary air_chord_time;              ///< s, complete chords
  Summary water_chord_time;            ///< s, complete chords
  Summary interarrival_time;           ///< s, between starts of successive air chords
  Histogram air_chord_histogram, water_chord_histogram;
  std::optional<Summary> air_chord_length;  ///< m, with a velocity
  /// d32 = 1.5 u c_d / F of the dispersed phase, m, with a velocity and F >
  /// 0: c_d = dispersed_fraction(c), the bubbles' c up to 0.5, the droplets'
  /// 1 - c above (F counts both alike: a droplet is the water between two
  /// air chords).
  std::optional<double> sauter_diameter;
};

/// The volume fraction of the dispersed phase at void fraction c: c up to
/// 0.5 (bubbles in water), 1 - c above (droplets in air), -. The one place
/// of the rule; at 0.5 both are the same.
double dispersed_fraction(double void_fraction);
/// "bubble" or "droplet": the dispersed phase's name by the same rule.
std::string_view dispersed_particle(double void_fraction);

/// The Sauter diameter d32 = 1.5 u c / F of spheres of volume fraction c
/// passing a point at F per second with velocity u (|u| used), m: the one
/// place of the formula (PhaseStatistics::sauter_diameter, and the
/// droplets' 1.5 u (1 - c) / F in awcc/position_sizes.hpp). None unless F > 0.
std::optional<double> sauter_diameter(double velocity, double fraction, double count_rate);

Summary summarise(std::vector<double> values);
/// Same, sorting `values` in place.
Summary summarise_in_place(std::vector<double>& values);
PhaseStatistics phase_statistics(const AirIntervals& signal, const PhaseStatisticsOptions& options = {});

}  // namespace awcc
