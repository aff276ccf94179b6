#pragma once
// Full-signal cross-correlation (FSCC), METHOD.md 3.
//
// With x (leading) and y (trailing) the mean-removed binary signals,
//   R12(k) = sum_t x(t) y(t + k) / sqrt(sum x^2 sum y^2),   R11 likewise,
// summed over the t where both samples exist. tau = lag of the R12 maximum,
// u = dx / tau, R12max the peak. T05: lag where R11 first falls to 0.5;
// tau05: half-width at half maximum of R12 around its peak (both sides, or the
// one found); Txx = integral of R11 from 0 to its first zero; Txy = integral of
// R12 from its peak to its first zero; Chanson's turbulence intensity
// Tu = 0.851 sqrt(tau05^2 - T05^2) / tau (known to overestimate badly).
//
// Segmented (Felder's program): the record is cut into S non-overlapping
// segments; in each, a Pearson coefficient per lag over a fixed window
// (the segment less the lag span, so that every lag uses the same samples of
// x); the S coefficients are averaged. Felder's lags: auto 0..999, cross
// -199..800 samples, and the peak is the first lag within 1e-5 of the maximum,
// without interpolation.
//
// The lagged products are computed from the pairs of air intervals within the
// lag range, or from FFTs of blocks (overlap-save) when bubbles are so dense
// that the pairs cost more; memory depends on the lag range, not on the
// record's length.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/fft.hpp"

namespace awcc {

enum class Subsample { none, parabolic };
std::string_view to_string(Subsample subsample);

struct FsccOptions {
  int segments = 1;                  ///< 1 = full record; Felder used 15
  double max_lag = 0.02;             ///< s: auto lags [0, max], cross lags [-max, max]
  bool felder_lags = false;          ///< Felder's lag ranges in samples and first-maximum peak rule
  Subsample subsample = Subsample::none;

  [[nodiscard]] std::string validate() const;
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
  std::optional<double> t05, tau05, txx, txy;       ///< s
  std::optional<double> turbulence_intensity_chanson;
  std::string note;                  ///< e.g. why a time scale is missing
  std::vector<std::string> warnings; ///< a velocity that is defined but implausible, with the likely cause
  std::int64_t r11_first_lag = 0, r12_first_lag = 0;  ///< lag (samples) of r11[0], r12[0]
  std::vector<double> r11, r12;      ///< the correlation functions over the lags searched
};

/// FSCC of two binary signals of equal length and rate; dx in m.
FsccResult fscc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const FsccOptions& options = {});

}  // namespace awcc
