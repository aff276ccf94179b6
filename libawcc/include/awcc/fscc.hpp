#pragma once
// Full-signal cross-correlation (FSCC), METHOD.md 3.
//
// Correlation functions. Binary (default): with x (leading) and y
// (trailing) the mean-removed binary signals,
//   R12(k) = sum_t x(t) y(t + k) / sqrt(sum x^2 sum y^2),   R11 likewise,
// summed over the t where both samples exist. Raw: the voltages, always as
// the segmented form below (S = 1 is the whole record).
// Segmented (Felder's program): the record is cut into S non-overlapping
// segments of L = N div S samples; in each, Pearson's coefficient per lag over
// a fixed window of B = L - (lags) samples of x (awcc/lagged_pearson.hpp), and
// the S coefficients are averaged. Felder's lags: auto 0..999, cross
// -199..800 samples, and the peak is the first lag within 1e-5 of the maximum.
//
// Scales (lags in s, tau_k = k / fs; "interpolated" = linearly between the
// two lags around the first one at or below the level):
//   R12max = max R12 (not below 0), T_R12max its lag; u = dx / T_R12max;
//   T05: R11 first at or below 0.5, interpolated;
//   T_R11zero: R11 first at or below 0, interpolated; R11min and T_R11min:
//     0 and T_R11zero when R11 crosses 0, else its minimum and lag;
//   Txx: integral of R11 from 0 to T_R11zero (else to T_R11min), trapezoids;
//   T_half: R12 first at or below R12max / 2 right of the peak,
//     interpolated; tau05 = T_half - T_R12max (Chanson's half-width);
//   T_R12zero, R12min, T_R12min and Txy likewise from the peak;
//   Tu = 0.851 sqrt(tau05^2 - T05^2) / T_R12max (Chanson's; known to
//     overestimate badly).
// A scale that is not reached within the lags searched is empty, and
// scale_notes says why. Felder's scale rules (felder_scales, his program's
// printed values): lag times in float32, the peak and minima as the first
// lags within 1e-5, and integrals that run one lag past the zero or minimum
// (felder-program.md 3).
//
// Sampling interval of the velocity (95 %). FSCC gives one peak lag per
// record; its scatter is measured as batch means measure a mean's. The same
// correlation (signal, lag range, rules) over S = fscc_interval_segments
// non-overlapping segments gives S' peak lags k_s, in samples (the segments
// where both tips vary and R12 has a positive maximum). The record's R12 is
// about the mean of its segments' R12_s; near their peaks R12_s(k) ~
// R_s - a (k - k_s)^2 / 2 with about the same curvature a, so the record's
// peak lies at about the mean of the k_s and scatters as that mean: standard
// error s_k / sqrt(S'), s_k the k_s' sample standard deviation, 95 %
// half-width t(0.975, S' - 1) s_k / sqrt(S') (Student: S' is small). The
// record's integer peak adds its rounding, uniform within +/- 1/2 sample, of
// 95 % half-width 0.475 samples. The two combine in quadrature:
//   h = sqrt((t s_k / sqrt(S'))^2 + 0.475^2) samples, H = h / fs,
// and u = dx / tau maps the lag interval [tau - H, tau + H] onto
//   [dx / (tau + H), dx / (tau - H)]   (asymmetric; none when tau <= H).
// Segments of a 45 s record (4.5 s) are far longer than a flow's time
// scales (ms), so their peaks are independent. A segment of few bubbles
// peaks far from the others and widens the interval: it is conservative
// where FSCC rests on few bubbles. With fewer than fscc_interval_segments_min
// segments holding a peak there is no interval. Like AWCC's, it covers the
// scatter of a finite record only, not the method's bias.
//
// The lagged products of binary signals are computed from the pairs of air
// intervals within the lag range, or from FFTs of blocks (overlap-save) when
// bubbles are so dense that the pairs cost more; memory depends on the lag
// range, not on the record's length.

#include <cstdint>
#include <memory>
#include <span>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/fft.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/subsample_peak.hpp"
#include "awcc/validation.hpp"

namespace awcc {

/// What FSCC correlates: the binarised signals or the raw voltages.
enum class CorrelationSignal { binary, raw };
std::string_view to_string(CorrelationSignal signal);

struct FsccOptions {
  int segments = 1;                  ///< 1 = full record; Felder used 15
  double max_lag = 0.02;             ///< s: auto lags [0, max], cross lags [-max, max]
  bool felder_lags = false;          ///< Felder's lag ranges in samples and first-maximum peak rule
  bool felder_scales = false;        ///< Felder's rules for the time scales (see above)
  Subsample subsample = Subsample::none;

  [[nodiscard]] Validation validate() const;
};

/// Whether FSCC gave a velocity, and if not why; callers branch on this.
enum class FsccStatus {
  ok,
  constant_leading,       ///< the leading tip's signal is constant (no bubble)
  constant_trailing,      ///< the trailing tip's signal is constant
  no_common_segment,      ///< no segment holds bubbles on both tips
  no_positive_peak,       ///< R12 has no positive maximum: the signals are unrelated
  non_positive_lag,       ///< the peak is at lag 0: the delay is below one sample
  tips_swapped,           ///< the peak is at a negative lag (or AWCC's windows are): the tips are swapped
  peak_at_lag_range_end,  ///< the peak sits on the last lag searched: the range is too short
  no_tip_separation,      ///< dx = 0: no velocity can be computed
};
std::string_view to_string(FsccStatus status);

struct FsccResult {
  FsccStatus status = FsccStatus::constant_leading;
  std::string message;               ///< why not ok (empty when ok)
  [[nodiscard]] bool ok() const { return status == FsccStatus::ok; }
  double r12_max = 0.0;              ///< -
  std::int64_t lag_samples = 0;      ///< integer lag of the peak
  double lag = 0.0;                  ///< s (refined when requested)
  double velocity = 0.0;             ///< dx / lag, m/s (0 unless ok)
  CorrelationSignal signal = CorrelationSignal::binary;
  int segments_used = 0;             ///< segments averaged (1 for the full record)
  std::optional<double> t05, tau05, txx, txy;       ///< s
  std::optional<double> t_r11_zero, t_r11_min, r11_min;  ///< s, s, -
  std::optional<double> t_half, t_r12_zero, t_r12_min, r12_min;  ///< s (lags, not widths), -
  std::optional<double> turbulence_intensity_chanson;
  /// Scales that are empty, with the reason ("t_r12_zero": "R12 stays above 0 ...").
  std::vector<std::pair<std::string, std::string>> scale_notes;
  /// 95 % sampling interval of the velocity, m/s (above); empty unless ok and
  /// enough segments hold a peak.
  std::optional<Interval95> velocity_ci95;
  int interval_segments = 0;         ///< segments of the interval's correlation that hold a peak
  std::string note;                  ///< the scale notes in one sentence
  std::vector<std::string> warnings; ///< a velocity that is defined but implausible, with the likely cause
  std::int64_t r11_first_lag = 0, r12_first_lag = 0;  ///< lag (samples) of r11[0], r12[0]
  std::vector<double> r11, r12;      ///< the correlation functions over the lags searched
};

/// The lag ranges searched, in samples, for a record of `samples` at fs.
struct FsccLags {
  std::int64_t r11_last = 0;                  ///< R11 at lags 0 .. r11_last
  std::int64_t r12_first = 0, r12_last = 0;   ///< R12 at lags r12_first .. r12_last
};
FsccLags fscc_lags(std::int64_t samples, double fs, const FsccOptions& options);

/// R11 and R12 over the lags searched, before any scale is read from them.
struct CorrelationFunctions {
  double fs = 0.0;
  CorrelationSignal signal = CorrelationSignal::binary;
  std::int64_t r11_first_lag = 0, r12_first_lag = 0;
  std::vector<double> r11, r12;
  int segments_used = 0;
  /// R12's peak lag in each segment used, samples (segmented functions;
  /// segments whose R12 has no positive maximum give none).
  std::vector<std::int64_t> segment_peak_lags;
  FsccStatus status = FsccStatus::ok;  ///< ok, constant_*, no_common_segment
  std::string message;
};

/// The correlation functions of two binary signals of equal length and rate.
CorrelationFunctions correlation_functions(const AirIntervals& leading, const AirIntervals& trailing,
                                           const FsccOptions& options);

/// The correlation functions of raw voltages (always segmented; S = 1 is the
/// whole record), fed block by block: memory is that of the lag range and an
/// FFT chunk, not of the record.
class RawCorrelation {
 public:
  /// plans: FFT plans and scratch, owned by the caller so that records
  /// processed in turn share them.
  RawCorrelation(std::int64_t samples, double fs, const FsccOptions& options, FftPlanCache& plans);
  ~RawCorrelation();
  RawCorrelation(const RawCorrelation&) = delete;
  RawCorrelation& operator=(const RawCorrelation&) = delete;
  /// Feeds frames [first, first + leading.size()) of both tips, in order.
  void feed(std::int64_t first, std::span<const double> leading, std::span<const double> trailing);
  /// After every frame was fed.
  CorrelationFunctions finish();
  /// Whether a record of `samples` leaves each of the options' segments a
  /// correlation window (the constructor throws std::invalid_argument if not).
  static bool fits(std::int64_t samples, double fs, const FsccOptions& options);

 private:
  struct Segment;
  void open_segment();
  std::int64_t samples_;
  double fs_;
  FsccLags lags_;
  int segments_;
  std::int64_t length_;
  int next_ = 0;
  FftPlanCache& plans_;
  std::unique_ptr<Segment> accumulators_;
  Segment* current_ = nullptr;  // the segment being fed (accumulators_), or none
  std::vector<double> sum11_, sum12_;
  int used_ = 0;
  bool constant_leading_ = true, constant_trailing_ = true;
  std::vector<std::int64_t> segment_peaks_;
};

/// Segments of the velocity's sampling interval (above), and the fewest
/// holding a peak that give one.
inline constexpr int fscc_interval_segments = 10;
inline constexpr int fscc_interval_segments_min = 5;

/// The options of the interval's correlation: the record's own, over
/// fscc_interval_segments segments.
FsccOptions interval_options(const FsccOptions& options);

/// The 95 % sampling interval of u = dx / lag (lag in s, dx in m) from the
/// segments' peak lags (samples) at fs (above); empty with fewer than
/// fscc_interval_segments_min lags or when the lag interval reaches 0.
std::optional<Interval95> fscc_velocity_interval(std::span<const std::int64_t> segment_peak_lags, double lag,
                                                 double fs, double dx);

/// Sets result.velocity_ci95 and interval_segments from `spread`, the
/// functions of the same signals under interval_options (when result is ok).
void add_velocity_interval(FsccResult& result, const CorrelationFunctions& spread, double dx);

/// Peak, velocity (dx in m) and time scales from the correlation functions.
FsccResult fscc_from_functions(CorrelationFunctions functions, double dx, const FsccOptions& options);

/// FSCC of two binary signals of equal length and rate; dx in m; with the
/// velocity's sampling interval. With `second_thread`, the leading tip's
/// auto-correlation is summed on a thread of its own while the
/// cross-correlation is summed on this one (the full record's, segments = 1):
/// the same result, bit for bit (its sums are whole numbers), in about
/// 0.6 of the time where a second core is free.
FsccResult fscc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const FsccOptions& options = {},
                bool second_thread = false);

}  // namespace awcc
