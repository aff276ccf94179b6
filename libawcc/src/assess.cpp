#include "awcc/assess.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <string>

namespace awcc {

double correlation_peak_velocity(double mean, double turbulence_intensity) {
  return mean * (1.0 + std::sqrt(1.0 + 8.0 * turbulence_intensity * turbulence_intensity)) / 2.0;
}

namespace {

// The 95 % half-width of estimate - reference: the half-widths of the two
// intervals on the sides that face each other, added in quadrature.
double allowed_difference(double estimate, const Interval95& estimate_ci, double reference,
                          const Interval95& reference_ci) {
  const bool below = estimate < reference;
  const double h_reference = below ? reference - reference_ci.lower : reference_ci.upper - reference;
  const double h_estimate = below ? estimate_ci.upper - estimate : estimate - estimate_ci.lower;
  return std::hypot(h_reference, h_estimate);
}

}  // namespace

std::optional<MethodsComparison> compare_methods(const FsccResult& fscc, const AwccResult& awcc) {
  if (!fscc.ok() || !fscc.velocity_ci95 || !awcc.ok()) return std::nullopt;
  MethodsComparison c;
  c.fscc = fscc.velocity;
  c.awcc = awcc.velocity;
  c.fscc_ci95 = *fscc.velocity_ci95;
  c.awcc_ci95 = awcc.velocity_ci95;
  c.difference = c.awcc - c.fscc;
  c.allowed = allowed_difference(c.awcc, c.awcc_ci95, c.fscc, c.fscc_ci95);
  c.relative = std::abs(c.difference) / c.fscc;
  return c;
}

namespace {

std::optional<EventsComparison> against_reference(double velocity, const Interval95& velocity_ci95,
                                                  double turbulence_intensity, const ProcessResult& r) {
  EventsComparison c;
  c.tolerance = peak_model_tolerance;
  c.events = velocity;
  c.events_ci95 = velocity_ci95;
  if (r.fscc && r.fscc->ok() && r.fscc->velocity_ci95) {
    c.reference = "FSCC";
    c.reference_velocity = r.fscc->velocity;
    c.reference_ci95 = *r.fscc->velocity_ci95;
    const double tu = std::clamp(turbulence_intensity, 0.0, peak_model_tu_max);
    c.band_lower = c.reference_velocity / correlation_peak_velocity(1.0, tu);
  } else if (r.awcc && r.awcc->ok() && r.awcc->quality == AwccQuality::ok) {
    c.reference = "AWCC";
    c.reference_velocity = r.awcc->velocity;
    c.reference_ci95 = r.awcc->velocity_ci95;
    c.band_lower = c.reference_velocity;
  } else {
    return std::nullopt;
  }
  c.band_upper = c.reference_velocity;
  // The reference's interval carried to the band's end the mean faces.
  const bool below = velocity < c.band_lower;
  const double end = below ? c.band_lower : c.band_upper;
  const double scale = end / c.reference_velocity;
  const Interval95 end_ci{c.reference_ci95.lower * scale, c.reference_ci95.upper * scale};
  c.difference = below ? velocity - c.band_lower : (velocity > c.band_upper ? velocity - c.band_upper : 0.0);
  c.allowed = c.difference == 0.0 ? 0.0 : allowed_difference(velocity, velocity_ci95, end, end_ci);
  c.relative = std::abs(c.difference) / c.reference_velocity;
  return c;
}

}  // namespace

std::optional<EventsComparison> compare_events(const EventResult& events, const ProcessResult& r) {
  if (!events.ok()) return std::nullopt;
  return against_reference(events.velocity, events.velocity_ci95, events.turbulence_intensity, r);
}

std::optional<EventsComparison> compare_multi_tip(const MultiTipResult& vectors, const ProcessResult& r) {
  if (!vectors.ok()) return std::nullopt;
  return against_reference(vectors.velocity[0], vectors.velocity_ci95[0], vectors.turbulence_intensity[0], r);
}

// Event detection's velocity against FSCC's (else AWCC's of quality ok), by
// the rule FSCC and AWCC are compared by (awcc/assess.hpp): differing by more
// than their 95 % intervals allow together, event detection's quality is at
// most low and says why. Its Kramer pairing takes unrelated later bubbles as
// partners where bubbles are sparse or the tips offset, inside the outlier
// band (event_detection.hpp): the comparison is what catches that.
void judge_events(EventResult& e, const ProcessResult& out) {
  if (!e.ok()) return;
  // The resolution rule: paired bubbles whose centre lags spread less than
  // least_crossing_spread of a sample (sd) have no spread the interface
  // times resolve. Interpolated crossings of edges that carry little time
  // (libsynth's voltages at 20 kHz, lags of 5 samples: Tu 0.002 for a true
  // 0.05) pass the one-lag rule with such a spread; whole-sample lags that
  // are not all one have a spread of 0.2 sample or more.
  if (e.turbulence_measured && out.info.fs > 0.0) {
    std::vector<double> lags;
    for (const auto& b : e.bubbles)
      if (b.fate == BubbleFate::paired) lags.push_back(b.centre_lag * out.info.fs);
    if (lags.size() >= 2) {
      double mean = 0.0;
      for (double l : lags) mean += l;
      mean /= static_cast<double>(lags.size());
      double ss = 0.0;
      for (double l : lags) ss += (l - mean) * (l - mean);
      const double sd = std::sqrt(ss / static_cast<double>(lags.size() - 1));
      if (sd < least_crossing_spread) {
        e.turbulence_measured = false;
        if (e.quality == AwccQuality::ok) e.quality = AwccQuality::low;
        const std::string why = fmt::format(
            "the {} paired bubbles' centre lags spread by {:.3f} of a sample (sd), less than the {} the interface "
            "times resolve: Tu is not measured (sample faster)",
            lags.size(), sd, least_crossing_spread);
        e.quality_reason = e.quality_reason.empty() ? why : e.quality_reason + "; " + why;
      }
    }
  }
  const auto c = compare_events(e, out);
  if (!c || !c->disagree()) return;
  if (e.quality == AwccQuality::ok) e.quality = AwccQuality::low;
  const std::string why = fmt::format("its velocity differs from {}'s by {:.0f} %, more than their sampling intervals "
                                      "allow: its pairing is biased here",
                                      c->reference, 100.0 * c->relative);
  e.quality_reason = e.quality_reason.empty() ? why : e.quality_reason + "; " + why;
}


void judge_probe(ProbeResult& probe, const ProcessResult& out, const EventOptions& pairing) {
  const MultiTipResult& v = probe.vectors;
  if (!v.ok()) {
    probe.quality = AwccQuality::insufficient;
    probe.quality_reason = v.message;
    return;
  }
  std::vector<std::string> why;
  // A leading tip's signal that arrives after a trailing tip's is a channel
  // mapped to the wrong tip: the vectors are then of a different probe.
  auto order = [&](const std::optional<FsccResult>& f, std::size_t tip, double dx) {
    if (!f || (f->status != FsccStatus::tips_swapped && f->status != FsccStatus::non_positive_lag)) return;
    why.push_back(fmt::format("FSCC of the leading tip (channel {}) with tip {} (channel {}, {:.3g} mm downstream) "
                              "finds {}: is the channel of one of them swapped with another tip's? (tip-channels)",
                              probe.channels[0], tip, probe.channels[tip], dx * 1e3,
                              f->status == FsccStatus::tips_swapped ? "the trailing tip's signal first"
                                                                    : "no delay between them"));
  };
  order(out.fscc, 1, out.dx);
  for (const auto& pair : probe.pairs) order(pair.fscc, pair.tip, pair.dx);
  if (!v.caution.empty()) why.push_back(v.caution);
  // Two of the probe's tips holding one signal twice: no vector rests on them.
  for (const auto& c : out.channel_copies) {
    const auto in_probe = [&](int channel) {
      return std::find(probe.channels.begin(), probe.channels.end(), channel) != probe.channels.end();
    };
    if (in_probe(c.first) && in_probe(c.second)) {
      why.push_back(fmt::format("channels {} and {} hold {} signal (flag channels_copied): the vectors solved with "
                                "both are not a probe's",
                                c.first, c.second, c.identical ? "the same" : "nearly the same"));
    }
  }
  if (v.turbulence_intensity[0] > multi_tip_tu_truncated) {
    why.push_back(fmt::format("Tu_x = {:.2f}: the pairing accepts speeds {:g}-{:g} times FSCC's and directions within "
                              "{:g} degrees of x, which cut the tails of a flow this turbulent: u_x and Tu_x are "
                              "biased (on the synthetic validation at a true Tu_x of 0.3, u_x 4-11 % high and Tu_x "
                              "16-26 % low; a real flow's u_x may be biased either way)",
                              v.turbulence_intensity[0], pairing.probe_speed_min, pairing.probe_speed_max,
                              pairing.probe_angle_max));
  }
  if (const auto c = compare_multi_tip(v, out); c && c->disagree()) {
    why.push_back(fmt::format("its streamwise component {:.3f} m/s ({:.3f}-{:.3f}, Tu_x {:.2f}) lies {:.0f} % {} the "
                              "band {}'s velocity of the tip pair, {:.3f} m/s ({:.3f}-{:.3f}), allows ({:.3f}-{:.3f}): "
                              "more than their sampling intervals and {:.0f} % allow",
                              c->events, c->events_ci95.lower, c->events_ci95.upper, v.turbulence_intensity[0],
                              100.0 * c->relative, c->difference < 0.0 ? "below" : "above", c->reference,
                              c->reference_velocity, c->reference_ci95.lower, c->reference_ci95.upper, c->band_lower,
                              c->band_upper, 100.0 * c->tolerance));
  }
  probe.quality = why.empty() ? AwccQuality::ok : AwccQuality::low;
  for (const auto& w : why) probe.quality_reason += (probe.quality_reason.empty() ? "" : "; ") + w;
}

namespace {

// "channel 2", "channels 2 and 3", "channels 2, 3 and 4", with the names a column file gives.
std::string channel_list(const std::vector<int>& channels, const std::vector<std::string>& names) {
  constexpr std::size_t shown = 8;
  std::string out = channels.size() == 1 ? "channel " : "channels ";
  for (std::size_t i = 0; i < channels.size() && i < shown; ++i) {
    const auto c = static_cast<std::size_t>(channels[i]);
    if (i > 0) out += i + 1 == channels.size() ? " and " : ", ";
    out += std::to_string(channels[i]);
    if (c < names.size() && !names[c].empty()) out += fmt::format(" ('{}')", names[c]);
  }
  if (channels.size() > shown) out += fmt::format(" and {} more", channels.size() - shown);
  return out;
}

std::optional<Warning> channels_ignored(const ProcessResult& r) {
  std::vector<int> ignored;
  for (int c = 0; c < r.info.channels; ++c) {
    const bool tip = std::any_of(r.tips.begin(), r.tips.end(), [c](const TipResult& t) { return t.channel == c; });
    const bool probe_tip = r.probe && std::find(r.probe->channels.begin(), r.probe->channels.end(), c) !=
                                          r.probe->channels.end();
    if (!tip && !probe_tip) ignored.push_back(c);
  }
  if (ignored.empty() || r.tips.size() < 2) return std::nullopt;
  return Warning{Flag::channels_ignored,
                 fmt::format("{} of {} {} not processed (a {}-tip probe?): the tip pair alone was processed, "
                             "channels {} and {}; to process every tip as a probe of four or more, declare their "
                             "positions (tips, tip-channels)",
                             channel_list(ignored, r.info.channel_names), r.info.channels,
                             ignored.size() == 1 ? "is" : "are", r.info.channels, r.tips[0].channel, r.tips[1].channel)};
}

std::optional<Warning> methods_disagree(const ProcessResult& r) {
  if (!r.fscc || !r.awcc) return std::nullopt;
  const auto c = compare_methods(*r.fscc, *r.awcc);
  if (!c || !c->disagree()) return std::nullopt;
  const auto& a = *r.awcc;
  std::string text = fmt::format(
      "AWCC's velocity {:.3f} m/s (95 % sampling interval {:.3f}-{:.3f}) and FSCC's {:.3f} m/s ({:.3f}-{:.3f}) differ "
      "by {:.3f} m/s (AWCC {:.0f} % {} FSCC), more than their sampling intervals allow together ({:.3f} m/s): one "
      "method is biased here, which neither interval covers.",
      c->awcc, c->awcc_ci95.lower, c->awcc_ci95.upper, c->fscc, c->fscc_ci95.lower, c->fscc_ci95.upper,
      std::abs(c->difference), 100.0 * c->relative, c->difference < 0.0 ? "below" : "above", c->allowed);
  if (a.quality != AwccQuality::ok) {
    // Few windows: where they peak, against FSCC, shows the selection.
    double lag_min = 0.0, lag_max = 0.0;
    bool any = false;
    for (const auto& w : a.windows) {
      if (w.fate != WindowFate::accepted) continue;
      lag_min = any ? std::min(lag_min, w.lag) : w.lag;
      lag_max = any ? std::max(lag_max, w.lag) : w.lag;
      any = true;
    }
    if (any) {
      text += fmt::format(" AWCC's {} accepted windows peak at lags {:.2f}-{:.2f} ms, FSCC's whole record at {:.2f} ms.",
                          a.windows_accepted, lag_min * 1e3, lag_max * 1e3, r.fscc->lag * 1e3);
    }
    text += fmt::format(" AWCC rests on {} accepted windows of {} (quality {}): so few windows passing its filter can "
                        "be a biased selection of the bubbles",
                        a.windows_accepted, a.windows_total, to_string(a.quality));
    text += r.velocity_source() == VelocitySource::fscc ? ", and chord lengths and d32 use FSCC's velocity." : ".";
  } else {
    text += " Both rest on enough data: the bias correction estimates AWCC's bias; look at FSCC's correlation "
            "functions and AWCC's window table for the cause.";
  }
  return Warning{Flag::methods_disagree, std::move(text)};
}

std::optional<Warning> events_disagree(const ProcessResult& r) {
  if (!r.events) return std::nullopt;
  const auto c = compare_events(*r.events, r);
  if (!c || !c->disagree()) return std::nullopt;
  const auto& e = *r.events;
  return Warning{
      Flag::events_disagree,
      fmt::format("event detection's velocity {:.3f} m/s (95 % sampling interval {:.3f}-{:.3f}, {} paired bubbles of "
                  "{}; Tu {:.2f}) lies {:.0f} % of {}'s {:.3f} m/s ({:.3f}-{:.3f}) {} the band its peak allows "
                  "({:.3f}-{:.3f}), more than their sampling intervals allow together ({:.3f} m/s) and {:.0f} %: the "
                  "pairing ({}) is biased here (partners taken from later, unrelated bubbles where bubbles are sparse "
                  "or the tips offset); use {}'s velocity, and event detection's per-bubble table only to see the "
                  "pairing's fates",
                  e.velocity, e.velocity_ci95.lower, e.velocity_ci95.upper, e.bubbles_paired, e.bubbles_complete,
                  e.turbulence_intensity, 100.0 * c->relative, c->reference, c->reference_velocity,
                  c->reference_ci95.lower, c->reference_ci95.upper, c->difference < 0.0 ? "below" : "above",
                  c->band_lower, c->band_upper, c->allowed, 100.0 * c->tolerance,
                  to_string(e.options.pairing), c->reference)};
}

std::optional<Warning> multi_tip_doubtful(const ProcessResult& r) {
  if (!r.probe || r.probe->quality != AwccQuality::low) return std::nullopt;
  const auto& v = r.probe->vectors;
  return Warning{Flag::multi_tip_doubtful,
                 fmt::format("the multi-tip mean vector ({:.3f}, {:.3f}, {:.3f}) m/s from {} of {} leading bubbles is "
                             "doubtful: {}; use FSCC's or AWCC's velocity of the tip pairs, and the bubble table only "
                             "to see the fates",
                             v.velocity[0], v.velocity[1], v.velocity[2], v.bubbles_accepted, v.bubbles_complete,
                             r.probe->quality_reason)};
}

// METHOD 7 (d): the weighting gap above what arrivals in time allow.
std::optional<Warning> arrivals_along_flow(const ProcessResult& r) {
  if (!r.awcc || !r.awcc->ok() || !r.awcc->weighting_gap || !r.awcc->weighting_gap->along_flow) return std::nullopt;
  const auto& g = *r.awcc->weighting_gap;
  return Warning{Flag::arrivals_along_flow,
                 fmt::format("AWCC's weighting gap g = u_unweighted / u_weighted - 1 = {:.4f} (95 % {:.4f} to {:.4f}) "
                             "lies above the {:.4f} ({:g} Tu^2) that bubbles arriving in time allow: the bubbles look "
                             "spaced along the flow, a rule the bias correction was not trained on (its prior is "
                             "arrivals in time), so a corrected value of this row may be biased beyond its interval",
                             g.value, g.ci95.lower, g.ci95.upper, g.allowance, time_arrival_gap_allowance)};
}

// AWCC's edge rule (awcc/awcc.hpp, lag_range_end_share): any accepted
// window at an end of the velocity range's lags, with its count.
std::optional<Warning> lag_range_end(const ProcessResult& r) {
  if (!r.awcc || !r.awcc->ok()) return std::nullopt;
  const auto& a = *r.awcc;
  const std::int64_t at_ends = a.windows_at_least_lag + a.windows_at_greatest_lag;
  if (at_ends == 0) return std::nullopt;
  return Warning{Flag::lag_range_end,
                 fmt::format("{} of {} accepted AWCC windows peak at an end of the lags the velocity range {}-{} m/s "
                             "lets AWCC search ({} at the least lag, {} at the greatest): their peaks may lie beyond "
                             "it{}; widen the velocity range (velocity-range) or drop it",
                             at_ends, a.windows_accepted, a.options.velocity_min.value_or(0.0),
                             a.options.velocity_max.value_or(0.0), a.windows_at_least_lag, a.windows_at_greatest_lag,
                             lags_pile_up_at_range_end(a) ? ", and so many pile up there that the mean and Tu are "
                                                            "truncated (quality low; not corrected)"
                                                          : "")};
}

// AWCC's spread rule (AwccResult::turbulence_measured).
std::optional<Warning> tu_not_measured(const ProcessResult& r) {
  if (!r.awcc || !r.awcc->ok() || r.awcc->turbulence_measured) return std::nullopt;
  const auto& a = *r.awcc;
  return Warning{Flag::tu_not_measured,
                 fmt::format("every one of the {} accepted AWCC windows peaks at the same lag: u_rms is 0 by the lag's "
                             "resolution, so Tu is not measured and not given, and the velocity is bounded "
                             "({:.4g}-{:.4g} m/s); refine the peak (subsample), sample faster or widen the velocity "
                             "range",
                             a.windows_accepted, a.velocity_ci95.lower, a.velocity_ci95.upper)};
}

// Two tips holding one signal twice (process.hpp, copied_channel_correlation).
std::vector<Warning> channels_copied(const ProcessResult& r) {
  std::vector<Warning> out;
  for (const auto& c : r.channel_copies) {
    out.push_back({Flag::channels_copied,
                   fmt::format("channel {} ({}) {} channel {} ({}) (r = {:.6f} at lag 0, above {:g}): one channel "
                               "copied or cross-talk, not two tips; the delay between them, the velocities and "
                               "vectors that rest on both are not measurements (check the acquisition's channels)",
                               c.second, c.second_tip,
                               c.identical ? "holds the same signal as" : "holds nearly the same signal as", c.first,
                               c.first_tip, c.correlation, copied_channel_correlation)});
  }
  return out;
}

// One chord of a phase far longer than the tip's chords allow (assess.hpp,
// single_phase_stretch_factor).
std::optional<std::string> single_phase_stretch(const Summary& chords, std::string_view phase) {
  if (chords.count < single_phase_stretch_chords_min || !(chords.mean > 0.0)) return std::nullopt;
  const double chance = chords.mean * std::log(static_cast<double>(chords.count));
  if (!(chords.max > single_phase_stretch_factor * chance)) return std::nullopt;
  return fmt::format("one {} chord lasts {:.3f} s, {:.0f} times what its {} {} chords (mean {:.3g} ms) reach by "
                     "chance (their mean times the log of their count; above {:g} times is no flow)",
                     phase, chords.max, chords.max / chance, chords.count, phase, 1e3 * chords.mean,
                     single_phase_stretch_factor);
}

std::vector<Warning> long_single_phase(const ProcessResult& r) {
  std::vector<Warning> out;
  for (std::size_t i = 0; i < r.tips.size(); ++i) {
    const auto& phase = r.tips[i].phase;
    std::vector<std::string> parts;
    if (auto t = single_phase_stretch(phase.air_chord_time, "air")) parts.push_back(std::move(*t));
    if (auto t = single_phase_stretch(phase.water_chord_time, "water")) parts.push_back(std::move(*t));
    if (parts.empty()) continue;
    out.push_back({Flag::long_single_phase,
                   fmt::format("channel {} ({}): {}: the probe out of the flow, a stopped flow or a lost connection "
                               "for that long? c, F and the velocities include that stretch; cut the record to the "
                               "part that measured the flow",
                               r.tips[i].channel, i == 0 ? "leading tip" : "trailing tip", fmt::join(parts, "; "))});
  }
  return out;
}

}  // namespace

std::vector<Warning> assess(const ProcessResult& r) {
  std::vector<Warning> out;
  for (const auto& w : r.info.warnings) out.push_back({Flag::reader_note, w});
  for (std::size_t i = 0; i < r.tips.size(); ++i) {
    auto text = signal_warning(r.tips[i].signal, r.tips[i].channel, i == 0 ? "leading tip" : "trailing tip");
    if (!text.empty()) out.push_back({Flag::signal_check, std::move(text)});
  }
  // A probe's further tips: their checks too (a dead tip processed with
  // allow-bad-signal is in every output, as the pair's).
  for (std::size_t k = 0; r.probe && k < r.probe->further_tips.size(); ++k) {
    const auto& tip = r.probe->further_tips[k];
    auto text = signal_warning(tip.signal, tip.channel, fmt::format("tip {}", k + 2));
    if (!text.empty()) out.push_back({Flag::signal_check, std::move(text)});
  }
  if (auto w = channels_ignored(r)) out.push_back(std::move(*w));
  if (r.fscc) {
    for (const auto& w : r.fscc->warnings) out.push_back({Flag::fscc_implausible, w});
  }
  if (r.spectrum && !r.spectrum->warning.empty()) {
    out.push_back({r.spectrum->integral_time_scale ? Flag::integral_scale_short : Flag::integral_scale_undefined,
                   r.spectrum->warning});
  }
  if (auto w = methods_disagree(r)) out.push_back(std::move(*w));
  if (auto w = events_disagree(r)) out.push_back(std::move(*w));
  if (auto w = multi_tip_doubtful(r)) out.push_back(std::move(*w));
  if (auto w = arrivals_along_flow(r)) out.push_back(std::move(*w));
  if (auto w = lag_range_end(r)) out.push_back(std::move(*w));
  if (auto w = tu_not_measured(r)) out.push_back(std::move(*w));
  for (auto& w : channels_copied(r)) out.push_back(std::move(w));
  for (auto& w : long_single_phase(r)) out.push_back(std::move(w));
  return out;
}

}  // namespace awcc
