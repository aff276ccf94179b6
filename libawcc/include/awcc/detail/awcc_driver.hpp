#pragma once
// The one AWCC driver (awcc/awcc.hpp, METHOD 4): windows of the leading tip,
// the lags each can be searched over, its correlation's peak and SPR from a
// correlation source, the correlation filter, the bubble-probe correction, the
// outlier cutoff and the moments. What differs between binary signals and raw
// voltages is only where a window's correlation comes from: a new filter or
// decision goes into the driver (or the steps it calls), once for every source.
// For the library's own use and its tests; not installed.

#include <cstdint>
#include <span>

#include "awcc/detail/awcc_steps.hpp"

namespace awcc::detail {

/// The peak of one window's correlation, or that a segment of it is constant.
struct WindowPeak {
  CorrelationPeak peak;
  bool constant = false;  ///< a tip's segment does not vary: no correlation
};

/// Where the driver gets each window's correlation. The driver asks for the
/// windows in order, each once: correlate() for those it searches, skip() for
/// those too short for the lags searched (a source reading a file passes over
/// their samples). Scratch is the caller's workspace, so a source holds no
/// buffers of its own beyond what it reads.
class WindowCorrelations {
 public:
  virtual ~WindowCorrelations() = default;
  /// Peak and SPR (options.subsample, options.prominence_fraction) of window
  /// w's correlation over lags [k_min, k_max], k_min <= k_max.
  virtual WindowPeak correlate(const AwccWindow& w, std::int64_t k_min, std::int64_t k_max,
                               const AwccOptions& options, AwccWorkspace& workspace) = 0;
  /// Window w is not correlated.
  virtual void skip(const AwccWindow& /*w*/, AwccWorkspace& /*workspace*/) {}
};

/// The two tips' binary signals, which the sources below correlate.
class BinarySignals : public WindowCorrelations {
 public:
  BinarySignals(const AirIntervals& leading, const AirIntervals& trailing) : leading_(leading), trailing_(trailing) {}

 protected:
  const AirIntervals& leading_;
  const AirIntervals& trailing_;
};

/// Binary signals by their air intervals: exact, the piecewise-linear
/// correlation analysed at its breakpoints.
class IntervalCorrelations final : public BinarySignals {
 public:
  using BinarySignals::BinarySignals;
  WindowPeak correlate(const AwccWindow& w, std::int64_t k_min, std::int64_t k_max, const AwccOptions& options,
                       AwccWorkspace& workspace) override;
};

/// Binary signals rendered sample by sample over each window and correlated
/// by FFTs (agrees with the interval path to rounding).
class RenderedFftCorrelations final : public BinarySignals {
 public:
  using BinarySignals::BinarySignals;
  WindowPeak correlate(const AwccWindow& w, std::int64_t k_min, std::int64_t k_max, const AwccOptions& options,
                       AwccWorkspace& workspace) override;
};

/// The FFT path's peak of a window given as its samples (binary 0/1 or
/// voltages): what every sample-based source returns.
WindowPeak fft_window_peak(std::span<const double> x, std::span<const double> y, std::int64_t k_min,
                           std::int64_t k_max, const AwccOptions& options, AwccWorkspace& workspace);

/// AWCC with windows from the leading tip's intervals (its rate is the
/// record's) and correlations from `source`; options already validated.
AwccResult run_awcc(const AirIntervals& leading, double dx, const AwccOptions& options, WindowCorrelations& source,
                    AwccWorkspace& workspace);

}  // namespace awcc::detail
