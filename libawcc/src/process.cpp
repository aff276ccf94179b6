#include "awcc/process.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include "awcc/assess.hpp"
#include "awcc/detail/awcc_driver.hpp"
#include "awcc/detail/awcc_steps.hpp"
#include "awcc/detail/read_ahead.hpp"
#include "awcc/detail/two_level_scan.hpp"
#include "awcc/errors.hpp"
#include "awcc/units.hpp"

namespace awcc {

Validation ProcessOptions::validate() const {
  if (leading_channel < 0) return Validation::invalid("leading-channel", "channel indices must be >= 0");
  if (trailing_channel < 0) return Validation::invalid("trailing-channel", "channel indices must be >= 0");
  if (leading_channel == trailing_channel) {
    return Validation::invalid(
        "leading-channel,trailing-channel",
        fmt::format("the leading and trailing tips are both channel {}; choose two channels", leading_channel));
  }
  const std::vector<int> channels = tip_channels();
  for (std::size_t k = 2; k < channels.size(); ++k) {
    if (channels[k] < 0) return Validation::invalid("tip-channels", "channel indices must be >= 0");
    for (std::size_t j = 0; j < k; ++j) {
      if (channels[j] == channels[k]) {
        return Validation::invalid("tip-channels",
                                   fmt::format("tips {} and {} are both channel {}; give each tip its own channel", j,
                                               k, channels[k]));
      }
    }
  }
  if (!(dx >= 0.0 && std::isfinite(dx))) return Validation::invalid("dx", fmt::format("dx = {} m must be >= 0", dx));
  if (const auto tips = probe.validate(); !tips.ok()) return tips;
  if (probe.declared() && (dx != 0.0 || dy != 0.0)) {
    return Validation::invalid("dx,tips", "dx (or dy) and tips both declare the probe's geometry: give the tips "
                                          "alone (the pair's separation follows from them)");
  }
  if (probe.declared() && (leading_channel != 0 || trailing_channel != 1)) {
    return Validation::invalid("leading-channel,trailing-channel",
                               "with tips declared, tip-channels maps each tip to its channel and leading-tip names "
                               "the leading one: give those instead of the pair's channels");
  }
  for (const auto& part : {binarisation.validate(), signal_check.validate(), fscc_options.validate(),
                           awcc_options.validate(), structure.validate(), spectrum.validate(),
                           event_options.validate(), multi_tip_options.validate(), size_options.validate()}) {
    if (!part.ok()) return part;
  }
  if (block_frames < 1) return Validation::invalid("", "block_frames must be >= 1");
  if (!allow_unusual) return implausible();
  return {};
}

std::vector<int> ProcessOptions::tip_channels() const {
  std::vector<int> out{leading_channel, trailing_channel};
  out.insert(out.end(), further_channels.begin(), further_channels.end());
  return out;
}

EventOptions ProcessOptions::effective_event_options() const {
  EventOptions out = event_options;
  out.roc = awcc_options.roc;
  out.weighting = awcc_options.weighting;
  return out;
}

namespace {

// The tip pair's options and the positions of the tips processed, in
// processing order (leading, trailing, further tips): tip_pair_options()
// and binarise_recording() read them from here.
struct ResolvedTips {
  ProcessOptions options;
  std::vector<Vec3> positions;
};

bool wants_multi_tip(MultiTipChoice choice, std::size_t tips) {
  return choice == MultiTipChoice::on || (choice == MultiTipChoice::automatic && tips >= 4);
}

ResolvedTips resolve_tips(const ProcessOptions& options, const RecordingInfo& info) {
  const ProbeTips probe = probe_of(options.probe, info);
  ResolvedTips resolved{options, {}};
  ProcessOptions& out = resolved.options;
  out.probe = {};
  const std::string file = info.path.string();
  const bool resolved_before = !options.further_channels.empty();
  if (!probe.declared()) {
    if (options.multi_tip == MultiTipChoice::on && !resolved_before) {
      throw InputError(fmt::format("{}: multi-tip processing needs the probe's tip positions, which neither the options "
                                   "nor the file give: declare them (tips, or a [probe] table), or choose another "
                                   "method",
                                   file),
                       "tips");
    }
    return resolved;
  }
  const bool declared = options.probe.declared();
  // The pair's positions: a declared probe's by tip, a file's by channel.
  std::size_t a = 0, b = 0;
  if (declared) {
    a = b = static_cast<std::size_t>(probe.leading);
    for (std::size_t k = 0; k < probe.positions.size() && b == a; ++k) {
      if (k != a && probe.positions[k][0] > probe.positions[a][0]) b = k;
    }
    if (b == a) {
      throw InputError(fmt::format("{}: no declared tip lies downstream of the leading tip {} (none has a larger x): "
                                   "the tip pair needs one; check the order of the coordinates x,y,z, or name the "
                                   "leading tip",
                                   file, a),
                       "leading-tip");
    }
    out.leading_channel = probe.channel_of(a);
    out.trailing_channel = probe.channel_of(b);
  } else {
    if (options.leading_channel >= info.channels || options.trailing_channel >= info.channels) {
      return resolved;  // binarise_recording() names the channel
    }
    a = static_cast<std::size_t>(options.leading_channel);
    b = static_cast<std::size_t>(options.trailing_channel);
  }
  const auto& p = probe.positions;
  resolved.positions = {p[a], p[b]};
  if (wants_multi_tip(options.multi_tip, p.size())) {
    if (p.size() < 4) {
      throw InputError(fmt::format("{}: multi-tip processing needs a leading tip and at least three trailing tips, "
                                   "but the probe {} {} tips: declare every tip, or choose another method",
                                   file, declared ? "is declared with" : "stated by the file has", p.size()),
                       "method");
    }
    if (!resolved_before) {
      for (std::size_t k = 0; k < p.size(); ++k) {
        if (k != a && k != b) out.further_channels.push_back(probe.channel_of(k));
      }
    }
    // The further tips' positions, in the order of their channels.
    for (int c : out.further_channels) {
      for (std::size_t k = 0; k < p.size(); ++k) {
        if (k != a && k != b && probe.channel_of(k) == c) resolved.positions.push_back(p[k]);
      }
    }
    if (resolved.positions.size() != 2 + out.further_channels.size()) resolved.positions.clear();
  }
  const double along = p[b][0] - p[a][0], across = std::hypot(p[b][1] - p[a][1], p[b][2] - p[a][2]);
  if (declared) {
    out.dx = along;
    out.dy = across;
    return resolved;
  }
  const auto stated = [&](const char* name, double given, double file_value) {
    if (given == 0.0) return file_value;
    if (std::fabs(given - file_value) <= separation_tolerance) return given;
    throw InputError(fmt::format("{}: {} = {} is given, but the file states the tips of channels {} and {} {} apart: "
                                 "one of them is wrong; correct {}, or leave it out to use the file's",
                                 file, name, format_quantity(given, Dimension::length), a, b,
                                 format_quantity(file_value, Dimension::length), name),
                     name);
  };
  out.dx = stated("dx", options.dx, along);
  out.dy = stated("dy", options.dy, across);
  if (!(out.dx > 0.0)) {
    throw InputError(fmt::format("{}: the file states the tip of channel {} at x = {} and that of channel {} at x = "
                                 "{}: the trailing tip is not downstream; choose leading-channel and "
                                 "trailing-channel",
                                 file, a, format_quantity(p[a][0], Dimension::length), b,
                                 format_quantity(p[b][0], Dimension::length)),
                     "leading-channel,trailing-channel");
  }
  return resolved;
}

}  // namespace

ProcessOptions tip_pair_options(const ProcessOptions& options, const RecordingInfo& info) {
  return resolve_tips(options, info).options;
}

Validation ProcessOptions::implausible() const {
  // The fix is the unit of the value named, or allow-unusual when it is right.
  if (dx != 0.0 && (dx < 0.1e-3 || dx > 100e-3)) {
    return Validation::implausible(
        "allow-unusual",
        fmt::format("dx = {} lies outside 0.1 mm to 100 mm, the tip separations of phase-detection probes: check "
                    "its unit, or allow unusual values",
                    format_quantity(dx, Dimension::length)));
  }
  if (reader.fs > 0.0 && (reader.fs < plausible_fs_min || reader.fs > plausible_fs_max)) {
    return Validation::implausible(
        "allow-unusual",
        fmt::format("fs = {} lies outside 1 kHz to 100 MHz, the sampling rates of probe recordings: check its unit, "
                    "or allow unusual values",
                    format_quantity(reader.fs, Dimension::frequency)));
  }
  const auto& a = awcc_options;
  for (const auto& v : {a.velocity_min, a.velocity_max}) {
    if (v && (*v < 0.01 || *v > 200.0)) {
      return Validation::implausible(
          "allow-unusual",
          fmt::format("the velocity range end {} lies outside 0.01 m/s to 200 m/s, the velocities of air-water "
                      "flows: check its unit, or allow unusual values",
                      format_quantity(*v, Dimension::velocity)));
    }
  }
  return {};
}

namespace {

// The tips' channels among `stride` interleaved ones, the leading tip first.
struct ChannelSelection {
  std::size_t stride;
  std::vector<std::size_t> tips;
};

// What binarisation gives for one tip.
struct TipSignal {
  Threshold threshold;
  AirIntervals signal;
  std::optional<VoltageHistogram> histogram;
};

// The threshold options of tip k: every tip but the leading one is a trailing tip.
BinarisationOptions tip_options(const BinarisationOptions& bopt, std::size_t k) {
  return k == 0 ? bopt : bopt.for_trailing_tip();
}

// Blocks of a recording in order, read one ahead on a second thread where the
// options allow it and a second core exists (same blocks either way).
// Whether a second thread can run beside this one without waiting for it.
bool two_cores() {
  static const bool two = std::thread::hardware_concurrency() >= 2;
  return two;
}

template <class Sample>
detail::ReadAhead<Sample> blocks(Recording& recording, const ProcessOptions& options, const ChannelSelection& ch) {
  typename detail::ReadAhead<Sample>::ReadFn read;
  if constexpr (std::is_same_v<Sample, float>) {
    read = [&recording](std::span<float> out, std::int64_t n) { return recording.read(out, n); };
  } else {
    read = [&recording](std::span<std::int16_t> out, std::int64_t n) { return recording.read_int16(out, n); };
  }
  // A byte budget per block as well as a frame count: a file of thousands of
  // channels must not allocate gigabytes before any data is read.
  constexpr std::size_t block_budget = std::size_t{4} << 20;
  const auto frames = std::clamp<std::int64_t>(
      static_cast<std::int64_t>(block_budget / (ch.stride * sizeof(Sample))), 1, options.block_frames);
  return detail::ReadAhead<Sample>(std::move(read), frames, ch.stride, options.read_ahead && two_cores());
}

// Two passes over floating (or non-16-bit) samples: histograms, then thresholds.
std::vector<TipSignal> binarise_two_pass(Recording& recording, const ProcessOptions& options,
                                         const BinarisationOptions& bopt, const ChannelSelection& ch) {
  const auto& path = recording.info().path;
  const std::size_t tips = ch.tips.size();
  std::vector<VoltageHistogram> histograms(tips, VoltageHistogram(recording.info().quantum));
  std::int64_t frames = 0;
  {
    auto reader = blocks<float>(recording, options, ch);
    for (auto used = reader.next(); !used.empty(); used = reader.next()) {
      for (std::size_t k = 0; k < tips; ++k) histograms[k].add(used, ch.tips[k], ch.stride);
      frames += static_cast<std::int64_t>(used.size() / ch.stride);
    }
  }
  if (frames == 0) throw InputError(fmt::format("{}: the recording holds no samples", path.string()));
  std::vector<TipSignal> out(tips);
  std::vector<Binariser> binarisers;
  binarisers.reserve(tips);
  for (std::size_t k = 0; k < tips; ++k) {
    out[k].threshold = choose_threshold(histograms[k], tip_options(bopt, k));
    out[k].histogram = std::move(histograms[k]);
    binarisers.emplace_back(out[k].threshold, recording.info().fs);
  }
  recording.rewind();
  {
    auto reader = blocks<float>(recording, options, ch);
    for (auto used = reader.next(); !used.empty(); used = reader.next()) {
      for (std::size_t k = 0; k < tips; ++k) binarisers[k].feed(used, ch.tips[k], ch.stride);
    }
  }
  for (std::size_t k = 0; k < tips; ++k) out[k].signal = binarisers[k].finish();
  if (out[0].signal.sample_count != frames) {
    throw InputError(fmt::format("{}: the second reading gave {} frames instead of {}; the file changed while "
                                         "being read",
                                         path.string(), out[0].signal.sample_count, frames));
  }
  return out;
}

// One pass over 16-bit samples. The thresholds depend on the histogram of the
// whole record, which is known only at its end, so the pass keeps what any
// threshold inside a band [lo, hi] needs: runs of samples below the band, runs
// above it, and the few samples inside it (interfaces, noise) with their
// values. If the final thresholds fall outside the band, a
// second pass binarises exactly. Histograms are per count, two copies
// alternating so that runs of equal counts do not serialise on one counter.
// The band comes from the first block's thresholds (see band_from).
class BandRecorder {
 public:
  BandRecorder(std::int16_t lo, std::int16_t hi) : lo_(lo), hi_(hi), h0_(65536, 0), h1_(65536, 0) {}

  void feed(const std::int16_t* data, std::size_t frames, std::size_t stride, std::size_t channel) {
    std::uint32_t* h0 = h0_.data();
    std::uint32_t* h1 = h1_.data();
    std::uint8_t previous = previous_;
    std::int64_t index = position_;
    const std::int16_t lo = lo_, hi = hi_;
    std::size_t i = 0;
    for (; i + 1 < frames; i += 2) {
      const std::int16_t a = data[i * stride + channel];
      const std::int16_t b = data[(i + 1) * stride + channel];
      ++h0[static_cast<std::uint16_t>(a)];
      ++h1[static_cast<std::uint16_t>(b)];
      const std::uint8_t ka = a < lo ? 0 : (a > hi ? 1 : 2);
      const std::uint8_t kb = b < lo ? 0 : (b > hi ? 1 : 2);
      if (ka != previous || ka == 2) [[unlikely]] events_.push_back({index, a, ka});
      if (kb != ka || kb == 2) [[unlikely]] events_.push_back({index + 1, b, kb});
      previous = kb;
      index += 2;
    }
    for (; i < frames; ++i) {
      const std::int16_t a = data[i * stride + channel];
      ++h0[static_cast<std::uint16_t>(a)];
      const std::uint8_t ka = a < lo ? 0 : (a > hi ? 1 : 2);
      if (ka != previous || ka == 2) events_.push_back({index, a, ka});
      previous = ka;
      ++index;
    }
    previous_ = previous;
    position_ = index;
    // Move the 32-bit counters into 64-bit totals long before they can overflow.
    if (++blocks_ % 1024 == 0) flush();
  }

  VoltageHistogram histogram(double quantum) {
    flush();
    VoltageHistogram h(quantum);
    // Tables are indexed by the count reinterpreted as uint16; order them by value.
    std::vector<std::int64_t> ordered(65536);
    for (std::int32_t c = -32768; c < 32768; ++c) ordered[static_cast<std::size_t>(c + 32768)] = total_[static_cast<std::uint16_t>(c)];
    h.add_counts(ordered, -32768);
    return h;
  }

  /// True when every threshold of t lies strictly inside the band.
  [[nodiscard]] bool covers(const Threshold& t, double quantum) const {
    const double lo = static_cast<double>(lo_) * quantum, hi = static_cast<double>(hi_) * quantum;
    const double a = std::min(t.lower, t.upper) - t.tolerance, b = std::max(t.lower, t.upper) + t.tolerance;
    return lo < a && b < hi;
  }

  AirIntervals resolve(const Threshold& t, double quantum, double fs) const {
    Binariser b(t, fs);
    // An interval opens at one event and closes at a later one.
    b.reserve(events_.size() / 2 + 1);
    const auto below = static_cast<float>((static_cast<double>(lo_) - 0.5) * quantum);
    const auto above = static_cast<float>((static_cast<double>(hi_) + 0.5) * quantum);
    for (std::size_t e = 0; e < events_.size(); ++e) {
      const auto& ev = events_[e];
      const std::int64_t next = e + 1 < events_.size() ? events_[e + 1].index : position_;
      if (ev.kind == 2) {
        const float v[1] = {static_cast<float>(static_cast<double>(ev.count) * quantum)};
        b.feed(v, 0, 1);
      } else {
        b.feed_run(ev.kind == 0 ? below : above, next - ev.index);
      }
    }
    return b.finish();
  }

  [[nodiscard]] std::int64_t samples() const { return position_; }
  /// Frees the events once resolved (the next tip's resolving needs the room).
  void release() { events_ = {}; }

 private:
  struct Event {
    std::int64_t index;
    std::int16_t count;
    std::uint8_t kind;  // 0 below the band, 1 above, 2 inside (value kept)
  };
  void flush() {
    for (std::size_t k = 0; k < 65536; ++k) {
      total_[k] += h0_[k] + static_cast<std::int64_t>(h1_[k]);
      h0_[k] = h1_[k] = 0;
    }
  }

  std::int16_t lo_, hi_;
  std::vector<std::uint32_t> h0_, h1_;
  std::vector<std::int64_t> total_ = std::vector<std::int64_t>(65536, 0);
  std::vector<Event> events_;
  std::uint8_t previous_ = 3;  // no sample yet: the first sample opens an event
  std::int64_t position_ = 0;
  std::int64_t blocks_ = 0;
};

// The band for one channel from the first block: its thresholds widened by
// 8 % of the span between its modes on each side. Narrow, so that only samples
// near the threshold are kept (memory is costly to touch on a virtual
// machine); wide enough that the whole record's thresholds, from the same
// modes in nearly every recording, fall inside it.
std::optional<std::pair<std::int16_t, std::int16_t>> band_from(const std::int16_t* data, std::size_t frames,
                                                                std::size_t stride, std::size_t channel,
                                                                double quantum, const BinarisationOptions& bopt) {
  if (bopt.rule == ThresholdRule::fixed) {
    // The threshold is known: a band of one count around it.
    const double c = bopt.fixed_threshold.value_or(0.0) / quantum;
    if (!(std::fabs(c) < 32000.0)) return std::nullopt;
    return std::pair{static_cast<std::int16_t>(std::floor(c) - 1), static_cast<std::int16_t>(std::ceil(c) + 1)};
  }
  std::vector<std::int64_t> counts(65536, 0);
  for (std::size_t i = 0; i < frames; ++i) ++counts[static_cast<std::size_t>(data[i * stride + channel] + 32768)];
  VoltageHistogram h(quantum);
  h.add_counts(counts, -32768);
  try {
    const Threshold t = choose_threshold(h, bopt);
    if (t.binary_input || t.constant) return std::nullopt;
    const double span = std::fabs(t.water_level - t.air_level);
    const double lo = (std::min(t.lower, t.upper) - 0.08 * span) / quantum;
    const double hi = (std::max(t.lower, t.upper) + 0.08 * span) / quantum;
    if (!(hi - lo > 2.0) || !(lo > -32000.0) || !(hi < 32000.0)) return std::nullopt;
    return std::pair{static_cast<std::int16_t>(std::ceil(lo)), static_cast<std::int16_t>(std::floor(hi))};
  } catch (const std::runtime_error&) {
    return std::nullopt;
  }
}

// The signal check of both tips (awcc/signal_check.hpp), before any
// statistics: a failure stops the recording unless allowed; an allowed
// failure or a flag becomes a warning of the result (signal_warning, assess).
void check_tips(BinarisedRecording& out, const ProcessOptions& options, std::optional<DigitiserLimits> limits) {
  struct Tip {
    const std::optional<VoltageHistogram>& histogram;
    SignalCheck& check;
    int channel;
    std::string name;
  };
  std::vector<Tip> tips{{out.leading_histogram, out.leading_signal, options.leading_channel, "leading tip"},
                        {out.trailing_histogram, out.trailing_signal, options.trailing_channel, "trailing tip"}};
  for (std::size_t k = 0; k < out.further_tips.size(); ++k) {
    BinarisedTip& tip = out.further_tips[k];
    tips.push_back({tip.histogram, tip.check, tip.channel, fmt::format("tip {}", k + 2)});
  }
  const bool allowed = options.signal_check.allow_bad_signal;
  std::string refusal, quantity = "allow-bad-signal";
  const SignalCheck* first = nullptr;
  for (const Tip& tip : tips) {
    if (!tip.histogram) continue;
    tip.check = check_signal(*tip.histogram, options.binarisation.probe, limits, options.signal_check);
    const std::string where = fmt::format("channel {} ({})", tip.channel, tip.name);
    if (!tip.check.failed()) continue;  // a flag, if any, is the result's warning (assess)
    if (allowed) {
      tip.check.overridden = true;
      continue;
    }
    if (!first) {
      first = &tip.check;
      refusal = where + ": " + tip.check.message;
    } else if (tip.check.status == first->status) {
      refusal += fmt::format("; {} likewise", where);
    } else {
      refusal += "; " + where + ": " + tip.check.message;
    }
    if (tip.check.status == SignalStatus::inverted_polarity) quantity = "probe,allow-bad-signal";
  }
  // Two tips holding one signal twice (copied_channel_correlation): r of
  // binary signals at lag 0 from their air and shared air samples.
  std::vector<const AirIntervals*> signals{&out.leading, &out.trailing};
  for (const auto& tip : out.further_tips) signals.push_back(&tip.signal);
  out.copies.clear();
  bool copy_refused = false;
  for (std::size_t i = 0; options.signal_check.find_copies && i < signals.size(); ++i) {
    for (std::size_t j = i + 1; j < signals.size(); ++j) {
      const AirIntervals& a = *signals[i];
      const AirIntervals& b = *signals[j];
      const auto n = static_cast<double>(a.sample_count);
      const auto na = static_cast<double>(a.air_samples()), nb = static_cast<double>(b.air_samples());
      const double spread = na * (n - na) * nb * (n - nb);
      if (a.sample_count != b.sample_count || !(spread > 0.0)) continue;
      const double r = (n * static_cast<double>(shared_air_samples(a, b)) - na * nb) / std::sqrt(spread);
      if (r < copied_channel_correlation) continue;
      out.copies.push_back({tips[i].channel, tips[j].channel, tips[i].name, tips[j].name, r,
                            a.intervals == b.intervals});
      const auto& copy = out.copies.back();
      if (!copy.identical || allowed) continue;
      refusal += fmt::format("{}channel {} ({}) holds the same signal as channel {} ({}): one channel copied (a "
                             "wiring or channel-map slip) gives no delay between them and no velocity vector; check "
                             "the acquisition's channels",
                             refusal.empty() ? "" : "; ", copy.second, copy.second_tip, copy.first, copy.first_tip);
      copy_refused = true;
    }
  }
  if (!first && !copy_refused) return;
  const std::string what = out.info.path.empty() ? out.info.description : out.info.path.string();
  throw InputError(fmt::format("{}: {}; to process it anyway, with the failure in every output, allow a bad signal",
                               what, refusal),
                   quantity);
}

}  // namespace

namespace {

// The tips' signals by the fastest exact path the recording allows: a binary
// 16-bit recording by its level changes; other 16-bit recordings in one pass
// (BandRecorder) when the whole record's thresholds fall in the first block's
// bands; anything else in two passes. Every path gives the same signals.
std::vector<TipSignal> binarise_tips(Recording& recording, const ProcessOptions& options,
                                     const BinarisationOptions& bopt, const ChannelSelection& ch) {
  const RecordingInfo& info = recording.info();
  const std::size_t tips = ch.tips.size();
  if (options.single_pass && recording.has_int16() && info.quantum > 0.0) {
    // A binary recording (two levels per tip): its level changes only.
    {
      auto reader = blocks<std::int16_t>(recording, options, ch);
      detail::TwoLevelScan binary(ch.stride, ch.tips);
      bool two_levels = true;
      for (auto used = reader.next(); two_levels && !used.empty(); used = reader.next()) {
        two_levels = binary.feed(used.data(), used.size() / ch.stride);
      }
      if (two_levels && binary.samples() > 0) {
        std::vector<TipSignal> out(tips);
        for (std::size_t k = 0; k < tips; ++k) {
          const int tip = static_cast<int>(k);
          out[k].histogram = binary.histogram(tip, info.quantum);
          out[k].threshold = choose_threshold(*out[k].histogram, tip_options(bopt, k));
          out[k].signal = binary.intervals(tip, out[k].threshold, info.quantum, info.fs);
        }
        return out;
      }
    }
    // Not binary: a band of candidate thresholds per tip from the first block, then one pass.
    recording.rewind();
    {
      auto reader = blocks<std::int16_t>(recording, options, ch);
      auto used = reader.next();
      const std::size_t n = used.size() / ch.stride;
      std::vector<BandRecorder> recorders;
      recorders.reserve(tips);
      for (std::size_t k = 0; k < tips && n > 0; ++k) {
        const auto band = band_from(used.data(), n, ch.stride, ch.tips[k], info.quantum, tip_options(bopt, k));
        if (!band) break;
        recorders.emplace_back(band->first, band->second);
      }
      if (n > 0 && recorders.size() == tips) {
        for (; !used.empty(); used = reader.next()) {
          for (std::size_t k = 0; k < tips; ++k) {
            recorders[k].feed(used.data(), used.size() / ch.stride, ch.stride, ch.tips[k]);
          }
        }
        std::vector<TipSignal> out(tips);
        bool covered = true;
        for (std::size_t k = 0; k < tips; ++k) {
          out[k].histogram = recorders[k].histogram(info.quantum);
          out[k].threshold = choose_threshold(*out[k].histogram, tip_options(bopt, k));
          covered = covered && recorders[k].covers(out[k].threshold, info.quantum);
        }
        if (covered) {
          for (std::size_t k = 0; k < tips; ++k) {
            out[k].signal = recorders[k].resolve(out[k].threshold, info.quantum, info.fs);
            recorders[k].release();
          }
          return out;
        }
      }
    }
    recording.rewind();
  }
  return binarise_two_pass(recording, options, bopt, ch);
}

}  // namespace

BinarisedRecording binarise_recording(const std::filesystem::path& path, const ProcessOptions& options) {
  options.validate().throw_if_failed();
  auto recording = open_recording(path, options.reader);
  return binarise_recording(*recording, options);
}

BinarisedRecording binarise_recording(Recording& opened, const ProcessOptions& given) {
  given.validate().throw_if_failed();
  ResolvedTips resolved = resolve_tips(given, opened.info());
  const ProcessOptions& options = resolved.options;
  Recording* recording = &opened;
  const RecordingInfo& info = recording->info();
  const std::filesystem::path& path = info.path;
  const int channels = info.channels;
  const std::vector<int> tip_channels = options.tip_channels();
  if (channels < 2) {
    throw InputError(fmt::format("{}: the recording has {} channel{}, but pdp processes the tips of a probe together "
                                 "(at least a leading and a trailing tip): give a recording holding both tips' "
                                 "signals, a column or channel per tip",
                                 path.string(), channels, channels == 1 ? "" : "s"));
  }
  for (std::size_t k = 0; k < tip_channels.size(); ++k) {
    const int c = tip_channels[k];
    if (c >= channels) {
      throw InputError(fmt::format("{}: tip {} is channel {}, but the recording has {} channels (numbered from 0 to "
                                   "{}); choose the tips' channels within range",
                                   path.string(), k, c, channels, channels - 1),
                       k < 2 ? "leading-channel,trailing-channel" : "tip-channels");
    }
  }
  ChannelSelection ch{static_cast<std::size_t>(channels), {}};
  for (int c : tip_channels) ch.tips.push_back(static_cast<std::size_t>(c));
  if (!options.allow_unusual && (info.fs < plausible_fs_min || info.fs > plausible_fs_max)) {
    throw InputError(fmt::format("{}: the file records a sampling rate of {}, outside 1 kHz to 100 MHz: is it a probe "
                                 "recording? If so, allow unusual values",
                                 path.string(), format_quantity(info.fs, Dimension::frequency)),
                     "allow-unusual");
  }
  if (options.binarisation.rule == ThresholdRule::fixed && !info.volts_known) {
    throw InputError(fmt::format("{}: a fixed threshold is a voltage, but the recording's samples are not in volts "
                                 "(its scale is unknown); state its volts per count",
                                 path.string()),
                     "volts-per-count");
  }
  BinarisationOptions bopt = options.binarisation;
  if (!info.volts_known && bopt.bin_width > 0.0 && bopt.rule != ThresholdRule::felder) bopt.bin_width = 0.0;

  BinarisedRecording out;
  out.info = info;
  std::vector<TipSignal> tips;
  try {
    tips = binarise_tips(*recording, options, bopt, ch);
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.rfind(path.string(), 0) == 0) throw;
    throw InputError(fmt::format("{}: {}", path.string(), what), e.quantity());
  }
  if (tips.at(0).signal.sample_count == 0) {
    throw InputError(fmt::format("{}: the recording holds no samples", path.string()));
  }
  out.leading_threshold = tips[0].threshold;
  out.leading = std::move(tips[0].signal);
  out.leading_histogram = std::move(tips[0].histogram);
  out.trailing_threshold = tips[1].threshold;
  out.trailing = std::move(tips[1].signal);
  out.trailing_histogram = std::move(tips[1].histogram);
  for (std::size_t k = 2; k < tips.size(); ++k) {
    BinarisedTip& further = out.further_tips.emplace_back();
    further.channel = options.further_channels[k - 2];
    further.threshold = tips[k].threshold;
    further.signal = std::move(tips[k].signal);
    further.histogram = std::move(tips[k].histogram);
  }
  out.info.frames = out.leading.sample_count;
  out.tip_positions = std::move(resolved.positions);
  check_tips(out, options,
             recording->has_int16() && info.quantum > 0.0 ? std::optional(int16_limits(info.quantum)) : std::nullopt);
  return out;
}

std::vector<Crossing> BinarisedRecording::tip_crossings(std::size_t k) const {
  if (k < crossings.size()) return crossings[k];
  const AirIntervals& signal = k == 0 ? leading : k == 1 ? trailing : further_tips.at(k - 2).signal;
  return awcc::crossings(signal);
}

namespace {

// One tip's edges in time order (front of interval j at 2j, rear at 2j + 1),
// each timed from the two samples around it as the blocks pass.
class EdgeTimer {
 public:
  EdgeTimer(const Threshold& t, const AirIntervals& signal, std::vector<Crossing>& out)
      : signal_(signal), out_(out) {
    const bool air_low = t.probe == ProbeType::conductivity;
    // The level each direction compares with (Binariser::feed).
    if (t.rule == ThresholdRule::hysteresis) {
      front_level_ = air_low ? t.lower : t.upper;
      rear_level_ = air_low ? t.upper : t.lower;
    } else {
      front_level_ = rear_level_ = air_low ? t.upper : t.lower;
    }
  }

  // Samples [first, first + frames) of this tip: values[first_value + i * stride].
  void feed(std::span<const float> values, std::size_t first_value, std::size_t stride, std::int64_t first,
            std::int64_t frames) {
    const auto& intervals = signal_.intervals;
    const std::size_t edges = 2 * intervals.size();
    auto value = [&](std::int64_t n) { return static_cast<double>(values[first_value + static_cast<std::size_t>(n - first) * stride]); };
    for (; next_ < edges; ++next_) {
      const auto& interval = intervals[next_ / 2];
      const bool front = next_ % 2 == 0;
      const std::int64_t n = front ? interval.start : interval.stop;
      if (n >= first + frames) break;
      // At the record's ends the interface is outside the record: the midpoint stays.
      if (n == 0 || n >= signal_.sample_count) continue;
      const double before = n - 1 >= first ? value(n - 1) : previous_;
      const double at = value(n);
      double f = ((front ? front_level_ : rear_level_) - before) / (at - before);
      if (!std::isfinite(f)) f = 0.5;
      f = std::clamp(f, 0.0, 1.0);
      (front ? fronts_ : rears_).push_back(f);
      (front ? out_[next_ / 2].front : out_[next_ / 2].rear) = (static_cast<double>(n - 1) + f) / signal_.fs;
    }
    if (frames > 0) previous_ = value(first + frames - 1);
  }

  // Edges sharper than a sample cross the level at one fraction, whatever
  // the interface's true time: their crossings hold no sub-sample time, only
  // noise, which would break the ties of whole-sample lags and pass as a
  // measured spread (event_detection.hpp, item 9). Such an edge direction
  // (the middle half of its fractions narrower than `least_spread` of a
  // sample) keeps the midpoints; says which, or "".
  std::string keep_informative(double least_spread, const std::string& tip) {
    std::string out;
    for (const bool front : {true, false}) {
      auto& f = front ? fronts_ : rears_;
      if (f.size() < 20) continue;
      std::sort(f.begin(), f.end());
      const double spread = f[3 * f.size() / 4] - f[f.size() / 4];
      if (spread >= least_spread) continue;
      const auto midpoints = crossings(signal_);
      for (std::size_t j = 0; j < midpoints.size(); ++j) {
        if (front) out_[j].front = midpoints[j].front;
        else out_[j].rear = midpoints[j].rear;
      }
      out += fmt::format("{}{}'s {} at the midpoints: the middle half of their crossings lies within {:.3f} of a "
                         "sample (edges sharper than a sample hold no sub-sample time)",
                         out.empty() ? "" : "; ", tip, front ? "fronts" : "rears", spread);
    }
    return out;
  }

 private:
  const AirIntervals& signal_;
  std::vector<Crossing>& out_;
  double front_level_ = 0.0, rear_level_ = 0.0;
  std::size_t next_ = 0;
  double previous_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> fronts_, rears_;  // the fractions of the timed edges
};

}  // namespace

ThresholdCrossings threshold_crossings(Recording& recording, const BinarisedRecording& b,
                                       const ProcessOptions& given) {
  const ResolvedTips resolved = resolve_tips(given, recording.info());
  ChannelSelection ch{static_cast<std::size_t>(recording.info().channels), {}};
  for (int c : resolved.options.tip_channels()) ch.tips.push_back(static_cast<std::size_t>(c));
  std::vector<const Threshold*> thresholds{&b.leading_threshold, &b.trailing_threshold};
  for (const auto& t : b.further_tips) thresholds.push_back(&t.threshold);
  if (thresholds.size() != ch.tips.size()) {
    throw std::invalid_argument(fmt::format("threshold_crossings: {} binarised tips, {} channels", thresholds.size(),
                                            ch.tips.size()));
  }
  ThresholdCrossings result;
  auto& out = result.tips;
  out.resize(thresholds.size());
  std::vector<EdgeTimer> timers;
  std::vector<std::size_t> timed;  // the tips whose voltages are read (a binary signal's midpoints are exact)
  timers.reserve(out.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k] = b.tip_crossings(k);
    if (thresholds[k]->binary_input || thresholds[k]->constant) continue;
    const AirIntervals& signal = k == 0 ? b.leading : k == 1 ? b.trailing : b.further_tips[k - 2].signal;
    timers.emplace_back(*thresholds[k], signal, out[k]);
    timed.push_back(k);
  }
  if (timed.empty()) {
    result.note = "every tip's signal is binary: the midpoints are its crossings";
    return result;
  }
  recording.rewind();
  std::int64_t position = 0;
  auto reader = blocks<float>(recording, resolved.options, ch);
  for (auto used = reader.next(); !used.empty(); used = reader.next()) {
    const auto frames = static_cast<std::int64_t>(used.size() / ch.stride);
    for (std::size_t i = 0; i < timed.size(); ++i) timers[i].feed(used, ch.tips[timed[i]], ch.stride, position, frames);
    position += frames;
  }
  if (position != b.leading.sample_count) {
    throw InputError(fmt::format("{}: reading the voltages again for the interfaces' crossings gave {} frames instead "
                                 "of {}; the file changed while being read",
                                 recording.info().path.string(), position, b.leading.sample_count));
  }
  for (std::size_t i = 0; i < timed.size(); ++i) {
    const auto kept = timers[i].keep_informative(least_crossing_spread, fmt::format("tip {}", timed[i]));
    if (!kept.empty()) result.note += (result.note.empty() ? "" : "; ") + kept;
  }
  return result;
}

namespace {

// A binary channel as a binary file reads (TwoLevelScan): the histogram of
// its two levels, 0 water and 1 air, one count per level.
VoltageHistogram two_levels(const AirIntervals& signal) {
  VoltageHistogram h(1.0);
  const std::int64_t air = signal.air_samples();
  const std::int64_t counts[2] = {signal.sample_count - air, air};
  h.add_counts(counts, 0);
  return h;
}

}  // namespace

BinarisedRecording binary_recording(std::vector<AirIntervals> signals, const ProcessOptions& options,
                                    std::vector<int> channels, std::vector<Vec3> positions) {
  if (channels.empty()) {
    for (std::size_t k = 0; k < signals.size(); ++k) channels.push_back(static_cast<int>(k));
  }
  if (signals.size() < 2 || channels.size() != signals.size() || (!positions.empty() && positions.size() != signals.size())) {
    throw std::invalid_argument(fmt::format("binary_recording: {} signals, {} channels and {} tip positions: give at "
                                            "least two signals, one channel each, and one position each or none",
                                            signals.size(), channels.size(), positions.size()));
  }
  BinarisedRecording out;
  out.info.description = "binary signals in memory";
  out.info.channels = *std::max_element(channels.begin(), channels.end()) + 1;
  out.info.fs = signals[0].fs;
  out.info.frames = signals[0].sample_count;
  out.info.quantum = 1.0;
  const BinarisationOptions& bopt = options.binarisation;
  for (std::size_t k = 0; k < signals.size(); ++k) {
    VoltageHistogram h = two_levels(signals[k]);
    const Threshold threshold = choose_threshold(h, tip_options(bopt, k));
    if (k == 0) {
      out.leading_threshold = threshold;
      out.leading = std::move(signals[k]);
      out.leading_histogram = std::move(h);
    } else if (k == 1) {
      out.trailing_threshold = threshold;
      out.trailing = std::move(signals[k]);
      out.trailing_histogram = std::move(h);
    } else {
      BinarisedTip& tip = out.further_tips.emplace_back();
      tip.channel = channels[k];
      tip.threshold = threshold;
      tip.signal = std::move(signals[k]);
      tip.histogram = std::move(h);
    }
  }
  out.tip_positions = std::move(positions);
  ProcessOptions checked = options;
  checked.leading_channel = channels[0];
  checked.trailing_channel = channels[1];
  check_tips(out, checked, std::nullopt);
  return out;
}

std::vector<TipResult> tip_results(const BinarisedRecording& r, const ProcessOptions& options,
                                   std::optional<double> velocity);

namespace {

// Swapped tips (METHOD 4, item 10): when either method sees the trailing
// tip's signal lead, neither reports a velocity.
void apply_tip_order(ProcessResult& r) {
  const bool fscc_swapped = r.fscc && r.fscc->status == FsccStatus::tips_swapped;
  const bool awcc_swapped = r.awcc && r.awcc->status == AwccStatus::tips_swapped;
  if (fscc_swapped && r.awcc && r.awcc->status != AwccStatus::tips_swapped) {
    detail::tips_swapped(*r.awcc, "FSCC peaks at a negative lag: the tips are swapped (or dx has the wrong sign); "
                                  "exchange the tips' channels");
  }
  if (awcc_swapped && r.fscc && r.fscc->status != FsccStatus::tips_swapped) {
    r.fscc->status = FsccStatus::tips_swapped;
    r.fscc->message = "most AWCC windows peak at a negative lag: the tips are swapped (or dx has the wrong sign); "
                      "exchange the tips' channels";
    r.fscc->velocity = 0.0;
    r.fscc->turbulence_intensity_chanson.reset();
  }
}

}  // namespace

namespace {

// The structure outputs need the velocity of the chord lengths, known once
// every correlation has run. Felder's conventions use his FSCC velocity.
void add_spectrum(ProcessResult& out, const ProcessOptions& options) {
  if (!options.velocity_spectrum || !out.awcc) return;
  const double duration = out.info.fs > 0.0 ? static_cast<double>(out.info.frames) / out.info.fs : 0.0;
  out.spectrum = velocity_spectrum(*out.awcc, duration, options.spectrum);
}

void add_structure(ProcessResult& out, const BinarisedRecording& b, const ProcessOptions& options) {
  if (!options.structure.enabled) return;
  std::optional<double> velocity = out.velocity();
  std::string source(to_string(out.velocity_source()));
  if (options.structure.felder_defects) {
    velocity.reset();
    source = "none";
    if (out.fscc && out.fscc->ok()) {
      velocity = out.fscc->velocity;
      source = "fscc";
    }
  }
  out.structure = analyse_structure(b.leading, b.trailing, out.tips.at(0).phase.void_fraction,
                                    b.leading_histogram ? &*b.leading_histogram : nullptr,
                                    b.trailing_histogram ? &*b.trailing_histogram : nullptr, velocity, source,
                                    options.structure);
}

// The sizes and interfacial area (awcc/position_sizes.hpp), from every
// velocity the other steps gave.
void add_sizes(ProcessResult& out, const BinarisedRecording& b, const ProcessOptions& options) {
  const PhaseStatistics& leading = out.tips.at(0).phase;
  if (options.sizes) {
    out.sizes = position_sizes(b.leading, leading, out.awcc, out.events, out.velocity(),
                               to_string(out.velocity_source()), options.size_options);
  }
  const MultiTipResult* vectors = out.probe ? &out.probe->vectors : nullptr;
  const bool probe_ok = out.probe && out.probe->quality == AwccQuality::ok;
  out.interfacial_area = interfacial_area(leading, out.velocity(), out.velocity_ci95(), vectors, probe_ok,
                                          out.probe ? out.probe->quality_reason : std::string());
}

}  // namespace

std::optional<double> ProcessResult::velocity() const {
  const auto s = velocity_source();
  if (s == VelocitySource::awcc) return awcc->velocity;
  if (s == VelocitySource::fscc) return fscc->velocity;
  return std::nullopt;
}

std::optional<Interval95> ProcessResult::velocity_ci95() const {
  const auto s = velocity_source();
  if (s == VelocitySource::awcc) return awcc->velocity_ci95;
  if (s == VelocitySource::fscc) return fscc->velocity_ci95;
  return std::nullopt;
}

VelocitySource ProcessResult::velocity_source() const {
  if (awcc && awcc->ok() && awcc->quality == AwccQuality::ok) return VelocitySource::awcc;
  if (fscc && fscc->ok()) return VelocitySource::fscc;
  if (awcc && awcc->ok()) return VelocitySource::awcc;  // low quality, flagged; FSCC gave nothing better
  return VelocitySource::none;
}

std::string_view to_string(VelocitySource source) {
  switch (source) {
    case VelocitySource::awcc: return "awcc";
    case VelocitySource::fscc: return "fscc";
    case VelocitySource::none: return "none";
  }
  return "?";
}

namespace {

// Shen's first velocity V_gas (METHOD 11.2): FSCC's of the tip pair, else AWCC's.
std::optional<double> first_velocity(const ProcessResult& out) {
  if (out.fscc && out.fscc->ok()) return out.fscc->velocity;
  if (out.awcc && out.awcc->ok()) return out.awcc->velocity;
  return std::nullopt;
}

// The bubble-by-bubble methods on the binarised tips: event detection on
// the pair, the multi-tip vectors with FSCC and AWCC on every further pair.
void add_bubble_methods(ProcessResult& out, const BinarisedRecording& r, const ProcessOptions& options) {
  const std::string file = r.info.path.string();
  const auto velocity = first_velocity(out);
  const EventOptions event_options = options.effective_event_options();
  if (options.events) {
    out.events = event_detection(r.tip_crossings(0), r.tip_crossings(1), options.dx, event_options, velocity);
    out.events->interface_times_note = r.crossings_note;
    judge_events(*out.events, out);
  }
  const std::size_t tips = r.tip_positions.size();
  if (!wants_multi_tip(options.multi_tip, tips)) return;
  if (tips < 4 || tips != 2 + r.further_tips.size()) {
    throw InputError(fmt::format("{}: multi-tip processing needs every tip's position and signal (at least four "
                                 "tips), but {} positions and {} binarised tips are known: declare the probe's tips",
                                 file, tips, 2 + r.further_tips.size()),
                     "tips");
  }
  ProbeResult probe;
  probe.geometry = ProbeGeometry(r.tip_positions, 0);
  if (const auto v = probe.geometry.check(options.multi_tip_options.conditioning_min); !v.ok()) {
    throw InputError(fmt::format("{}: {} (or process the tip pair alone: method both)", file, v.message), v.quantity);
  }
  // The binarised tips' own channels (a recording built in memory need not name them in the options).
  probe.channels = {options.leading_channel, options.trailing_channel};
  for (const auto& t : r.further_tips) probe.channels.push_back(t.channel);
  PhaseStatisticsOptions po;
  po.histogram_bins = options.histogram_bins;
  po.velocity = out.velocity();
  std::vector<std::vector<Crossing>> crossings;
  crossings.reserve(tips);
  for (std::size_t k = 0; k < tips; ++k) crossings.push_back(r.tip_crossings(k));
  for (const auto& t : r.further_tips) {
    const auto& names = r.info.channel_names;
    const auto c = static_cast<std::size_t>(t.channel);
    probe.further_tips.push_back(
        {t.channel, c < names.size() ? names[c] : std::string(), t.threshold, phase_statistics(t.signal, po), t.check});
  }
  probe.pairing = pair_probe(probe.geometry, crossings, event_options, velocity);
  const double record_length = static_cast<double>(r.leading.sample_count) / r.leading.fs;
  if (probe.pairing.ok()) {
    probe.vectors = multi_tip(probe.geometry, probe.pairing.bubbles, record_length, options.multi_tip_options);
  } else {
    probe.vectors.options = options.multi_tip_options;
    probe.vectors.record_length = record_length;
    probe.vectors.message = probe.pairing.message;
  }
  const bool binary = options.awcc_options.signal == CorrelationSignal::binary;
  for (std::size_t k = 2; binary && k < tips; ++k) {
    const Vec3& a = r.tip_positions[0];
    const Vec3& b = r.tip_positions[k];
    TipPairResult pair;
    pair.tip = k;
    pair.channel = probe.channels[k];
    pair.dx = b[0] - a[0];
    pair.dy = std::hypot(b[1] - a[1], b[2] - a[2]);
    if (!(pair.dx > 0.0)) continue;  // not downstream: no streamwise velocity
    const AirIntervals& trailing = r.further_tips[k - 2].signal;
    if (options.fscc) pair.fscc = fscc(r.leading, trailing, pair.dx, options.fscc_options);
    if (options.awcc) pair.awcc = awcc::awcc(r.leading, trailing, pair.dx, options.awcc_options);
    probe.pairs.push_back(std::move(pair));
  }
  judge_probe(probe, out, event_options);
  out.probe = std::move(probe);
}

// The one list of processing steps after the correlations, whatever they
// correlated (both entry points below): the tip order FSCC and AWCC say,
// the phase statistics at the chosen velocity, the bubble-by-bubble methods,
// the sizes, the structure, the velocity series and the row's warnings. A
// new step goes here, once.
void finish(ProcessResult& out, const BinarisedRecording& r, const ProcessOptions& options) {
  out.channel_copies = r.copies;  // before the probe's judgement reads them
  apply_tip_order(out);
  out.tips = tip_results(r, options, out.velocity());
  add_bubble_methods(out, r, options);
  add_sizes(out, r, options);
  add_structure(out, r, options);
  add_spectrum(out, options);
  out.warnings = assess(out);
}

ProcessResult started(const RecordingInfo& info, const ProcessOptions& options) {
  ProcessResult out;
  out.info = info;
  out.dx = options.dx;
  out.dy = options.dy;
  return out;
}

}  // namespace

ProcessResult process_binarised(const BinarisedRecording& r, const ProcessOptions& given) {
  const ProcessOptions options = tip_pair_options(given, r.info);
  if (options.awcc_options.signal != CorrelationSignal::binary && (options.fscc || options.awcc)) {
    throw OptionError(fmt::format("{}: FSCC and AWCC correlate the raw voltages here (correlate = raw), which a "
                                  "binarised recording no longer holds: process the recording itself, or correlate "
                                  "the binary signals",
                                  r.info.path.string()),
                      "correlate");
  }
  ProcessResult out = started(r.info, options);
  if (options.fscc) {
    out.fscc = fscc(r.leading, r.trailing, options.dx, options.fscc_options, options.parallel_fscc && two_cores());
  }
  if (options.awcc) out.awcc = awcc::awcc(r.leading, r.trailing, options.dx, options.awcc_options);
  finish(out, r, options);
  return out;
}

std::vector<TipResult> tip_results(const BinarisedRecording& r, const ProcessOptions& options,
                                   std::optional<double> velocity) {
  PhaseStatisticsOptions po;
  po.histogram_bins = options.histogram_bins;
  po.velocity = velocity;
  auto name = [&](int channel) {
    const auto& n = r.info.channel_names;
    return channel >= 0 && static_cast<std::size_t>(channel) < n.size() ? n[static_cast<std::size_t>(channel)]
                                                                       : std::string();
  };
  return {{options.leading_channel, name(options.leading_channel), r.leading_threshold, phase_statistics(r.leading, po),
           r.leading_signal},
          {options.trailing_channel, name(options.trailing_channel), r.trailing_threshold,
           phase_statistics(r.trailing, po), r.trailing_signal}};
}

namespace {

// The raw voltages of the two tips over each window, read block by block as
// the driver asks for the windows (in order; they tile the record from its start).
class RawVoltageCorrelations final : public detail::WindowCorrelations {
 public:
  RawVoltageCorrelations(Recording& recording, const ProcessOptions& options)
      : recording_(recording), block_frames_(options.block_frames),
        stride_(static_cast<std::size_t>(recording.info().channels)),
        lead_(static_cast<std::size_t>(options.leading_channel)),
        trail_(static_cast<std::size_t>(options.trailing_channel)),
        block_(static_cast<std::size_t>(options.block_frames) * stride_) {
    recording_.rewind();
  }

  detail::WindowPeak correlate(const AwccWindow& w, std::int64_t k_min, std::int64_t k_max, const AwccOptions& options,
                               AwccWorkspace& workspace) override {
    read(w, workspace);
    auto& s = workspace.scratch();
    return detail::fft_window_peak(s.samples_x, s.samples_y, k_min, k_max, options, workspace);
  }
  void skip(const AwccWindow& w, AwccWorkspace& workspace) override { read(w, workspace); }

 private:
  // The window's samples into the workspace's samples_x, samples_y.
  void read(const AwccWindow& w, AwccWorkspace& workspace) {
    auto& xs = workspace.scratch().samples_x;
    auto& ys = workspace.scratch().samples_y;
    xs.clear();
    ys.clear();
    const std::int64_t end = w.start + w.length;
    while (position_ < end) {
      if (position_ >= block_start_ + in_block_) {
        block_start_ += in_block_;
        in_block_ = recording_.read(block_, block_frames_);
        if (in_block_ == 0) {
          throw InputError(fmt::format("{}: the recording ended at frame {} while reading it again for AWCC",
                                       recording_.info().path.string(), position_));
        }
        continue;
      }
      const std::int64_t from = std::max(position_, w.start);
      const std::int64_t to = std::min(end, block_start_ + in_block_);
      for (std::int64_t t = from; t < to; ++t) {
        const auto f = static_cast<std::size_t>(t - block_start_);
        xs.push_back(block_[f * stride_ + lead_]);
        ys.push_back(block_[f * stride_ + trail_]);
      }
      position_ = to;
    }
  }

  Recording& recording_;
  std::int64_t block_frames_;
  std::size_t stride_, lead_, trail_;
  std::vector<float> block_;
  std::int64_t position_ = 0, in_block_ = 0, block_start_ = 0;  // next frame; frames in the block; its first frame
};

}  // namespace

AwccResult awcc_raw(const std::filesystem::path& path, const BinarisedRecording& b, const ProcessOptions& options) {
  return awcc_raw(*open_recording(path, options.reader), b, options);
}

AwccResult awcc_raw(Recording& recording, const BinarisedRecording& b, const ProcessOptions& options) {
  AwccWorkspace workspace;
  return awcc_raw(recording, b, options, workspace);
}

AwccResult awcc_raw(Recording& recording, const BinarisedRecording& b, const ProcessOptions& given,
                    AwccWorkspace& workspace) {
  const ProcessOptions options = tip_pair_options(given, b.info);
  const AwccOptions& ao = options.awcc_options;
  ao.validate().throw_if_failed();
  RawVoltageCorrelations voltages(recording, options);
  return detail::run_awcc(b.leading, options.dx, ao, voltages, workspace);
}

FsccResult fscc_raw(const std::filesystem::path& path, const BinarisedRecording& b, const ProcessOptions& options) {
  return fscc_raw(*open_recording(path, options.reader), b, options);
}

FsccResult fscc_raw(Recording& recording, const BinarisedRecording& b, const ProcessOptions& options) {
  FftPlanCache plans;
  return fscc_raw(recording, b, options, plans);
}

FsccResult fscc_raw(Recording& recording, const BinarisedRecording& b, const ProcessOptions& given,
                    FftPlanCache& plans) {
  const ProcessOptions options = tip_pair_options(given, b.info);
  const std::filesystem::path& path = recording.info().path;
  recording.rewind();
  const auto stride = static_cast<std::size_t>(recording.info().channels);
  const auto lead = static_cast<std::size_t>(options.leading_channel);
  const auto trail = static_cast<std::size_t>(options.trailing_channel);
  RawCorrelation correlation(b.info.frames, b.info.fs, options.fscc_options, plans);
  // The same correlation over the interval's segments, fed alongside (the velocity's sampling interval).
  const FsccOptions spread_options = interval_options(options.fscc_options);
  std::optional<RawCorrelation> spread;
  if (RawCorrelation::fits(b.info.frames, b.info.fs, spread_options)) spread.emplace(b.info.frames, b.info.fs, spread_options, plans);
  // 16-bit counts are read as they are stored (volts = count x quantum, exact in double).
  const bool counts = recording.has_int16() && recording.info().quantum > 0.0;
  const double quantum = recording.info().quantum;
  std::vector<float> block(counts ? 0 : static_cast<std::size_t>(options.block_frames) * stride);
  std::vector<std::int16_t> block16(counts ? static_cast<std::size_t>(options.block_frames) * stride : 0);
  std::vector<double> xs, ys;
  std::int64_t position = 0;
  for (;;) {
    const std::int64_t n = counts ? recording.read_int16(block16, options.block_frames)
                                  : recording.read(block, options.block_frames);
    if (n == 0) break;
    xs.resize(static_cast<std::size_t>(n));
    ys.resize(static_cast<std::size_t>(n));
    const auto frames = static_cast<std::size_t>(n);
    if (counts) {
      for (std::size_t f = 0; f < frames; ++f) {
        xs[f] = block16[f * stride + lead] * quantum;
        ys[f] = block16[f * stride + trail] * quantum;
      }
    } else {
      for (std::size_t f = 0; f < frames; ++f) {
        xs[f] = block[f * stride + lead];
        ys[f] = block[f * stride + trail];
      }
    }
    correlation.feed(position, xs, ys);
    if (spread) spread->feed(position, xs, ys);
    position += n;
  }
  if (position != b.info.frames) {
    throw InputError(fmt::format("{}: reading it again for FSCC gave {} frames instead of {}; the file changed while "
                                 "being read",
                                 path.string(), position, b.info.frames));
  }
  auto out = fscc_from_functions(correlation.finish(), options.dx, options.fscc_options);
  if (spread) add_velocity_interval(out, spread->finish(), options.dx);
  return out;
}

ProcessResult process_recording(const std::filesystem::path& path, const ProcessOptions& options) {
  ProcessWorkspace workspace;
  return process_recording(path, options, workspace);
}

ProcessResult process_recording(const std::filesystem::path& path, const ProcessOptions& options,
                                ProcessWorkspace& workspace) {
  options.validate().throw_if_failed();
  auto recording = open_recording(path, options.reader);
  return process_recording(*recording, options, workspace);
}

ProcessResult process_recording(Recording& recording, const ProcessOptions& options) {
  ProcessWorkspace workspace;
  return process_recording(recording, options, workspace);
}

ProcessResult process_recording(Recording& recording, const ProcessOptions& given, ProcessWorkspace& workspace) {
  const auto start = std::chrono::steady_clock::now();
  given.validate().throw_if_failed();
  // The tip pair of a declared (or recorded) probe, once: every step below reads it.
  const ProcessOptions options = tip_pair_options(given, recording.info());
  // Only bubble-by-bubble lags read interface times: a run without them
  // would report numbers the option did not touch as if it had.
  if (options.effective_event_options().interface_times == InterfaceTiming::crossing && !options.events &&
      !wants_multi_tip(options.multi_tip, options.tip_channels().size())) {
    throw OptionError(
        fmt::format("{}: interface-times = crossing times the interfaces of event detection and of the multi-tip "
                    "pairing, and this run does neither (FSCC and AWCC correlate whole signals; their lags below a "
                    "sample come from subsample): add events to the method (method = events, or awcc+events), or "
                    "process a probe of four or more tips; or leave interface-times at midpoint",
                    recording.info().path.string()),
        "interface-times");
  }
  if (given.hash_input) recording.hash_while_reading();
  recording.rewind();
  // From the options as given: a declared probe's positions are the binarised tips'.
  auto binarised = binarise_recording(recording, given);
  if (options.effective_event_options().interface_times == InterfaceTiming::crossing) {
    auto timed = threshold_crossings(recording, binarised, given);
    binarised.crossings = std::move(timed.tips);
    binarised.crossings_note = std::move(timed.note);
  }
  ProcessResult out;
  if (options.awcc_options.signal == CorrelationSignal::binary) {
    out = process_binarised(binarised, options);
  } else {
    out = started(binarised.info, options);
    if (options.fscc) out.fscc = fscc_raw(recording, binarised, options, workspace.plans);
    if (options.awcc) out.awcc = awcc_raw(recording, binarised, options, workspace.awcc);
    finish(out, binarised, options);
  }
  // Whatever the reading did not hash (nothing, for a container read front to back) is read here.
  if (given.hash_input) out.input_sha256 = recording.sha256();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace awcc
