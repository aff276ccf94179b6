#include "awcc/position_sizes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "awcc/clusters.hpp"

namespace awcc {

std::string_view to_string(SizesStatus status) {
  switch (status) {
    case SizesStatus::ok: return "ok";
    case SizesStatus::not_converged: return "not_converged";
    case SizesStatus::no_velocity: return "no_velocity";
    case SizesStatus::intermediate_void_fraction: return "intermediate_void_fraction";
    case SizesStatus::too_few_chords: return "too_few_chords";
    case SizesStatus::coarse_sampling: return "coarse_sampling";
  }
  return "?";
}

std::string_view to_string(DispersedPhase phase) { return phase == DispersedPhase::bubbles ? "bubbles" : "droplets"; }

std::string_view to_string(ChordVelocity source) { return chord_velocity_names[static_cast<std::size_t>(source)]; }

std::string_view to_string(AreaSource source) { return source == AreaSource::dual_tip ? "dual_tip" : "multi_tip"; }

Validation SizesOptions::validate() const {
  if (!(samples_min >= 0.0) || !std::isfinite(samples_min)) {
    return Validation::invalid("size-samples-min",
                               fmt::format("size-samples-min = {} must be a number of samples >= 0", samples_min));
  }
  return inversion.validate();
}

namespace {

// One chord of the dispersed phase: its first sample and its samples.
struct Chord {
  std::int64_t first = 0, samples = 0;
  std::size_t bubble = 0;  // the leading air interval (bubbles only)
};

}  // namespace

SizesResult position_sizes(const AirIntervals& leading, const PhaseStatistics& phase,
                           const std::optional<AwccResult>& awcc, const std::optional<EventResult>& events,
                           std::optional<double> record_velocity, std::string_view record_source,
                           const SizesOptions& options) {
  options.validate().throw_if_failed();
  SizesResult out;
  out.record_velocity_source = std::string(record_source);
  out.distribution.options = options.inversion;
  const double c = phase.void_fraction;
  const FlowRegime regime = flow_regime(c);
  if (regime == FlowRegime::intermediate) {
    out.status = SizesStatus::intermediate_void_fraction;
    out.message = fmt::format("void fraction {:.4f} lies in 0.3 to 0.7: neither bubbles nor droplets are particles "
                              "(flow_regime); no size distribution",
                              c);
    return out;
  }
  const bool bubbles = regime == FlowRegime::bubbly;
  out.phase = bubbles ? DispersedPhase::bubbles : DispersedPhase::droplets;
  const double u = record_velocity ? std::fabs(*record_velocity) : 0.0;
  if (u > 0.0) {
    out.sauter_flux = sauter_diameter(u, dispersed_fraction(c), phase.bubble_count_rate);
  }

  // The complete chords of the dispersed phase.
  const auto& iv = leading.intervals;
  std::vector<Chord> chords;
  if (bubbles) {
    for (std::size_t i = 0; i < iv.size(); ++i) {
      if (iv[i].start > 0 && iv[i].stop < leading.sample_count) chords.push_back({iv[i].start, iv[i].stop - iv[i].start, i});
    }
  } else {
    for (std::size_t i = 0; i + 1 < iv.size(); ++i) chords.push_back({iv[i].stop, iv[i + 1].start - iv[i].stop, i});
  }
  out.chords_given = static_cast<std::int64_t>(chords.size());

  // Which finer velocities may be used (header).
  const bool per_bubble = bubbles && events && events->ok() && events->quality == AwccQuality::ok &&
                          events->bubbles.size() == iv.size();
  if (bubbles && events && !per_bubble) {
    out.velocity_note = events->ok() && events->quality != AwccQuality::ok
                            ? fmt::format("event detection's per-bubble velocities are not used: its quality is {} "
                                          "({})",
                                          to_string(events->quality), events->quality_reason)
                            : fmt::format("event detection gave no per-bubble velocities ({})", events->message);
  }
  if (!bubbles && events) out.velocity_note = "event detection pairs air chords, not droplets: no per-droplet velocity";
  const bool windows = awcc && awcc->ok() && awcc->quality == AwccQuality::ok;
  if (awcc && awcc->ok() && !windows) {
    const std::string why = fmt::format("AWCC's window velocities are not used: its quality is {} ({})",
                                        to_string(awcc->quality), awcc->quality_reason);
    out.velocity_note += (out.velocity_note.empty() ? "" : "; ") + why;
  }
  std::vector<std::int64_t> window_starts;
  if (windows) {
    window_starts.reserve(awcc->windows.size());
    for (const auto& w : awcc->windows) window_starts.push_back(w.start);
  }
  // The chords come in increasing `first`: the window holding one is found
  // by walking on from the last one's (the window a binary search finds, the
  // last starting at or before `first`, without a search per chord).
  std::size_t next_window = 0;  // windows [0, next_window) start at or before the last chord's first sample
  const auto window_velocity = [&](std::int64_t first) -> double {
    if (!windows || window_starts.empty()) return 0.0;
    while (next_window > 0 && window_starts[next_window - 1] > first) --next_window;
    while (next_window < window_starts.size() && window_starts[next_window] <= first) ++next_window;
    if (next_window == 0) return 0.0;
    const AwccWindow& w = awcc->windows[next_window - 1];
    if (first >= w.start + w.length || w.fate != WindowFate::accepted || !(w.velocity > 0.0)) return 0.0;
    return w.velocity;
  };

  // Lengths with their counts; the record velocity's by whole samples.
  const double fs = leading.fs;
  std::vector<double> lengths;
  std::vector<std::int64_t> counts, samples_of;  // samples_of: per entry of lengths
  std::map<std::int64_t, std::int64_t> at_record;
  for (const Chord& ch : chords) {
    double v = 0.0;
    ChordVelocity source = ChordVelocity::none;
    if (per_bubble) {
      const EventBubble& b = events->bubbles[ch.bubble];
      if (b.fate == BubbleFate::paired && std::isfinite(b.velocity) && b.velocity > 0.0) {
        v = b.velocity;
        source = ChordVelocity::bubble;
      }
    }
    if (source == ChordVelocity::none) {
      if (const double w = window_velocity(ch.first); w > 0.0) {
        v = w;
        source = ChordVelocity::window;
      } else if (u > 0.0) {
        source = ChordVelocity::record;
      }
    }
    ++out.chords_by_velocity[static_cast<std::size_t>(source)];
    if (source == ChordVelocity::record) {
      ++at_record[ch.samples];
    } else if (source != ChordVelocity::none) {
      lengths.push_back(static_cast<double>(ch.samples) / fs * v);
      counts.push_back(1);
      samples_of.push_back(ch.samples);
    }
  }
  for (const auto& [k, n] : at_record) {
    lengths.push_back(static_cast<double>(k) / fs * u);
    counts.push_back(n);
    samples_of.push_back(k);
  }
  if (lengths.empty() && !(u > 0.0) && out.count(ChordVelocity::window) == 0 && out.count(ChordVelocity::bubble) == 0) {
    out.status = SizesStatus::no_velocity;
    out.message = fmt::format("no velocity: the record has none ({}) and no chord has its bubble's or its window's; "
                              "chord lengths and sizes are unknown",
                              record_source);
    return out;
  }

  out.distribution = size_distribution(lengths, counts, options.inversion);
  out.distribution.chords_given = out.chords_given;  // the chords without a velocity are given, not used
  const SizeDistribution& d = out.distribution;
  if (d.status == SizeStatus::too_few_chords) {
    out.status = SizesStatus::too_few_chords;
    out.message = d.message;
    return out;
  }
  // The number median in samples (header): the chords' length per sample.
  double total_length = 0.0, total_samples = 0.0;
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    total_length += static_cast<double>(counts[i]) * lengths[i];
    total_samples += static_cast<double>(counts[i]) * static_cast<double>(samples_of[i]);
  }
  out.median_samples = d.median * total_samples / total_length;
  if (out.median_samples < options.samples_min) {
    out.status = SizesStatus::coarse_sampling;
    out.message = fmt::format("the inverted number median, {:.3g} mm, spans {:.2g} samples, fewer than "
                              "size-samples-min = {:g}: chord times are whole samples, and at 2 samples the median "
                              "comes out 15 % low (docs/validation.md, \"Bubble sizes from chord lengths\"); "
                              "sample faster. 1.5 x mean chord = {:.4g} mm is d32 without inversion",
                              1e3 * d.median, out.median_samples, options.samples_min, 1e3 * d.sauter_from_chords);
    SizeDistribution kept;
    kept.status = SizeStatus::too_few_chords;
    kept.options = d.options;
    kept.chords_given = d.chords_given;
    kept.chords_used = d.chords_used;
    kept.mean_chord = d.mean_chord;
    kept.sauter_from_chords = d.sauter_from_chords;
    out.distribution = std::move(kept);
    return out;
  }
  out.status = d.ok() ? SizesStatus::ok : SizesStatus::not_converged;
  out.message = d.message;
  return out;
}

std::string SizesResult::report() const {
  std::string s = fmt::format("sizes ({}): {}{}\n", phase ? to_string(*phase) : std::string_view("no particles"),
                              to_string(status), message.empty() ? "" : " - " + message);
  if (status == SizesStatus::intermediate_void_fraction) return s;
  s += fmt::format("  {} complete chords: {} at their bubble's velocity, {} at their window's, {} at the record's "
                   "({}), {} without\n",
                   chords_given, count(ChordVelocity::bubble), count(ChordVelocity::window),
                   count(ChordVelocity::record), record_velocity_source, count(ChordVelocity::none));
  if (!velocity_note.empty()) s += "  " + velocity_note + "\n";
  if (distribution.chords_used > 0) {
    s += fmt::format("  mean chord {:.4g} mm; d32 = 1.5 x mean chord {:.4g} mm", 1e3 * distribution.mean_chord,
                     1e3 * distribution.sauter_from_chords);
    if (sauter_flux) s += fmt::format(", 1.5 u c / F {:.4g} mm", 1e3 * *sauter_flux);
    s += "\n";
  }
  if (has_distribution()) {
    const auto& d = distribution;
    s += fmt::format("  number distribution, {} bins {:.4g}-{:.4g} mm: median {:.4g} mm ({:.3g} samples), "
                     " d10 {:.4g} mm, d20 {:.4g} mm, d30 {:.4g} mm, d32 {:.4g} mm; {} EM iterations\n",
                     d.diameters.size(), 1e3 * d.edges.front(), 1e3 * d.edges.back(),
                     1e3 * d.median, median_samples, 1e3 * d.d10, 1e3 * d.d20, 1e3 * d.d30, 1e3 * d.d32, d.iterations);
  }
  return s;
}

std::optional<double> InterfacialArea::value() const {
  if (!source) return std::nullopt;
  return *source == AreaSource::multi_tip ? multi_tip : dual_tip;
}

std::optional<Interval95> InterfacialArea::ci95() const {
  if (!source) return std::nullopt;
  return *source == AreaSource::multi_tip ? multi_tip_ci95 : dual_tip_ci95;
}

std::string InterfacialArea::report() const {
  std::string s = "interfacial area: ";
  const auto one = [](std::optional<double> v, std::optional<Interval95> ci) {
    if (!v) return std::string("none");
    return ci ? fmt::format("{:.4g} 1/m ({:.4g}-{:.4g})", *v, ci->lower, ci->upper) : fmt::format("{:.4g} 1/m", *v);
  };
  s += fmt::format("dual tip 4 F / u = 6 c / d32 {}", one(dual_tip, dual_tip_ci95));
  if (multi_tip) s += fmt::format(", multi-tip {}", one(multi_tip, multi_tip_ci95));
  s += fmt::format("; the row's: {}", source ? to_string(*source) : std::string_view("none"));
  if (!message.empty()) s += " (" + message + ")";
  return s + "\n";
}

InterfacialArea interfacial_area(const PhaseStatistics& phase, std::optional<double> velocity,
                                 std::optional<Interval95> velocity_ci95, const MultiTipResult* vectors,
                                 bool multi_tip_quality_ok, std::string_view multi_tip_reason) {
  InterfacialArea out;
  std::vector<std::string> why;
  const double F = phase.bubble_count_rate;
  const double u = velocity ? std::fabs(*velocity) : 0.0;
  if (!(u > 0.0)) {
    why.emplace_back("no dual-tip value: the record has no velocity");
  } else if (!(F > 0.0)) {
    why.emplace_back("dual tip: no complete bubble, F = 0");
    out.dual_tip = 0.0;
  } else {
    const double a = 4.0 * F / u;
    out.dual_tip = a;
    const Interval95& f = phase.bubble_count_rate_ci95;
    if (velocity_ci95 && velocity_ci95->lower > 0.0 && velocity_ci95->upper >= u && f.lower > 0.0 &&
        f.upper >= F && velocity_ci95->lower <= u && f.lower <= F) {
      // The header's propagation on the log scale.
      const double up = std::hypot(std::log(f.upper / F), std::log(u / velocity_ci95->lower));
      const double down = std::hypot(std::log(F / f.lower), std::log(velocity_ci95->upper / u));
      out.dual_tip_ci95 = Interval95{a * std::exp(-down), a * std::exp(up)};
    } else {
      why.emplace_back(velocity_ci95 ? "no dual-tip interval: F's interval reaches 0 (too few chords)"
                                     : "no dual-tip interval: the velocity has none");
    }
  }
  if (vectors && vectors->interfacial_area) {
    out.multi_tip = vectors->interfacial_area;
    out.multi_tip_ci95 = vectors->interfacial_area_ci95;
    if (multi_tip_quality_ok) {
      out.source = AreaSource::multi_tip;
    } else {
      why.push_back(fmt::format("the multi-tip value is not the row's: the probe's quality is not ok ({})",
                                multi_tip_reason));
    }
  }
  if (!out.source && out.dual_tip) out.source = AreaSource::dual_tip;
  for (const auto& w : why) out.message += (out.message.empty() ? "" : "; ") + w;
  return out;
}

}  // namespace awcc
