#pragma once
// Inter-particle arrival times per particle-size class (METHOD.md 8; Chanson
// and Toombes 2002, Felder 2013).
//
// Particles (complete bubbles when c < 0.3, complete droplets when c > 0.7
// (complete_droplets), nothing between)
// are sorted into classes by their own chord (length: <= 1, 3, 6, 10, > 10 mm;
// time: <= 0.5, 1.5, 3, 5, > 5 ms). For each particle, the time to the next
// particle of its class is one interval; a class of N particles gives N - 1.
// Histogram: bins ((m - 1) w, m w], m = 1..M (w = 1 ms, M = 100) and an
// overflow bin; PDF = count / intervals.
//
// Reference: N events placed at random in a record of duration T have the
// interval density P(t) = (N/T)^2 (T - t) exp(-N t / T) / (N - 1 + exp(-N)),
// 0 <= t <= T (it integrates to 1). With lambda = N / T its integral over a
// bin [a, b] is
//   [e^{-lambda b} (1 - lambda (T - b)) - e^{-lambda a} (1 - lambda (T - a))] / (N - 1 + e^{-N}),
// the reference probability of the bin. Grouping shows as an excess of short
// intervals: excess = observed / expected count in the first bin, and its
// standard error under the reference, sqrt((1 - p) / (n p)) for n intervals
// and a bin probability p (the count is binomial).
//
// Felder's program (felder = true; felder-program.md 5): intervals from the
// trailing edge of a particle to the leading edge of the next (not between
// arrivals), PDF = count / N (particles), the last bin also holds the
// overflow, the reference density evaluated at each bin's upper edge in
// float32, T = D x 1000 ms, the droplet time classes <= 6 ms where the labels
// say 5.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "awcc/chords.hpp"
#include "awcc/clusters.hpp"

namespace awcc {

struct ArrivalOptions {
  double bin_width = 1e-3;   ///< s: histogram bin
  int bins = 100;            ///< bins before the overflow bin
  /// Upper limits of the size classes (a last class takes the rest): m and s.
  std::vector<double> length_classes{1e-3, 3e-3, 6e-3, 10e-3};
  std::vector<double> time_classes{0.5e-3, 1.5e-3, 3e-3, 5e-3};
};

struct ArrivalClass {
  std::optional<double> lower;        ///< s or m: chords above this (empty: from 0)
  std::optional<double> upper;        ///< s or m: chords up to this (empty: no limit)
  std::int64_t particles = 0;         ///< N
  std::int64_t intervals = 0;         ///< counted in the histogram
  std::vector<std::int64_t> counts;   ///< bins 1..M, then the overflow bin (Felder: in bin M)
  std::vector<double> pdf;            ///< per bin (and overflow)
  std::vector<double> reference;      ///< the random-arrival probability of each bin (and overflow)
  std::optional<double> excess_first_bin;     ///< observed / reference count in bin 1
  std::optional<double> excess_first_bin_se;  ///< its standard error under the reference
};

struct ArrivalAnalysis {
  ClusterStatus status = ClusterStatus::ok;   ///< intermediate_void_fraction, no_velocity, too_few_particles
  std::string message;
  FlowRegime regime = FlowRegime::bubbly;
  ChordBasis basis = ChordBasis::time;
  double bin_width = 0.0;                     ///< s
  std::vector<ArrivalClass> classes;
};

ArrivalAnalysis arrival_analysis(const ChordSequence& chords, double void_fraction, ChordBasis basis,
                                 const ArrivalOptions& options, double velocity = 0.0);
ArrivalAnalysis felder_arrival_analysis(const FelderChords& chords, double void_fraction, ChordBasis basis,
                                        double velocity = 0.0);

/// The reference probability of the bin [a, b] (s) for N particles in T (s).
double random_arrival_probability(double a, double b, std::int64_t particles, double duration);

}  // namespace awcc
