#pragma once
#include <cstdint>
// A processed recording's one list of warnings (awcc/flags.hpp), assembled in
// one place after processing: the reader's notes, the channels not processed,
// FSCC's plausibility warnings, the velocity series' time-scale warning and
// the consistency of FSCC and AWCC. process_recording and process_binarised
// fill ProcessResult::warnings with it; every output writes that list.
//
// FSCC and AWCC disagree (methods_disagree) when their velocities differ by
// more than their 95 % sampling intervals allow together. With d = u_AWCC -
// u_FSCC and h_F, h_A the half-widths of the two intervals on the sides that
// face each other (FSCC's is asymmetric, awcc/fscc.hpp), the difference of
// two independent estimates has the 95 % half-width sqrt(h_F^2 + h_A^2); the
// flag is raised when |d| exceeds it. Both methods read the same record, so
// their sampling errors are positively correlated and the difference scatters
// less than that: the rule is conservative (a flagged difference is no
// scatter). It compares whenever both give a velocity: AWCC of quality low
// is compared (its interval is wide when its windows are few), AWCC of
// quality insufficient gives no velocity and is not. FSCC without an interval
// (too few segments hold a peak) is not compared. Event detection's velocity
// is compared with FSCC's (or AWCC's) by the same rule (events_disagree).

#include <cmath>
#include <optional>
#include <vector>

#include "awcc/flags.hpp"
#include "awcc/process.hpp"

namespace awcc {

/// FSCC's and AWCC's velocities side by side (m/s).
struct MethodsComparison {
  double fscc = 0.0, awcc = 0.0;
  Interval95 fscc_ci95, awcc_ci95;
  double difference = 0.0;  ///< awcc - fscc
  double allowed = 0.0;     ///< the 95 % half-width of the difference (above)
  double relative = 0.0;    ///< |difference| / fscc
  [[nodiscard]] bool disagree() const { return std::abs(difference) > allowed; }
};

/// Both velocities and their intervals; empty unless both methods gave a
/// velocity and FSCC an interval.
std::optional<MethodsComparison> compare_methods(const FsccResult& fscc, const AwccResult& awcc);

/// The velocity FSCC's peak gives for a flow of mean streamwise velocity U
/// and turbulence intensity Tu, m/s. FSCC's lag is the cross-correlation's
/// peak, the most probable lag tau = dx / u, not dx / U: for u ~ N(U, (Tu
/// U)^2) the lag's density p(tau) ~ tau^-2 phi((dx / tau - U) / (Tu U))
/// peaks where v = dx / tau solves v^2 - U v - 2 (Tu U)^2 = 0, i.e.
///   v = U (1 + sqrt(1 + 8 Tu^2)) / 2,
/// +4.3 % at Tu = 0.15 and +15.6 % at 0.3 (the tip-geometry study measured
/// FSCC 1.6-7 % and 10-26 % above the realised mean there).
double correlation_peak_velocity(double mean, double turbulence_intensity);

/// A bubble-by-bubble mean velocity against a correlation method's (m/s):
/// event detection's, or the multi-tip mean vector's streamwise component.
/// FSCC's peak lies above the mean by a factor that grows with Tu
/// (correlation_peak_velocity), so against FSCC (where it has an interval)
/// the mean is expected in the band [u_F / g, u_F], g the peak factor at the
/// method's own Tu held at most at 0.3 (the range the peak model was measured
/// over; a mis-paired record's Tu is itself inflated, 0.9-1.7 on the
/// spillway rows, and must not widen the band); against AWCC of quality ok
/// (AWCC's windows average velocities, not lags) the band is u_A alone. The
/// difference is the mean's distance from the band. They disagree when it
/// exceeds both the 95 % half-width of the difference (the intervals' sides
/// that face each other, added in quadrature, as compare_methods) and
/// `tolerance` of the reference: the peak model's residual (the tip-geometry
/// study's FSCC lay up to 10 % beyond the band at Tu 0.3). What it is for is
/// gross: event detection's Kramer pairing taking unrelated later bubbles as
/// partners where bubbles are sparse (the spillway rows at c < 0.2: 30-60 %
/// below FSCC, with hundreds of bubbles whose own interval cannot show it),
/// multi-tip vectors from mis-paired bubbles.
struct EventsComparison {
  std::string_view reference;      ///< "FSCC" or "AWCC"
  double events = 0.0;             ///< the method's mean, m/s
  double reference_velocity = 0.0;
  Interval95 events_ci95, reference_ci95;
  double band_lower = 0.0, band_upper = 0.0;  ///< where the mean is expected, m/s
  double difference = 0.0;  ///< the mean's distance from the band (negative below), m/s
  double allowed = 0.0;     ///< the 95 % half-width of the difference
  double relative = 0.0;    ///< |difference| / reference
  double tolerance = 0.0;   ///< the least relative difference that counts
  [[nodiscard]] bool disagree() const { return std::abs(difference) > allowed && relative > tolerance; }
};
/// The turbulence intensity at which the peak band is held (above).
inline constexpr double peak_model_tu_max = 0.3;
/// The peak model's residual that a disagreement must exceed (above).
inline constexpr double peak_model_tolerance = 0.10;
/// Empty unless event detection gave a velocity and a reference exists.
std::optional<EventsComparison> compare_events(const EventResult& events, const ProcessResult& result);
/// The same for the multi-tip mean vector's streamwise component (its
/// interval: mean +/- 1.96 rms / sqrt(N), awcc/multi_tip.hpp, and its Tu_x)
/// against FSCC's velocity of the tip pair; empty unless both exist.
std::optional<EventsComparison> compare_multi_tip(const MultiTipResult& vectors, const ProcessResult& result);

/// The consistency rules' effect on the bubble-by-bubble methods' quality,
/// here beside the warnings they raise (one owner): event detection of
/// quality ok that compare_events finds in disagreement becomes low, saying
/// why (its Kramer pairing takes unrelated later bubbles as partners where
/// bubbles are sparse or the tips offset, inside the outlier band: the
/// comparison is what catches that).
void judge_events(EventResult& events, const ProcessResult& result);

// A measured Tu_x above which the joint pairing's speed band and cone
// (probe-speed-min, probe-speed-max, probe-angle-max) cut the tails of the
// velocity distribution enough to bias the mean: in the tip-geometry study
// (docs/validation.md) a flow of Tu_x 0.3 came out with u_x 4-11 % high and
// Tu_x 16-26 % low (measured Tu_x 0.22-0.25), one of 0.15 within 2.4 % and
// 5 % (measured Tu_x <= 0.16).
inline constexpr double multi_tip_tu_truncated = 0.2;

// A stretch of one phase far longer than the record's chords allow: the
// probe lifted out of the flow, a flow stopped, a connection lost for a
// while. Among n chords of a phase with mean m drawn independently from an
// exponential law, P(longest > k m ln n) = 1 - (1 - n^-k)^n, about n^(1-k):
// nothing at k = 15. Real chords are clustered and overdispersed: on the ten
// real recordings the longest chord of either phase is 1.1-4.3 times m ln n;
// 5 s of a 45 s record in air gave 175, in water 28, one channel at 0 V for
// 1 s 96 (docs/reliability.md). Below 20 chords ln n says too little.
inline constexpr double single_phase_stretch_factor = 15.0;
inline constexpr std::int64_t single_phase_stretch_chords_min = 20;

/// The multi-tip vectors' quality (ProbeResult::quality): insufficient
/// without vectors; low, with every reason, when FSCC of the leading tip with
/// a trailing tip finds no delay or the trailing signal first (a channel
/// mapped to the wrong tip), the solver's caution is raised, the measured
/// Tu_x exceeds multi_tip_tu_truncated, or compare_multi_tip disagrees.
void judge_probe(ProbeResult& probe, const ProcessResult& result, const EventOptions& pairing);

/// Every warning of a processed recording, in the order of the list above.
std::vector<Warning> assess(const ProcessResult& result);

}  // namespace awcc
