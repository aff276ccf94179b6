#pragma once
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

/// Event detection's velocity against a correlation method's, by the same
/// rule (m/s): FSCC's where it has an interval, else AWCC's of quality ok.
/// Event detection's Kramer pairing takes an unrelated later bubble as the
/// partner of one that passed beside the trailing tip; where bubbles are
/// sparse those lags are long and the mean is biased low (30-60 % on the
/// spillway recordings), inside the outlier band, with hundreds of bubbles:
/// its own interval cannot show it, the comparison does.
struct EventsComparison {
  std::string_view reference;      ///< "FSCC" or "AWCC"
  double events = 0.0, reference_velocity = 0.0;
  Interval95 events_ci95, reference_ci95;
  double difference = 0.0;  ///< events - reference
  double allowed = 0.0;     ///< the 95 % half-width of the difference
  double relative = 0.0;    ///< |difference| / reference
  [[nodiscard]] bool disagree() const { return std::abs(difference) > allowed; }
};
/// Empty unless event detection gave a velocity and a reference exists.
std::optional<EventsComparison> compare_events(const EventResult& events, const ProcessResult& result);
/// The same for the multi-tip mean vector's streamwise component (its
/// interval: mean +/- 1.96 rms / sqrt(N), awcc/multi_tip.hpp) against FSCC's
/// velocity of the tip pair; empty unless both exist.
std::optional<EventsComparison> compare_multi_tip(const MultiTipResult& vectors, const ProcessResult& result);

/// Every warning of a processed recording, in the order of the list above.
std::vector<Warning> assess(const ProcessResult& result);

}  // namespace awcc
