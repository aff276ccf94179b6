#include "awcc/process.hpp"

#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

namespace awcc {

std::string ProcessOptions::validate() const {
  if (leading_channel < 0 || trailing_channel < 0) return "channel indices must be >= 0";
  if (leading_channel == trailing_channel)
    return fmt::format("the leading and trailing tips are both channel {}; choose two channels", leading_channel);
  if (!(dx >= 0.0 && std::isfinite(dx))) return fmt::format("dx = {} m must be >= 0", dx);
  if (auto why = binarisation.validate(); !why.empty()) return why;
  if (auto why = fscc_options.validate(); !why.empty()) return why;
  if (block_frames < 1) return "block_frames must be >= 1";
  return {};
}

namespace {

struct ChannelSelection {
  std::size_t stride, lead, trail;
};

// Two passes over floating (or non-16-bit) samples: histograms, then thresholds.
void binarise_two_pass(Recording& recording, const ProcessOptions& options, const BinarisationOptions& bopt,
                       const ChannelSelection& ch, BinarisedRecording& out) {
  const auto& path = recording.info().path;
  std::vector<float> block(static_cast<std::size_t>(options.block_frames) * ch.stride);
  VoltageHistogram h_lead(recording.info().quantum), h_trail(recording.info().quantum);
  std::int64_t frames = 0;
  for (;;) {
    const std::int64_t n = recording.read(block, options.block_frames);
    if (n == 0) break;
    const auto used = std::span<const float>(block.data(), static_cast<std::size_t>(n) * ch.stride);
    h_lead.add(used, ch.lead, ch.stride);
    h_trail.add(used, ch.trail, ch.stride);
    frames += n;
  }
  if (frames == 0) throw std::runtime_error(fmt::format("{}: the recording holds no samples", path.string()));
  out.leading_threshold = choose_threshold(h_lead, bopt);
  out.trailing_threshold = choose_threshold(h_trail, bopt);
  recording.rewind();
  Binariser b_lead(out.leading_threshold, recording.info().fs), b_trail(out.trailing_threshold, recording.info().fs);
  for (;;) {
    const std::int64_t n = recording.read(block, options.block_frames);
    if (n == 0) break;
    const auto used = std::span<const float>(block.data(), static_cast<std::size_t>(n) * ch.stride);
    b_lead.feed(used, ch.lead, ch.stride);
    b_trail.feed(used, ch.trail, ch.stride);
  }
  out.leading = b_lead.finish();
  out.trailing = b_trail.finish();
  if (out.leading.sample_count != frames) {
    throw std::runtime_error(fmt::format("{}: the second reading gave {} frames instead of {}; the file changed while "
                                         "being read",
                                         path.string(), out.leading.sample_count, frames));
  }
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
    const double c = bopt.fixed_threshold / quantum;
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

}  // namespace

BinarisedRecording binarise_recording(const std::filesystem::path& path, const ProcessOptions& options) {
  if (auto why = options.validate(); !why.empty()) throw std::invalid_argument(why);
  auto recording = open_recording(path, options.reader);
  return binarise_recording(*recording, options);
}

BinarisedRecording binarise_recording(Recording& opened, const ProcessOptions& options) {
  if (auto why = options.validate(); !why.empty()) throw std::invalid_argument(why);
  Recording* recording = &opened;
  const RecordingInfo& info = recording->info();
  const std::filesystem::path& path = info.path;
  const int channels = info.channels;
  for (int c : {options.leading_channel, options.trailing_channel}) {
    if (c >= channels) {
      throw std::runtime_error(fmt::format(
          "{}: channel {} requested but the recording has {} channel{} (numbered from 0); choose "
          "--leading-channel/--trailing-channel within range",
          path.string(), c, channels, channels == 1 ? "" : "s"));
    }
  }
  const ChannelSelection ch{static_cast<std::size_t>(channels), static_cast<std::size_t>(options.leading_channel),
                            static_cast<std::size_t>(options.trailing_channel)};
  BinarisationOptions bopt = options.binarisation;
  if (!info.volts_known && bopt.bin_width > 0.0 && bopt.rule != ThresholdRule::felder) bopt.bin_width = 0.0;

  BinarisedRecording out;
  out.info = info;
  try {
    bool done = false;
    if (options.single_pass && recording->has_int16() && info.quantum > 0.0) {
      std::vector<std::int16_t> block(static_cast<std::size_t>(options.block_frames) * ch.stride);
      std::int64_t n = recording->read_int16(block, options.block_frames);
      const auto band_lead = band_from(block.data(), static_cast<std::size_t>(n), ch.stride, ch.lead, info.quantum, bopt);
      const auto band_trail = band_from(block.data(), static_cast<std::size_t>(n), ch.stride, ch.trail, info.quantum, bopt);
      if (n > 0 && band_lead && band_trail) {
        BandRecorder lead(band_lead->first, band_lead->second), trail(band_trail->first, band_trail->second);
        while (n > 0) {
          lead.feed(block.data(), static_cast<std::size_t>(n), ch.stride, ch.lead);
          trail.feed(block.data(), static_cast<std::size_t>(n), ch.stride, ch.trail);
          n = recording->read_int16(block, options.block_frames);
        }
        out.leading_threshold = choose_threshold(lead.histogram(info.quantum), bopt);
        out.trailing_threshold = choose_threshold(trail.histogram(info.quantum), bopt);
        if (lead.covers(out.leading_threshold, info.quantum) && trail.covers(out.trailing_threshold, info.quantum)) {
          out.leading = lead.resolve(out.leading_threshold, info.quantum, info.fs);
          out.trailing = trail.resolve(out.trailing_threshold, info.quantum, info.fs);
          done = true;
        }
      }
      if (!done) recording->rewind();
    }
    if (!done) binarise_two_pass(*recording, options, bopt, ch, out);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.rfind(path.string(), 0) == 0) throw;
    throw std::runtime_error(fmt::format("{}: {}", path.string(), what));
  }
  if (out.leading.sample_count == 0) {
    throw std::runtime_error(fmt::format("{}: the recording holds no samples", path.string()));
  }
  out.info.frames = out.leading.sample_count;
  return out;
}

std::vector<TipResult> tip_results(const BinarisedRecording& r, const ProcessOptions& options,
                                   std::optional<double> velocity);

std::optional<double> ProcessResult::velocity() const {
  if (awcc && awcc->defined) return awcc->velocity;
  if (fscc && fscc->defined) return fscc->velocity;
  return std::nullopt;
}

ProcessResult process_binarised(const BinarisedRecording& r, const ProcessOptions& options) {
  ProcessResult out;
  out.info = r.info;
  out.dx = options.dx;
  out.dy = options.dy;
  const std::string no_dx = "no tip separation given (--dx): the velocity cannot be computed";
  if (options.fscc) {
    out.fscc = fscc(r.leading, r.trailing, options.dx, options.fscc_options);
    if (!(options.dx > 0.0) && out.fscc->defined) {
      out.fscc->defined = false;
      out.fscc->reason = no_dx;
      out.fscc->velocity = 0.0;
    }
  }
  if (options.awcc && !options.correlate_raw) {
    out.awcc = awcc::awcc(r.leading, r.trailing, options.dx, options.awcc_options);
    if (!(options.dx > 0.0)) {
      out.awcc->defined = false;
      out.awcc->reason = no_dx;
    }
  }
  out.tips = tip_results(r, options, out.velocity());
  return out;
}

std::vector<TipResult> tip_results(const BinarisedRecording& r, const ProcessOptions& options,
                                   std::optional<double> velocity) {
  PhaseStatisticsOptions po;
  po.histogram_bins = options.histogram_bins;
  po.velocity = velocity;
  return {{options.leading_channel, r.leading_threshold, phase_statistics(r.leading, po)},
          {options.trailing_channel, r.trailing_threshold, phase_statistics(r.trailing, po)}};
}

AwccResult awcc_raw(const std::filesystem::path& path, const BinarisedRecording& b, const ProcessOptions& options) {
  const AwccOptions& ao = options.awcc_options;
  if (auto why = ao.validate(); !why.empty()) throw std::invalid_argument(why);
  AwccResult result;
  result.np = ao.np;
  result.windows = awcc_windows(b.leading, ao.np);
  auto recording = open_recording(path, options.reader);
  const auto stride = static_cast<std::size_t>(recording->info().channels);
  const auto lead = static_cast<std::size_t>(options.leading_channel);
  const auto trail = static_cast<std::size_t>(options.trailing_channel);
  std::vector<float> block(static_cast<std::size_t>(options.block_frames) * stride);
  std::vector<double> xs, ys;
  FftPlanCache plans;
  const double fs = b.info.fs;
  std::int64_t position = 0, in_block = 0, block_start = 0;
  std::size_t w = 0;
  // Windows are contiguous: fill each from the blocks as they come.
  while (w < result.windows.size()) {
    AwccWindow& window = result.windows[w];
    if (position >= block_start + in_block) {
      block_start += in_block;
      in_block = recording->read(block, options.block_frames);
      if (in_block == 0) {
        throw std::runtime_error(fmt::format("{}: the recording ended at frame {} while reading it again for AWCC",
                                             path.string(), position));
      }
      continue;
    }
    const std::int64_t end = window.start + window.length;
    const std::int64_t take = std::min(end, block_start + in_block) - position;
    for (std::int64_t i = 0; i < take; ++i) {
      const auto f = static_cast<std::size_t>(position - block_start + i);
      xs.push_back(block[f * stride + lead]);
      ys.push_back(block[f * stride + trail]);
    }
    position += take;
    if (position == end) {
      const auto [k_min, k_max] = awcc_lag_range(window.length, options.dx, fs, ao);
      std::vector<double> r;
      if (k_max >= k_min) r = window_correlation_fft(xs, ys, k_min, k_max, plans);
      analyse_window(window, r, k_min, options.dx, fs, ao);
      xs.clear();
      ys.clear();
      ++w;
    }
  }
  awcc_summarise(result, ao);
  return result;
}

std::string awcc_windows_csv(const AwccResult& result) {
  std::string out = "start_time,duration,particles,lag,velocity,r12_max,spr,void_fraction,count_rate,fate\n";
  for (const auto& w : result.windows) {
    out += fmt::format("{:.9g},{:.9g},{},{:.9g},{:.9g},{:.6f},{:.6f},{:.6f},{:.6g},{}\n", w.start_time, w.duration,
                       w.particles, w.lag, w.velocity, w.r12_max, w.spr, w.void_fraction, w.count_rate,
                       to_string(w.fate));
  }
  return out;
}

ProcessResult process_recording(const std::filesystem::path& path, const ProcessOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const auto binarised = binarise_recording(path, options);
  ProcessResult out = process_binarised(binarised, options);
  if (options.awcc && options.correlate_raw) {
    out.awcc = awcc_raw(path, binarised, options);
    if (!(options.dx > 0.0)) {
      out.awcc->defined = false;
      out.awcc->reason = "no tip separation given (--dx): the velocity cannot be computed";
    }
    out.tips = tip_results(binarised, options, out.velocity());
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

namespace {

using nlohmann::json;

json optional(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json ci(const Interval95& i) { return json::array({i.lower, i.upper}); }

json summary(const Summary& s) {
  json pct = json::object();
  for (std::size_t i = 0; i < s.percentiles.size(); ++i) pct[fmt::format("{:g}", Summary::levels[i])] = s.percentiles[i];
  return json{{"count", s.count}, {"mean", s.mean},       {"median", s.median},         {"std", s.std},
              {"min", s.min},     {"max", s.max},         {"percentiles", pct},         {"mean_ci95", ci(s.mean_ci95)},
              {"median_ci95", ci(s.median_ci95)}};
}

json histogram(const Histogram& h) { return json{{"bin_width", h.bin_width}, {"counts", h.counts}}; }

}  // namespace

json to_json(const ProcessResult& r) {
  json tips = json::array();
  for (const auto& t : r.tips) {
    const auto& p = t.phase;
    json tip{
        {"channel", t.channel},
        {"threshold", t.threshold.threshold},
        {"threshold_rule", std::string(to_string(t.threshold.rule))},
        {"threshold_lower", t.threshold.lower},
        {"threshold_upper", t.threshold.upper},
        {"air_level", t.threshold.air_level},
        {"water_level", t.threshold.water_level},
        {"binary_input", t.threshold.binary_input},
        {"void_fraction", p.void_fraction},
        {"void_fraction_ci95", ci(p.void_fraction_ci95)},
        {"bubble_count_rate", p.bubble_count_rate},
        {"bubble_count_rate_ci95", ci(p.bubble_count_rate_ci95)},
        {"chord_time_mean", p.air_chord_time.mean},
        {"chord_time_median", p.air_chord_time.median},
        {"air_chord_time", summary(p.air_chord_time)},
        {"water_chord_time", summary(p.water_chord_time)},
        {"interarrival_time", summary(p.interarrival_time)},
        {"air_chord_time_histogram", histogram(p.air_chord_histogram)},
        {"water_chord_time_histogram", histogram(p.water_chord_histogram)},
        {"chord_length", p.air_chord_length ? summary(*p.air_chord_length) : json(nullptr)},
        {"sauter_diameter", optional(p.sauter_diameter)},
    };
    if (!t.threshold.note.empty()) tip["threshold_note"] = t.threshold.note;
    tips.push_back(tip);
  }
  json out{
      {"file", r.info.path.string()},
      {"format", r.info.description},
      {"fs", r.info.fs},
      {"samples", r.info.frames},
      {"duration", r.info.fs > 0 ? static_cast<double>(r.info.frames) / r.info.fs : 0.0},
      {"dx", r.dx},
      {"dy", r.dy},
      {"tips", tips},
  };
  if (r.fscc) {
    const auto& f = *r.fscc;
    out["fscc"] = json{
        {"defined", f.defined},
        {"reason", f.defined ? json(nullptr) : json(f.reason)},
        {"velocity", f.defined ? json(f.velocity) : json(nullptr)},
        {"lag", f.lag},
        {"lag_samples", f.lag_samples},
        {"r12_max", f.r12_max},
        {"t05", optional(f.t05)},
        {"tau05", optional(f.tau05)},
        {"txx", optional(f.txx)},
        {"txy", optional(f.txy)},
        {"turbulence_intensity_chanson", optional(f.turbulence_intensity_chanson)},
        {"note", f.note.empty() ? json(nullptr) : json(f.note)},
    };
  }
  if (r.awcc) {
    const auto& a = *r.awcc;
    auto value = [&](double v) { return a.defined ? json(v) : json(nullptr); };
    auto interval = [&](const Interval95& i) { return a.defined ? ci(i) : json(nullptr); };
    out["awcc"] = json{
        {"defined", a.defined},
        {"reason", a.defined ? json(nullptr) : json(a.reason)},
        {"np", a.np},
        {"velocity", value(a.velocity)},
        {"velocity_ci95", interval(a.velocity_ci95)},
        {"velocity_rms", value(a.velocity_rms)},
        {"velocity_rms_ci95", interval(a.velocity_rms_ci95)},
        {"turbulence_intensity", value(a.turbulence_intensity)},
        {"turbulence_intensity_ci95", interval(a.turbulence_intensity_ci95)},
        {"windows_total", a.windows_total},
        {"windows_accepted", a.windows_accepted},
        {"windows_rejected_correlation", a.rejected_correlation},
        {"windows_rejected_lag", a.rejected_lag},
        {"windows_rejected_roc", a.rejected_roc},
        {"windows_rejected_constant", a.rejected_constant},
        {"windows_lag_zero", a.lag_zero_windows},
        {"roc_iterations", a.roc_iterations},
    };
  }
  return out;
}

std::string ProcessResult::report() const {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line(fmt::format("{}: {}, {} channels, {:.6g} Hz, {} samples ({:.3f} s)", info.path.string(), info.description,
                   info.channels, info.fs, info.frames, info.fs > 0 ? static_cast<double>(info.frames) / info.fs : 0.0));
  const char* names[2] = {"leading", "trailing"};
  for (std::size_t i = 0; i < tips.size(); ++i) {
    const auto& t = tips[i];
    const auto& p = t.phase;
    line(fmt::format("  {} tip (channel {}): threshold {:.4f} V ({}{}), air {:.4f} V, water {:.4f} V", names[i % 2],
                     t.channel, t.threshold.threshold, to_string(t.threshold.rule),
                     t.threshold.binary_input ? ", binary input" : "", t.threshold.air_level, t.threshold.water_level));
    line(fmt::format("    void fraction        {:.5f}  (95 % CI {:.5f} - {:.5f})", p.void_fraction,
                     p.void_fraction_ci95.lower, p.void_fraction_ci95.upper));
    line(fmt::format("    bubble count rate    {:.3f} /s  (95 % CI {:.3f} - {:.3f}), {} complete chords",
                     p.bubble_count_rate, p.bubble_count_rate_ci95.lower, p.bubble_count_rate_ci95.upper,
                     p.air_chord_time.count));
    line(fmt::format("    air chord time       mean {:.4f} ms, median {:.4f} ms, std {:.4f} ms", p.air_chord_time.mean * 1e3,
                     p.air_chord_time.median * 1e3, p.air_chord_time.std * 1e3));
    line(fmt::format("    water chord time     mean {:.4f} ms, median {:.4f} ms", p.water_chord_time.mean * 1e3,
                     p.water_chord_time.median * 1e3));
    if (p.air_chord_length) {
      line(fmt::format("    air chord length     mean {:.4f} mm, median {:.4f} mm", p.air_chord_length->mean * 1e3,
                       p.air_chord_length->median * 1e3));
    }
    if (p.sauter_diameter) line(fmt::format("    Sauter diameter d32  {:.4f} mm", *p.sauter_diameter * 1e3));
    if (!t.threshold.note.empty()) line("    note: " + t.threshold.note);
  }
  if (fscc) {
    const auto& f = *fscc;
    if (f.defined) {
      line(fmt::format("  FSCC: velocity {:.4f} m/s (dx {:.3f} mm / lag {:.4f} ms), R12max {:.4f}", f.velocity, dx * 1e3,
                       f.lag * 1e3, f.r12_max));
    } else {
      line(fmt::format("  FSCC: velocity undefined: {}", f.reason));
    }
    auto ms = [](const std::optional<double>& v) { return v ? fmt::format("{:.4f} ms", *v * 1e3) : std::string("n/a"); };
    line(fmt::format("        T05 {}, tau05 {}, Txx {}, Txy {}", ms(f.t05), ms(f.tau05), ms(f.txx), ms(f.txy)));
    line(fmt::format("        Chanson turbulence intensity {}",
                     f.turbulence_intensity_chanson ? fmt::format("{:.4f}", *f.turbulence_intensity_chanson)
                                                    : std::string("n/a")));
    if (!f.note.empty()) line("        note: " + f.note);
  }
  if (awcc) {
    const auto& a = *awcc;
    if (a.defined) {
      line(fmt::format("  AWCC: velocity {:.4f} m/s (95 % CI {:.4f} - {:.4f}), u_rms {:.4f} m/s, Tu {:.4f} (95 % CI "
                       "{:.4f} - {:.4f})",
                       a.velocity, a.velocity_ci95.lower, a.velocity_ci95.upper, a.velocity_rms,
                       a.turbulence_intensity, a.turbulence_intensity_ci95.lower, a.turbulence_intensity_ci95.upper));
    } else {
      line(fmt::format("  AWCC: undefined: {}", a.reason));
    }
    line(fmt::format("        windows {} accepted of {} (rejected: {} correlation, {} lag, {} outlier cutoff, {} "
                     "constant)",
                     a.windows_accepted, a.windows_total, a.rejected_correlation, a.rejected_lag, a.rejected_roc,
                     a.rejected_constant));
  }
  return out;
}

}  // namespace awcc
