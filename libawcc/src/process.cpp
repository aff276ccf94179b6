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

BinarisedRecording binarise_recording(const std::filesystem::path& path, const ProcessOptions& options) {
  if (auto why = options.validate(); !why.empty()) throw std::invalid_argument(why);
  auto recording = open_recording(path, options.reader);
  const RecordingInfo& info = recording->info();
  const int channels = info.channels;
  for (int c : {options.leading_channel, options.trailing_channel}) {
    if (c >= channels) {
      throw std::runtime_error(fmt::format(
          "{}: channel {} requested but the recording has {} channel{} (numbered from 0); choose "
          "--leading-channel/--trailing-channel within range",
          path.string(), c, channels, channels == 1 ? "" : "s"));
    }
  }
  const auto stride = static_cast<std::size_t>(channels);
  const auto lead = static_cast<std::size_t>(options.leading_channel);
  const auto trail = static_cast<std::size_t>(options.trailing_channel);
  std::vector<float> block(static_cast<std::size_t>(options.block_frames) * stride);

  // Pass 1: histograms (only what the rule needs).
  BinarisationOptions bopt = options.binarisation;
  if (!info.volts_known && bopt.bin_width > 0.0 && bopt.rule != ThresholdRule::felder) bopt.bin_width = 0.0;
  VoltageHistogram h_lead(info.quantum), h_trail(info.quantum);
  std::int64_t frames = 0;
  for (;;) {
    const std::int64_t n = recording->read(block, options.block_frames);
    if (n == 0) break;
    const auto used = std::span<const float>(block.data(), static_cast<std::size_t>(n) * stride);
    h_lead.add(used, lead, stride);
    h_trail.add(used, trail, stride);
    frames += n;
  }
  if (frames == 0) throw std::runtime_error(fmt::format("{}: the recording holds no samples", path.string()));
  BinarisedRecording out;
  out.info = info;
  out.info.frames = frames;
  try {
    out.leading_threshold = choose_threshold(h_lead, bopt);
    out.trailing_threshold = choose_threshold(h_trail, bopt);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("{}: {}", path.string(), e.what()));
  }

  // Pass 2: binarise.
  recording->rewind();
  Binariser b_lead(out.leading_threshold, info.fs), b_trail(out.trailing_threshold, info.fs);
  for (;;) {
    const std::int64_t n = recording->read(block, options.block_frames);
    if (n == 0) break;
    const auto used = std::span<const float>(block.data(), static_cast<std::size_t>(n) * stride);
    b_lead.feed(used, lead, stride);
    b_trail.feed(used, trail, stride);
  }
  out.leading = b_lead.finish();
  out.trailing = b_trail.finish();
  if (out.leading.sample_count != frames) {
    throw std::runtime_error(fmt::format("{}: the second reading gave {} frames instead of {}; the file changed while "
                                         "being read",
                                         path.string(), out.leading.sample_count, frames));
  }
  return out;
}

ProcessResult process_binarised(const BinarisedRecording& r, const ProcessOptions& options) {
  ProcessResult out;
  out.info = r.info;
  out.dx = options.dx;
  out.dy = options.dy;
  if (options.fscc) {
    out.fscc = fscc(r.leading, r.trailing, options.dx, options.fscc_options);
    if (!(options.dx > 0.0) && out.fscc->defined) {
      out.fscc->defined = false;
      out.fscc->reason = "no tip separation given (--dx): the velocity cannot be computed";
      out.fscc->velocity = 0.0;
    }
  }
  PhaseStatisticsOptions po;
  po.histogram_bins = options.histogram_bins;
  if (out.fscc && out.fscc->defined) po.velocity = out.fscc->velocity;
  out.tips.push_back({options.leading_channel, r.leading_threshold, phase_statistics(r.leading, po)});
  out.tips.push_back({options.trailing_channel, r.trailing_threshold, phase_statistics(r.trailing, po)});
  return out;
}

ProcessResult process_recording(const std::filesystem::path& path, const ProcessOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ProcessResult out = process_binarised(binarise_recording(path, options), options);
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
  return out;
}

}  // namespace awcc
