#include "awcc/event_detection.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "awcc/detail/awcc_steps.hpp"

namespace awcc {

std::string_view to_string(Pairing pairing) { return pairing == Pairing::kramer ? "kramer" : "shen"; }

std::string_view to_string(InterfaceTiming timing) {
  return timing == InterfaceTiming::midpoint ? "midpoint" : "crossing";
}

std::string_view to_string(BubbleFate fate) {
  const auto i = static_cast<std::size_t>(fate);
  return i < bubble_fate_names.size() ? bubble_fate_names[i] : "?";
}

std::string_view to_string(EventStatus status) {
  switch (status) {
    case EventStatus::ok: return "ok";
    case EventStatus::no_bubbles: return "no_bubbles";
    case EventStatus::no_first_velocity: return "no_first_velocity";
    case EventStatus::too_few_bubbles: return "too_few_bubbles";
    case EventStatus::no_tip_separation: return "no_tip_separation";
  }
  return "?";
}

Validation EventOptions::validate() const {
  if (!(disparity_max > 0.0) || !std::isfinite(disparity_max)) {
    return Validation::invalid("chord-disparity-max",
                               fmt::format("chord-time disparity limit {} must be positive: no pair has a disparity "
                                           "below 0",
                                           disparity_max));
  }
  if (!(shen_lag_factor > 0.0 && shen_lag_factor <= 1.0)) {
    return Validation::invalid("shen-lag-factor",
                               fmt::format("Shen's lag factor {} must lie in (0, 1]: the lag limit is |S| / (factor x "
                                           "first velocity)",
                                           shen_lag_factor));
  }
  if (!(probe_speed_min > 0.0 && probe_speed_min < 1.0)) {
    return Validation::invalid("probe-speed-min",
                               fmt::format("probe-speed-min = {} must lie in (0, 1): the slowest bubble paired, as a "
                                           "fraction of the first velocity",
                                           probe_speed_min));
  }
  if (!(probe_speed_max > 1.0) || !std::isfinite(probe_speed_max)) {
    return Validation::invalid("probe-speed-max",
                               fmt::format("probe-speed-max = {} must be above 1: the fastest bubble paired, as a "
                                           "multiple of the first velocity",
                                           probe_speed_max));
  }
  if (!(probe_angle_max > 0.0 && probe_angle_max < 90.0)) {
    return Validation::invalid("probe-angle-max",
                               fmt::format("probe-angle-max = {} degrees must lie in (0, 90): the largest angle "
                                           "between a bubble's velocity and the streamwise axis",
                                           probe_angle_max));
  }
  if (!(probe_diameter_mismatch > 0.0)) {
    return Validation::invalid("probe-diameter-mismatch",
                               fmt::format("probe-diameter-mismatch = {} must be positive (a large value turns the "
                                           "check off)",
                                           probe_diameter_mismatch));
  }
  if (bubbles_reported < 2) {
    return Validation::invalid("bubbles-reported",
                               fmt::format("bubbles reported {}: moments need at least 2 bubbles", bubbles_reported));
  }
  if (bubbles_ok < bubbles_reported) {
    return Validation::invalid("bubbles-ok", fmt::format("bubbles ok {} must be at least bubbles reported {}",
                                                         bubbles_ok, bubbles_reported));
  }
  if (!(pairing_yield_ok >= 0.0 && pairing_yield_ok <= 1.0)) {
    return Validation::invalid("pairing-yield-ok", fmt::format("pairing yield ok {} must lie in [0, 1]", pairing_yield_ok));
  }
  return {};
}

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Why Shen's pairing cannot run, or empty.
std::string refuse_first_velocity(const EventOptions& options, const std::optional<double>& first_velocity) {
  if (options.pairing != Pairing::shen) return {};
  if (!first_velocity) {
    return fmt::format("Shen pairing needs a first velocity estimate V_gas (its lag limit is |S| / ({:g} V_gas)) and "
                       "none was given: give FSCC's or AWCC's velocity, or set pairing to kramer",
                       options.shen_lag_factor);
  }
  if (!(*first_velocity > 0.0) || !std::isfinite(*first_velocity)) {
    return fmt::format("Shen pairing needs a positive first velocity estimate; {} m/s was given", *first_velocity);
  }
  return {};
}

// The lags and disparity of leading bubble a with candidate b.
void measure(BubblePairing& p, const Crossing& a, const Crossing& b) {
  p.front_lag = b.front - a.front;
  p.rear_lag = b.rear - a.rear;
  p.centre_lag = 0.5 * (p.front_lag + p.rear_lag);
  p.disparity = std::fabs(a.chord_time() - b.chord_time()) / a.chord_time();
}

}  // namespace

PairingResult pair_bubbles(std::span<const Crossing> leading, std::span<const Crossing> trailing, double tip_distance,
                           const EventOptions& options, std::optional<double> first_velocity) {
  options.validate().throw_if_failed();
  PairingResult result;
  if (auto why = refuse_first_velocity(options, first_velocity); !why.empty()) {
    result.status = EventStatus::no_first_velocity;
    result.message = std::move(why);
    return result;
  }
  const bool kramer = options.pairing == Pairing::kramer;
  const double shen_limit = kramer ? kInfinity : tip_distance / (options.shen_lag_factor * *first_velocity);
  auto& out = result.bubbles;
  out.resize(leading.size());
  // Leading and trailing bubbles are in time order and do not overlap, so
  // their fronts and centres increase: the candidate of the next leading
  // bubble is at or after this one's (one pass over each list).
  std::size_t j = 0;
  for (std::size_t h = 0; h < leading.size(); ++h) {
    const Crossing& a = leading[h];
    BubblePairing& p = out[h];
    if (kramer) {
      while (j < trailing.size() && !(trailing[j].centre() > a.centre())) ++j;
    } else {
      while (j < trailing.size() && !(trailing[j].front > a.front)) ++j;
    }
    if (a.censored) {
      p.fate = BubbleFate::censored;
      continue;
    }
    if (j == trailing.size()) {
      p.fate = BubbleFate::no_partner;
      continue;
    }
    p.candidate = j;
    const Crossing& b = trailing[j];
    measure(p, a, b);
    if (b.censored) {
      p.fate = BubbleFate::censored;
    } else if (kramer) {
      const double to_next = h + 1 < leading.size() ? leading[h + 1].centre() - a.centre() : kInfinity;
      if (!(p.centre_lag < to_next)) p.fate = BubbleFate::beyond_next;
      else if (!(p.disparity < options.disparity_max)) p.fate = BubbleFate::disparity;
      else p.fate = BubbleFate::paired;
    } else {
      if (!(std::fabs(p.front_lag) <= shen_limit && std::fabs(p.rear_lag) <= shen_limit)) p.fate = BubbleFate::shen_lag;
      else if (!(p.centre_lag > 0.0)) p.fate = BubbleFate::non_positive_lag;
      else p.fate = BubbleFate::paired;
    }
  }
  // A candidate claimed by two bubbles that passed every rule: neither is
  // kept (header, item 4). Candidates never decrease with h, so the claims
  // on one trailing bubble are consecutive among the paired ones.
  std::size_t run_start = 0;
  std::optional<std::size_t> run_candidate;
  std::vector<std::size_t> paired;
  for (std::size_t h = 0; h < out.size(); ++h)
    if (out[h].fate == BubbleFate::paired) paired.push_back(h);
  for (std::size_t i = 0; i <= paired.size(); ++i) {
    const bool same = i < paired.size() && run_candidate && out[paired[i]].candidate == run_candidate;
    if (same) continue;
    if (i - run_start > 1) {
      for (std::size_t r = run_start; r < i; ++r) out[paired[r]].fate = BubbleFate::claimed_twice;
    }
    if (i < paired.size()) {
      run_start = i;
      run_candidate = out[paired[i]].candidate;
    }
  }
  return result;
}

namespace {

void no_velocity(EventResult& result, EventStatus status, std::string why) {
  result.status = status;
  result.message = std::move(why);
  result.quality = AwccQuality::insufficient;
  result.quality_reason = result.message;
}

// The moments, intervals, quality and chord lengths of the paired bubbles.
void summarise_events(EventResult& result, const EventOptions& options) {
  auto& bubbles = result.bubbles;
  if (options.roc) result.roc_iterations = detail::cut_outliers(bubbles, BubbleFate::paired, BubbleFate::roc);
  result.bubbles_by_fate.fill(0);
  for (const auto& b : bubbles) ++result.bubbles_by_fate[static_cast<std::size_t>(b.fate)];
  result.bubbles_paired = result.count(BubbleFate::paired);
  if (result.bubbles_paired < options.bubbles_reported) {
    no_velocity(result, EventStatus::too_few_bubbles,
                fmt::format("{} of {} complete leading bubbles paired ({} without a later trailing bubble, {} beyond "
                            "the next leading bubble, {} by chord-time disparity, {} beyond Shen's lag limit, {} "
                            "with a non-positive lag, {} claiming a trailing bubble twice, {} by the outlier cutoff; "
                            "{} censored): too few for statistics (fewer than {})",
                            result.bubbles_paired, result.bubbles_complete, result.count(BubbleFate::no_partner),
                            result.count(BubbleFate::beyond_next), result.count(BubbleFate::disparity),
                            result.count(BubbleFate::shen_lag), result.count(BubbleFate::non_positive_lag),
                            result.count(BubbleFate::claimed_twice), result.count(BubbleFate::roc),
                            result.count(BubbleFate::censored), options.bubbles_reported));
    return;
  }
  std::vector<double> values, weights, lengths;
  values.reserve(static_cast<std::size_t>(result.bubbles_paired));
  weights.reserve(values.capacity());
  lengths.reserve(values.capacity());
  for (const auto& b : bubbles) {
    if (b.fate != BubbleFate::paired) continue;
    values.push_back(b.velocity);
    weights.push_back(options.weighting == Weighting::duration ? b.weight : 1.0);
    lengths.push_back(b.chord_length);
  }
  const auto [mean, rms] = detail::weighted_moments(values, weights);
  const auto intervals = detail::moment_intervals95(mean, rms, result.bubbles_paired);
  result.status = EventStatus::ok;
  result.message.clear();
  result.velocity = mean;
  result.velocity_rms = rms;
  result.turbulence_intensity = intervals.turbulence_intensity;
  result.velocity_ci95 = intervals.mean;
  result.velocity_rms_ci95 = intervals.rms;
  result.turbulence_intensity_ci95 = intervals.tu;
  result.chord_length = summarise(std::move(lengths));
  result.sauter_diameter = 1.5 * result.chord_length.mean;
  std::tie(result.quality, result.quality_reason) =
      detail::reported_quality(result.bubbles_paired, result.bubbles_complete, options.bubbles_ok,
                               options.pairing_yield_ok, intervals,
                               {"paired bubbles", "pairing yield", "complete leading bubbles paired", "the paired bubbles"});
  // The spread rule: bubbles that all share one centre lag have no measured
  // spread. One lag, not one double: interface times at different places of
  // the record round differently (1e-13 of a lag), which is no spread.
  if (std::all_of(values.begin(), values.end(),
                  [&](double v) { return std::fabs(v - values.front()) <= 1e-9 * std::fabs(values.front()); })) {
    result.turbulence_measured = false;
    result.quality = AwccQuality::low;
    result.quality_reason = fmt::format(
        "every one of the {} paired bubbles has the same centre lag (u = {:.4g} m/s): u_rms is 0 by the interface "
        "times' resolution, not by the flow, so Tu is not measured (sample faster)",
        result.bubbles_paired, mean);
  }
}

}  // namespace

EventResult event_detection(std::span<const Crossing> leading, std::span<const Crossing> trailing, double dx,
                            const EventOptions& options, std::optional<double> first_velocity) {
  options.validate().throw_if_failed();
  EventResult result;
  result.options = options;
  result.first_velocity = first_velocity;
  result.bubbles_total = static_cast<std::int64_t>(leading.size());
  result.bubbles_complete =
      std::count_if(leading.begin(), leading.end(), [](const Crossing& c) { return !c.censored; });
  if (!(dx > 0.0) || !std::isfinite(dx)) {
    no_velocity(result, EventStatus::no_tip_separation,
                fmt::format("tip separation {} m is not positive: no per-bubble velocity can be computed", dx));
    return result;
  }
  const auto pairing = pair_bubbles(leading, trailing, dx, options, first_velocity);
  if (!pairing.ok()) {
    no_velocity(result, pairing.status, pairing.message);
    return result;
  }
  result.bubbles.resize(leading.size());
  for (std::size_t h = 0; h < leading.size(); ++h) {
    const Crossing& a = leading[h];
    const BubblePairing& p = pairing.bubbles[h];
    EventBubble& e = result.bubbles[h];
    e.leading_front = a.front;
    e.leading_rear = a.rear;
    e.fate = p.fate;
    if (!p.candidate) continue;
    const Crossing& b = trailing[*p.candidate];
    e.trailing_front = b.front;
    e.trailing_rear = b.rear;
    e.front_lag = p.front_lag;
    e.rear_lag = p.rear_lag;
    e.centre_lag = p.centre_lag;
    e.disparity = p.disparity;
    e.weight = std::max(a.rear, b.rear) - std::min(a.front, b.front);
    if (p.centre_lag > 0.0) {
      e.velocity = dx / p.centre_lag;
      e.chord_length = a.chord_time() * e.velocity;
    }
  }
  if (result.bubbles_complete == 0) {
    // Fates are still counted: every leading bubble is censored.
    result.bubbles_by_fate.fill(0);
    for (const auto& b : result.bubbles) ++result.bubbles_by_fate[static_cast<std::size_t>(b.fate)];
    no_velocity(result, EventStatus::no_bubbles,
                fmt::format("no complete bubble at the leading tip ({} touching a record end): no pair can be formed",
                            result.bubbles_total));
    return result;
  }
  summarise_events(result, options);
  return result;
}

EventResult event_detection(const AirIntervals& leading, const AirIntervals& trailing, double dx,
                            const EventOptions& options, std::optional<double> first_velocity) {
  if (leading.sample_count != trailing.sample_count || leading.fs != trailing.fs) {
    throw std::invalid_argument(fmt::format(
        "event detection needs two signals of the same length and sampling rate: the leading tip has {} samples at "
        "{} Hz, the trailing tip {} at {} Hz",
        leading.sample_count, leading.fs, trailing.sample_count, trailing.fs));
  }
  const auto a = crossings(leading);
  const auto b = crossings(trailing);
  return event_detection(a, b, dx, options, first_velocity);
}

}  // namespace awcc
