#include "awcc/serialise.hpp"

#include <fmt/format.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <span>

#include "awcc/csv.hpp"
#include "awcc/options.hpp"
#include "awcc/sha256.hpp"
#include "awcc/version.hpp"

namespace awcc {

std::string awcc_windows_csv(const AwccResult& result) {
  std::string out = "start_time,duration,particles,lag,velocity,r12_max,spr,void_fraction,count_rate,fate\n";
  for (const auto& w : result.windows) {
    out += fmt::format("{:.9g},{:.9g},{},{:.9g},{:.9g},{:.6f},{:.6f},{:.6f},{:.6g},{}\n", w.start_time, w.duration,
                       w.particles, w.lag, w.velocity, w.r12_max, w.spr, w.void_fraction, w.count_rate,
                       to_string(w.fate));
  }
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

namespace {

template <class T>
void add_options(json& out, std::span<const OptionField<T>> fields, const T& target) {
  for (const auto& f : fields) out[std::string(f.name)] = f.format(target);
}

}  // namespace

json options_json(const ProcessOptions& o) {
  json out = json::object();
  add_options(out, process_option_fields(), o);
  add_options(out, reader_option_fields(), o.reader);
  add_options(out, binarisation_option_fields(), o.binarisation);
  add_options(out, fscc_option_fields(), o.fscc_options);
  add_options(out, awcc_option_fields(), o.awcc_options);
  return out;
}

json provenance_json(const ProcessOptions& options, const std::vector<std::string>& inputs,
                     const std::string& command_line) {
  json files = json::array();
  for (const auto& path : inputs) {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(path, ec);
    files.push_back(json{{"file", path}, {"bytes", ec ? json(nullptr) : json(bytes)}, {"sha256", sha256_of_file(path)}});
  }
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return json{{"pdp_version", version},
              {"command_line", command_line},
              {"options", options_json(options)},
              {"inputs", files},
              {"utc_time", when}};
}

json to_json(const AwccOptions& o) {
  return json{{"np", o.np},
              {"filter_a", o.filter_a},
              {"roc", o.roc},
              {"weighting", to_string(o.weighting)},
              {"signal", to_string(o.signal)},
              {"subsample", to_string(o.subsample)},
              {"prominence_fraction", o.prominence_fraction},
              {"velocity_min", optional(o.velocity_min)},
              {"velocity_max", optional(o.velocity_max)}};
}

json to_json(const ProcessResult& r) {
  json tips = json::array();
  for (const auto& t : r.tips) {
    const auto& p = t.phase;
    json tip{
        {"channel", t.channel},
        {"name", t.name.empty() ? json(nullptr) : json(t.name)},
        {"status", to_string(p.status)},
        {"status_message", p.message.empty() ? json(nullptr) : json(p.message)},
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
      {"warnings", r.info.warnings},
      {"chord_velocity_source", to_string(r.velocity_source())},
      {"chord_velocity", optional(r.velocity())},
  };
  if (r.fscc) {
    const auto& f = *r.fscc;
    out["fscc"] = json{
        {"status", to_string(f.status)},
        {"defined", f.ok()},
        {"reason", f.ok() ? json(nullptr) : json(f.message)},
        {"velocity", f.ok() ? json(f.velocity) : json(nullptr)},
        {"lag", f.lag},
        {"lag_samples", f.lag_samples},
        {"r12_max", f.r12_max},
        {"t05", optional(f.t05)},
        {"tau05", optional(f.tau05)},
        {"txx", optional(f.txx)},
        {"txy", optional(f.txy)},
        {"turbulence_intensity_chanson", optional(f.turbulence_intensity_chanson)},
        {"note", f.note.empty() ? json(nullptr) : json(f.note)},
        {"warnings", f.warnings},
    };
  }
  if (r.awcc) {
    const auto& a = *r.awcc;
    auto value = [&](double v) { return a.ok() ? json(v) : json(nullptr); };
    auto interval = [&](const Interval95& i) { return a.ok() ? ci(i) : json(nullptr); };
    out["awcc"] = json{
        {"status", to_string(a.status)},
        {"defined", a.ok()},
        {"reason", a.ok() ? json(nullptr) : json(a.message)},
        {"np", a.np},
        {"options", to_json(a.options)},
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
        {"windows_rejected_too_short", a.rejected_too_short},
        {"windows_lag_zero", a.lag_zero_windows},
        {"roc_iterations", a.roc_iterations},
        {"windows_negative_lag", a.negative_lag_windows},
        {"quality", to_string(a.quality)},
        {"quality_reason", a.quality_reason.empty() ? json(nullptr) : json(a.quality_reason)},
        {"yield", a.windows_total > 0 ? json(static_cast<double>(a.windows_accepted) /
                                              static_cast<double>(a.windows_total))
                                        : json(nullptr)},
    };
  }
  return out;
}

std::string profile_csv_header() {
  return "file,position,void_fraction,bubble_count_rate,chord_time_mean,chord_time_median,threshold,"
         "void_fraction_trailing,bubble_count_rate_trailing,fscc_velocity,fscc_lag,fscc_r12_max,fscc_t05,fscc_tau05,"
         "fscc_turbulence_intensity_chanson,sauter_diameter,fscc_reason,awcc_velocity,awcc_velocity_rms,"
         "awcc_turbulence_intensity,awcc_windows_accepted,awcc_windows_total,awcc_reason,fscc_status,awcc_status,dx,dy,"
         "np,awcc_filter_a,awcc_roc,awcc_weighting,awcc_signal,awcc_subsample,fs,duration,awcc_quality,"
         "awcc_quality_reason,void_fraction_ci95_lower,void_fraction_ci95_upper,bubble_count_rate_ci95_lower,"
         "bubble_count_rate_ci95_upper,awcc_velocity_ci95_lower,awcc_velocity_ci95_upper,awcc_velocity_rms_ci95_lower,"
         "awcc_velocity_rms_ci95_upper,awcc_turbulence_intensity_ci95_lower,awcc_turbulence_intensity_ci95_upper,"
         "chord_velocity_source,pdp_version,warnings";
}

std::string profile_csv_row(const ProcessResult& r, const std::optional<double>& position) {
  const auto& lead = r.tips.at(0).phase;
  const auto& trail = r.tips.at(1).phase;
  const auto& f = r.fscc;
  const auto& a = r.awcc;
  const bool fscc_ok = f && f->ok();
  const bool awcc_ok = a && a->ok();
  auto number = [](double v) { return csv_number(v); };
  std::string out = fmt::format(
      "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csv_cell(r.info.path.filename().string()),
      csv_number(position), number(lead.void_fraction), number(lead.bubble_count_rate),
      number(lead.air_chord_time.mean), number(lead.air_chord_time.median), number(r.tips[0].threshold.threshold),
      number(trail.void_fraction), number(trail.bubble_count_rate),
      csv_number(fscc_ok ? std::optional(f->velocity) : std::nullopt),
      csv_number(f ? std::optional(f->lag) : std::nullopt), csv_number(f ? std::optional(f->r12_max) : std::nullopt),
      csv_number(f ? f->t05 : std::nullopt), csv_number(f ? f->tau05 : std::nullopt),
      csv_number(f ? f->turbulence_intensity_chanson : std::nullopt), csv_number(lead.sauter_diameter),
      csv_cell(f && !f->ok() ? f->message : std::string()));
  out += fmt::format(",{},{},{},{},{},{}", csv_number(awcc_ok ? std::optional(a->velocity) : std::nullopt),
                     csv_number(awcc_ok ? std::optional(a->velocity_rms) : std::nullopt),
                     csv_number(awcc_ok ? std::optional(a->turbulence_intensity) : std::nullopt),
                     a ? std::to_string(a->windows_accepted) : std::string(),
                     a ? std::to_string(a->windows_total) : std::string(),
                     csv_cell(a && !a->ok() ? a->message : std::string()));
  out += fmt::format(",{},{},{},{}", f ? to_string(f->status) : "", a ? to_string(a->status) : "", number(r.dx),
                     number(r.dy));
  if (a) {
    const auto& o = a->options;
    out += fmt::format(",{},{},{},{},{},{}", o.np, number(o.filter_a), o.roc ? "on" : "off", to_string(o.weighting),
                       to_string(o.signal), to_string(o.subsample));
  } else {
    out += ",,,,,,";
  }
  const double duration = r.info.fs > 0 ? static_cast<double>(r.info.frames) / r.info.fs : 0.0;
  auto interval = [&](bool known, const Interval95& i) {
    return known ? fmt::format("{},{}", number(i.lower), number(i.upper)) : std::string(",");
  };
  out += fmt::format(",{},{},{},{},{},{},{},{},{},{},{}", number(r.info.fs), number(duration),
                     a ? to_string(a->quality) : "", csv_cell(a ? a->quality_reason : std::string()),
                     interval(true, lead.void_fraction_ci95), interval(true, lead.bubble_count_rate_ci95),
                     interval(awcc_ok, a ? a->velocity_ci95 : Interval95{}),
                     interval(awcc_ok, a ? a->velocity_rms_ci95 : Interval95{}),
                     interval(awcc_ok, a ? a->turbulence_intensity_ci95 : Interval95{}), to_string(r.velocity_source()),
                     version);
  std::string warnings;
  for (const auto& w : r.info.warnings) warnings += (warnings.empty() ? "" : "; ") + w;
  if (f) {
    for (const auto& w : f->warnings) warnings += (warnings.empty() ? "" : "; ") + w;
  }
  out += "," + csv_cell(warnings);
  return out;
}

std::string ProcessResult::report() const {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line(fmt::format("{}: {}, {} channels, {:.6g} Hz, {} samples ({:.3f} s)", info.path.string(), info.description,
                   info.channels, info.fs, info.frames, info.fs > 0 ? static_cast<double>(info.frames) / info.fs : 0.0));
  for (const auto& w : info.warnings) line("  warning: " + w);
  const char* names[2] = {"leading", "trailing"};
  for (std::size_t i = 0; i < tips.size(); ++i) {
    const auto& t = tips[i];
    const auto& p = t.phase;
    line(fmt::format("  {} tip (channel {}{}): threshold {:.4f} V ({}{}), air {:.4f} V, water {:.4f} V", names[i % 2],
                     t.channel, t.name.empty() ? std::string() : fmt::format(", '{}'", t.name), t.threshold.threshold, to_string(t.threshold.rule),
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
    if (p.status != PhaseStatus::ok) line("    note: " + p.message);
  }
  if (fscc) {
    const auto& f = *fscc;
    if (f.ok()) {
      line(fmt::format("  FSCC: velocity {:.4f} m/s (dx {:.3f} mm / lag {:.4f} ms), R12max {:.4f}", f.velocity, dx * 1e3,
                       f.lag * 1e3, f.r12_max));
    } else {
      line(fmt::format("  FSCC: velocity undefined: {}", f.message));
    }
    auto ms = [](const std::optional<double>& v) { return v ? fmt::format("{:.4f} ms", *v * 1e3) : std::string("n/a"); };
    line(fmt::format("        T05 {}, tau05 {}, Txx {}, Txy {}", ms(f.t05), ms(f.tau05), ms(f.txx), ms(f.txy)));
    line(fmt::format("        Chanson turbulence intensity {}",
                     f.turbulence_intensity_chanson ? fmt::format("{:.4f}", *f.turbulence_intensity_chanson)
                                                    : std::string("n/a")));
    if (!f.note.empty()) line("        note: " + f.note);
    for (const auto& w : f.warnings) line("        warning: " + w);
  }
  if (awcc) {
    const auto& a = *awcc;
    if (a.ok()) {
      line(fmt::format("  AWCC: velocity {:.4f} m/s (95 % CI {:.4f} - {:.4f}), u_rms {:.4f} m/s, Tu {:.4f} (95 % CI "
                       "{:.4f} - {:.4f})",
                       a.velocity, a.velocity_ci95.lower, a.velocity_ci95.upper, a.velocity_rms,
                       a.turbulence_intensity, a.turbulence_intensity_ci95.lower, a.turbulence_intensity_ci95.upper));
    } else {
      line(fmt::format("  AWCC: no velocity: {}", a.message));
    }
    line(fmt::format("        quality {}{}", to_string(a.quality),
                     a.quality == AwccQuality::low ? ": " + a.quality_reason : std::string()));
    line(fmt::format("        windows {} accepted of {} (rejected: {} correlation, {} lag, {} outlier cutoff, {} "
                     "constant{})",
                     a.windows_accepted, a.windows_total, a.rejected_correlation, a.rejected_lag, a.rejected_roc,
                     a.rejected_constant,
                     a.rejected_too_short ? fmt::format(", {} too short", a.rejected_too_short) : std::string()));
  }
  if (const auto s = velocity_source(); s != VelocitySource::awcc && (awcc || fscc)) {
    line(s == VelocitySource::fscc ? "  chord lengths and d32 use FSCC's velocity (AWCC's is not of quality ok)"
                                   : "  chord lengths and d32: no velocity");
  }
  return out;
}

}  // namespace awcc
