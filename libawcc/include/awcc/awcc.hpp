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
//    gives no velocity (rejected); optional parabolic refinement of k_i.
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

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/fft.hpp"
#include "awcc/fscc.hpp"
#include "awcc/phase_statistics.hpp"

namespace awcc {

enum class Weighting { duration, none };
enum class CorrelationPath { automatic, fft, intervals };
enum class WindowFate { accepted, correlation, lag, roc, constant };

std::string_view to_string(WindowFate fate);

struct AwccOptions {
  int np = 10;                            ///< particles (air chords) per window, 1-1000
  double filter_a = 0.4;                  ///< correlation filter threshold A, -
  bool roc = true;                        ///< robust outlier cutoff
  Weighting weighting = Weighting::duration;
  Subsample subsample = Subsample::none;  ///< parabolic refinement of the peak lag
  CorrelationPath path = CorrelationPath::automatic;  ///< automatic: intervals for binary signals
  double prominence_fraction = 0.3;       ///< peaks kept for the SPR, fraction of the tallest's prominence
  std::optional<double> velocity_min;     ///< m/s: with velocity_max, lags searched from dx / u
  std::optional<double> velocity_max;     ///< m/s
  /// Largest |lag| searched, samples: bounds the work and memory of
  /// pathological windows (a record of a few enormous bubbles); 2^20 is far
  /// beyond any physical transit (2 s at 500 kHz).
  std::int64_t max_lag_samples = std::int64_t{1} << 20;

  [[nodiscard]] std::string validate() const;
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
  double velocity = 0.0;        ///< dx / lag, m/s (0 when the lag is not positive)
  double r12_max = 0.0;
  double spr = 0.0;             ///< secondary peak ratio
  double void_fraction = 0.0;   ///< leading tip, in the window
  double count_rate = 0.0;      ///< particles / duration, 1/s
  WindowFate fate = WindowFate::accepted;
};

struct AwccResult {
  bool defined = false;         ///< false: see reason; the figures below are 0
  std::string reason;
  int np = 0;                   ///< particles per window used
  double velocity = 0.0;        ///< m/s
  double velocity_rms = 0.0;    ///< m/s
  double turbulence_intensity = 0.0;
  Interval95 velocity_ci95, velocity_rms_ci95, turbulence_intensity_ci95;
  std::int64_t windows_total = 0, windows_accepted = 0;
  std::int64_t rejected_correlation = 0, rejected_lag = 0, rejected_roc = 0, rejected_constant = 0;
  std::int64_t lag_zero_windows = 0;  ///< windows peaking at lag 0 (delay below one sample)
  int roc_iterations = 0;
  std::vector<AwccWindow> windows;
};

/// Windows of Np particles on the leading tip (start and length only).
std::vector<AwccWindow> awcc_windows(const AirIntervals& leading, int np);

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
                                                  std::int64_t length, std::int64_t k_min, std::int64_t k_max);

/// The normalised cross-correlation of a window, lags [k_min, k_max].
/// Binary signals, interval path (exact): the piecewise form expanded.
std::vector<double> window_correlation_intervals(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                                 std::int64_t length, std::int64_t k_min, std::int64_t k_max);
/// Any signals given as the window's samples (binary 0/1 or voltages), FFT path.
std::vector<double> window_correlation_fft(std::span<const double> x, std::span<const double> y, std::int64_t k_min,
                                           std::int64_t k_max, FftPlanCache& plans);

/// Peak and secondary peak ratio of a correlation function whose first value
/// is at lag first_lag.
struct CorrelationPeak {
  std::size_t index = 0;        ///< of the maximum
  double height = 0.0;
  double refined_index = 0.0;   ///< parabolic refinement when asked, else index
  double spr = 0.0;
};
CorrelationPeak analyse_correlation(std::span<const double> r, Subsample subsample, double prominence_fraction);
/// The same on the piecewise form; indices count lags from k_min.
CorrelationPeak analyse_correlation(const PiecewiseCorrelation& r, Subsample subsample, double prominence_fraction);

/// Prominences of the local maxima of r (scipy's definition): (index, prominence).
std::vector<std::pair<std::size_t, double>> peak_prominences(std::span<const double> r);
/// Same for samples at increasing integer positions, linear in between;
/// returns (position, prominence), a flat top at the middle of its positions.
std::vector<std::pair<std::int64_t, double>> peak_prominences(std::span<const double> values,
                                                              std::span<const std::int64_t> positions);

/// Robust outlier cutoff over the velocities whose flag is true; clears the
/// flag of the rejected ones. Returns the number of iterations.
int robust_outlier_cutoff(std::span<const double> velocities, std::vector<bool>& keep);

/// Lags searched in a window of `length` samples: all, or those of the
/// stated velocity range.
std::pair<std::int64_t, std::int64_t> awcc_lag_range(std::int64_t length, double dx, double fs,
                                                      const AwccOptions& options);

/// Fills a window's peak, lag, velocity, SPR and fate (constant, lag or
/// correlation; accepted otherwise) from its correlation r over lags
/// [first_lag, first_lag + r.size()); an empty r means a constant segment.
void analyse_window(AwccWindow& window, std::span<const double> r, std::int64_t first_lag, double dx, double fs,
                    const AwccOptions& options);
/// Same from a peak already found (piecewise path); `constant` for a constant segment.
void analyse_window(AwccWindow& window, const CorrelationPeak& peak, bool constant, std::int64_t first_lag, double dx,
                    double fs, const AwccOptions& options);

/// Applies the robust outlier cutoff to the accepted windows, then fills the
/// moments, intervals, counts and the reason when undefined.
void awcc_summarise(AwccResult& result, const AwccOptions& options);

/// AWCC of two binary signals (correlated as binary).
AwccResult awcc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const AwccOptions& options = {});

}  // namespace awcc
