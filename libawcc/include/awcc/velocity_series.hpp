#pragma once
// The AWCC velocity series: resampling, spectrum and time scale (METHOD.md 10).
//
// AWCC gives an irregular series u_i at the centres of its accepted windows.
// As for irregular LDA data (Velte et al. 2014), the series is resampled by
// sample-and-hold (zero-order hold: each instant takes the latest accepted
// window's velocity) at about the window rate, 1 / T_W with T_W the mean
// window duration. Then:
//  - the power spectral density by Welch's method: segments of L samples,
//    Hann windows, 50 % overlap, each segment's mean removed, one-sided
//    density P(f) = 2 |X(f)|^2 / (f_r sum w^2) (not doubled at 0 and f_r/2),
//    averaged over the segments, (m/s)^2/Hz;
//  - the frequencies the windows can resolve: below 1 / (2 T_W); sample and
//    hold also low-pass filters and biases the spectrum towards the holding
//    rate (Adrian and Yao 1987), so the PSD is trustworthy well below that;
//  - the autocorrelation of u (biased estimator, mean removed) and its
//    integral time scale T_u = integral from 0 to its first zero (trapezoids,
//    the last piece to the interpolated zero).
// Sample-and-hold lengthens the autocorrelation by the holding: with
// accepted windows at a mean rate nu (gaps where windows are rejected), an
// exponential autocorrelation of scale T becomes
//   rho_SH(tau) = e^{-nu tau} + (1 - e^{-nu tau}) e^{-tau/T},
// whose integral is T + 1/nu - T / (1 + nu T): the held series' scale is
// biased up by about 1/nu when windows are sparse (validation.md). The
// integral time scale reported is therefore the slotted one (Mayo 1974;
// Tummers and Passchier 1996): products u'_i u'_j of every pair of accepted
// windows binned by their separation in slots of T_W / 2, normalised by the
// variance, integrated to the first zero; the held series' scale is reported
// beside it.
// T_u / T_W < 2 means the windows are too long to follow the turbulence:
// AWCC's Tu is then underestimated (the paper's error E4); said in a warning
// whose advice fits the row. Windows last T_W = Np d_b / (1.5 u c) (METHOD 6),
// proportional to Np, so windows of Np' <= Np (T_u / T_W) / 2 particles would
// reach the ratio 2 if T_u stays; below np_least particles (METHOD 4: Np
// 3-30) the windows cannot be shortened enough. Adjacent windows are about T_W
// apart: when their velocities are uncorrelated the slotted autocorrelation
// (slots T_W / 2) falls to 0 by lag T_W and T_u / T_W <= 1/2, and at most 1/4
// when it is 0 by the first slot: the scale is then not resolved and the true
// one may be shorter still, so Np' is an upper bound. With fewer accepted
// windows than quality ok needs, T_u itself is uncertain, and the warning says so.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "awcc/awcc.hpp"

namespace awcc {

struct SpectrumOptions {
  /// Welch segment length in resampled points: longer resolves lower
  /// frequencies, shorter averages more segments (less noise).
  int segment_length = 256;
  [[nodiscard]] Validation validate() const;
};

/// A regularly sampled series.
struct RegularSeries {
  double rate = 0.0;            ///< Hz
  double start = 0.0;           ///< s: time of the first value
  std::vector<double> values;
};

/// Sample-and-hold of values at irregular instants (ascending): at
/// start + k / rate each point takes the latest value at or before it; points
/// before the first instant take the first value.
RegularSeries sample_and_hold(std::span<const double> times, std::span<const double> values, double rate, double start,
                              double end);

struct PowerSpectrum {
  std::vector<double> frequency;  ///< Hz
  std::vector<double> density;    ///< per Hz, one-sided
  int segments = 0;
};

/// Welch's PSD of x sampled at rate (see above); empty when x is shorter
/// than one segment.
PowerSpectrum welch_psd(std::span<const double> x, double rate, int segment_length);

/// Normalised autocorrelation r(k), k = 0..max_lag, of x (mean removed,
/// biased: sum over the overlap divided by the sum of squares).
std::vector<double> autocorrelation(std::span<const double> x, std::size_t max_lag);

/// The slotted autocorrelation of irregular samples: r(k) for lags in
/// ((k - 1/2) w, (k + 1/2) w], k = 1..slots, r(0) = 1; a slot without pairs
/// takes the previous slot's value.
std::vector<double> slotted_autocorrelation(std::span<const double> times, std::span<const double> values, double slot,
                                            std::size_t slots);

/// Integral of r (sampled every dt) from 0 to its first zero; empty when r
/// stays positive.
std::optional<double> integral_to_first_zero(std::span<const double> r, double dt);

/// The integral from 0 to the first zero of the slotted autocorrelation
/// (slotted_autocorrelation's r over `slots` slots of width `slot`),
/// formed a band of slots at a time (16, 32, 64, ...), so that pairs beyond
/// the band holding the first zero are never formed, and stopped once the
/// integral reaches `stop_at` (s). Its cost therefore grows with
/// min(T_u, stop_at), not with the record or the slots. Each slot's sum has
/// slotted_autocorrelation's pairs in its order, and the trapezoids are
/// integral_to_first_zero's: the same value, bit for bit.
struct SlottedIntegral {
  double integral = 0.0;      ///< s: to the first zero, or as far as it went
  bool zero_reached = false;  ///< the autocorrelation reached 0 (integral complete)
  bool stopped = false;       ///< the integral reached stop_at first
};
SlottedIntegral slotted_integral_to_first_zero(std::span<const double> times, std::span<const double> values,
                                               double slot, std::size_t slots, double stop_at);

enum class SpectrumStatus { ok, no_awcc_velocity, too_few_points };
std::string_view to_string(SpectrumStatus status);

struct VelocitySpectrum {
  SpectrumStatus status = SpectrumStatus::no_awcc_velocity;
  std::string message;
  double mean_window_duration = 0.0;  ///< T_W, s
  double resample_rate = 0.0;         ///< Hz (1 / T_W)
  double resolvable_frequency = 0.0;  ///< 1 / (2 T_W), Hz
  PowerSpectrum psd;
  std::vector<double> autocorrelation;  ///< at lags k / resample_rate
  std::optional<double> integral_time_scale;  ///< T_u, s, slotted (unbiased by the holding)
  std::optional<double> integral_time_scale_held;  ///< s, of the sample-and-hold series (biased up by the holding)
  std::optional<double> time_scale_ratio;     ///< T_u / T_W
  std::string warning;                ///< T_u / T_W < 2, or T_u not reached
};

/// The least T_u / T_W at which AWCC's windows follow the velocity (error E4 below).
inline constexpr double time_scale_ratio_min = 2.0;
/// T_u / T_W at or below which adjacent windows' velocities are uncorrelated (above).
inline constexpr double time_scale_ratio_unresolved = 0.5;
/// The fewest particles per window the method is used with (METHOD 4: Np 3-30).
inline constexpr int np_least = 3;

namespace detail {
/// The E4 warning of an AWCC result whose T_u / T_W is `ratio` (< time_scale_ratio_min),
/// with the advice that fits it: the np that would do, or that none would,
/// and whether the accepted windows are few.
std::string windows_too_long(const AwccResult& awcc, double ratio);
}  // namespace detail

/// The spectrum and time scale of AWCC's accepted windows over a record of
/// `duration` s.
VelocitySpectrum velocity_spectrum(const AwccResult& awcc, double duration, const SpectrumOptions& options);

/// Where AWCC's T_u / T_W is capped (AwccResult::time_scale_ratio, the bias
/// correction's feature): an oracle test (the true T / T_W clipped to
/// 0.5-20 as a feature, docs/history/correction-foreign-conventions.md
/// "The time scale: a feature the record carries") kept most of the
/// unclipped ratio's gain, and windows 20 times shorter than T_u follow the
/// velocity; the cap also bounds the cost (below).
inline constexpr double time_scale_ratio_cap = 20.0;

/// T_u / T_W as the bias correction reads it (correction/features.hpp,
/// feature time_scale_ratio): velocity_spectrum's slotted ratio, capped at
/// `cap` (> 0). The integral stops once it reaches cap T_W, so the cost is
/// a few cap pairs per accepted window whatever T_u and the record's length
/// (a study computes it on every run; the spectrum's full integral can take
/// thousands of pairs per window where T_u is long). Where the slotted
/// autocorrelation stays positive over every slot (a quarter of the
/// record), the integral so far: a lower bound. A series without variance
/// (every accepted window at one lag, AWCC's Tu 0) has r = 1 at every slot
/// (slotted_autocorrelation's rule) and gives the cap: it has no scale, and
/// the cap keeps the feature defined for every result AWCC gives. Equal to
/// min(velocity_spectrum's time_scale_ratio, cap) wherever that exists.
/// Empty when AWCC gave no velocity or accepted fewer than two windows.
std::optional<double> capped_time_scale_ratio(const AwccResult& awcc, double cap);

}  // namespace awcc
