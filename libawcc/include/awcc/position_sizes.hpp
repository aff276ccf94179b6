#pragma once
// A position's bubble sizes and interfacial area (METHOD.md 12, "Bubble
// sizes, not only d32" and "Interfacial area"; issue 31): what
// process_binarised adds to a ProcessResult from its other results.
//
// Sizes. The chords are the leading tip's complete chords of the dispersed
// phase: air chords where c < 0.3, water chords (the droplets, the signal
// check's air_continuous) where c > 0.7 (flow_regime, awcc/clusters.hpp);
// between, neither phase is particles and nothing is inverted (as the
// cluster analysis). Each chord's length is its chord time times, in this
// order:
//  1. its bubble's own velocity, where event detection ran, paired the bubble
//     (fate paired: the outlier cutoff kept it) and is of quality ok;
//     event detection of low quality is biased (its pairing takes unrelated
//     bubbles where bubbles are sparse: awcc/event_detection.hpp) and its
//     velocities would scale the chords wrongly, so they are not used and
//     the result says why;
//  2. the velocity of the AWCC window holding the chord's first sample,
//     where that window was accepted and AWCC is of quality ok (the record's
//     velocity choice, ProcessResult::velocity_source, trusts AWCC no further);
//  3. the record's velocity (ProcessResult::velocity()).
// Droplets have no per-bubble velocity (event detection pairs air chords).
// The lengths go to size_distribution (awcc/size_distribution.hpp) as
// distinct lengths with their counts: chords of one velocity repeat a few
// hundred lengths (whole samples times it).
//
// Sampling. A chord's time is whole samples: a chord of length l at sample
// spacing delta covers floor(l / delta + U) samples, U the interface's phase
// on the grid. Measured (bench/size_distribution_bench --sampling, 5,000
// chords, 10 draws, log-normal sigma 0.3 / 0.6), by the population's number
// median D50 in samples:
//   D50 / delta   number median: bias, worst     d32: bias, worst
//   2             -15 / -16 %, 21 / 24 %          +3 %, 6 / 4 %
//   4             +1.7 / +2.9 %, 3.8 / 12 %       +1.6 / +1.0 %, 3 %
//   8             +0.7 / +1.1 %, 2.7 / 9.7 %      +0.5 / +0.3 %, 2 %
//   >= 16         within 0.5 %, as unrounded      within 0.2 %
// (the worst at sigma 0.6 is the inversion's own spread at 5,000 chords,
// 8.7 %). The grid floor's chord is then a single sample from D50 = 4 to
// 8 delta and still the answer holds: what decides is how many samples the
// median bubble spans. So where the inverted number median is fewer than
// samples_min samples long (delta = the chords' total length over their
// total samples: u / fs for one velocity), the sampling grid, not the
// bubbles, shapes the small sizes: status coarse_sampling and no
// distribution (d32 from the mean chord, which the rounding biases by
// under 3 %, stays).
// Interfacial area, dual tip (METHOD 12; Kataoka et al. 1986 for a flow
// along the probe): each passage of a sphere through a point adds on average
// 4 / u of interface per unit volume and time (two interfaces, E[1 / cos] = 2
// each over the pierced disk: awcc/multi_tip.hpp derives it), so
//   a = 4 F / u,
// F the leading tip's bubble count rate and u the record's velocity. With
// d32 = 1.5 u c / F (PhaseStatistics::sauter_diameter) it equals 6 c / d32
// by construction: 6 c / (1.5 u c / F) = 4 F / u. It is no second
// measurement of d32, only F and u restated. (For droplets the same passages
// count: a = 4 F / u = 6 (1 - c) / d32 of the droplets.)
// Its 95 % interval: ln a = ln 4 + ln F - ln u, and F (a count of bubbles)
// and u (a correlation's lag) are estimated from different features of the
// record, taken independent; the half-widths of ln F and ln u on each side
// add in quadrature (the delta method on the log scale, which keeps the
// asymmetry of u's interval, u = dx / lag):
//   upper = a exp(sqrt(ln(F_hi / F)^2 + ln(u / u_lo)^2)),
//   lower = a exp(-sqrt(ln(F / F_lo)^2 + ln(u_hi / u)^2)).
// Bubble clustering makes F's interval too narrow (phase_statistics.hpp),
// and so this one.
// Multi-tip: the probe's (4 / T) N_0 <1 / |v|> with the full 3-D speeds
// (awcc/multi_tip.hpp), taken as it is. The row's value is the multi-tip one
// where it exists and the probe's quality is ok, else the dual-tip one.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "awcc/air_intervals.hpp"
#include "awcc/awcc.hpp"
#include "awcc/event_detection.hpp"
#include "awcc/multi_tip.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/size_distribution.hpp"
#include "awcc/validation.hpp"

namespace awcc {

struct SizesOptions {
  /// The inversion's options (size-chords-min, size-penalty, size-bin-width
  /// are declared; the rest keep their measured defaults).
  SizeDistributionOptions inversion;
  /// Least number median diameter, in samples (status coarse_sampling
  /// below). 4: the table above (bias under 3 % at 4, -15 % at 2).
  double samples_min = 4.0;

  [[nodiscard]] Validation validate() const;
};

enum class SizesStatus {
  ok,
  not_converged,               ///< the EM stopped at size-iterations-max: the last iterate's values
  no_velocity,                 ///< no chord has a velocity: no lengths
  intermediate_void_fraction,  ///< 0.3 <= c <= 0.7: neither bubbles nor droplets are particles
  too_few_chords,              ///< fewer usable chords than size-chords-min
  coarse_sampling,             ///< the number median spans fewer than size-samples-min samples
};
std::string_view to_string(SizesStatus status);

/// Which phase's chords are sized.
enum class DispersedPhase { bubbles, droplets };
std::string_view to_string(DispersedPhase phase);

/// The velocity a chord's length took (the order above; none: not used).
enum class ChordVelocity { bubble, window, record, none };
inline constexpr std::array<std::string_view, 4> chord_velocity_names{"bubble", "window", "record", "none"};
std::string_view to_string(ChordVelocity source);

struct SizesResult {
  SizesStatus status = SizesStatus::no_velocity;
  std::string message;        ///< why not ok (empty when ok)
  /// Why per-bubble or window velocities were not used although computed
  /// (event detection or AWCC not of quality ok); empty otherwise.
  std::string velocity_note;
  [[nodiscard]] bool ok() const { return status == SizesStatus::ok; }
  /// Whether the inversion's distribution and moments exist (ok or not_converged).
  [[nodiscard]] bool has_distribution() const {
    return status == SizesStatus::ok || status == SizesStatus::not_converged;
  }
  std::optional<DispersedPhase> phase;  ///< none between 0.3 and 0.7
  std::int64_t chords_given = 0;        ///< complete chords of the dispersed phase
  std::array<std::int64_t, 4> chords_by_velocity{};  ///< indexed by ChordVelocity
  [[nodiscard]] std::int64_t count(ChordVelocity v) const { return chords_by_velocity[static_cast<std::size_t>(v)]; }
  std::string record_velocity_source;   ///< as ProcessResult::velocity_source's text
  /// The inverted number median in samples (its length over the chords'
  /// total length per total samples); 0 unless the inversion ran.
  double median_samples = 0.0;
  /// 1.5 u c / F (droplets: 1.5 u (1 - c) / F), m; none without a velocity.
  std::optional<double> sauter_flux;
  /// The inversion: counts, mean chord and 1.5 x mean chord always; the
  /// distribution and moments when has_distribution().
  SizeDistribution distribution;

  [[nodiscard]] std::string report() const;
};

/// The leading tip's chords sized as above. `phase` is the leading tip's
/// phase statistics (c, F), `record_velocity` ProcessResult::velocity() and
/// `record_source` the text of its source. Throws OptionError when the
/// options are refused.
SizesResult position_sizes(const AirIntervals& leading, const PhaseStatistics& phase,
                           const std::optional<AwccResult>& awcc, const std::optional<EventResult>& events,
                           std::optional<double> record_velocity, std::string_view record_source,
                           const SizesOptions& options = {});

/// Which estimate is a row's interfacial area.
enum class AreaSource { dual_tip, multi_tip };
std::string_view to_string(AreaSource source);

struct InterfacialArea {
  std::optional<double> dual_tip;              ///< 4 F / u, 1/m
  std::optional<Interval95> dual_tip_ci95;
  std::optional<double> multi_tip;             ///< MultiTipResult::interfacial_area, 1/m
  std::optional<Interval95> multi_tip_ci95;
  std::optional<AreaSource> source;            ///< the row's; none when neither exists
  std::string message;  ///< why dual_tip (or its interval) is missing, or why multi_tip is not the row's

  [[nodiscard]] std::optional<double> value() const;
  [[nodiscard]] std::optional<Interval95> ci95() const;
  [[nodiscard]] std::string report() const;
};

/// The dual-tip estimate from the leading tip's F (with its interval) and
/// the record's velocity u (with its interval where it has one); the
/// multi-tip one from `vectors` where given, the row's when
/// `multi_tip_quality_ok` (its reason otherwise in the message).
InterfacialArea interfacial_area(const PhaseStatistics& phase, std::optional<double> velocity,
                                 std::optional<Interval95> velocity_ci95, const MultiTipResult* vectors = nullptr,
                                 bool multi_tip_quality_ok = false, std::string_view multi_tip_reason = {});

}  // namespace awcc
