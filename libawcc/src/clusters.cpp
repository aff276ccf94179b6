#include "awcc/clusters.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "awcc/order_statistics.hpp"

namespace awcc {

std::string_view to_string(FlowRegime regime) {
  switch (regime) {
    case FlowRegime::bubbly: return "bubbly";
    case FlowRegime::intermediate: return "intermediate";
    case FlowRegime::droplet: return "droplet";
  }
  return "?";
}

std::string_view to_string(ClusterCriterion criterion) {
  switch (criterion) {
    case ClusterCriterion::median: return "median";
    case ClusterCriterion::constant: return "constant";
    case ClusterCriterion::near_wake: return "near_wake";
  }
  return "?";
}

std::string_view to_string(ClusterStatus status) {
  switch (status) {
    case ClusterStatus::ok: return "ok";
    case ClusterStatus::intermediate_void_fraction: return "intermediate_void_fraction";
    case ClusterStatus::too_few_particles: return "too_few_particles";
    case ClusterStatus::no_velocity: return "no_velocity";
  }
  return "?";
}

FlowRegime flow_regime(double void_fraction) {
  if (void_fraction < 0.3) return FlowRegime::bubbly;
  if (void_fraction > 0.7) return FlowRegime::droplet;
  return FlowRegime::intermediate;
}

std::optional<ParticleRefusal> particle_refusal(FlowRegime regime, double void_fraction, ChordBasis basis,
                                                double velocity, std::string_view analysis) {
  if (regime == FlowRegime::intermediate) {
    return ParticleRefusal{ClusterStatus::intermediate_void_fraction,
                           fmt::format("void fraction {:.4f} lies in 0.3 to 0.7: neither bubbles nor droplets are "
                                       "particles; no {}",
                                       void_fraction, analysis)};
  }
  if (basis == ChordBasis::length && !(velocity > 0.0)) {
    return ParticleRefusal{ClusterStatus::no_velocity,
                           "no velocity: chord lengths are unknown; the time-based analysis stands"};
  }
  return std::nullopt;
}

namespace {

constexpr std::array<ClusterCriterion, 3> kCriteria{ClusterCriterion::median, ClusterCriterion::constant,
                                                    ClusterCriterion::near_wake};

// The checks every analysis makes before it runs.
bool refused(ClusterAnalysis& out, double void_fraction, ChordBasis basis, double velocity, std::size_t particles) {
  if (auto why = particle_refusal(out.regime, void_fraction, basis, velocity, "cluster analysis")) {
    out.status = why->status;
    out.message = std::move(why->message);
    return true;
  }
  if (particles < 3) {
    out.status = ClusterStatus::too_few_particles;
    out.message = fmt::format("{} {}: at least 3 are needed", particles,
                              out.regime == FlowRegime::bubbly ? "bubbles" : "droplets");
    return true;
  }
  return false;
}

void add_size(ClusterStatistics& s, std::int64_t size) { ++s.size_counts[static_cast<std::size_t>(std::min<std::int64_t>(size, 21) - 2)]; }

void finish_pdf(ClusterStatistics& s) {
  if (s.clusters == 0) return;
  std::array<double, 20> pdf{};
  for (std::size_t k = 0; k < pdf.size(); ++k) pdf[k] = static_cast<double>(s.size_counts[k]) / static_cast<double>(s.clusters);
  s.size_pdf = pdf;
}

}  // namespace

ClusterAnalysis cluster_analysis(const ChordSequence& chords, double void_fraction, ChordBasis basis,
                                 const ClusterOptions& options, double velocity) {
  ClusterAnalysis out;
  out.regime = flow_regime(void_fraction);
  out.basis = basis;
  const std::size_t n = chords.bubbles();
  // Particles and the separations after each (in samples).
  std::vector<std::int64_t> particle, gap;
  if (out.regime == FlowRegime::bubbly) {
    for (std::size_t i = 0; i < n; ++i) particle.push_back(chords.air(i));
    for (std::size_t i = 0; i + 1 < n; ++i) gap.push_back(chords.water(i));
  } else if (out.regime == FlowRegime::droplet) {
    const auto droplets = complete_droplets(chords);
    const std::size_t m = droplets.droplets();
    for (std::size_t i = 0; i < m; ++i) particle.push_back(droplets.water(i));
    for (std::size_t i = 0; i + 1 < m; ++i) gap.push_back(droplets.air(i));  // between droplets i and i + 1
  }
  if (refused(out, void_fraction, basis, velocity, particle.size())) return out;
  const double scale = (basis == ChordBasis::length ? velocity : 1.0) / chords.fs;  // s or m per sample
  const std::size_t m = particle.size();
  double all = 0.0;
  for (const auto p : particle) all += static_cast<double>(p) * scale;
  const double mean_all = all / static_cast<double>(m);
  std::vector<double> gaps(gap.size());
  for (std::size_t i = 0; i < gap.size(); ++i) gaps[i] = static_cast<double>(gap[i]) * scale;
  const double median_gap = median(gaps);
  const double duration = static_cast<double>(chords.sample_count) / chords.fs;
  for (const auto criterion : kCriteria) {
    ClusterStatistics s;
    s.criterion = criterion;
    s.particles = static_cast<std::int64_t>(m);
    std::vector<bool> clustered(m - 1);
    if (criterion == ClusterCriterion::near_wake) {
      for (std::size_t i = 0; i + 1 < m; ++i) clustered[i] = gap[i] <= particle[i];
    } else {
      const double limit = criterion == ClusterCriterion::median
                               ? options.median_fraction * median_gap
                               : (basis == ChordBasis::length ? options.constant_length : options.constant_time);
      s.criterion_value = limit;
      for (std::size_t i = 0; i + 1 < m; ++i) clustered[i] = static_cast<double>(gap[i]) * scale <= limit;
    }
    double chord_sum = 0.0, lead_sum = 0.0;
    for (std::size_t i = 0; i + 1 < m; ++i) {
      if (!clustered[i] || (i > 0 && clustered[i - 1])) continue;
      std::size_t last = i;  // the run of clustered pairs i..last: particles i..last+1
      while (last + 2 < m && clustered[last + 1]) ++last;
      const std::size_t size = last - i + 2;
      double members = 0.0;
      for (std::size_t j = i; j <= last + 1; ++j) members += static_cast<double>(particle[j]) * scale;
      s.in_clusters += static_cast<std::int64_t>(size);
      ++s.clusters;
      chord_sum += members;
      lead_sum += static_cast<double>(particle[i]) * scale / (members / static_cast<double>(size));
      add_size(s, static_cast<std::int64_t>(size));
    }
    s.percent_in_clusters = 100.0 * static_cast<double>(s.in_clusters) / static_cast<double>(m);
    s.clusters_per_second = static_cast<double>(s.clusters) / duration;
    if (s.clusters > 0) {
      s.mean_particles_per_cluster = static_cast<double>(s.in_clusters) / static_cast<double>(s.clusters);
      s.mean_chord_in_cluster = chord_sum / static_cast<double>(s.in_clusters);
      s.ratio_cluster_chord_to_mean_chord = *s.mean_chord_in_cluster / mean_all;
      s.ratio_lead_to_cluster_mean_chord = lead_sum / static_cast<double>(s.clusters);
    }
    finish_pdf(s);
    out.criteria.push_back(s);
  }
  return out;
}

ClusterAnalysis felder_cluster_analysis(const FelderChords& f, double void_fraction, ChordBasis basis,
                                        const ClusterOptions& options, double velocity) {
  ClusterAnalysis out;
  // His regime test: float32 C against float32 literals.
  const auto c = static_cast<float>(void_fraction);
  out.regime = c < 0.3f ? FlowRegime::bubbly : (c > 0.7f ? FlowRegime::droplet : FlowRegime::intermediate);
  out.basis = basis;
  const auto& chords = f.chords;
  const auto n = static_cast<std::size_t>(std::max<std::int64_t>(0, std::min<std::int64_t>(f.n_cluster, static_cast<std::int64_t>(chords.bubbles()))));
  const bool bubbly = out.regime == FlowRegime::bubbly;
  if (refused(out, void_fraction, basis, velocity, bubbly ? n : (n > 0 ? n - 1 : 0))) return out;
  // His arrays, 1-based: a[1..n] air, w[1..n-1] water, in ms or mm.
  auto value = [&](std::int64_t samples) {
    const double t = felder_chord_ms(samples, chords.fs);
    return basis == ChordBasis::length ? t * velocity : t;
  };
  std::vector<double> a(n + 2, 0.0), w(n + 1, 0.0);
  for (std::size_t i = 1; i <= n; ++i) a[i] = value(chords.air(i - 1));
  for (std::size_t i = 1; i + 1 <= n; ++i) w[i] = value(chords.water(i - 1));
  const std::vector<double>& particle = bubbly ? a : w;       // P[1..m]
  const std::vector<double>& separator = bubbly ? w : a;      // flag i tests separator[i]
  const std::size_t m = bubbly ? n : n - 1;
  const std::size_t flags = bubbly ? n - 1 : n;
  double all = 0.0;
  for (std::size_t i = 1; i <= m; ++i) all += particle[i];
  const double mean_all = all / static_cast<double>(m);
  // His median: the middle value, the mean of the two middle ones for an even count.
  std::vector<double> separations(separator.begin() + 1, separator.begin() + 1 + static_cast<std::ptrdiff_t>(flags));
  const double median_separation = median(separations);
  const double tolerance = 1e-5f;
  const auto duration = static_cast<float>(static_cast<double>(chords.sample_count) / chords.fs);
  for (const auto criterion : kCriteria) {
    ClusterStatistics s;
    s.criterion = criterion;
    s.particles = static_cast<std::int64_t>(m);
    std::int64_t sum_up = 1, counter = 0, detector = 0;
    double size = 0.0, chord_size_cluster = 0.0, lead_sum = 0.0;
    auto close = [&](std::size_t i) {  // the cluster of particles i+2-sum_up .. i+1
      add_size(s, sum_up);
      ++detector;
      counter += sum_up;
      chord_size_cluster += size + particle[i + 1];
      double members = 0.0;
      for (std::int64_t k = 1; k <= sum_up; ++k) members += particle[i + 1 - static_cast<std::size_t>(sum_up) + static_cast<std::size_t>(k)];
      lead_sum += particle[i + 2 - static_cast<std::size_t>(sum_up)] / (members / static_cast<double>(static_cast<float>(sum_up)));
      sum_up = 1;
      size = 0.0;
    };
    if (criterion == ClusterCriterion::near_wake) {
      if (bubbly) {
        for (std::size_t i = 1; i + 2 <= n; ++i) {
          if (w[i] - a[i] <= tolerance) {
            ++sum_up;
            size += a[i];
            if (a[i + 1] - w[i + 1] <= tolerance) close(i);
          }
        }
      } else {
        for (std::size_t i = 1; i + 3 <= n; ++i) {
          if (a[i + 1] - w[i] <= tolerance) {
            ++sum_up;
            size += w[i];
            if (w[i + 1] - a[i + 2] <= tolerance) close(i);
          }
        }
      }
    } else {
      const double limit = criterion == ClusterCriterion::median
                               ? median_separation * static_cast<double>(static_cast<float>(options.median_fraction))
                               : static_cast<double>(static_cast<float>(
                                     (basis == ChordBasis::length ? options.constant_length : options.constant_time) * 1e3));
      s.criterion_value = limit * 1e-3;
      std::vector<int> flag(flags + 2, 0);
      for (std::size_t i = 1; i <= flags; ++i) flag[i] = separator[i] <= limit ? 1 : 0;
      for (std::size_t i = 1; i + 2 <= n; ++i) {
        sum_up += flag[i];
        if (flag[i] == 1) size += particle[i];
        if (flag[i] == 1 && flag[i + 1] == 0) close(i);
      }
    }
    s.in_clusters = counter;
    s.clusters = detector;
    s.percent_in_clusters =
        static_cast<float>(static_cast<float>(static_cast<float>(counter) / static_cast<float>(m)) * 100.0f);
    s.clusters_per_second = static_cast<float>(static_cast<float>(detector) / duration);
    if (detector > 0) {
      s.mean_particles_per_cluster = static_cast<float>(static_cast<float>(counter) / static_cast<float>(detector));
      const double mean_chord = chord_size_cluster / static_cast<double>(static_cast<float>(counter));
      s.mean_chord_in_cluster = mean_chord * 1e-3;
      s.ratio_cluster_chord_to_mean_chord = mean_chord / mean_all;
      s.ratio_lead_to_cluster_mean_chord = lead_sum / static_cast<double>(static_cast<float>(detector));
      std::array<double, 20> pdf{};
      for (std::size_t k = 0; k < pdf.size(); ++k)
        pdf[k] = static_cast<float>(static_cast<float>(s.size_counts[k]) / static_cast<float>(detector));
      s.size_pdf = pdf;
    }
    out.criteria.push_back(s);
  }
  return out;
}

}  // namespace awcc
