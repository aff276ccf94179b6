#include "awcc/chords.hpp"

#include <cmath>
#include <stdexcept>

namespace awcc {

std::string_view to_string(ChordBasis basis) { return basis == ChordBasis::length ? "length" : "time"; }

ChordSequence complete_chords(const AirIntervals& signal) {
  ChordSequence out;
  out.fs = signal.fs;
  out.sample_count = signal.sample_count;
  for (const auto& iv : signal.intervals) {
    const bool cut_start = iv.start == 0, cut_end = iv.stop == signal.sample_count;
    // A water chord follows air cut by the start unless that air fills the record.
    if (cut_start && !cut_end) out.water_after_cut_start = iv.stop;
    if (cut_end && !cut_start) out.air_cut_by_end = iv.start;
    if (cut_start || cut_end) continue;  // cut by the record's start or end
    out.start.push_back(iv.start);
    out.end.push_back(iv.stop);
  }
  return out;
}

DropletSequence complete_droplets(const ChordSequence& c) {
  DropletSequence d;
  const std::size_t n = c.bubbles();
  if (c.water_after_cut_start && (n > 0 || c.air_cut_by_end)) {
    d.start.push_back(*c.water_after_cut_start);
    d.end.push_back(n > 0 ? c.start[0] : *c.air_cut_by_end);
  }
  for (std::size_t i = 0; i + 1 < n; ++i) {
    d.start.push_back(c.end[i]);
    d.end.push_back(c.start[i + 1]);
  }
  if (c.air_cut_by_end && n > 0) {
    d.start.push_back(c.end[n - 1]);
    d.end.push_back(*c.air_cut_by_end);
  }
  return d;
}

FelderChords felder_chords(const AirIntervals& signal) {
  FelderChords out;
  auto& c = out.chords;
  c.fs = signal.fs;
  c.sample_count = signal.sample_count;
  const std::int64_t n = signal.sample_count;
  // His 1-based indices: s = first air sample, e = first water sample; a
  // record that starts in air leaves the first s at 0; the last e is N.
  for (const auto& iv : signal.intervals) {
    c.start.push_back(iv.start == 0 ? 0 : iv.start + 1);
    c.end.push_back(iv.stop + 1);
  }
  if (!c.end.empty()) c.end.back() = n;
  const auto bubbles = static_cast<float>(c.start.size());
  const float rate = static_cast<float>(bubbles * static_cast<float>(signal.fs)) / static_cast<float>(n);
  out.bubble_count_rate = rate;
  const double duration = static_cast<double>(n) / signal.fs;
  out.pdf_norm = static_cast<float>(static_cast<double>(rate) * duration);
  out.n_pdf = static_cast<std::int64_t>(out.pdf_norm);
  out.n_cluster = static_cast<std::int64_t>(static_cast<double>(rate) * duration);
  return out;
}

FelderCounts felder_counts(const AirIntervals& signal) {
  FelderCounts c;
  const std::int64_t n = signal.sample_count;
  std::int64_t air = signal.air_samples();
  if (!signal.intervals.empty() && signal.intervals.back().stop == n) --air;  // the last sample is not counted
  c.bubbles = static_cast<std::int64_t>(signal.intervals.size());
  c.void_fraction = static_cast<float>(static_cast<float>(air) / static_cast<float>(n));
  c.bubble_count_rate = static_cast<float>(static_cast<float>(static_cast<float>(c.bubbles) * static_cast<float>(signal.fs)) /
                                           static_cast<float>(n));
  return c;
}

double felder_chord_ms(std::int64_t samples, double fs) {
  const float t = static_cast<float>(samples) / static_cast<float>(fs);
  return static_cast<float>(t * 1000.0f);
}

namespace {

std::size_t regular_bins(const ChordPdfOptions& o) {
  if (!(o.bin_width > 0.0) || !(o.max > 0.0)) throw std::invalid_argument("chord PDF: bin width and maximum must be > 0");
  return static_cast<std::size_t>(std::llround(o.max / o.bin_width));
}

ChordPdf empty_pdf(ChordBasis basis, const ChordPdfOptions& o, std::size_t bins) {
  ChordPdf p;
  p.basis = basis;
  p.bin_width = o.bin_width;
  p.max = static_cast<double>(bins) * o.bin_width;
  p.air_counts.assign(bins + 1, 0);
  p.water_counts.assign(bins + 1, 0);
  p.air_fraction.assign(bins + 1, 0.0);
  p.water_fraction.assign(bins + 1, 0.0);
  for (std::size_t k = 0; k <= bins; ++k) p.lower_edges.push_back(static_cast<double>(k) * o.bin_width);
  return p;
}

}  // namespace

ChordPdf chord_pdf(const ChordSequence& chords, ChordBasis basis, const ChordPdfOptions& options, double velocity) {
  const std::size_t bins = regular_bins(options);
  ChordPdf p = empty_pdf(basis, options, bins);
  const double scale = (basis == ChordBasis::length ? velocity : 1.0) / chords.fs / options.bin_width;  // bins per sample
  // Bin (k w, (k + 1) w]: a chord on an upper edge belongs to the lower bin
  // (the tolerance absorbs the rounding of samples / fs / w).
  auto bin = [&](std::int64_t samples) {
    const double x = static_cast<double>(samples) * scale;
    if (x > static_cast<double>(bins) + 1e-9) return bins;
    const double k = std::ceil(x - 1e-9) - 1.0;
    return k < 0.0 ? std::size_t{0} : static_cast<std::size_t>(k);
  };
  const std::size_t n = chords.bubbles();
  for (std::size_t i = 0; i < n; ++i) ++p.air_counts[bin(chords.air(i))];
  for (std::size_t i = 0; i + 1 < n; ++i) ++p.water_counts[bin(chords.water(i))];
  p.air_chords = static_cast<std::int64_t>(n);
  p.water_chords = n > 0 ? static_cast<std::int64_t>(n - 1) : 0;
  for (std::size_t k = 0; k <= bins; ++k) {
    if (p.air_chords > 0) p.air_fraction[k] = static_cast<double>(p.air_counts[k]) / static_cast<double>(p.air_chords);
    if (p.water_chords > 0)
      p.water_fraction[k] = static_cast<double>(p.water_counts[k]) / static_cast<double>(p.water_chords);
  }
  return p;
}

ChordPdf felder_chord_pdf(const FelderChords& f, ChordBasis basis, const ChordPdfOptions& options, double velocity) {
  const std::size_t bins = regular_bins(options);
  ChordPdf p = empty_pdf(basis, options, bins);
  const auto& c = f.chords;
  // His units: ms and mm, bins in float32.
  const auto width = static_cast<float>(options.bin_width * 1e3);
  const auto max = static_cast<float>(options.max * 1e3);
  const double tolerance = 1e-5f;
  auto value = [&](std::int64_t samples) {
    const double t = felder_chord_ms(samples, c.fs);
    return basis == ChordBasis::length ? t * velocity : t;
  };
  auto bin = [&](double v) {
    for (std::size_t k = 1; k <= bins + 1; ++k) {
      const float edge = static_cast<float>(k) * width;
      if (v - static_cast<double>(edge) < tolerance) return k - 1;
      if (v > static_cast<double>(max)) return bins;
    }
    return bins;
  };
  const auto n = static_cast<std::size_t>(std::max<std::int64_t>(0, std::min<std::int64_t>(f.n_pdf, static_cast<std::int64_t>(c.bubbles()))));
  for (std::size_t i = 0; i < n; ++i) ++p.air_counts[bin(value(c.air(i)))];
  for (std::size_t i = 0; i + 1 < n; ++i) ++p.water_counts[bin(value(c.water(i)))];
  p.air_chords = static_cast<std::int64_t>(n);
  p.water_chords = n > 0 ? static_cast<std::int64_t>(n - 1) : 0;
  for (std::size_t k = 0; k <= bins; ++k) {
    // His labels: fl32(min + fl32((k - 1) w)) in ms or mm.
    p.lower_edges[k] = static_cast<double>(0.0f + static_cast<float>(k) * width) * 1e-3;
    p.air_fraction[k] = static_cast<float>(static_cast<float>(p.air_counts[k]) / f.pdf_norm);
    p.water_fraction[k] = static_cast<float>(static_cast<float>(p.water_counts[k]) / (f.pdf_norm - 1.0f));
  }
  return p;
}

}  // namespace awcc
