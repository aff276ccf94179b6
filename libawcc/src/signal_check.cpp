#include "awcc/signal_check.hpp"

#include <cmath>
#include <fmt/format.h>

#include "awcc/clusters.hpp"
#include "awcc/units.hpp"

namespace awcc {

Validation SignalCheckOptions::validate() const {
  for (const double share : {max_rail_share, min_minor_share, min_flatness}) {
    if (!(share > 0.0 && share < 1.0)) {
      return Validation::invalid("", fmt::format("signal check: the share {} must lie in (0, 1)", share));
    }
  }
  if (!(min_separation_counts >= 1.0 && std::isfinite(min_separation_counts))) {
    return Validation::invalid("", fmt::format("signal check: the least separation {} must be >= 1 resolution step",
                                               min_separation_counts));
  }
  if (!(zero_level_ratio > 1.0 && std::isfinite(zero_level_ratio))) {
    return Validation::invalid("", fmt::format("signal check: the zero-level ratio {} must be > 1", zero_level_ratio));
  }
  return {};
}

std::string_view to_string(SignalStatus status) {
  switch (status) {
    case SignalStatus::two_level: return "two_level";
    case SignalStatus::binary_input: return "binary_input";
    case SignalStatus::unchecked: return "unchecked";
    case SignalStatus::air_continuous: return "air_continuous";
    case SignalStatus::one_level: return "one_level";
    case SignalStatus::no_flat_level: return "no_flat_level";
    case SignalStatus::saturated: return "saturated";
    case SignalStatus::inverted_polarity: return "inverted_polarity";
  }
  return "?";
}

bool SignalCheck::failed() const {
  switch (status) {
    case SignalStatus::one_level:
    case SignalStatus::no_flat_level:
    case SignalStatus::saturated:
    case SignalStatus::inverted_polarity: return true;
    default: return false;
  }
}

DigitiserLimits int16_limits(double quantum) { return {-32767.0 * quantum, 32767.0 * quantum}; }

namespace {

std::string percent(double share) { return fmt::format("{:.3g} %", 100.0 * share); }

const char* no_interface_cause = "a dead or disconnected probe, or a tip in clear water or air throughout?";

// Cue 5a (the header): the stated air level holds the droplet regime's share.
bool air_is_continuous(double air_share) { return flow_regime(air_share) == FlowRegime::droplet; }

std::string air_continuous_message(std::string_view air, double air_share, std::string_view fix) {
  return fmt::format("the {} holds {} of the samples: air is the continuous phase, as in a spray region; in a bubbly "
                     "region this means inverted polarity ({})",
                     air, percent(air_share), fix);
}

SignalCheck binary_input(const VoltageHistogram& h, const std::vector<double>& levels) {
  SignalCheck out;
  out.status = SignalStatus::binary_input;
  out.low_level = levels.front();
  out.high_level = levels.back();
  const auto values = h.values();
  out.air_share = static_cast<double>(values.back().second) / static_cast<double>(h.total());
  out.minor_share = std::min(out.air_share, 1.0 - out.air_share);
  if (air_is_continuous(out.air_share)) {
    out.status = SignalStatus::air_continuous;
    out.message = air_continuous_message(fmt::format("binary input's air value ({:.4g})", out.high_level),
                                         out.air_share, "binary input takes its higher value as air");
  }
  return out;
}

}  // namespace

SignalCheck check_signal(const VoltageHistogram& h, ProbeType probe, std::optional<DigitiserLimits> limits,
                         const SignalCheckOptions& o) {
  SignalCheck out;
  if (h.total() == 0) return out;
  const double n = static_cast<double>(h.total());
  const double q = h.resolution();
  const auto at_limit = [&](double v) { return limits && (v <= limits->low + 0.5 * q || v >= limits->high - 0.5 * q); };
  const auto values = h.values();
  if (const auto levels = h.binary_levels(); levels && values.size() == 2) return binary_input(h, *levels);
  if (values.size() == 1) {
    // One value, or several within one step of the data's resolution.
    const double v = values.front().first;
    out.low_level = out.high_level = v;
    out.flatness = 1.0;
    if (at_limit(v)) {
      out.status = SignalStatus::saturated;
      out.rail_share = 1.0;
      out.message = fmt::format("every sample sits at the digitiser's limit ({:+.4g} V): the channel is saturated", v);
    } else {
      out.status = SignalStatus::one_level;
      out.message = fmt::format("every sample is {:.4g} V (to the data's resolution, {}): one level, no interface ({})",
                                v, format_quantity(q, Dimension::voltage), no_interface_cause);
    }
    return out;
  }

  // 1. The levels: the histogram rule's modes with 100 bins over the range.
  BinarisationOptions modes;
  modes.rule = ThresholdRule::histogram;
  modes.probe = ProbeType::conductivity;  // air_level is then the low mode
  modes.bin_width = 0.0;
  const Threshold t = choose_threshold(h, modes);
  const double lo = t.air_level, hi = t.water_level;
  const double separation = hi - lo, middle = 0.5 * (lo + hi), near = separation / 8.0;
  out.low_level = lo;
  out.high_level = hi;

  std::int64_t below = 0, flat_low = 0, flat_high = 0, at_rail = 0;
  double rail_value = 0.0;
  for (const auto& [v, count] : values) {
    if (v < middle) {
      below += count;
      if (std::fabs(v - lo) <= near) flat_low += count;
    } else if (std::fabs(v - hi) <= near) {
      flat_high += count;
    }
    if (at_limit(v)) {
      at_rail += count;
      rail_value = v;
    }
  }
  const auto share = [](std::int64_t part, std::int64_t whole) {
    return whole > 0 ? static_cast<double>(part) / static_cast<double>(whole) : 0.0;
  };
  const std::int64_t above = h.total() - below;
  out.flatness = std::max(share(flat_low, below), share(flat_high, above));
  out.minor_share = static_cast<double>(std::min(below, above)) / n;
  out.rail_share = static_cast<double>(at_rail) / n;
  const bool air_low = probe == ProbeType::conductivity;
  out.air_share = static_cast<double>(air_low ? below : above) / n;

  // 2-4 (the header), the first that fails.
  if (limits && out.rail_share >= o.max_rail_share) {
    out.status = SignalStatus::saturated;
    out.message = fmt::format(
        "{} of the samples sit at the digitiser's limit ({:+.4g} V): a level is clipped, so neither it nor the "
        "threshold between the levels is known; lower the gain or shift the offset until both levels lie inside the "
        "range",
        percent(out.rail_share), rail_value);
    return out;
  }
  if (out.flatness < o.min_flatness) {
    out.status = SignalStatus::no_flat_level;
    out.message = fmt::format(
        "the voltage histogram has no flat level: within {:.3g} V of its modes ({:.4g} V and {:.4g} V) lie at most "
        "{} of their side's samples, where a phase-detection signal holds {} or more: noise (a disconnected or "
        "dead probe?), or levels that drift by a third of their separation or more during the record",
        near, lo, hi, percent(out.flatness), percent(o.min_flatness));
    return out;
  }
  const double level = below > above ? lo : hi;  // the majority's
  if (separation < o.min_separation_counts * q) {
    out.status = SignalStatus::one_level;
    out.message = fmt::format(
        "the voltage histogram has one level ({:.4g} V): its modes lie {} apart, {:.0f} steps of the data's "
        "resolution {}, where two levels lie {:.0f} or more apart ({})",
        level, format_quantity(separation, Dimension::voltage), separation / q, format_quantity(q, Dimension::voltage),
        o.min_separation_counts, no_interface_cause);
    return out;
  }
  if (out.minor_share < o.min_minor_share) {
    out.status = SignalStatus::one_level;
    out.message = fmt::format(
        "the voltage histogram has one level ({:.4g} V): {} of the samples ({}) lie past the midpoint towards "
        "{:.4g} V, where a second level holds {} or more ({})",
        level, percent(out.minor_share), std::min(below, above), level == lo ? hi : lo, percent(o.min_minor_share),
        no_interface_cause);
    return out;
  }

  // 5. Polarity.
  out.status = SignalStatus::two_level;
  if (!air_is_continuous(out.air_share)) return out;
  const double air = air_low ? lo : hi, water = air_low ? hi : lo;
  const std::string_view side = air_low ? "low" : "high", other_side = air_low ? "high" : "low";
  const std::string_view other_probe = to_string(air_low ? ProbeType::optical : ProbeType::conductivity);
  // Cue b: the no-signal state (conductivity: air; optical: water) is the level nearer 0 V.
  const double no_signal = air_low ? air : water, signal = air_low ? water : air;
  const bool inverted = no_signal * signal > 0.0 && std::fabs(no_signal) >= o.zero_level_ratio * std::fabs(signal);
  const std::string fix =
      fmt::format("if air is this recording's {} level, state probe = {}", other_side, other_probe);
  if (inverted) {
    out.status = SignalStatus::inverted_polarity;
    out.message = fmt::format(
        "the polarity contradicts probe = {}: its air level, the {} one ({:.4g} V), holds {} of the samples and lies "
        "farther from 0 V than the {} one ({:.4g} V); but {}, the level nearer 0 V, and a bubbly flow's signal holds "
        "water's level most: the recording's sign looks inverted; {}",
        to_string(probe), side, air, percent(out.air_share), other_side, water,
        air_low ? "air is a conductivity probe's no-current level" : "water is an optical probe's no-light level", fix);
    return out;
  }
  out.status = SignalStatus::air_continuous;
  out.message = air_continuous_message(
      fmt::format("{} level ({:.4g} V), air for probe = {},", side, air, to_string(probe)), out.air_share, fix);
  return out;
}

std::string signal_warning(const SignalCheck& check, int channel, std::string_view tip) {
  if (check.message.empty()) return {};
  const auto where = fmt::format("channel {} ({})", channel, tip);
  if (!check.overridden) return fmt::format("{}: {}", where, check.message);
  return fmt::format("{}: {}; processed anyway, as allow-bad-signal asks: this tip's numbers may describe no flow",
                     where, check.message);
}

}  // namespace awcc
