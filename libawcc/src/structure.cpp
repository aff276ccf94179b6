#include "awcc/structure.hpp"

#include <fmt/format.h>

namespace awcc {

Validation StructureOptions::validate() const {
  if (!(voltage_bin > 0.0))
    return Validation::invalid("voltage-pdf-bin", fmt::format("voltage PDF bin {} V must be > 0", voltage_bin));
  struct Chord {
    const ChordPdfOptions* options;
    const char* bin;  // the declared names of its width and its range
    const char* max;
  };
  for (const auto& [o, bin, max] : {Chord{&chord_time, "chord-time-bin", "chord-time-max"},
                                    Chord{&chord_length, "chord-length-bin", "chord-length-max"}}) {
    if (!(o->bin_width > 0.0) || !(o->max >= o->bin_width) || o->max / o->bin_width > 1e6) {
      return Validation::invalid(
          o->bin_width > 0.0 ? max : bin,
          fmt::format("chord PDF bins: width {} and range {} must be > 0, the range at least one bin and at most a "
                      "million bins",
                      o->bin_width, o->max));
    }
  }
  if (!(clusters.median_fraction > 0.0))
    return Validation::invalid("cluster-median-fraction", "the median cluster criterion's fraction must be > 0");
  if (!(clusters.constant_length > 0.0))
    return Validation::invalid("cluster-constant-length", "the constant cluster criteria must be > 0");
  if (!(clusters.constant_time > 0.0))
    return Validation::invalid("cluster-constant-time", "the constant cluster criteria must be > 0");
  if (!(arrivals.bin_width > 0.0))
    return Validation::invalid("arrival-bin", "arrival-time bins: width > 0 and at least one bin");
  if (arrivals.bins < 1) return Validation::invalid("arrival-bins", "arrival-time bins: width > 0 and at least one bin");
  for (const auto& [limits, option] : {std::pair{&arrivals.length_classes, "arrival-length-classes"},
                                       std::pair{&arrivals.time_classes, "arrival-time-classes"}}) {
    for (std::size_t i = 0; i < limits->size(); ++i) {
      if (!((*limits)[i] > 0.0) || (i > 0 && !((*limits)[i] > (*limits)[i - 1]))) {
        return Validation::invalid(option, "arrival size classes: limits must be positive and increasing");
      }
    }
  }
  return {};
}

StructureResult analyse_structure(const AirIntervals& leading, const AirIntervals& trailing, double void_fraction,
                                  const VoltageHistogram* leading_histogram, const VoltageHistogram* trailing_histogram,
                                  std::optional<double> velocity, const std::string& velocity_source,
                                  const StructureOptions& o) {
  StructureResult r;
  r.felder_defects = o.felder_defects;
  r.velocity = velocity;
  r.velocity_source = velocity ? velocity_source : "none";
  const double u = velocity.value_or(0.0);
  auto volts = [&](const VoltageHistogram* h) -> std::optional<VoltagePdf> {
    if (!h || h->binary_levels()) return std::nullopt;
    return o.felder_defects ? felder_voltage_pdf(*h) : voltage_pdf(*h, o.voltage_bin);
  };
  r.voltage_leading = volts(leading_histogram);
  r.voltage_trailing = volts(trailing_histogram);
  if (o.felder_defects) {
    r.felder_counts = std::array<FelderCounts, 2>{felder_counts(leading), felder_counts(trailing)};
    const auto f = felder_chords(leading);
    r.bubbles_used = f.n_cluster;
    r.chord_time = felder_chord_pdf(f, ChordBasis::time, o.chord_time);
    if (velocity) r.chord_length = felder_chord_pdf(f, ChordBasis::length, o.chord_length, u);
    r.clusters_time = felder_cluster_analysis(f, void_fraction, ChordBasis::time, o.clusters);
    r.clusters_length = felder_cluster_analysis(f, void_fraction, ChordBasis::length, o.clusters, u);
    r.arrivals_time = felder_arrival_analysis(f, void_fraction, ChordBasis::time);
    r.arrivals_length = felder_arrival_analysis(f, void_fraction, ChordBasis::length, u);
  } else {
    const auto c = complete_chords(leading);
    r.bubbles_used = static_cast<std::int64_t>(c.bubbles());
    r.chord_time = chord_pdf(c, ChordBasis::time, o.chord_time);
    if (velocity) r.chord_length = chord_pdf(c, ChordBasis::length, o.chord_length, u);
    r.clusters_time = cluster_analysis(c, void_fraction, ChordBasis::time, o.clusters);
    r.clusters_length = cluster_analysis(c, void_fraction, ChordBasis::length, o.clusters, u);
    r.arrivals_time = arrival_analysis(c, void_fraction, ChordBasis::time, o.arrivals);
    r.arrivals_length = arrival_analysis(c, void_fraction, ChordBasis::length, o.arrivals, u);
  }
  return r;
}

}  // namespace awcc
