#include "process_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <map>
#include <sstream>

#include "awcc/atomic_output.hpp"
#include "awcc/correction.hpp"
#include "awcc/process.hpp"
#include "awcc/units.hpp"
#include "terminal.hpp"

namespace pdp {

CLI::App* setup_process(CLI::App& app, ProcessCommandOptions& o) {
  auto* cmd = app.add_subcommand("process", "Process recordings: binarisation, phase statistics and FSCC");
  cmd->set_config("--config", "", "TOML file of these options ([process] table or top-level keys)");
  cmd->add_option("files", o.files, "recordings (one: a summary; several: a profile, one CSV row each)")
      ->required()
      ->check(CLI::ExistingFile);
  auto probe = "Probe";
  cmd->add_option("--dx", o.dx, "streamwise tip separation, m (units allowed, e.g. 7.15mm); 0 = no velocity")
      ->capture_default_str()->group(probe);
  cmd->add_option("--dy", o.dy, "lateral tip separation, m (reported)")->capture_default_str()->group(probe);
  cmd->add_option("--probe", o.probe, "conductivity (air low) | optical (air high)")
      ->check(CLI::IsMember({"conductivity", "optical"}))->capture_default_str()->group(probe);
  cmd->add_option("--leading-channel", o.leading_channel, "channel of the leading tip (from 0)")
      ->capture_default_str()->group(probe);
  cmd->add_option("--trailing-channel", o.trailing_channel, "channel of the trailing tip (from 0)")
      ->capture_default_str()->group(probe);
  auto input = "Input";
  cmd->add_option("--fs", o.fs, "sampling rate, Hz (required for .dat, raw and CSV without time column; overrides)")
      ->group(input);
  cmd->add_option("--format", o.format, "auto | sndfile | dat | raw | csv")
      ->check(CLI::IsMember({"auto", "sndfile", "dat", "raw", "csv"}))->capture_default_str()->group(input);
  cmd->add_option("--raw-type", o.raw_type, "raw sample type: int16 | int32 | float32 | float64")
      ->check(CLI::IsMember({"int16", "int32", "float32", "float64"}))->capture_default_str()->group(input);
  cmd->add_option("--raw-order", o.raw_order, "raw byte order: little | big")
      ->check(CLI::IsMember({"little", "big"}))->capture_default_str()->group(input);
  cmd->add_option("--raw-channels", o.raw_channels, "raw channel count")->capture_default_str()->group(input);
  cmd->add_option("--raw-header", o.raw_header, "raw header bytes to skip")->capture_default_str()->group(input);
  cmd->add_option("--volts-per-count", o.volts_per_count,
                  "V per integer count (raw default 1; .dat 5/32768; audio: from a .truth.json sidecar, else "
                  "normalised)")->group(input);
  cmd->add_option("--csv-header", o.csv_header, "CSV header row: auto | yes | no")
      ->check(CLI::IsMember({"auto", "yes", "no"}))->capture_default_str()->group(input);
  cmd->add_option("--time-column", o.time_column, "CSV time column: auto (by name) | none | index from 0")
      ->capture_default_str()->group(input);
  auto bin = "Binarisation";
  cmd->add_option("--threshold-rule", o.threshold_rule, "histogram | felder | fixed | hysteresis")
      ->check(CLI::IsMember({"histogram", "felder", "fixed", "hysteresis"}))->capture_default_str()->group(bin);
  cmd->add_option("--threshold", o.threshold,
                  "histogram/felder: fraction from air to water mode [0.5]; fixed: a voltage (e.g. 2.5V); "
                  "hysteresis: two fractions 'low,high' [0.4,0.6]")->group(bin);
  cmd->add_option("--bin-width", o.bin_width, "histogram bin width, V; 0 = 100 bins over the range")
      ->capture_default_str()->group(bin);
  auto corr = "Correlation";
  cmd->add_option("--method", o.method, "awcc | fscc | both")->check(CLI::IsMember({"awcc", "fscc", "both"}))
      ->capture_default_str()->group(corr);
  cmd->add_option("--np", o.np, "AWCC particles (air chords) per window")->check(CLI::Range(1, 1000))
      ->capture_default_str()->group(corr);
  cmd->add_option("--filter-a", o.filter_a, "AWCC correlation filter threshold A: reject R12max/(SPR^2+1) < A")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str()->group(corr);
  cmd->add_option("--roc", o.roc, "AWCC robust outlier cutoff: on | off")->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str()->group(corr);
  cmd->add_option("--weighting", o.weighting, "AWCC moments: duration (window duration weights) | none")
      ->check(CLI::IsMember({"duration", "none"}))->capture_default_str()->group(corr);
  cmd->add_option("--correlate", o.correlate, "AWCC correlates the binary signals or the raw voltages: binary | raw")
      ->check(CLI::IsMember({"binary", "raw"}))->capture_default_str()->group(corr);
  cmd->add_option("--velocity-range", o.velocity_range,
                  "AWCC lags searched from a velocity range 'min,max' (e.g. 0.5m/s,20m/s) [default: all lags]")
      ->group(corr);
  cmd->add_option("--segments", o.segments, "FSCC segments: 1 = full record; Felder used 15")
      ->check(CLI::Range(1, 1000))->capture_default_str()->group(corr);
  cmd->add_option("--max-lag", o.max_lag, "FSCC lags searched: auto [0, max], cross [-max, max], s")
      ->capture_default_str()->group(corr);
  cmd->add_flag("--felder-lags", o.felder_lags,
                "Felder's program: auto lags 0..999, cross -199..800 samples, first peak within 1e-5")->group(corr);
  cmd->add_option("--subsample", o.subsample, "peak refinement: none | parabolic")
      ->check(CLI::IsMember({"none", "parabolic"}))->capture_default_str()->group(corr);
  auto out = "Output";
  cmd->add_option("--json", o.json, "write the results as JSON (keys in docs/output.md)")->group(out);
  cmd->add_option("--csv", o.csv, "profile CSV file (several recordings; default: stdout)")->group(out);
  cmd->add_option("--windows", o.windows, "AWCC per-window table as CSV (one recording)")->group(out);
  cmd->add_option("--positions", o.positions, "profile positions, one per file: '2mm,8mm,...'")->group(out);
  cmd->add_option("--manifest", o.manifest, "profile manifest CSV with columns file,position")
      ->check(CLI::ExistingFile)->group(out);
  cmd->add_option("--histogram-bins", o.histogram_bins, "bins of the chord-time histograms")
      ->check(CLI::Range(1, 100000))->capture_default_str()->group(out);
  cmd->add_option("--correct", o.correct,
                  "bias-correct AWCC's velocity and Tu with this model (.qrf from pdp train; samples/model/awcc.qrf "
                  "ships): adds quantiles to the JSON, CSV and report")
      ->check(CLI::ExistingFile)->group(corr);
  return cmd;
}

namespace {

double quantity(const std::string& text, awcc::Dimension d, std::string_view option) {
  try {
    return awcc::parse_quantity(text, d);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("--{}: {}", option, e.what()));
  }
}

awcc::ProcessOptions build_options(const ProcessCommandOptions& o) {
  using awcc::Dimension;
  awcc::ProcessOptions p;
  p.dx = quantity(o.dx, Dimension::length, "dx");
  p.dy = quantity(o.dy, Dimension::length, "dy");
  if (!o.fs.empty()) p.reader.fs = quantity(o.fs, Dimension::frequency, "fs");
  static const std::map<std::string, awcc::InputFormat> formats{{"auto", awcc::InputFormat::automatic},
                                                                {"sndfile", awcc::InputFormat::sndfile},
                                                                {"dat", awcc::InputFormat::uq_dat},
                                                                {"raw", awcc::InputFormat::raw},
                                                                {"csv", awcc::InputFormat::csv}};
  p.reader.format = formats.at(o.format);
  static const std::map<std::string, awcc::SampleType> types{{"int16", awcc::SampleType::int16},
                                                             {"int32", awcc::SampleType::int32},
                                                             {"float32", awcc::SampleType::float32},
                                                             {"float64", awcc::SampleType::float64}};
  p.reader.raw.sample_type = types.at(o.raw_type);
  p.reader.raw.byte_order = o.raw_order == "big" ? awcc::ByteOrder::big : awcc::ByteOrder::little;
  p.reader.raw.channels = o.raw_channels;
  p.reader.raw.header_bytes = o.raw_header;
  if (!o.volts_per_count.empty()) {
    const double vpc = quantity(o.volts_per_count, Dimension::voltage, "volts-per-count");
    p.reader.volts_per_count = vpc;
    p.reader.raw.volts_per_count = vpc;
  }
  if (o.csv_header != "auto") p.reader.csv.header = o.csv_header == "yes";
  if (o.time_column == "none") p.reader.csv.time_column = -1;
  else if (o.time_column != "auto") p.reader.csv.time_column = static_cast<int>(quantity(o.time_column, Dimension::dimensionless, "time-column"));
  p.leading_channel = o.leading_channel;
  p.trailing_channel = o.trailing_channel;
  auto& b = p.binarisation;
  static const std::map<std::string, awcc::ThresholdRule> rules{{"histogram", awcc::ThresholdRule::histogram},
                                                                {"felder", awcc::ThresholdRule::felder},
                                                                {"fixed", awcc::ThresholdRule::fixed},
                                                                {"hysteresis", awcc::ThresholdRule::hysteresis}};
  b.rule = rules.at(o.threshold_rule);
  b.probe = o.probe == "optical" ? awcc::ProbeType::optical : awcc::ProbeType::conductivity;
  b.bin_width = quantity(o.bin_width, Dimension::voltage, "bin-width");
  if (!o.threshold.empty()) {
    switch (b.rule) {
      case awcc::ThresholdRule::histogram:
      case awcc::ThresholdRule::felder:
        b.theta = quantity(o.threshold, Dimension::dimensionless, "threshold");
        break;
      case awcc::ThresholdRule::fixed:
        b.fixed_threshold = quantity(o.threshold, Dimension::voltage, "threshold");
        break;
      case awcc::ThresholdRule::hysteresis: {
        const auto comma = o.threshold.find(',');
        if (comma == std::string::npos) throw std::invalid_argument("--threshold: hysteresis needs 'low,high', e.g. 0.4,0.6");
        b.hysteresis_low = quantity(o.threshold.substr(0, comma), Dimension::dimensionless, "threshold");
        b.hysteresis_high = quantity(o.threshold.substr(comma + 1), Dimension::dimensionless, "threshold");
        break;
      }
    }
  } else if (b.rule == awcc::ThresholdRule::fixed) {
    throw std::invalid_argument("--threshold-rule fixed needs --threshold with a voltage, e.g. --threshold 2.5V");
  }
  p.fscc_options.segments = o.segments;
  p.fscc_options.max_lag = quantity(o.max_lag, Dimension::time, "max-lag");
  p.fscc_options.felder_lags = o.felder_lags;
  p.fscc_options.subsample = o.subsample == "parabolic" ? awcc::Subsample::parabolic : awcc::Subsample::none;
  p.histogram_bins = o.histogram_bins;
  p.fscc = o.method != "awcc";
  p.awcc = o.method != "fscc";
  auto& a = p.awcc_options;
  a.np = o.np;
  a.filter_a = o.filter_a;
  a.roc = o.roc == "on";
  a.weighting = o.weighting == "none" ? awcc::Weighting::none : awcc::Weighting::duration;
  a.subsample = p.fscc_options.subsample;
  p.correlate_raw = o.correlate == "raw";
  if (!o.velocity_range.empty()) {
    const auto comma = o.velocity_range.find(',');
    if (comma == std::string::npos) {
      throw std::invalid_argument("--velocity-range needs 'min,max', e.g. 0.5m/s,20m/s");
    }
    a.velocity_min = quantity(o.velocity_range.substr(0, comma), Dimension::velocity, "velocity-range");
    a.velocity_max = quantity(o.velocity_range.substr(comma + 1), Dimension::velocity, "velocity-range");
  }
  if (auto why = a.validate(); !why.empty()) throw std::invalid_argument(why);
  if (auto why = p.validate(); !why.empty()) throw std::invalid_argument(why);
  if (!o.windows.empty() && o.files.size() != 1) {
    throw std::invalid_argument("--windows writes the window table of one recording; give one file");
  }
  if (!o.windows.empty() && !p.awcc) throw std::invalid_argument("--windows needs --method awcc or both");
  return p;
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

// Positions per file: from --positions, or a manifest CSV "file,position".
std::vector<std::optional<double>> positions_for(const ProcessCommandOptions& o) {
  std::vector<std::optional<double>> out(o.files.size());
  if (!o.positions.empty()) {
    const auto items = split_list(o.positions);
    if (items.size() != o.files.size()) {
      throw std::invalid_argument(fmt::format("--positions gives {} positions for {} files; give one per file",
                                              items.size(), o.files.size()));
    }
    for (std::size_t i = 0; i < items.size(); ++i) out[i] = quantity(items[i], awcc::Dimension::length, "positions");
  } else if (!o.manifest.empty()) {
    std::ifstream in(o.manifest);
    std::map<std::string, double> by_name;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto cells = split_list(line);
      if (cells.size() < 2) continue;
      try {
        by_name[std::filesystem::path(cells[0]).filename().string()] =
            awcc::parse_quantity(cells[1], awcc::Dimension::length);
      } catch (const std::invalid_argument& e) {
        if (number == 1) continue;  // header row
        throw std::invalid_argument(fmt::format("{}:{}: {}", o.manifest, number, e.what()));
      }
    }
    for (std::size_t i = 0; i < o.files.size(); ++i) {
      const auto name = std::filesystem::path(o.files[i]).filename().string();
      const auto it = by_name.find(name);
      if (it == by_name.end()) {
        throw std::invalid_argument(fmt::format("{}: no position for {}; add a row '{},<position>'", o.manifest, name, name));
      }
      out[i] = it->second;
    }
  }
  return out;
}

std::string csv_number(const std::optional<double>& v) { return v ? fmt::format("{:.10g}", *v) : std::string(); }

std::string profile_csv(const std::vector<awcc::ProcessResult>& results, const std::vector<std::optional<double>>& pos,
                        const std::vector<awcc::Correction>& corrections) {
  std::string out =
      "file,position,void_fraction,bubble_count_rate,chord_time_mean,chord_time_median,threshold,"
      "void_fraction_trailing,bubble_count_rate_trailing,fscc_velocity,fscc_lag,fscc_r12_max,fscc_t05,fscc_tau05,"
      "fscc_turbulence_intensity_chanson,sauter_diameter,fscc_reason,awcc_velocity,awcc_velocity_rms,"
      "awcc_turbulence_intensity,awcc_windows_accepted,awcc_windows_total,awcc_reason";
  out += corrections.empty() ? "\n" : "," + awcc::correction_csv_header() + "\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    const auto& lead = r.tips[0].phase;
    const auto& trail = r.tips[1].phase;
    const auto& f = r.fscc;
    auto clean = [](std::string text) {
      for (auto& ch : text)
        if (ch == ',' || ch == '"' || ch == '\n') ch = ';';
      return text;
    };
    const std::string reason = clean(f && !f->defined ? f->reason : std::string());
    const auto& a = r.awcc;
    const bool awcc_ok = a && a->defined;
    out += fmt::format("{},{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                       r.info.path.filename().string(), csv_number(pos[i]), lead.void_fraction, lead.bubble_count_rate,
                       lead.air_chord_time.mean, lead.air_chord_time.median, r.tips[0].threshold.threshold,
                       trail.void_fraction, trail.bubble_count_rate,
                       csv_number(f && f->defined ? std::optional(f->velocity) : std::nullopt),
                       csv_number(f ? std::optional(f->lag) : std::nullopt),
                       csv_number(f ? std::optional(f->r12_max) : std::nullopt), csv_number(f ? f->t05 : std::nullopt),
                       csv_number(f ? f->tau05 : std::nullopt),
                       csv_number(f ? f->turbulence_intensity_chanson : std::nullopt),
                       csv_number(lead.sauter_diameter), reason,
                       csv_number(awcc_ok ? std::optional(a->velocity) : std::nullopt),
                       csv_number(awcc_ok ? std::optional(a->velocity_rms) : std::nullopt),
                       csv_number(awcc_ok ? std::optional(a->turbulence_intensity) : std::nullopt),
                       a ? std::to_string(a->windows_accepted) : std::string(),
                       a ? std::to_string(a->windows_total) : std::string(),
                       clean(a && !a->defined ? a->reason : std::string()));
    out += corrections.empty() ? "\n" : "," + awcc::correction_csv_cells(corrections[i]) + "\n";
  }
  return out;
}

std::string correction_report(const awcc::Correction& c) {
  if (!c.in_range) return fmt::format("  correction: not corrected: {}\n", c.reason);
  const auto& u = *c.velocity;
  const auto& t = *c.turbulence_intensity;
  return fmt::format(
      "  correction (quantile regression forest):\n"
      "    velocity             {:.4f} m/s median; 80 % {:.4f} - {:.4f}, 95 % {:.4f} - {:.4f} (measured {:.4f})\n"
      "    turbulence intensity {:.4f} median; 80 % {:.4f} - {:.4f}, 95 % {:.4f} - {:.4f} (measured {:.4f})\n",
      u.median(), u.quantiles[1], u.quantiles[5], u.quantiles[0], u.quantiles[6], u.measured, t.median(),
      t.quantiles[1], t.quantiles[5], t.quantiles[0], t.quantiles[6], t.measured);
}

}  // namespace

int run_process(const ProcessCommandOptions& o) {
  awcc::ProcessOptions options;
  std::vector<std::optional<double>> positions;
  std::optional<awcc::CorrectionModel> model;
  try {
    options = build_options(o);
    positions = positions_for(o);
    if (!o.correct.empty() && !options.awcc) {
      throw std::invalid_argument("--correct corrects AWCC's estimates; use --method awcc or both");
    }
    // Inputs are never modified: refuse an output that is one of them.
    for (const auto& output : {o.json, o.csv, o.windows}) {
      if (output.empty() || !std::filesystem::exists(output)) continue;
      for (const auto& input : o.files) {
        if (std::filesystem::equivalent(output, input)) {
          throw std::invalid_argument(fmt::format("{} is an input recording; choose another output file", output));
        }
      }
    }
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  // The model is read before any processing: a damaged one fails fast.
  if (!o.correct.empty()) {
    try {
      model = awcc::CorrectionModel::load(o.correct);
    } catch (const std::exception& e) {
      spdlog::error("--correct: {}", e.what());
      return 2;
    }
  }
  std::vector<awcc::ProcessResult> results;
  try {
    Progress progress("processing");
    for (std::size_t i = 0; i < o.files.size(); ++i) {
      results.push_back(awcc::process_recording(o.files[i], options));
      spdlog::debug("{}: {:.3f} s", o.files[i], results.back().seconds);
      progress(static_cast<double>(i + 1) / static_cast<double>(o.files.size()));
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  std::vector<awcc::Correction> corrections;
  if (model) {
    for (const auto& r : results) {
      std::string why;
      const auto f = awcc::correction_features(r, &why);
      corrections.push_back(f ? model->correct(*f) : awcc::not_corrected(why));
      if (!corrections.back().in_range) {
        spdlog::warn("{}: not corrected: {}", r.info.path.string(), corrections.back().reason);
      }
    }
  }
  auto correction_json = [&](std::size_t i) {
    auto c = awcc::to_json(corrections[i]);
    c["model"] = std::filesystem::path(o.correct).filename().string();
    return c;
  };
  try {
    if (!o.json.empty()) {
      nlohmann::json j;
      if (results.size() == 1) {
        j = awcc::to_json(results[0]);
        if (model) j["correction"] = correction_json(0);
      } else {
        j["profile"] = nlohmann::json::array();
        for (std::size_t i = 0; i < results.size(); ++i) {
          auto row = awcc::to_json(results[i]);
          row["position"] = positions[i] ? nlohmann::json(*positions[i]) : nlohmann::json(nullptr);
          if (model) row["correction"] = correction_json(i);
          j["profile"].push_back(row);
        }
      }
      awcc::write_text_atomically(o.json, j.dump(2) + "\n");
    }
    if (!o.windows.empty() && results[0].awcc) {
      awcc::write_text_atomically(o.windows, awcc::awcc_windows_csv(*results[0].awcc));
    }
    if (results.size() == 1 && o.csv.empty()) {
      fmt::print("{}", results[0].report());
      if (model) fmt::print("{}", correction_report(corrections[0]));
    } else {
      const std::string table = profile_csv(results, positions, corrections);
      if (o.csv.empty()) fmt::print("{}", table);
      else awcc::write_text_atomically(o.csv, table);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}

}  // namespace pdp
