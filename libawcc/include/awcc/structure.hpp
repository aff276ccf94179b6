#pragma once
// The structure of the flow at one position, from the leading tip (METHOD.md
// 8): voltage PDFs of both tips, chord-time and chord-length PDFs, cluster
// analyses and inter-particle arrival times, on chord times and, with a
// velocity, on chord lengths. Felder's conventions (felder_defects) replay
// his program exactly (felder-program.md); the default fixes its defects.
// Each part is computed only when asked for (`structure`), and costs one pass
// over the chords.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "awcc/arrivals.hpp"
#include "awcc/binarisation.hpp"
#include "awcc/chords.hpp"
#include "awcc/clusters.hpp"
#include "awcc/voltage_pdf.hpp"

namespace awcc {

struct StructureOptions {
  bool enabled = true;                 ///< compute the structure outputs
  /// Felder's program's conventions and defects (felder-program.md 10), for
  /// reproducing his printed numbers; off fixes them (METHOD 8, Decision).
  bool felder_defects = false;
  double voltage_bin = 0.1;            ///< V: voltage PDF bin (Felder: his 0.1 V bins from -1 V)
  ChordPdfOptions chord_time{1e-4, 10e-3};     ///< s: bin width and upper end of the chord-time PDF
  ChordPdfOptions chord_length{0.5e-3, 20e-3}; ///< m: of the chord-length PDF
  ClusterOptions clusters;
  ArrivalOptions arrivals;

  [[nodiscard]] Validation validate() const;
};

struct StructureResult {
  bool felder_defects = false;
  std::optional<VoltagePdf> voltage_leading, voltage_trailing;  ///< empty for binary input
  ChordPdf chord_time;
  std::optional<ChordPdf> chord_length;     ///< with a velocity
  std::optional<double> velocity;           ///< m/s: the velocity of the chord lengths
  std::string velocity_source;              ///< "awcc", "fscc" or "none"
  ClusterAnalysis clusters_time, clusters_length;
  ArrivalAnalysis arrivals_time, arrivals_length;
  std::int64_t bubbles_used = 0;            ///< bubbles of the leading tip the analyses use
  /// Felder's conventions: C and F of the leading and trailing tips as his program counts them.
  std::optional<std::array<FelderCounts, 2>> felder_counts;
};

/// The analyses of the leading tip's binary signal (and the histograms of
/// both tips, when given). velocity: m/s for the length-based parts.
StructureResult analyse_structure(const AirIntervals& leading, const AirIntervals& trailing, double void_fraction,
                                  const VoltageHistogram* leading_histogram, const VoltageHistogram* trailing_histogram,
                                  std::optional<double> velocity, const std::string& velocity_source,
                                  const StructureOptions& options);

}  // namespace awcc
