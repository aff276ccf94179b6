#pragma once
// Event detection (ED) for a tip pair, METHOD.md 11.1, 11.2 and 11.6 (dual
// tip): the same bubble found at the leading tip 0 and at a trailing tip k,
// one velocity per bubble (Kramer et al. 2020, ISHS; Shen et al. 2005, IJMF
// 31). pdp-sim's mssp.py is the seed system; where pdp differs it says so.
//
// Bubble h at a tip (awcc/interface_times.hpp): front t_2h, rear t_2h+1, chord
// time dt_h = t_2h+1 - t_2h, centre (t_2h + t_2h+1) / 2, in seconds.
//
// 1. Pairing, Kramer et al. 2020 (default). The candidate of leading bubble h
//    is the trailing bubble whose centre comes first strictly after h's
//    centre. Accepted when
//      centre lag < centre of leading bubble h+1 - centre of h
//    (otherwise the candidate is more likely the next bubble's; the last
//    leading bubble has no such limit) and
//      disparity = |dt_0,h - dt_k,h| / dt_0,h < d_max   (0.5)
//    (two different bubbles seldom share a chord time). Both are strict, as
//    METHOD and mssp.py state them: a lag or disparity exactly at its limit is
//    rejected.
//    Where a true partner is missed (a bubble that passes beside the
//    trailing tip), the candidate is an unrelated later bubble, accepted
//    when it falls within the time to the next leading bubble and its chord
//    is similar. Sparse bubbles make that window long and the wrong lags
//    long: the mean is biased low (the spillway recordings at C < 0.2: ED
//    0.9-1.8 m/s against AWCC 1.7-3.3 m/s); dense small bubbles with a
//    lateral tip offset make it short and bias the mean high (the synthetic
//    base case: 16 m/s against 10). The robust outlier cutoff cannot remove
//    them (they pile up between 0 and the true velocity, inside its band);
//    Shen's lag limit bounds them from a first velocity. Compare ED with
//    AWCC's interval before trusting it.
// 2. Pairing, Shen et al. 2005. The candidate of leading bubble h is the
//    trailing bubble whose front comes first strictly after h's front; its
//    rear is that bubble's own rear. Accepted when both |front lag| and
//    |rear lag| are at most |S_0k| / (f V_gas), f = 0.3 (Shen's Eq. 43; "at
//    most": a lag exactly at the limit is kept), V_gas a first estimate of
//    the mean velocity given by the caller (pdp: FSCC's, or AWCC's of the
//    closest trailing tip). Without one the pairing is refused, never guessed.
//    (mssp.py takes the second falling edge when tip k is in air at tip 0's
//    front, a remnant of a backward search it commented out; pdp takes the
//    candidate's own rear.)
// 3. Censoring: a leading bubble, or its candidate, that touches a record end
//    has an interface outside the record: its lags and chord are cut, so it
//    is not paired (fate censored).
// 4. A trailing bubble claimed twice. Among leading bubbles that pass every
//    rule above, two that share a candidate are both rejected (fate
//    claimed_twice). At most one of them is the same bubble, and the times do
//    not say which; keeping the closer one would keep the shorter lag, i.e.
//    select the faster velocity, a bias on the very quantity measured. Under
//    Kramer's rule it cannot happen (the lag limit puts the candidate before
//    the next leading centre, which the next bubble's candidate must follow);
//    under Shen's it does where a trailing tip sees two close bubbles as one.
// 5. Velocity, dual tip: u_h = dx / centre lag, centre lag = (front lag + rear
//    lag) / 2 (both pairings, as mssp.py); a centre lag <= 0 (possible under
//    Shen's rule with a short trailing chord) gives no velocity (fate
//    non_positive_lag).
// 6. Statistics of the paired bubbles (METHOD 11.6, and 4 items 6-8): the
//    robust outlier cutoff on u_h (fate roc for the rejected), then
//      u = sum w u_h / sum w, u_rms = sqrt(sum w (u_h - u)^2 / sum w),
//      Tu = u_rms / u,
//    with w_h = 1 (weighting none) or w_h = the bubble's interaction time
//    span (weighting duration), decided as mssp.py's time_reconst:
//      w_h = max(t_0,2h+1, t_k,2h+1) - min(t_0,2h, t_k,2h),
//    from the first interface of the bubble at either tip to its last. It is
//    a residence time (Buchhave 1979): chord time plus lag, both ~ 1/u_h, so
//    it cancels the excess of fast bubbles in a count of passages, as AWCC's
//    window duration does. 95 % intervals as AWCC's, N = paired bubbles:
//    u +/- 1.96 u_rms / sqrt(N); u_rms +/- 1.96 u_rms / sqrt(2N);
//    Tu +/- 1.96 sigma_T, sigma_T^2 = Tu^2 (Tu^2 / N + 1 / (2N)).
// 7. Quality: insufficient below `bubbles_reported` paired bubbles (10), low
//    below `bubbles_ok` (100) or a pairing yield (paired / complete leading
//    bubbles) below `pairing_yield_ok` (5 %), ok otherwise. The counts are
//    AWCC's window counts because the intervals are the same function of N:
//    Tu's relative half-width 1.96 sqrt(Tu^2 / N + 1 / (2N)) is 0.45 at N = 10
//    and 0.14 at N = 100 for Tu = 0.2, so "low" means the same width for both
//    methods. Per-bubble velocities are correlated within a bubble cluster, so
//    the effective N is smaller and the intervals are then too narrow (as
//    AWCC's). A low yield means the paired bubbles are a selection (those
//    that hit both tips squarely), which biases the mean.
// 8. Chord lengths from each bubble's own velocity: l_h = dt_0,h u_h (leading
//    chord time), summarised over the paired bubbles (mean, median,
//    percentiles); the Sauter mean diameter d32 = 1.5 mean(l): for spheres
//    pierced uniformly over their cross-section the mean chord of a sphere is
//    2 d / 3 and the pierced population is weighted by d^2, so
//    mean(l) = (2/3) sum n d^3 / sum n d^2 = (2/3) d32.
// 9. Interface times (EventOptions::interface_times; event detection and the
//    multi-tip pairing alike). midpoint: half way between the two samples
//    that straddle the edge (awcc/interface_times.hpp), so that a lag is a
//    whole number of samples. crossing: where the voltage crosses the level
//    that switched the phase (the threshold; for hysteresis the level of that
//    direction), interpolated linearly between the two samples,
//      t = (n - 1 + (level - v[n-1]) / (v[n] - v[n-1])) / fs,
//    n the edge's first sample of the new phase (the fraction clamped to
//    [0, 1], 1/2 where the two samples are equal). At 10-40 kHz a bubble's
//    lag is 5-50 samples, so whole samples spread the per-bubble velocities
//    by up to 10 % and inflate Tu; where the probe's rise time spans a
//    sample or more, the crossing resolves the lag below one. It needs the
//    voltages: one more pass over the file (processing keeps only the air
//    intervals), and a binary signal gives the midpoint exactly. An edge at
//    the record's first or last sample keeps the midpoint (that bubble is
//    censored anyway). An edge direction whose crossing fractions barely
//    vary (edges sharper than a sample: the fraction is the level's place
//    between the two phases' levels, plus noise) keeps its midpoints: the
//    noise would break the ties of whole-sample lags and pass as a measured
//    spread (awcc/process.hpp, least_crossing_spread).

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/awcc.hpp"
#include "awcc/interface_times.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/validation.hpp"

namespace awcc {

/// How a bubble's interfaces are timed on a raw voltage (item 9 below).
enum class InterfaceTiming { midpoint, crossing };
std::string_view to_string(InterfaceTiming timing);

/// The interface-pairing rule (items 1 and 2 above).
enum class Pairing { kramer, shen };
std::string_view to_string(Pairing pairing);

/// What became of a leading bubble, in the order the rules are applied (the
/// first that fails names the fate).
enum class BubbleFate {
  paired,            ///< paired and its velocity used
  censored,          ///< it or its candidate touches a record end
  no_partner,        ///< no later bubble at the trailing tip
  beyond_next,       ///< Kramer: centre lag not shorter than the time to the leading tip's next bubble
  disparity,         ///< Kramer: chord-time disparity not below d_max
  shen_lag,          ///< Shen: a front or rear lag above |S| / (f V_gas)
  non_positive_lag,  ///< the centre lag is not positive: no velocity
  claimed_twice,     ///< its candidate is also another leading bubble's
  ambiguous,         ///< multi-tip pairing: two or more candidates in the tip's lag window
  inconsistent,      ///< multi-tip pairing: its partners at the trailing tips are not one bubble's
  roc,               ///< paired, rejected by the robust outlier cutoff
};
/// The fates' names in the enum's order: the bubble table's fate column and
/// the result's counts are written from this one table.
inline constexpr std::array<std::string_view, 11> bubble_fate_names{
    "paired",        "censored",  "no_partner",   "beyond_next", "disparity", "shen_lag", "non_positive_lag",
    "claimed_twice", "ambiguous", "inconsistent", "roc"};
inline constexpr std::size_t bubble_fate_count = bubble_fate_names.size();
static_assert(static_cast<std::size_t>(BubbleFate::roc) + 1 == bubble_fate_count,
              "a fate added to BubbleFate needs its name in bubble_fate_names");
std::string_view to_string(BubbleFate fate);

struct EventOptions {
  /// Kramer et al. 2020 (default: it also refuses two different bubbles by
  /// their chord times) or Shen et al. 2005 (needs a first velocity).
  Pairing pairing = Pairing::kramer;
  /// Interface times (item 9): midpoint by default, which needs only the
  /// binarised signal; crossing reads the voltages once more.
  InterfaceTiming interface_times = InterfaceTiming::midpoint;
  /// Kramer: largest relative chord-time disparity of a pair, -; 0.5 as
  /// pdp-sim's tests. Lower refuses more true pairs of bubbles cut
  /// off-centre by one tip; higher accepts more wrong pairs.
  double disparity_max = 0.5;
  /// Shen: f in the lag limit |S| / (f V_gas), -; 0.3 as Shen et al. 2005
  /// (lags up to 3.3 times the mean transit: bubbles at 30 % of the mean
  /// velocity still pair).
  double shen_lag_factor = 0.3;
  /// Robust outlier cutoff on the per-bubble velocities. pdp's front ends
  /// set it from AWCC's declared `roc`: one switch for both methods.
  bool roc = true;
  /// Moments weighted by each bubble's interaction time span (item 6) or not
  /// at all. pdp's front ends set it from AWCC's declared `weighting`.
  Weighting weighting = Weighting::duration;
  /// Multi-tip pairing (pair_probe, awcc/multi_tip.hpp), from the first
  /// velocity V_ref (FSCC's of the tip pair) along x. A bubble's velocity is
  /// taken to lie within a speed band and a cone around x; its centre lag to
  /// each trailing tip then lies in a window, and its partners' vector must
  /// lie in the band and cone too.
  /// Slowest and fastest bubble paired, as fractions of V_ref, -. 0.5 keeps
  /// bubbles 2.5 standard deviations below the mean at Tu_x = 0.2 (the
  /// slowest 0.1-0.3 % of pdp's four-tip sample fall below); every 0.5 of
  /// V_ref / slowest adds a window a quarter of the mean lag wide in which an
  /// unrelated bubble passes (measured: 0.5 against Shen's 0.3 halves the
  /// mis-paired bubbles). 2.5 costs little: the window's short end is
  /// where few wrong partners fall (their lags are uniform, their speeds
  /// dense at the slow end).
  double probe_speed_min = 0.5;
  double probe_speed_max = 2.5;
  /// Largest angle between a bubble's velocity and x, degrees. 30 keeps a
  /// lateral component 4.6 standard deviations out at Tu_y = 0.125 (the
  /// sample's); the wrong partners it refuses give vectors tilted 55-85
  /// degrees (measured median tan 2.4). Raise it for strongly 3-D flows.
  double probe_angle_max = 30.0;
  /// Largest |D_front - D_rear| / D of a bubble's Shen & Nakamura diameters
  /// over every combination of its paired tips, -. Exact (0) for a sphere
  /// pierced by the right partners; measured 99 % below 0.066-0.084 on the
  /// four-tip sample, while a partner from another bubble gives a median
  /// 0.04-0.05 with a long tail: 0.1 refuses a quarter to a third of the
  /// wrong ones that pass the window and cone. Bubbles far from spheres
  /// need more (it is refused, counted, as inconsistent).
  double probe_diameter_mismatch = 0.1;
  /// Fewest paired bubbles whose moments are reported (quality insufficient below).
  int bubbles_reported = 10;
  /// Fewest paired bubbles of quality ok (low below).
  int bubbles_ok = 100;
  /// Least pairing yield (paired / complete leading bubbles) of quality ok, -.
  double pairing_yield_ok = 0.05;

  [[nodiscard]] Validation validate() const;
};

/// Whether event detection gave a velocity, and if not why.
enum class EventStatus {
  ok,
  no_bubbles,         ///< no complete bubble at the leading tip
  no_first_velocity,  ///< Shen pairing without a positive first velocity estimate
  too_few_bubbles,    ///< fewer paired bubbles than options.bubbles_reported
  no_tip_separation,  ///< the tip separation is not positive: no velocity
};
std::string_view to_string(EventStatus status);

/// One leading bubble's pairing with a trailing tip.
struct BubblePairing {
  /// The trailing bubble the rule proposed (an index into the trailing
  /// crossings), also when it was refused; none when no later bubble exists
  /// or the leading bubble is censored. The partner when fate is paired.
  std::optional<std::size_t> candidate;
  double front_lag = std::numeric_limits<double>::quiet_NaN();   ///< t_k,2h - t_0,2h, s
  double rear_lag = std::numeric_limits<double>::quiet_NaN();    ///< t_k,2h+1 - t_0,2h+1, s
  double centre_lag = std::numeric_limits<double>::quiet_NaN();  ///< mean of the two, s
  double disparity = std::numeric_limits<double>::quiet_NaN();   ///< |dt_0,h - dt_k,h| / dt_0,h, -
  BubbleFate fate = BubbleFate::no_partner;                      ///< never roc here
};

/// The pairing of every leading bubble with one trailing tip.
struct PairingResult {
  EventStatus status = EventStatus::ok;  ///< ok or no_first_velocity
  std::string message;                   ///< why not ok
  [[nodiscard]] bool ok() const { return status == EventStatus::ok; }
  std::vector<BubblePairing> bubbles;    ///< one per leading crossing, in order (empty unless ok)
};

/// Pairs each leading bubble with a bubble of trailing tip k (items 1-4):
/// tip_distance is |S_0k| in m (Shen's limit), first_velocity V_gas in m/s
/// (needed by Shen, not read by Kramer). Fates: paired, censored,
/// no_partner, beyond_next, disparity, shen_lag, non_positive_lag,
/// claimed_twice. O(N + M).
PairingResult pair_bubbles(std::span<const Crossing> leading, std::span<const Crossing> trailing, double tip_distance,
                           const EventOptions& options, std::optional<double> first_velocity = std::nullopt);

/// A row of the bubble table (written by awcc/serialise.hpp's
/// event_bubbles_csv): one per leading bubble. NaN where a bubble has no value.
struct EventBubble {
  double leading_front = 0.0, leading_rear = 0.0;  ///< s
  double trailing_front = std::numeric_limits<double>::quiet_NaN();  ///< s, the candidate's
  double trailing_rear = std::numeric_limits<double>::quiet_NaN();   ///< s
  double front_lag = std::numeric_limits<double>::quiet_NaN();       ///< s
  double rear_lag = std::numeric_limits<double>::quiet_NaN();        ///< s
  double centre_lag = std::numeric_limits<double>::quiet_NaN();      ///< s
  double disparity = std::numeric_limits<double>::quiet_NaN();       ///< -
  /// dx / centre lag, m/s, wherever the candidate's centre lag is positive
  /// (also for a refused candidate: the fate says whether it counts).
  double velocity = std::numeric_limits<double>::quiet_NaN();
  double chord_length = std::numeric_limits<double>::quiet_NaN();    ///< leading chord time x velocity, m
  double weight = std::numeric_limits<double>::quiet_NaN();          ///< interaction time span, s
  BubbleFate fate = BubbleFate::no_partner;
};

struct EventResult {
  EventStatus status = EventStatus::no_bubbles;
  std::string message;  ///< why not ok (empty when ok)
  [[nodiscard]] bool ok() const { return status == EventStatus::ok; }
  /// AWCC's levels, with the bubble counts of item 7; insufficient whenever not ok.
  AwccQuality quality = AwccQuality::insufficient;
  std::string quality_reason;  ///< why low or insufficient (empty when ok)
  EventOptions options;        ///< the options that made this result
  /// With interface_times crossing: which tips' fronts or rears kept their
  /// midpoints and why (awcc/process.hpp, threshold_crossings); "" otherwise.
  std::string interface_times_note;
  std::optional<double> first_velocity;  ///< V_gas given, m/s
  double velocity = 0.0;       ///< m/s (0 unless ok)
  double velocity_rms = 0.0;   ///< m/s
  double turbulence_intensity = 0.0;
  Interval95 velocity_ci95, velocity_rms_ci95, turbulence_intensity_ci95;
  /// Whether Tu is a measurement: false when every paired bubble has the
  /// same centre lag (interface times at whole samples of a slow rate):
  /// u_rms is then 0 by the lag's resolution; the outputs give no Tu and
  /// quality is low (AWCC's spread rule, awcc/awcc.hpp).
  bool turbulence_measured = true;
  std::int64_t bubbles_total = 0;     ///< leading bubbles (crossings), censored included
  std::int64_t bubbles_complete = 0;  ///< leading bubbles not censored: the yield's denominator
  std::int64_t bubbles_paired = 0;    ///< count(BubbleFate::paired), the N of the moments
  /// Leading bubbles of each fate, indexed by BubbleFate; they sum to
  /// bubbles_total once the pairing ran (all zero, and `bubbles` empty, when
  /// it was refused: no_tip_separation, no_first_velocity).
  std::array<std::int64_t, bubble_fate_count> bubbles_by_fate{};
  [[nodiscard]] std::int64_t count(BubbleFate fate) const { return bubbles_by_fate[static_cast<std::size_t>(fate)]; }
  int roc_iterations = 0;
  /// Chord lengths of the paired bubbles at their own velocities, m (count 0 unless ok).
  Summary chord_length;
  double sauter_diameter = 0.0;  ///< 1.5 x mean chord length, m (0 unless ok)
  std::vector<EventBubble> bubbles;  ///< one per leading bubble, in time order
};

/// Event detection of a tip pair from their crossings: dx the streamwise tip
/// separation in m (the velocity's numerator and, for Shen, |S|),
/// first_velocity Shen's V_gas in m/s.
EventResult event_detection(std::span<const Crossing> leading, std::span<const Crossing> trailing, double dx,
                            const EventOptions& options = {}, std::optional<double> first_velocity = std::nullopt);
/// The same from the binarised signals (same sampling rate and length).
EventResult event_detection(const AirIntervals& leading, const AirIntervals& trailing, double dx,
                            const EventOptions& options = {}, std::optional<double> first_velocity = std::nullopt);

}  // namespace awcc
