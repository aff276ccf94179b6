#pragma once
// Adaptive Window Cross-Correlation (AWCC), METHOD.md section 4 (Kramer et al.
// 2019, 2020; robust outlier cutoff after Valero et al. 2020).
//
// 1. Windows: contiguous, each holding Np air and Np water chords of the
//    leading tip: the boundary of window i is the 2 Np i-th transition of the
//    leading signal counted from the record's start; leftover chords join the
//    last window. Window i starts at s_i, has N_i samples, T_W,i = N_i / fs.
// 2. Correlation per window over [s_i, s_i + N_i) of both signals, each
//    segment's mean removed:
//      R12,i(k) = sum_t x(t) y(t + k) / sqrt(sum x^2 sum y^2),
//    t and t + k inside the window, for the lags searched (all, by default).
//    Two exact paths for binary signals: FFTs of the window (zero-padded to a
//    fast size >= 2N - 1, plans reused per size), and the interval path: each
//    pair of air intervals adds a trapezoid in k, summed through its second
//    differences; the mean terms come from prefix sums. Raw voltages are
//    correlated with the FFT path.
// 3. Peak: R12,i,max at lag k_i; tau_i = k_i / fs, u_i = dx / tau_i; k_i <= 0
//    gives no velocity (rejected); optional parabolic refinement of k_i. A
//    window shorter than the least lag of a stated velocity range cannot be
//    correlated over it (rejected as too short).
// 4. Secondary peak ratio: local maxima of R12,i with their prominences (as
//    MATLAB findpeaks / scipy peak_prominences); peaks of prominence at least
//    0.3 x that of the tallest peak are kept; SPR = second-tallest kept peak /
//    tallest (0 with one).
// 5. Correlation filter: reject when R12,i,max / (SPR_i^2 + 1) < A (0.4).
// 6. Robust outlier cutoff, iterated until nothing more is rejected: centre =
//    median of the surviving u_i, s = 1.4826 median |u_i - centre|, reject
//    |u_i - centre| > sqrt(2 ln N) s, N the number surviving.
// 7. Moments with weights w_i = T_W,i (duration weighting, Buchhave 1979) or
//    1: u = sum w u_i / sum w, u_rms = sqrt(sum w (u_i - u)^2 / sum w),
//    Tu = u_rms / u.
// 8. 95 % intervals, N accepted windows: u +/- 1.96 u_rms / sqrt(N);
//    u_rms +/- 1.96 u_rms / sqrt(2N); Tu +/- 1.96 sigma_T with
//    sigma_T^2 = Tu^2 (Tu^2 / N + 1 / (2N)).
// 9. Quality (METHOD 4, item 10): insufficient below `windows_reported`
//    accepted windows (10: the Tu interval's relative half-width
//    1.96 sqrt(Tu^2 / N + 1 / (2N)) is 0.45 at N = 10 for Tu = 0.2): no
//    velocity or Tu, the reason instead; low below `windows_ok` (100: 0.14)
//    or a data yield (accepted / total windows) below `yield_ok` (5 %):
//    reported and flagged; ok otherwise. Windows that mostly peak at negative
//    lags mean swapped tips (or a dx of the wrong sign): no velocity. A mean
//    lag below least_resolved_lag_samples (a lag of one sample) is `low`
//    too: the velocity is bounded, not measured; so is a data yield below
//    chance_data_yield: the accepted windows may be chance peaks.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <memory>

#include "awcc/air_intervals.hpp"
#include "awcc/fft.hpp"
#include "awcc/fscc.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/probe_correction.hpp"
#include "awcc/weighting_gap.hpp"

namespace awcc {

enum class Weighting { duration, none };
enum class CorrelationPath { automatic, fft, intervals };
enum class WindowFate { accepted, correlation, lag, roc, constant, too_short, correction };
/// The fates' names in the enum's order: the windows table's fate column and
/// the result's window counts (awcc/serialise.hpp) are written from this one table.
inline constexpr std::array<std::string_view, 7> window_fate_names{"accepted", "correlation", "lag",       "roc",
                                                                   "constant", "too_short",   "correction"};
inline constexpr std::size_t window_fate_count = window_fate_names.size();
static_assert(static_cast<std::size_t>(WindowFate::correction) + 1 == window_fate_count,
              "a fate added to WindowFate needs its name in window_fate_names");

std::string_view to_string(WindowFate fate);
std::string_view to_string(Weighting weighting);

/// Np's range, the one statement of it (options, validation, designs, pdp correct).
inline constexpr int np_min = 1, np_max = 1000;

struct AwccOptions {
  /// Particles (air chords of the leading tip) per window, np_min-np_max.
  /// Fewer give more windows (a finer velocity series) but noisier
  /// correlations.
  int np = 10;
  /// Correlation filter threshold A, -: windows with R12max / (SPR^2 + 1) < A
  /// are rejected; 0.4 balances yield against spurious peaks (Kramer 2019).
  double filter_a = 0.4;
  /// Robust outlier cutoff (Valero et al. 2020) on the accepted velocities.
  bool roc = true;
  /// Moments weighted by window duration (Buchhave 1979: removes the bias
  /// towards fast windows) or not at all.
  Weighting weighting = Weighting::duration;
  /// Correlate the binarised signals or the raw voltages (windows are still
  /// cut from the binarised leading tip). pdp process applies it to FSCC too.
  CorrelationSignal signal = CorrelationSignal::binary;
  Subsample subsample = Subsample::none;  ///< parabolic refinement of the peak lag
  CorrelationPath path = CorrelationPath::automatic;  ///< automatic: intervals for binary signals
  /// Peaks kept for the SPR, as a fraction of the tallest peak's prominence:
  /// lower counts ripples as secondary peaks.
  double prominence_fraction = 0.3;
  std::optional<double> velocity_min;     ///< m/s: with velocity_max, lags searched from dx / u
  std::optional<double> velocity_max;     ///< m/s
  /// Largest |lag| searched, samples: bounds the work and memory of
  /// pathological windows (a record of a few enormous bubbles); 2^20 is far
  /// beyond any physical transit (2 s at 500 kHz).
  std::int64_t max_lag_samples = std::int64_t{1} << 20;
  /// Fewest accepted windows whose moments are reported (quality
  /// `insufficient` below): fewer give a confident-looking but meaningless mean.
  int windows_reported = 10;
  /// Fewest accepted windows of quality `ok` (`low` below).
  int windows_ok = 100;
  /// Least data yield (accepted / total windows) of quality `ok`, -.
  double yield_ok = 0.05;
  /// Bubble-probe interaction correction of every accepted window before the
  /// outlier cutoff and the moments (awcc/probe_correction.hpp); off by default.
  ProbeCorrectionOptions probe_correction;

  [[nodiscard]] Validation validate() const;
};

/// One window: where it is, what its correlation said, and its fate.
struct AwccWindow {
  std::int64_t start = 0;       ///< first sample
  std::int64_t length = 0;      ///< samples
  double start_time = 0.0;      ///< s
  double duration = 0.0;        ///< s
  int particles = 0;            ///< air chords of the leading tip starting in the window
  std::int64_t lag_samples = 0; ///< integer lag of the peak
  double lag = 0.0;             ///< s (refined when asked)
  double velocity = 0.0;        ///< dx / lag, m/s (0 when the lag is not positive); corrected when asked
  double measured_velocity = 0.0;  ///< dx / lag before the bubble-probe correction, m/s
  double r12_max = 0.0;
  double spr = 0.0;             ///< secondary peak ratio
  double void_fraction = 0.0;   ///< leading tip, in the window
  double count_rate = 0.0;      ///< particles / duration, 1/s
  WindowFate fate = WindowFate::accepted;
};

/// Whether AWCC gave a velocity, and if not why; callers branch on this.
enum class AwccStatus {
  ok,
  too_few_particles,       ///< fewer than Np particles: no window
  delay_below_one_sample,  ///< most windows peak at lag 0: sample faster or separate the tips more
  too_few_windows,         ///< fewer accepted windows than reported (options.windows_reported)
  tips_swapped,            ///< most windows (or FSCC) peak at negative lags: the tips are swapped
  no_tip_separation,       ///< dx = 0: no velocity can be computed
};
std::string_view to_string(AwccStatus status);

/// How far to trust an AWCC result (item 9 above).
enum class AwccQuality { ok, low, insufficient };
std::string_view to_string(AwccQuality quality);

/// The least mean lag, in samples, at which AWCC's velocity is a
/// measurement. The mean lag is dx fs / u = sum w / sum (w / k_i) over the
/// accepted windows' whole-sample peak lags k_i (w their weights). A peak
/// lag is the tip-to-tip delay rounded to a whole sample, so every delay of
/// 0.5-1.5 samples reads as one: windows that peak at one sample bound the
/// velocity between dx fs / 1.5 and dx fs / 0.5 and read Tu 0, whatever the
/// flow. 1.5 is where the mean stops being a lag of one sample (half the
/// windows at two samples give 1.33, all at two give 2). Measured on the
/// conventions campaign's runs with at least 10 accepted windows: of the 929
/// that read one sample, the true velocity lay between 0.63 and 3.0 times
/// the reading for 95 % (median 1.00); of the 935 at two samples, 0.68-1.32;
/// above ten samples, 0.74-1.06 (docs/validation.md). Not an option: it is
/// the quantisation's, not a tuning choice. The AWCC quality (`low`) and the
/// correction's trust rule (c) (correction/model.hpp) read it.
inline constexpr double least_resolved_lag_samples = 1.5;
/// The velocities a delay of one sample allows, {dx fs / 1.5, dx fs / 0.5}, m/s.
[[nodiscard]] inline std::pair<double, double> one_sample_velocity_bounds(double dx, double fs) {
  return {dx * fs / 1.5, dx * fs / 0.5};
}

/// The data yield (accepted / formed windows) below which the accepted
/// windows may be chance peaks rather than the flow's. Signals that share no
/// bubble (one record's leading tip, another seed's trailing tip) still pass
/// the correlation filter and the outlier cutoff in some windows: 0.03-0.08 %
/// of them in five scenes of 20 s at 200 kHz (the base case, the base case
/// with dy 3 mm, 1 mm bubbles at dy 2 mm, c 0.02, and a 32 m/s scene of
/// 1.3 mm bubbles at dy 1.9 mm; docs/validation.md). A record whose yield is
/// within about that of chance holds as many chance windows as real ones:
/// on the conventions campaign's scored runs (own-test, long's held-out
/// records, the foreign sets), raw AWCC's velocity was off by a median 58 %
/// below 0.1 % of yield (60 runs) against 14 % at 0.1-0.2 % and 4 % above
/// 1 %. Not an option: it is what unrelated signals give, not a tuning
/// choice. The AWCC quality (`low`) and the correction's trust rule (d)
/// (correction/model.hpp) read it.
inline constexpr double chance_data_yield = 0.001;

/// The share of accepted windows at an end of the lags a velocity range lets
/// AWCC search above which they pile up there: the flow's delays run past
/// that end, so the peaks found there are the range's, not the windows', and
/// the mean and Tu are truncated (quality low, and the correction refuses
/// the row). A range that holds the flow's delays leaves an end empty but
/// for a window whose peak the outlier cutoff did not catch: on the ten
/// real recordings at 20 kHz with 0.5-20 m/s, 0 of 1,934 accepted windows;
/// the 0.5-3.5 m/s on dc157_10 put 130 of 320 (41 %) at the least
/// lag. 5 % is far from both, and a truncation that moves fewer windows
/// than that moves the mean by less than the lag's resolution. Any window
/// at an end is still flagged (lag_range_end), with its count.
inline constexpr double lag_range_end_share = 0.05;

struct AwccResult {
  AwccStatus status = AwccStatus::too_few_particles;
  std::string message;          ///< why not ok (empty when ok)
  [[nodiscard]] bool ok() const { return status == AwccStatus::ok; }
  AwccQuality quality = AwccQuality::insufficient;  ///< insufficient whenever not ok
  std::string quality_reason;   ///< why low or insufficient (empty when ok)
  int np = 0;                   ///< particles per window used
  AwccOptions options;          ///< the options that made this result
  double velocity = 0.0;        ///< m/s (0 unless ok)
  double velocity_rms = 0.0;    ///< m/s
  double turbulence_intensity = 0.0;
  Interval95 velocity_ci95, velocity_rms_ci95, turbulence_intensity_ci95;
  std::int64_t windows_total = 0;
  std::int64_t windows_accepted = 0;  ///< count(WindowFate::accepted), the N of the moments
  /// Windows of each fate, indexed by WindowFate (count() reads one); they sum
  /// to windows_total. too_short: shorter than the velocity range's least lag;
  /// correction: the bubble-probe correction failed.
  std::array<std::int64_t, window_fate_count> windows_by_fate{};
  [[nodiscard]] std::int64_t count(WindowFate fate) const { return windows_by_fate[static_cast<std::size_t>(fate)]; }
  std::int64_t lag_zero_windows = 0;  ///< windows peaking at lag 0 (delay below one sample)
  std::int64_t negative_lag_windows = 0;  ///< windows peaking at a negative lag
  /// The accepted windows' mean whole-sample lag, sum w / sum (w / k_i)
  /// (least_resolved_lag_samples); 0 unless ok.
  double mean_lag_samples = 0.0;
  /// An ok result's velocity is bounded, not measured: a lag of one sample.
  bool one_sample_lag = false;
  /// An ok result's data yield is below chance_data_yield.
  bool chance_yield = false;
  /// Accepted windows whose peak lag is the least (the fastest velocity) or
  /// the greatest (the slowest) that the velocity range lets AWCC search
  /// (options.velocity_min, velocity_max): the window's own peak may lie
  /// beyond. Both zero without a velocity range. Above lag_range_end_share
  /// of the accepted windows: quality low (lags_pile_up_at_range_end).
  std::int64_t windows_at_least_lag = 0, windows_at_greatest_lag = 0;
  /// Whether Tu is a measurement. False when every accepted window peaks at
  /// the same lag (whole-sample lags at a slow rate, a range clipped to one
  /// lag, a trailing tip stuck to the leading one): u_rms is then 0 by the
  /// lag's quantisation, not by the flow; the outputs give no Tu, the
  /// velocity's interval is the half-sample bound, quality is low and the
  /// correction refuses the row.
  bool turbulence_measured = true;
  int roc_iterations = 0;
  /// How the moments were taken (options.weighting): a correction model
  /// learns the bias of one weighting, or takes it as a feature.
  Weighting weighting = Weighting::duration;
  /// Bubble-probe correction: the moments above are of the corrected
  /// velocities; these of the measured ones over the same windows.
  bool probe_corrected = false;
  double velocity_measured = 0.0, velocity_rms_measured = 0.0, turbulence_intensity_measured = 0.0;
  std::int64_t windows_not_bubbly = 0;    ///< accepted windows above the bubbly void fraction: as measured
  /// T_u / T_W of the accepted windows, capped at time_scale_ratio_cap
  /// (awcc/velocity_series.hpp, capped_time_scale_ratio): the bias
  /// correction's feature time_scale_ratio; empty unless ok.
  std::optional<double> time_scale_ratio;
  /// The weighting gap g of the accepted windows and its flag
  /// (awcc/weighting_gap.hpp): whether the bubbles arrive as the
  /// correction's prior assumes; empty unless ok.
  std::optional<WeightingGap> weighting_gap;
  std::vector<AwccWindow> windows;
};

/// Whether an ok result's accepted windows pile up at an end of the
/// velocity range's lags (lag_range_end_share).
[[nodiscard]] bool lags_pile_up_at_range_end(const AwccResult& result);

namespace detail {
struct AwccScratch;
}

/// The scratch memory and FFT plans of the window correlations, owned by the
/// caller and reused from window to window and record to record (one per
/// thread: it is not shared).
class AwccWorkspace {
 public:
  AwccWorkspace();
  ~AwccWorkspace();
  AwccWorkspace(AwccWorkspace&&) noexcept;
  AwccWorkspace& operator=(AwccWorkspace&&) noexcept;
  [[nodiscard]] detail::AwccScratch& scratch() { return *scratch_; }

 private:
  std::unique_ptr<detail::AwccScratch> scratch_;
};

/// Windows of Np particles on the leading tip (start and length only).
std::vector<AwccWindow> awcc_windows(const AirIntervals& leading, int np);

/// AWCC of two binary signals (correlated as binary; options.signal must be
/// binary: raw voltages are correlated by awcc_raw in awcc/process.hpp).
AwccResult awcc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const AwccOptions& options = {});

/// The mean and rms (item 7) of the accepted windows' `velocity` under a
/// weighting: what AWCC reports with that weighting, from the same windows
/// (the filter and the outlier cutoff do not depend on it). {0, 0} without
/// an accepted window.
[[nodiscard]] std::pair<double, double> accepted_moments(std::span<const AwccWindow> windows, Weighting weighting,
                                                         double AwccWindow::*velocity = &AwccWindow::velocity);
/// The same with the caller's workspace.
AwccResult awcc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const AwccOptions& options,
                AwccWorkspace& workspace);

}  // namespace awcc
