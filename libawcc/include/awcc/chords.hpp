#pragma once
// The leading tip's chord sequence and the chord PDFs (METHOD.md 8;
// felder-program.md 2).
//
// A sequence of bubbles i = 0..n-1 with first air sample start_i and first
// water sample after it end_i: air chord a_i = end_i - start_i samples, water
// chord w_i = start_{i+1} - end_i between bubbles i and i+1. Chord time =
// samples / fs, chord length = chord time x u.
//
// Default: the complete bubbles only (a bubble cut by the record's start or
// end is not a chord), and the water chords between them; for the droplet
// regime the complete droplets (complete_droplets), which in a record that
// starts or ends in air include the water chords next to the cut air. Felder's program
// (felder_chords): every bubble, a first bubble that starts the record one
// sample too long, the last bubble's end moved to the record's end, and the
// bubble counts of his float32 arithmetic (n_pdf for the PDFs, n_cluster for
// clusters and arrivals; felder-program.md 2).
//
// Chord PDFs: K = max / width bins (lower, upper] and an overflow bin for
// chords above max (the first bin also holds chords of zero length). The
// fraction of a bin is count / chords. Felder: his float32 chord values and
// bin edges, a 1e-5 tolerance on the upper edge, and normalisation by his
// bubble count n_pdf (air) and n_pdf - 1 (water).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "awcc/air_intervals.hpp"

namespace awcc {

struct ChordSequence {
  double fs = 0.0;                     ///< Hz
  std::int64_t sample_count = 0;       ///< of the record
  std::vector<std::int64_t> start, end;  ///< per bubble: first air sample, first water sample after it
  /// The complete water chords beyond the complete bubbles, at the record's
  /// ends: where an air interval is cut by the record's start, the first
  /// water sample after it (a water chord then runs from here to start[0],
  /// or to the cut air at the end); where one is cut by the record's end,
  /// its first air sample. A spray record starts and ends in air, and its
  /// droplets there are complete (complete_droplets).
  std::optional<std::int64_t> water_after_cut_start, air_cut_by_end;

  [[nodiscard]] std::size_t bubbles() const { return start.size(); }
  [[nodiscard]] std::int64_t air(std::size_t i) const { return end[i] - start[i]; }
  [[nodiscard]] std::int64_t water(std::size_t i) const { return start[i + 1] - end[i]; }  ///< i < bubbles() - 1
};

/// The complete bubbles of a binary signal (default analysis).
ChordSequence complete_chords(const AirIntervals& signal);

/// The complete droplets (water chords cut by neither end of the record),
/// the particles of the droplet regime, as the complete bubbles are the
/// bubbly regime's: the water chords between complete bubbles and, in a
/// record that starts or ends in air, the one before the first and after
/// the last complete bubble. Droplet i runs from start[i] (its first water
/// sample) to end[i] (the first air sample after it); the air chord between
/// droplets i and i + 1 is start[i + 1] - end[i].
struct DropletSequence {
  std::vector<std::int64_t> start, end;
  [[nodiscard]] std::size_t droplets() const { return start.size(); }
  [[nodiscard]] std::int64_t water(std::size_t i) const { return end[i] - start[i]; }
  [[nodiscard]] std::int64_t air(std::size_t i) const { return start[i + 1] - end[i]; }  ///< i < droplets() - 1
};
DropletSequence complete_droplets(const ChordSequence& chords);

/// Felder's bubbles (every air interval, his start and end rules; indices 1-based as his).
struct FelderChords {
  ChordSequence chords;
  std::int64_t n_pdf = 0;      ///< bubbles his chord PDFs use: INT(fl32(F D))
  float pdf_norm = 0.0f;       ///< fl32(F D), not rounded: what his PDFs divide by
  std::int64_t n_cluster = 0;  ///< bubbles his clusters and arrivals use: INT(F D) in double
  double bubble_count_rate = 0.0;  ///< his F = fl32(fl32(n fs) / N), 1/s
};
FelderChords felder_chords(const AirIntervals& signal);

/// C and F of one tip as Felder's program counts them: C = fl32(A / N) with A
/// the air samples among the first N - 1 (the last is never counted), F =
/// fl32(fl32(n fs) / N) with n every air interval, cut ones included.
struct FelderCounts {
  double void_fraction = 0.0;
  double bubble_count_rate = 0.0;  ///< 1/s
  std::int64_t bubbles = 0;
};
FelderCounts felder_counts(const AirIntervals& signal);

/// Felder's chord time in ms, fl32(fl32(samples / fs) x 1000).
double felder_chord_ms(std::int64_t samples, double fs);

enum class ChordBasis { time, length };
std::string_view to_string(ChordBasis basis);

struct ChordPdf {
  ChordBasis basis = ChordBasis::time;
  double bin_width = 0.0;              ///< s or m
  double max = 0.0;                    ///< s or m: upper edge of the last regular bin
  std::int64_t air_chords = 0, water_chords = 0;   ///< the normalisations
  /// Per bin k = 0..K-1: chords in (k w, (k + 1) w]; bin K: above max.
  std::vector<std::int64_t> air_counts, water_counts;
  std::vector<double> air_fraction, water_fraction;
  std::vector<double> lower_edges;     ///< s or m, per bin (Felder: his float32 labels)
  [[nodiscard]] double lower_edge(std::size_t k) const { return lower_edges[k]; }
};

struct ChordPdfOptions {
  double bin_width = 0.0;  ///< s or m
  double max = 0.0;        ///< s or m
};

/// Chord PDF of the sequence's air chords 0..air_count-1 and water chords
/// 0..air_count-2 (default: all), by time or by length (velocity in m/s).
ChordPdf chord_pdf(const ChordSequence& chords, ChordBasis basis, const ChordPdfOptions& options, double velocity = 0.0);
/// Felder's chord PDF (his bins, tolerance and normalisation).
ChordPdf felder_chord_pdf(const FelderChords& chords, ChordBasis basis, const ChordPdfOptions& options,
                          double velocity = 0.0);

}  // namespace awcc
