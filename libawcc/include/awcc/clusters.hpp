#pragma once
// Cluster analysis of the leading tip's particles (METHOD.md 8; Chanson and
// Toombes 2002, Felder 2013).
//
// Regime from the void fraction c: bubbly (c < 0.3), particles are the
// complete air chords and separations the water chords between them;
// droplet (c > 0.7), the roles swap: the complete water chords
// (complete_droplets, those next to air cut by the record's ends included)
// and the air chords between them; in between nothing is computed (status
// says so).
// Particles p_1..p_m with separations g_i between p_i and p_{i+1}: the pair
// (i, i+1) is clustered when g_i <= a criterion:
//   median:    f x the median separation (f = 0.1);
//   constant:  a fixed separation (1 mm of length, 1 ms of time);
//   near-wake: the leading particle's own chord p_i (the follower is in its wake).
// A cluster is a maximal run of clustered pairs i = q..r: particles q..r+1.
// Per criterion: particles in clusters (and % of m), clusters (and per
// second), mean particles per cluster, mean chord of the clustered particles
// and its ratio to the mean chord of all particles, the mean over clusters of
// (lead particle's chord / its cluster's mean chord), and the cluster-size
// PDF over sizes 2, 3, ..., 20, >= 21 (fraction of clusters).
//
// Felder's program (felder = true; felder-program.md 4) keeps its defects: his
// bubble count, runs that reach the last separation dropped, the droplet
// median/constant criteria testing the separation before the pair, a wake
// particle counted in two clusters when its separation equals its chord,
// the criterion factor in float32 (0.1f), % of droplets over n - 1.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/chords.hpp"

namespace awcc {

enum class FlowRegime { bubbly, intermediate, droplet };
enum class ClusterCriterion { median, constant, near_wake };
enum class ClusterStatus {
  ok,
  intermediate_void_fraction,  ///< 0.3 <= c <= 0.7: neither bubbles nor droplets are particles
  too_few_particles,           ///< fewer than 3 particles
  no_velocity,                 ///< length basis without a velocity
};
std::string_view to_string(FlowRegime regime);
std::string_view to_string(ClusterCriterion criterion);
std::string_view to_string(ClusterStatus status);

/// The regime of a void fraction (c < 0.3 bubbly, c > 0.7 droplet).
FlowRegime flow_regime(double void_fraction);

/// Why an analysis of particles (clusters, arrivals) cannot run: the regime
/// between 0.3 and 0.7, or chord lengths without a velocity; empty when it can.
struct ParticleRefusal {
  ClusterStatus status = ClusterStatus::ok;
  std::string message;
};
std::optional<ParticleRefusal> particle_refusal(FlowRegime regime, double void_fraction, ChordBasis basis,
                                                double velocity, std::string_view analysis);

struct ClusterOptions {
  /// Median criterion: fraction of the median separation, -. 0.1 is Chanson's.
  double median_fraction = 0.1;
  /// Constant criterion on chord lengths, m, and on chord times, s.
  double constant_length = 1e-3;
  double constant_time = 1e-3;
};

struct ClusterStatistics {
  ClusterCriterion criterion = ClusterCriterion::median;
  std::optional<double> criterion_value;       ///< s or m (near-wake: per particle, empty)
  std::int64_t particles = 0;                  ///< m
  std::int64_t in_clusters = 0;
  double percent_in_clusters = 0.0;
  std::int64_t clusters = 0;
  double clusters_per_second = 0.0;
  std::optional<double> mean_particles_per_cluster;
  std::optional<double> mean_chord_in_cluster;          ///< s or m
  std::optional<double> ratio_cluster_chord_to_mean_chord;
  std::optional<double> ratio_lead_to_cluster_mean_chord;
  std::array<std::int64_t, 20> size_counts{};           ///< clusters of 2, 3, ..., 20, >= 21 particles
  std::optional<std::array<double, 20>> size_pdf;       ///< size_counts / clusters
};

struct ClusterAnalysis {
  ClusterStatus status = ClusterStatus::ok;
  std::string message;
  FlowRegime regime = FlowRegime::bubbly;
  ChordBasis basis = ChordBasis::time;
  std::vector<ClusterStatistics> criteria;     ///< median, constant, near-wake
};

/// Default analysis of the complete chords; velocity (m/s) for the length basis.
ClusterAnalysis cluster_analysis(const ChordSequence& chords, double void_fraction, ChordBasis basis,
                                 const ClusterOptions& options, double velocity = 0.0);
/// Felder's analysis of his chords (his velocity, in m/s, for the length basis).
ClusterAnalysis felder_cluster_analysis(const FelderChords& chords, double void_fraction, ChordBasis basis,
                                        const ClusterOptions& options, double velocity = 0.0);

}  // namespace awcc
