#pragma once
// The steps of AWCC (awcc/awcc.hpp), for the library's own use, its tests,
// benchmarks and fuzz targets; not installed, not a stable interface.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "awcc/awcc.hpp"

namespace awcc::detail {

/// A window correlation of binary signals held at its breakpoints: R12 is
/// linear in the lag between consecutive entries of `lags` (every kink of the
/// overlap sums and of the mean terms is one of them), so peaks, prominences
/// and the SPR follow from these few hundred points exactly instead of from
/// every lag.
struct PiecewiseCorrelation {
  std::vector<std::int64_t> lags;   ///< increasing, first = k_min, last = k_max
  std::vector<double> values;       ///< R12 at those lags
  [[nodiscard]] bool empty() const { return lags.empty(); }
  /// R12 at any lag in [k_min, k_max] (linear between breakpoints).
  [[nodiscard]] double at(std::int64_t lag) const;
  /// R12 at every lag k_min..k_max.
  [[nodiscard]] std::vector<double> expand() const;
};

/// Interval path (exact, binary signals): empty when a segment is constant.
PiecewiseCorrelation window_correlation_piecewise(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                                  std::int64_t length, std::int64_t k_min, std::int64_t k_max,
                                                  AwccWorkspace& workspace);
/// The same into the caller's `out`, whose buffers are reused (no allocation per window).
void window_correlation_piecewise(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                  std::int64_t length, std::int64_t k_min, std::int64_t k_max,
                                  AwccWorkspace& workspace, PiecewiseCorrelation& out);

/// The normalised cross-correlation of a window, lags [k_min, k_max].
/// Binary signals, interval path (exact): the piecewise form expanded.
std::vector<double> window_correlation_intervals(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                                 std::int64_t length, std::int64_t k_min, std::int64_t k_max,
                                                 AwccWorkspace& workspace);
/// Any signals given as the window's samples (binary 0/1 or voltages), FFT path.
std::vector<double> window_correlation_fft(std::span<const double> x, std::span<const double> y, std::int64_t k_min,
                                           std::int64_t k_max, AwccWorkspace& workspace);

/// Peak and secondary peak ratio of a correlation function whose first value
/// is at lag first_lag.
struct CorrelationPeak {
  std::size_t index = 0;        ///< of the maximum
  double height = 0.0;
  double refined_index = 0.0;   ///< parabolic refinement when asked, else index
  double spr = 0.0;
};
CorrelationPeak analyse_correlation(std::span<const double> r, Subsample subsample, double prominence_fraction,
                                    AwccWorkspace& workspace);
/// The same on the piecewise form; indices count lags from k_min.
CorrelationPeak analyse_correlation(const PiecewiseCorrelation& r, Subsample subsample, double prominence_fraction,
                                    AwccWorkspace& workspace);

/// Prominences of the local maxima of r (scipy's definition): (index, prominence).
std::vector<std::pair<std::size_t, double>> peak_prominences(std::span<const double> r);
/// Same for samples at increasing integer positions, linear in between;
/// returns (position, prominence), a flat top at the middle of its positions.
std::vector<std::pair<std::int64_t, double>> peak_prominences(std::span<const double> values,
                                                              std::span<const std::int64_t> positions);

/// Robust outlier cutoff over the velocities whose flag is true; clears the
/// flag of the rejected ones. Returns the number of iterations.
int robust_outlier_cutoff(std::span<const double> velocities, std::vector<bool>& keep);

/// The robust outlier cutoff over the `velocity` of the items (AWCC's
/// windows, event detection's bubbles) whose fate is `accepted`; those it
/// rejects get fate `rejected`. Returns the number of iterations.
template <class Item, class Fate>
int cut_outliers(std::vector<Item>& items, Fate accepted, Fate rejected) {
  std::vector<double> u(items.size());
  std::vector<bool> keep(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    u[i] = items[i].velocity;
    keep[i] = items[i].fate == accepted;
  }
  const int iterations = robust_outlier_cutoff(u, keep);
  for (std::size_t i = 0; i < items.size(); ++i)
    if (items[i].fate == accepted && !keep[i]) items[i].fate = rejected;
  return iterations;
}

/// The moments of METHOD 4 item 7 over accepted values, each with its
/// weight (a window's duration, a bubble's interaction time span, or 1):
/// mean = sum w u / sum w, rms = sqrt(sum w (u - mean)^2 / sum w). AWCC and
/// event detection both take them from here.
struct WeightedMoments {
  double mean = 0.0;
  double rms = 0.0;
};
WeightedMoments weighted_moments(std::span<const double> values, std::span<const double> weights);

/// The 95 % intervals of METHOD 4 item 8 from N accepted values: mean +/-
/// 1.96 rms / sqrt(N), rms +/- 1.96 rms / sqrt(2N), Tu = rms / mean +/- 1.96
/// sigma_T with sigma_T^2 = Tu^2 (Tu^2 / N + 1 / (2N)); the half-widths too
/// (a quality reason quotes Tu's).
struct MomentIntervals {
  double turbulence_intensity = 0.0;   ///< rms / mean
  double mean_half = 0.0, rms_half = 0.0, turbulence_intensity_half = 0.0;
  Interval95 mean, rms, tu;
};
MomentIntervals moment_intervals95(double mean, double rms, std::int64_t n);
/// The same for one component of a vector mean, whose turbulence intensity
/// is rms / scale (the multi-tip vectors' Tu_j = rms_j / |mean vector|).
MomentIntervals moment_intervals95(double mean, double rms, std::int64_t n, double scale);

/// The words of a quality reason: what is counted ("accepted windows"),
/// the yield's name ("data yield"), its ratio ("windows accepted") and the
/// selection it may bias ("the accepted windows").
struct QualityWords {
  std::string_view counted, yield, ratio, selection;
};
/// METHOD 4 item 10 for a result whose moments are reported: low below
/// `ok_count` accepted items (the reason quotes Tu's interval) or below the
/// least yield accepted / total, ok otherwise (empty reason). AWCC's windows
/// and event detection's bubbles are judged by this one rule.
std::pair<AwccQuality, std::string> reported_quality(std::int64_t accepted, std::int64_t total, std::int64_t ok_count,
                                                     double yield_ok, const MomentIntervals& intervals,
                                                     const QualityWords& words);

/// Lags searched in a window of `length` samples: all, or those of the
/// stated velocity range (k_max < k_min: the window is too short for it).
std::pair<std::int64_t, std::int64_t> awcc_lag_range(std::int64_t length, double dx, double fs,
                                                      const AwccOptions& options);

/// Fills a window's peak, lag, velocity, SPR and fate (constant, lag or
/// correlation; accepted otherwise) from its correlation r over lags
/// [first_lag, first_lag + r.size()); an empty r means a constant segment.
void analyse_window(AwccWindow& window, std::span<const double> r, std::int64_t first_lag, double dx, double fs,
                    const AwccOptions& options, AwccWorkspace& workspace);
/// Same from a peak already found (piecewise path); `constant` for a constant segment.
void analyse_window(AwccWindow& window, const CorrelationPeak& peak, bool constant, std::int64_t first_lag, double dx,
                    double fs, const AwccOptions& options);

/// Applies the robust outlier cutoff to the accepted windows, then fills the
/// moments, intervals, counts, the status and its message.
void awcc_summarise(AwccResult& result, const AwccOptions& options);

/// The accepted windows' mean whole-sample lag, sum w / sum (w / k_i)
/// (awcc/awcc.hpp, least_resolved_lag_samples); 0 without an accepted window.
[[nodiscard]] double mean_lag_samples(std::span<const AwccWindow> windows, Weighting weighting);

/// Quality `low`, with the bounds, when an ok result's mean lag is below
/// least_resolved_lag_samples: its velocity is bounded, not measured.
void flag_unresolved_lag(AwccResult& result, double dx, double fs);
/// The edge and spread rules (AwccResult::windows_at_least_lag,
/// turbulence_measured): counts the accepted windows at an end of the
/// velocity range's lags, and finds whether they all share one lag; either
/// lowers the quality with the reason.
void judge_lag_range_and_spread(AwccResult& result, double dx, double fs, const AwccOptions& options);

/// The bubble-probe correction of every accepted window (when the options
/// ask for it): velocity becomes u0, measured_velocity keeps dx / lag; a
/// failure rejects the window (fate correction). Run before awcc_summarise.
void correct_windows(AwccResult& result, double dx, const AwccOptions& options);

/// Marks an otherwise good result as having no velocity for want of dx.
void no_tip_separation(AwccResult& result);
/// Marks a result as having no velocity because the tips are swapped (`why`).
void tips_swapped(AwccResult& result, const std::string& why);

/// Scratch of the window correlations (AwccWorkspace owns one).
struct AwccScratch {
  FftPlanCache plans;                           // one per FFT size, built on first use
  FftBuffers fft;                               // the transform of the window being correlated
  std::vector<std::uint8_t> rendered_x, rendered_y;  // a window of binary signals, sample by sample
  std::vector<double> samples_x, samples_y;     // a window's samples as the FFT path takes them
  PiecewiseCorrelation piecewise;               // the interval path's correlation of the window
  std::vector<AirInterval> clipped_x, clipped_y;
  std::vector<std::int32_t> impulse;            // per lag; all zero between windows (the sweep clears what it used)
  std::vector<std::int32_t> impulse_x, impulse_y;  // the same for each tip's air in the overlapping range
  std::vector<std::uint64_t> mark;              // a bit per lag: a kink of the window's correlation there
  std::vector<std::complex<double>> spectrum;
  std::vector<double> turns, left, right, prominence;
  std::vector<std::pair<std::size_t, std::size_t>> tops;
  std::vector<std::pair<double, double>> stack;
};

}  // namespace awcc::detail
