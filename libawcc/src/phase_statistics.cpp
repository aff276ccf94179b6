#include "awcc/phase_statistics.hpp"

#include <algorithm>
#include <cmath>
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

}  // namespace

Summary summarise(std::vector<double> values) { return summarise_in_place(values); }

Summary summarise_in_place(std::vector<double>& values) {
  Summary s;
  s.count = static_cast<std::int64_t>(values.size());
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
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
  std::vector<double> air, water, arrivals;
  const auto& iv = signal.intervals;
  for (std::size_t i = 0; i < iv.size(); ++i) {
    const bool complete = iv[i].start > 0 && iv[i].stop < signal.sample_count;
    if (complete) air.push_back(static_cast<double>(iv[i].stop - iv[i].start) / fs);
    if (i + 1 < iv.size()) {
      water.push_back(static_cast<double>(iv[i + 1].start - iv[i].stop) / fs);
      if (i > 0 || iv[i].start > 0) arrivals.push_back(static_cast<double>(iv[i + 1].start - iv[i].start) / fs);
    }
  }
  const auto n = static_cast<double>(air.size());
  p.bubble_count_rate = p.duration > 0.0 ? n / p.duration : 0.0;
  // Sorted in place from here on (the order of chords is not needed again).
  p.air_chord_time = summarise_in_place(air);
  p.water_chord_time = summarise_in_place(water);
  p.interarrival_time = summarise_in_place(arrivals);
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
    p.air_chord_length = summarise(lengths);
    p.sauter_diameter = sauter_diameter(u, dispersed_fraction(p.void_fraction), p.bubble_count_rate);
  }
  return p;
}

}  // namespace awcc
