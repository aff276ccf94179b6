#pragma once
// The sub-sample peak of a correlation (METHOD 4.3): where between samples
// the maximum of R12 lies, from R12 at the whole-sample peak k and around it.
//
// A correlation sampled at whole lags peaks at the sample nearest its true
// peak, so a lag of L samples carries an error of up to 1/2 sample (a
// velocity bias of up to 1 / (2 L)), and when every window's true lag lies
// within the same sample AWCC's Tu collapses to zero. Each estimator below
// returns the offset delta (samples) to add to k; r- = R12(k-1), r0 = R12(k),
// r+ = R12(k+1):
//
//   parabolic  delta = (r- - r+) / (2 (r- - 2 r0 + r+)): the vertex of the
//              parabola through the three samples.
//   gaussian   the parabola through ln r-, ln r0, ln r+ (PIV's three-point
//              Gaussian); needs all three positive, else the parabola.
//   triangle   delta = (r+ - r-) / (2 (r0 - min(r-, r+))): the apex of the
//              symmetric triangle through the three samples, exact for the
//              cross-correlation of two equal rectangular pulses (one bubble
//              seen by both tips), whose peak is a cusp: a parabola through
//              a cusp locks toward the sample.
//   centroid   the centroid of R12 - r0/2 over the contiguous lags around k
//              where R12 > r0 / 2 (the peak above half its height).
//
// Each is 0 where the peak is flat on both sides (r0 = r- = r+) or lies at
// the end of the lags searched (no neighbour: the peak is not resolved
// there, and the edge rules say so). The default is chosen by measurement
// (bench/subsample_study.cpp, docs/validation.md "The sub-sample peak").
#include <cstdint>
#include <functional>
#include <string_view>

namespace awcc {

/// How the peak lag is refined below one sample. The order is the model
/// file's code (0 none, 1 parabolic, ...): append only (awcc::values::subsample
/// in read_back.hpp lists them).
enum class Subsample { none, parabolic, gaussian, triangle, centroid };
std::string_view to_string(Subsample subsample);

/// R12 at a whole lag inside the lags searched.
using CorrelationAt = std::function<double(std::int64_t lag)>;

/// The offset (samples) from the whole-sample peak `peak` of R12 over lags
/// [first, last] to its refined peak; 0 for Subsample::none, at the ends of
/// the range, and where the estimator is undefined (see above).
double subsample_offset(Subsample method, const CorrelationAt& r, std::int64_t peak, std::int64_t first,
                        std::int64_t last);

namespace detail {
double parabolic_offset(double minus, double centre, double plus);
double gaussian_offset(double minus, double centre, double plus);
double triangle_offset(double minus, double centre, double plus);
}  // namespace detail

}  // namespace awcc
