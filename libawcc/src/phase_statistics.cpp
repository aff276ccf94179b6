#include "awcc/phase_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>
#include <fmt/format.h>

#include "awcc/order_statistics.hpp"

namespace awcc {
namespace {

double quantile(const std::vector<double>& sorted, double p) { return quantile_of_sorted(sorted, p); }

Histogram histogram_of(const std::vector<double>& sorted, int bins) {
  Histogram h;
  if (sorted.empty() || bins <= 0) return h;
  const double top = quantile(sorted, 0.99);
  h.bin_width = top > 0.0 ? top / bins : 1.0;
  h.counts.assign(static_cast<std::size_t>(bins), 0);
  for (double v : sorted) {
    auto k = static_cast<std::size_t>(std::max(0.0, std::floor(v / h.bin_width)));
    ++h.counts[std::min(k, h.counts.size() - 1)];
  }
  return h;
}

double variance(const std::vector<double>& v, double mean) {
  if (v.size() < 2) return 0.0;
  double s = 0.0;
  for (double x : v) s += (x - mean) * (x - mean);
  return s / static_cast<double>(v.size() - 1);
}

// Sorts whole numbers of samples (>= 0) in O(n): LSD radix, 11 bits a
// pass, as many passes as the largest needs (two for chords up to 4 M samples).
void sort_samples(std::vector<std::int64_t>& v, std::vector<std::int64_t>& buffer) {
  std::int64_t largest = 0;
  for (const auto x : v) largest = std::max(largest, x);
  buffer.resize(v.size());
  constexpr int bits = 11;
  constexpr std::size_t radix = std::size_t{1} << bits;
  std::vector<std::size_t> count(radix);
  for (int shift = 0; shift < 63 && (largest >> shift) != 0; shift += bits) {
    std::fill(count.begin(), count.end(), 0);
    for (const auto x : v) ++count[static_cast<std::size_t>(x >> shift) & (radix - 1)];
    std::size_t total = 0;
    for (auto& c : count) total += std::exchange(c, total);
    for (const auto x : v) buffer[count[static_cast<std::size_t>(x >> shift) & (radix - 1)]++] = x;
    v.swap(buffer);
  }
}

// Durations of whole samples, sorted, in s: sorting the integers sorts the
// durations (k / fs is increasing in k and exact in k), faster than sorting doubles.
std::vector<double> sorted_durations(std::vector<std::int64_t>& samples, std::vector<std::int64_t>& buffer,
                                     double fs) {
  sort_samples(samples, buffer);
  std::vector<double> out(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) out[i] = static_cast<double>(samples[i]) / fs;
  return out;
}

Summary summarise_sorted(const std::vector<double>& values) {
  Summary s;
  s.count = static_cast<std::int64_t>(values.size());
  if (values.empty()) return s;
  double sum = 0.0;
  for (double v : values) sum += v;
  const double n = static_cast<double>(values.size());
  s.mean = sum / n;
  s.std = std::sqrt(variance(values, s.mean));
  s.min = values.front();
  s.max = values.back();
  s.median = quantile(values, 0.5);
  for (std::size_t i = 0; i < s.percentiles.size(); ++i) s.percentiles[i] = quantile(values, Summary::levels[i] / 100.0);
  const double half = 1.96 * s.std / std::sqrt(n);
  s.mean_ci95 = {s.mean - half, s.mean + half};
  const double spread = 1.96 * std::sqrt(n) / 2.0;
  const auto rank = [&](double r) {
    return values[static_cast<std::size_t>(std::clamp(std::round(r), 0.0, n - 1.0))];
  };
  s.median_ci95 = {rank(n / 2.0 - spread - 0.5), rank(n / 2.0 + spread - 0.5)};
  return s;
}

}  // namespace

Summary summarise(std::vector<double> values) { return summarise_in_place(values); }

Summary summarise_in_place(std::vector<double>& values) {
  std::sort(values.begin(), values.end());
  return summarise_sorted(values);
}

std::string_view to_string(PhaseStatus status) {
  switch (status) {
    case PhaseStatus::ok: return "ok";
    case PhaseStatus::no_air: return "no_air";
    case PhaseStatus::all_air: return "all_air";
    case PhaseStatus::too_few_chords: return "too_few_chords";
  }
  return "?";
}

double dispersed_fraction(double void_fraction) { return void_fraction <= 0.5 ? void_fraction : 1.0 - void_fraction; }

std::string_view dispersed_particle(double void_fraction) { return void_fraction <= 0.5 ? "bubble" : "droplet"; }

std::optional<double> sauter_diameter(double velocity, double fraction, double count_rate) {
  if (!(count_rate > 0.0)) return std::nullopt;
  return 1.5 * std::fabs(velocity) * fraction / count_rate;
}

PhaseStatistics phase_statistics(const AirIntervals& signal, const PhaseStatisticsOptions& options) {
  PhaseStatistics p;
  const double fs = signal.fs;
  p.duration = fs > 0.0 ? static_cast<double>(signal.sample_count) / fs : 0.0;
  p.void_fraction = signal.void_fraction();
  // Chords and interarrival times in samples, then sorted durations (the
  // order of chords is not needed again), one kind at a time: a 300 s
  // record's arrays are 3 MB each, and the three kinds' samples, durations
  // and the sort's buffer held together were 27 MB of the run's peak
  // memory (docs/performance.md).
  const auto& iv = signal.intervals;
  std::vector<std::int64_t> samples, buffer;
  samples.reserve(iv.size());
  auto durations_of = [&](auto&& collect) {
    samples.clear();
    for (std::size_t i = 0; i < iv.size(); ++i) collect(i);
    return sorted_durations(samples, buffer, fs);
  };
  p.interarrival_time = summarise_sorted(durations_of([&](std::size_t i) {
    if (i + 1 < iv.size() && (i > 0 || iv[i].start > 0)) samples.push_back(iv[i + 1].start - iv[i].start);
  }));
  const std::vector<double> air = durations_of([&](std::size_t i) {
    if (iv[i].start > 0 && iv[i].stop < signal.sample_count) samples.push_back(iv[i].stop - iv[i].start);
  });
  const std::vector<double> water = durations_of([&](std::size_t i) {
    if (i + 1 < iv.size()) samples.push_back(iv[i + 1].start - iv[i].stop);
  });
  samples = {};
  buffer = {};
  const auto n = static_cast<double>(air.size());
  p.bubble_count_rate = p.duration > 0.0 ? n / p.duration : 0.0;
  p.air_chord_time = summarise_sorted(air);
  p.water_chord_time = summarise_sorted(water);
  p.air_chord_histogram = histogram_of(air, options.histogram_bins);
  p.water_chord_histogram = histogram_of(water, options.histogram_bins);
  // Confidence intervals of c and F (alternating renewal process, see header).
  p.void_fraction_ci95 = {p.void_fraction, p.void_fraction};
  p.bubble_count_rate_ci95 = {p.bubble_count_rate, p.bubble_count_rate};
  if (signal.air_samples() == 0) {
    p.status = PhaseStatus::no_air;
    p.message = "the tip saw no air";
  } else if (signal.air_samples() == signal.sample_count) {
    p.status = PhaseStatus::all_air;
    p.message = "the tip saw only air";
  } else if (air.size() < 2 || water.size() < 2) {
    p.status = PhaseStatus::too_few_chords;
    p.message = fmt::format("{} complete air and {} water chords: too few for confidence intervals", air.size(),
                            water.size());
  } else {
    const double ma = p.air_chord_time.mean, mw = p.water_chord_time.mean;
    const double va = variance(air, ma), vw = variance(water, mw);
    const double m = ma + mw;
    const double c = p.void_fraction;
    const double se_c = std::sqrt(((1 - c) * (1 - c) * va + c * c * vw) / (n * m * m));
    p.void_fraction_ci95 = {std::max(0.0, c - 1.96 * se_c), std::min(1.0, c + 1.96 * se_c)};
    const double se_f = p.bubble_count_rate * std::sqrt((va + vw) / (m * m) / n);
    p.bubble_count_rate_ci95 = {std::max(0.0, p.bubble_count_rate - 1.96 * se_f), p.bubble_count_rate + 1.96 * se_f};
  }
  if (options.velocity) {
    const double u = *options.velocity;
    std::vector<double> lengths;
    lengths.reserve(air.size());
    for (double t : air) lengths.push_back(t * std::fabs(u));
    p.air_chord_length = summarise_sorted(lengths);  // ascending: |u| >= 0 keeps the chords' order
    p.sauter_diameter = sauter_diameter(u, dispersed_fraction(p.void_fraction), p.bubble_count_rate);
  }
  return p;
}

}  // namespace awcc
