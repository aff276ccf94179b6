#include "awcc/arrivals.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace awcc {

double random_arrival_probability(double a, double b, std::int64_t particles, double duration) {
  const auto n = static_cast<double>(particles);
  if (particles < 1 || !(duration > 0.0)) return 0.0;
  a = std::clamp(a, 0.0, duration);
  b = std::clamp(b, 0.0, duration);
  const double lambda = n / duration;
  auto antiderivative = [&](double t) { return std::exp(-lambda * t) * (1.0 - lambda * (duration - t)); };
  return (antiderivative(b) - antiderivative(a)) / (n - 1.0 + std::exp(-n));
}

namespace {

struct Particle {
  double size;            // s or m
  std::int64_t from, to;  // sample indices the interval to the next of its class runs between
};

bool refused(ArrivalAnalysis& out, double void_fraction, ChordBasis basis, double velocity) {
  auto why = particle_refusal(out.regime, void_fraction, basis, velocity, "inter-particle arrival analysis");
  if (!why) return false;
  out.status = why->status;
  out.message = std::move(why->message);
  return true;
}

std::size_t class_of(double size, const std::vector<double>& limits) {
  for (std::size_t k = 0; k < limits.size(); ++k)
    if (size <= limits[k]) return k;
  return limits.size();
}

std::vector<ArrivalClass> empty_classes(const std::vector<double>& limits, double unit) {
  std::vector<ArrivalClass> classes(limits.size() + 1);
  for (std::size_t k = 0; k < classes.size(); ++k) {
    if (k > 0) classes[k].lower = limits[k - 1] * unit;
    if (k < limits.size()) classes[k].upper = limits[k] * unit;
  }
  return classes;
}

void excess(ArrivalClass& c) {
  if (c.intervals < 1 || c.reference.empty() || !(c.reference[0] > 0.0)) return;
  const double n = static_cast<double>(c.intervals), p = c.reference[0];
  c.excess_first_bin = static_cast<double>(c.counts[0]) / (n * p);
  c.excess_first_bin_se = std::sqrt((1.0 - p) / (n * p));
}

}  // namespace

ArrivalAnalysis arrival_analysis(const ChordSequence& chords, double void_fraction, ChordBasis basis,
                                 const ArrivalOptions& options, double velocity) {
  ArrivalAnalysis out;
  out.regime = flow_regime(void_fraction);
  out.basis = basis;
  out.bin_width = options.bin_width;
  if (refused(out, void_fraction, basis, velocity)) return out;
  const double scale = (basis == ChordBasis::length ? velocity : 1.0) / chords.fs;
  const auto& limits = basis == ChordBasis::length ? options.length_classes : options.time_classes;
  // Arrivals: a bubble's first air sample, a droplet's first water sample.
  std::vector<Particle> particles;
  const std::size_t n = chords.bubbles();
  if (out.regime == FlowRegime::bubbly) {
    for (std::size_t i = 0; i < n; ++i) particles.push_back({static_cast<double>(chords.air(i)) * scale, chords.start[i], 0});
  } else {
    const auto droplets = complete_droplets(chords);
    for (std::size_t i = 0; i < droplets.droplets(); ++i)
      particles.push_back({static_cast<double>(droplets.water(i)) * scale, droplets.start[i], 0});
  }
  out.classes = empty_classes(limits, 1.0);
  const auto bins = static_cast<std::size_t>(options.bins);
  const double duration = static_cast<double>(chords.sample_count) / chords.fs;
  std::vector<std::int64_t> last(out.classes.size(), -1);
  for (auto& c : out.classes) c.counts.assign(bins + 1, 0);
  for (const auto& p : particles) {
    const std::size_t k = class_of(p.size, limits);
    auto& c = out.classes[k];
    ++c.particles;
    if (last[k] >= 0) {
      // Bin ((m - 1) w, m w]; the tolerance absorbs the rounding of samples / fs / w.
      const double x = static_cast<double>(p.from - last[k]) / chords.fs / options.bin_width;
      const double m = std::ceil(x - 1e-9);
      const std::size_t bin = m > static_cast<double>(bins) ? bins : static_cast<std::size_t>(std::max(1.0, m)) - 1;
      ++c.counts[bin];
      ++c.intervals;
    }
    last[k] = p.from;
  }
  for (auto& c : out.classes) {
    c.pdf.assign(bins + 1, 0.0);
    c.reference.assign(bins + 1, 0.0);
    for (std::size_t m = 0; m <= bins; ++m) {
      if (c.intervals > 0) c.pdf[m] = static_cast<double>(c.counts[m]) / static_cast<double>(c.intervals);
      const double a = static_cast<double>(m) * options.bin_width;
      const double b = m < bins ? a + options.bin_width : duration;
      c.reference[m] = random_arrival_probability(a, b, c.particles, duration);
    }
    excess(c);
  }
  return out;
}

ArrivalAnalysis felder_arrival_analysis(const FelderChords& f, double void_fraction, ChordBasis basis, double velocity) {
  ArrivalAnalysis out;
  const auto cf = static_cast<float>(void_fraction);
  out.regime = cf < 0.3f ? FlowRegime::bubbly : (cf > 0.7f ? FlowRegime::droplet : FlowRegime::intermediate);
  out.basis = basis;
  out.bin_width = 1e-3;
  if (refused(out, void_fraction, basis, velocity)) return out;
  const auto& chords = f.chords;
  const bool bubbly = out.regime == FlowRegime::bubbly;
  // His classes: mm, or ms (droplets: 6 ms where the label says 5).
  const std::vector<double> limits = basis == ChordBasis::length ? std::vector<double>{1.0, 3.0, 6.0, 10.0}
                                     : bubbly                    ? std::vector<double>{0.5, 1.5, 3.0, 5.0}
                                                                 : std::vector<double>{0.5, 1.5, 3.0, 6.0};
  const auto n = static_cast<std::size_t>(std::max<std::int64_t>(0, std::min<std::int64_t>(f.n_cluster, static_cast<std::int64_t>(chords.bubbles()))));
  auto value = [&](std::int64_t samples) {
    const double t = felder_chord_ms(samples, chords.fs);
    return basis == ChordBasis::length ? t * velocity : t;
  };
  // Particle j's interval runs from its trailing edge to the next one's leading edge.
  std::vector<Particle> particles;
  if (bubbly) {
    for (std::size_t j = 0; j < n; ++j) particles.push_back({value(chords.air(j)), chords.end[j], chords.start[j]});
  } else {
    for (std::size_t j = 0; j + 1 < n; ++j) particles.push_back({value(chords.water(j)), chords.start[j + 1], chords.end[j]});
  }
  out.classes = empty_classes(limits, 1e-3);
  constexpr std::size_t bins = 100;
  const auto fs = static_cast<float>(chords.fs);
  for (auto& c : out.classes) c.counts.assign(bins + 1, 0);
  std::vector<std::size_t> klass(particles.size());
  for (std::size_t j = 0; j < particles.size(); ++j) {
    klass[j] = class_of(particles[j].size, limits);
    ++out.classes[klass[j]].particles;
  }
  for (std::size_t j = 0; j < particles.size(); ++j) {
    for (std::size_t next = j + 1; next < particles.size(); ++next) {
      if (klass[next] != klass[j]) continue;
      const double t = static_cast<float>(static_cast<float>(particles[next].to - particles[j].from) / fs * 1000.0f);
      std::size_t bin = bins - 1;  // over 100 ms: the last bin
      for (std::size_t m = 1; m <= bins; ++m) {
        if (t <= static_cast<double>(m)) {
          bin = m - 1;
          break;
        }
        if (t > 100.0) break;
      }
      ++out.classes[klass[j]].counts[bin];
      ++out.classes[klass[j]].intervals;
      break;
    }
  }
  // His reference density, in float32, at each bin's upper edge i (ms), times the 1 ms bin.
  const auto total_ms = static_cast<std::int64_t>(std::llround(std::floor(static_cast<double>(chords.sample_count) / chords.fs) * 1000.0));
  const auto t_ms = static_cast<float>(total_ms);
  auto expf32 = [](float x) { return static_cast<float>(std::exp(static_cast<double>(x))); };
  for (auto& c : out.classes) {
    if (c.particles == 0) continue;  // his 0/0
    const auto nk = static_cast<float>(c.particles);
    c.pdf.assign(bins + 1, 0.0);
    c.reference.assign(bins + 1, 0.0);
    for (std::size_t m = 0; m < bins; ++m) {
      c.pdf[m] = static_cast<double>(c.counts[m]) / static_cast<double>(nk);
      const auto i = static_cast<float>(m + 1);
      const float numerator = nk / t_ms * nk / t_ms * static_cast<float>(total_ms - static_cast<std::int64_t>(m + 1)) *
                              expf32(-(nk / t_ms * i));
      const float denominator = nk - 1.0f + expf32(-nk);
      c.reference[m] = numerator / denominator;
    }
    excess(c);
  }
  return out;
}

}  // namespace awcc
