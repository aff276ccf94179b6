#include "study/sweep.hpp"

#include "definition.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <span>
#include <sstream>
#include <stdexcept>
#include "awcc/errors.hpp"
#include "correction/features.hpp"
#include "correction/sweep_columns.hpp"
#include "awcc/option_field.hpp"
#include "awcc/settings_file.hpp"

#include "awcc/units.hpp"
#include "awcc/random.hpp"
#include "synth/random.hpp"

namespace study {
namespace {

using detail::dimension_of;

// The run's own fields beside the scene's (synth::scene_fields).
const awcc::OptionField<SweepRun> kRunFields[] = {
    {"np", "-", "points per AWCC window",
     [](SweepRun& run, std::string_view text) {
       const double v = awcc::parse_quantity(text, awcc::Dimension::dimensionless);
       if (v != std::floor(v) || v < 1 || v > 1000) {
         throw std::invalid_argument(fmt::format("{} must be a whole number in [1, 1000]", text));
       }
       run.np = static_cast<int>(v);
     },
     [](const SweepRun& run) { return std::to_string(run.np); }},
    {"anisotropy", "-", "Tu_y/Tu_x = Tu_z/Tu_x, applied when tu-y and tu-z are not set",
     [](SweepRun& run, std::string_view text) {
       run.anisotropy = awcc::parse_quantity(text, awcc::Dimension::dimensionless);
     },
     [](const SweepRun& run) { return fmt::format("{:g}", run.anisotropy); }},
};

bool is_field(const std::string& name) {
  return std::any_of(std::begin(kRunFields), std::end(kRunFields), [&](const auto& f) { return f.name == name; }) ||
         detail::is_scene_field(name);
}

// Applies one value of a field (the run's or the scene's) through the one
// application path; a refused value is awcc::setting_error's, naming
// setting.origin and the field.
void apply(SweepRun& run, const awcc::OptionSetting& setting) {
  const std::span<const awcc::OptionSetting> one(&setting, 1);
  std::vector<bool> used(1, false);
  awcc::apply_settings(std::span<const awcc::OptionField<SweepRun>>(kRunFields), one, run, used);
  if (!used[0]) awcc::apply_settings(synth::scene_fields(), one, run.scene, used);
}

void apply(SweepRun& run, const std::string& name, const std::string& text) { apply(run, {name, text, {}}); }

constexpr const char* kUnknownField = "unknown field; use a scene field's name (velocity, tu, time-scale, void-fraction, "
                                      "bubble-diameter, dx, fs, duration, ...), np or anisotropy";

}  // namespace

SweepDefinition load_sweep(const std::filesystem::path& path) {
  SweepDefinition d;
  const std::string file = path.string();
  auto fail = [&](const std::string& where, const std::string& what) -> void {
    throw awcc::OptionError(fmt::format("{}: {}: {}", file, where, what));
  };
  const auto tables = detail::definition_tables(path);
  std::map<std::string, const awcc::SettingTable*> by_name;
  for (const auto& t : tables) {
    if (t.name.empty()) {
      if (!t.settings.empty()) fail(t.settings.front().key, "must be a table");
      continue;
    }
    if (t.name != "sweep" && t.name != "base" && t.name != "grid" && t.name != "ranges" && t.name != "choices") {
      fail(t.name, "unknown table; use [sweep], [base], [grid], [ranges] and [choices]");
    }
    by_name[t.name] = &t;
  }
  auto table = [&](const char* name) { return by_name.count(name) ? by_name[name]->settings : std::vector<awcc::Setting>{}; };
  if (!by_name.count("sweep")) fail("[sweep]", "missing: give at least mode = \"grid\" or \"monte-carlo\"");
  for (const auto& s : table("sweep")) {
    if (s.key == "mode") {
      if (s.text != "grid" && s.text != "monte-carlo") fail("[sweep] mode", "write \"grid\" or \"monte-carlo\"");
      d.mode = s.text;
    } else if (s.key == "runs" || s.key == "repeat" || s.key == "seed") {
      long long v = 0;
      try {
        v = awcc::parse_whole(s.text, s.key == "seed" ? 0 : 1, std::int64_t{1} << 53);
      } catch (const std::exception&) {
        fail("[sweep] " + s.key, "must be a whole number >= " + std::string(s.key == "seed" ? "0" : "1"));
      }
      if (s.key == "runs") d.runs = v;
      if (s.key == "repeat") d.repeat = v;
      if (s.key == "seed") d.seed = static_cast<std::uint64_t>(v);
    } else {
      fail("[sweep] " + s.key, "unknown key; use mode, runs, repeat, seed");
    }
  }
  if (d.mode == "monte-carlo" && d.runs < 1) fail("[sweep] runs", "monte-carlo needs runs >= 1");
  SweepRun probe;
  // A refused value names the file and the table (the field is the
  // setting's); the quantity stays empty: it is fixed in the file.
  auto check_value = [&](const std::string& in_table, const std::string& name, const std::string& text) {
    SweepRun copy = probe;
    try {
      apply(copy, {name, text, file + ": " + in_table});
    } catch (const std::exception& e) {
      throw awcc::OptionError(e.what());
    }
  };
  for (const auto& s : table("base")) {
    if (!is_field(s.key)) fail("[base] " + s.key, kUnknownField);
    check_value("[base]", s.key, s.text);
    d.base[s.key] = s.text;
  }
  for (const auto& s : table("grid")) {
    if (!is_field(s.key)) fail("[grid] " + s.key, kUnknownField);
    if (s.items.empty()) fail("[grid] " + s.key, "must be a non-empty list of values");
    for (const auto& text : s.items) {
      check_value("[grid]", s.key, text);
      d.grid[s.key].push_back(text);
    }
  }
  if (d.mode == "monte-carlo") {
    d.ranges = {{"velocity", {1.0, 50.0}},       {"tu", {0.0, 0.35}},       {"time-scale", {1e-3, 1.0}},
                {"void-fraction", {0.005, 0.4}}, {"bubble-diameter", {0.5e-3, 20e-3}}, {"dx", {0.5e-3, 10e-3}}};
  }
  for (const auto& s : table("ranges")) {
    if (!is_field(s.key)) fail("[ranges] " + s.key, kUnknownField);
    const bool log = s.items.size() == 3 && s.items[2] == "log";
    if (s.items.size() != 2 && !log) fail("[ranges] " + s.key, "must be [min, max], or [min, max, \"log\"] for a log-uniform draw");
    double ends[2];
    for (std::size_t i = 0; i < 2; ++i) {
      try {
        ends[i] = awcc::parse_quantity(s.items[i], dimension_of(s.key));
      } catch (const std::exception& e) {
        fail("[ranges] " + s.key, e.what());
      }
    }
    if (!(ends[0] <= ends[1])) fail("[ranges] " + s.key, "min must not exceed max");
    if (log && !(ends[0] > 0.0)) fail("[ranges] " + s.key, "a log-uniform range needs min > 0");
    if (log && s.key == "time-scale") fail("[ranges] " + s.key, "the time scale is drawn log-normally already; drop \"log\"");
    d.ranges[s.key] = {ends[0], ends[1]};
    if (log) d.log_ranges.insert(s.key);
  }
  for (const auto& s : table("choices")) {
    if (d.mode != "monte-carlo") fail("[choices] " + s.key, "choices are drawn per run: use them in a monte-carlo sweep");
    if (!is_field(s.key)) fail("[choices] " + s.key, kUnknownField);
    if (s.items.size() < 2) fail("[choices] " + s.key, "must be a list of at least two values, one drawn per run");
    const auto ranged = table("ranges");
    if (d.base.count(s.key) ||
        std::any_of(ranged.begin(), ranged.end(), [&](const awcc::Setting& r) { return r.key == s.key; })) {
      fail("[choices] " + s.key, "also set in [base] or [ranges]: give the field in one table");
    }
    d.ranges.erase(s.key);  // a Monte Carlo default range gives way to the choices
    d.log_ranges.erase(s.key);
    for (const auto& text : s.items) {
      check_value("[choices]", s.key, text);
      d.choices[s.key].push_back(text);
    }
  }
  if (d.mode == "grid" && d.grid.empty()) fail("[grid]", "a grid sweep needs at least one list of values");
  // Canonical text: every setting, sorted.
  std::string c = fmt::format("mode={};runs={};repeat={};seed={};", d.mode, d.runs, d.repeat, d.seed);
  for (const auto& [k, v] : d.base) c += fmt::format("base.{}={};", k, v);
  for (const auto& [k, v] : d.grid) {
    c += "grid." + k + "=";
    for (const auto& x : v) c += x + ",";
    c += ";";
  }
  if (d.mode == "monte-carlo") {
    // Uniform ranges keep the text they had before log ranges existed (studies resume).
    for (const auto& [k, v] : d.ranges)
      c += fmt::format("ranges.{}={:.17g},{:.17g}{};", k, v.first, v.second, d.log_ranges.count(k) ? ",log" : "");
    for (const auto& [k, v] : d.choices) {
      c += "choices." + k + "=";
      for (const auto& x : v) c += x + ",";
      c += ";";
    }
  }
  d.canonical = c;
  return d;
}

std::vector<SweepRun> SweepDefinition::expand() const {
  std::vector<SweepRun> out;
  SweepRun base_run;
  for (const auto& [k, v] : base) apply(base_run, k, v);
  auto finish = [&](SweepRun run, bool tu_y_set, bool tu_z_set) {
    if (!tu_y_set) run.scene.tu_y = run.anisotropy * run.scene.tu;
    if (!tu_z_set) run.scene.tu_z = run.anisotropy * run.scene.tu;
    return run;
  };
  auto set_in = [&](const std::string& name) {
    return base.count(name) || grid.count(name) || ranges.count(name) || choices.count(name);
  };
  const bool tu_y_set = set_in("tu-y"), tu_z_set = set_in("tu-z");
  std::int64_t index = 0;
  if (mode == "grid") {
    std::vector<std::pair<std::string, std::vector<std::string>>> axes(grid.begin(), grid.end());
    std::vector<std::size_t> at(axes.size(), 0);
    for (;;) {
      SweepRun run = base_run;
      for (std::size_t a = 0; a < axes.size(); ++a) apply(run, axes[a].first, axes[a].second[at[a]]);
      run = finish(run, tu_y_set, tu_z_set);
      for (std::int64_t r = 0; r < repeat; ++r) {
        SweepRun copy = run;
        copy.index = index;
        copy.scene.seed = awcc::derive_seed(seed, static_cast<std::uint64_t>(index));
        out.push_back(copy);
        ++index;
      }
      std::size_t a = 0;
      while (a < axes.size() && ++at[a] == axes[a].second.size()) at[a++] = 0;
      if (a == axes.size()) break;
    }
  } else {
    for (std::int64_t set = 0; set < runs; ++set) {
      // Parameters from their own stream, keyed by the parameter set.
      synth::Rng rng(awcc::derive_seed(seed, static_cast<std::uint64_t>(set)), synth::Stream::bubbles);
      SweepRun run = base_run;
      for (const auto& [k, range] : ranges) {
        double v;
        if (k == "time-scale") {
          const double lo = std::log(range.first), hi = std::log(range.second);
          const double mid = 0.5 * (lo + hi), sd = (hi - lo) / 4.0;
          double z;
          do z = rng.normal(); while (std::fabs(z) > 2.0);
          v = std::exp(mid + sd * z);
        } else if (log_ranges.count(k)) {
          v = std::exp(std::log(range.first) + (std::log(range.second) - std::log(range.first)) * rng.uniform());
        } else {
          v = range.first + (range.second - range.first) * rng.uniform();
        }
        if (k == "np") v = std::round(v);
        // Every digit of the draw, in SI with its unit.
        apply(run, k, fmt::format("{:.17g}{}", v, awcc::si_unit(dimension_of(k))));
      }
      // After the ranges, so that a sweep without choices draws what it drew
      // before choices existed.
      for (const auto& [k, values] : choices) {
        const auto n = values.size();
        apply(run, k, values[std::min(n - 1, static_cast<std::size_t>(rng.uniform() * static_cast<double>(n)))]);
      }
      run = finish(run, tu_y_set, tu_z_set);
      for (std::int64_t r = 0; r < repeat; ++r) {
        SweepRun copy = run;
        copy.index = index;
        copy.scene.seed = awcc::derive_seed(seed ^ 0x5eedull, static_cast<std::uint64_t>(index));
        out.push_back(copy);
        ++index;
      }
    }
  }
  return out;
}

std::uint64_t study_id(const SweepDefinition& d) { return detail::definition_id(d.canonical); }

namespace {

std::string csv_field_name(std::string_view name) {
  std::string s(name);
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

std::string num(const std::optional<double>& v) { return v ? fmt::format("{:.10g}", *v) : std::string(); }

std::string clean(std::string s) {
  for (auto& c : s)
    if (c == ',' || c == '\n' || c == '"' || c == '\r') c = ';';
  return s;
}

}  // namespace

std::string sweep_header() {
  std::vector<std::string> scene;
  for (const auto& f : synth::scene_fields())
    if (f.name != "seed") scene.push_back(csv_field_name(f.name));
  return correction::sweep_csv_header(scene);
}

bool sets(const SweepDefinition& d, const std::string& name) {
  return d.base.count(name) || d.grid.count(name) || d.ranges.count(name) || d.choices.count(name);
}

std::string sweep_row(const SweepRun& run, const RunResult* r, const std::string& error, std::uint64_t study,
                      const awcc::AwccOptions& processing) {
  std::string row = fmt::format("{},{},{}", study, run.index, run.scene.seed);
  for (const auto& f : synth::scene_fields()) {
    if (f.name == "seed") continue;
    std::string v = f.format(run.scene);
    if (f.name == "time-scale-y" || f.name == "time-scale-z") {
      v = fmt::format("{:.10g}", run.scene.time_scale_of(f.name == "time-scale-y" ? 1 : 2));
    } else if (f.dimension != awcc::Dimension::dimensionless || f.name == "tu" || f.name.rfind("tu-", 0) == 0 ||
               f.name.rfind("rho", 0) == 0 || f.name == "void-fraction" || f.name == "diameter-log-sd" ||
               f.name == "aspect-ratio") {
      // Numbers in SI without units, so that the CSV reads as numbers.
      try {
        v = fmt::format("{:.10g}", awcc::parse_quantity(v, f.dimension));
      } catch (const std::exception&) {
      }
    }
    row += ',';
    row += clean(v);
  }
  using correction::SweepColumn;
  std::array<std::string, correction::sweep_result_column_count> cells;
  auto cell = [&](SweepColumn c) -> std::string& { return cells[static_cast<std::size_t>(c)]; };
  cell(SweepColumn::np) = std::to_string(run.np);
  cell(SweepColumn::anisotropy) = fmt::format("{:.10g}", run.anisotropy);
  auto finish = [&](double dx, double dy) {
    cell(SweepColumn::probe_dx) = fmt::format("{:.10g}", dx);
    cell(SweepColumn::probe_dy) = fmt::format("{:.10g}", dy);
    cell(SweepColumn::awcc_filter_a) = fmt::format("{:.10g}", processing.filter_a);
    cell(SweepColumn::awcc_roc) = correction::roc_text(processing.roc);
    cell(SweepColumn::awcc_weighting) = awcc::to_string(processing.weighting);
    cell(SweepColumn::awcc_signal) = awcc::to_string(processing.signal);
    cell(SweepColumn::awcc_subsample) = awcc::to_string(processing.subsample);
    cell(SweepColumn::generator_version) = std::to_string(awcc::generator_version);
    for (const auto& c : cells) row += "," + c;
    return row;
  };
  if (!r) {
    cell(SweepColumn::reason) = clean(error);
    return finish(run.scene.streamwise_separation(), run.scene.lateral_separation());
  }
  // What the correction reads is the measurement's; the scores are of what
  // pdp process reports.
  const auto& m = r->measurement.measurement;
  const auto& fscc = r->processed.fscc;
  const auto& awcc = r->processed.awcc;
  auto count = [](std::int64_t n) { return n >= 0 ? std::to_string(n) : std::string(); };
  std::string reason = error;
  if (awcc && !awcc->ok()) reason += "awcc: " + awcc->message;
  else if (r->measurement.status == correction::CorrectionStatus::probe_corrected) reason += "awcc: " + r->measurement.message;
  cell(SweepColumn::truth_velocity) = num(r->truth_velocity);
  cell(SweepColumn::truth_turbulence_intensity) = num(r->truth_turbulence_intensity);
  cell(SweepColumn::truth_void_fraction) = num(r->truth_void_fraction);
  cell(SweepColumn::truth_count_rate) = num(r->truth_count_rate);
  cell(SweepColumn::truth_d32) = num(r->truth_d32);
  cell(SweepColumn::awcc_velocity) = num(m.velocity);
  cell(SweepColumn::awcc_turbulence_intensity) = num(m.turbulence_intensity);
  cell(SweepColumn::awcc_void_fraction) = num(m.void_fraction);
  cell(SweepColumn::awcc_count_rate) = num(m.bubble_count_rate);
  cell(SweepColumn::awcc_d32) = num(r->awcc_d32.value);
  cell(SweepColumn::awcc_windows_accepted) = count(m.windows_accepted);
  cell(SweepColumn::awcc_windows_total) = count(m.windows_total);
  cell(SweepColumn::awcc_velocity_error) = num(r->awcc_velocity.error());
  cell(SweepColumn::awcc_turbulence_intensity_error) = num(r->awcc_turbulence_intensity.error());
  cell(SweepColumn::awcc_d32_error) = num(r->awcc_d32.error());
  cell(SweepColumn::fscc_velocity) = num(m.fscc_velocity);
  cell(SweepColumn::fscc_turbulence_intensity_chanson) = num(fscc ? fscc->turbulence_intensity_chanson : std::nullopt);
  cell(SweepColumn::fscc_r12_max) = num(fscc ? std::optional(fscc->r12_max) : std::nullopt);
  cell(SweepColumn::fscc_velocity_error) = num(r->fscc_velocity.error());
  cell(SweepColumn::window_bias) = num(r->window_bias);
  cell(SweepColumn::window_rms) = num(r->window_rms);
  // FSCC and AWCC run together, as in pdp process: their own seconds are not
  // measured (seconds_fscc and seconds_awcc stay empty).
  cell(SweepColumn::truth_velocity_y) = num(r->multi_tip_velocity[1].truth);
  cell(SweepColumn::truth_velocity_z) = num(r->multi_tip_velocity[2].truth);
  cell(SweepColumn::truth_turbulence_intensity_y) = num(r->multi_tip_turbulence_intensity[1].truth);
  cell(SweepColumn::truth_turbulence_intensity_z) = num(r->multi_tip_turbulence_intensity[2].truth);
  cell(SweepColumn::truth_interfacial_area) = num(r->multi_tip_interfacial_area.truth);
  if (const auto& probe = r->processed.probe) {
    constexpr SweepColumn velocity[] = {SweepColumn::multi_tip_velocity_x, SweepColumn::multi_tip_velocity_y,
                                        SweepColumn::multi_tip_velocity_z};
    constexpr SweepColumn tu[] = {SweepColumn::multi_tip_turbulence_intensity_x,
                                  SweepColumn::multi_tip_turbulence_intensity_y,
                                  SweepColumn::multi_tip_turbulence_intensity_z};
    for (std::size_t i = 0; i < 3; ++i) {
      cell(velocity[i]) = num(r->multi_tip_velocity[i].value);
      cell(tu[i]) = num(r->multi_tip_turbulence_intensity[i].value);
    }
    cell(SweepColumn::multi_tip_interfacial_area) = num(r->multi_tip_interfacial_area.value);
    cell(SweepColumn::multi_tip_quality) = std::string(awcc::to_string(probe->quality));
    cell(SweepColumn::multi_tip_bubbles_accepted) = count(probe->vectors.bubbles_accepted);
  }
  if (awcc && awcc->ok() && processing.weighting == awcc::Weighting::duration && !awcc->probe_corrected) {
    const auto [mean, rms] = awcc::accepted_moments(awcc->windows, awcc::Weighting::none);
    cell(SweepColumn::awcc_velocity_unweighted) = num(mean);
    cell(SweepColumn::awcc_turbulence_intensity_unweighted) = num(rms / mean);
  }
  cell(SweepColumn::awcc_time_scale_ratio) = num(m.time_scale_ratio);
  if (awcc && awcc->ok() && awcc->weighting_gap) {
    cell(SweepColumn::awcc_weighting_gap) = num(awcc->weighting_gap->value);
    cell(SweepColumn::awcc_weighting_gap_ci95_lower) = num(awcc->weighting_gap->ci95.lower);
    cell(SweepColumn::awcc_weighting_gap_ci95_upper) = num(awcc->weighting_gap->ci95.upper);
  }
  cell(SweepColumn::seconds_synth) = fmt::format("{:.4f}", r->seconds_synth);
  cell(SweepColumn::seconds_process) = fmt::format("{:.4f}", r->seconds_process);
  cell(SweepColumn::reason) = clean(reason);
  return finish(m.dx, m.dy);
}

std::string run_sweep_row(const SweepRun& run, const RunOptions& options, std::uint64_t study) {
  RunOptions o = options;
  o.awcc.np = run.np;
  try {
    const RunResult r = run_scene(run.scene, o);
    return sweep_row(run, &r, "", study, o.awcc) + "\n";
  } catch (const std::exception& e) {
    return sweep_row(run, nullptr, e.what(), study, o.awcc) + "\n";
  }
}

std::set<std::int64_t> finished_runs(const std::filesystem::path& csv, std::uint64_t study) {
  std::set<std::int64_t> done;
  std::error_code ec;
  if (!std::filesystem::exists(csv, ec) || std::filesystem::file_size(csv, ec) == 0) return done;
  std::string content;
  {
    std::ifstream in(csv, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    content = ss.str();
  }
  const std::string header = sweep_header();
  const auto first_newline = content.find('\n');
  const std::string_view first_line =
      first_newline == std::string::npos ? std::string_view(content) : std::string_view(content).substr(0, first_newline);
  // A sweep of an earlier pdp: its header is a beginning of this one (columns
  // are only ever added at the end, sweep_columns.hpp).
  if (first_line.size() < header.size() && header.starts_with(first_line) && header[first_line.size()] == ',') {
    const std::string_view missing = std::string_view(header).substr(first_line.size() + 1);
    if (missing.starts_with(correction::column_name(correction::SweepColumn::generator_version))) {
      throw awcc::InputError(fmt::format(
          "{}: written by pdp's generator version 1 (before the column generator_version); this pdp's generator is "
          "version {}, whose streams give other scenes for the same seeds; refusing to resume it: write the study to "
          "another file",
          csv.string(), awcc::generator_version));
    }
    throw awcc::InputError(fmt::format(
        "{}: written by an earlier pdp, whose rows end before the columns {}; refusing to resume it (its rows would "
        "lack them): write the study to another file",
        csv.string(), missing));
  }
  if (first_newline == std::string::npos || first_line != header) {
    throw awcc::InputError(fmt::format(
        "{}: not a pdp sweep CSV (its header differs); refusing to append to it: write the study to another file or "
        "remove this one",
        csv.string()));
  }
  // A crash can leave a partial last row: cut it off.
  const auto last_newline = content.rfind('\n');
  if (last_newline + 1 != content.size()) {
    std::filesystem::resize_file(csv, last_newline + 1);
    content.resize(last_newline + 1);
  }
  const auto columns = static_cast<std::size_t>(std::count(header.begin(), header.end(), ',') + 1);
  std::size_t pos = first_newline + 1;
  std::int64_t line = 1;
  while (pos < content.size()) {
    const auto end = content.find('\n', pos);
    const std::string_view row(content.data() + pos, end - pos);
    ++line;
    const auto cells = static_cast<std::size_t>(std::count(row.begin(), row.end(), ',') + 1);
    const auto c1 = row.find(','), c2 = row.find(',', c1 + 1);
    std::uint64_t id = 0;
    std::int64_t run = -1;
    try {
      id = std::stoull(std::string(row.substr(0, c1)));
      run = std::stoll(std::string(row.substr(c1 + 1, c2 - c1 - 1)));
    } catch (const std::exception&) {
      run = -1;
    }
    if (cells != columns || run < 0 || c1 == std::string_view::npos) {
      throw awcc::InputError(fmt::format("{}:{}: malformed row; the file is not a sweep CSV written by pdp; refusing "
                                         "to append to it",
                                         csv.string(), line));
    }
    if (id != study) {
      throw awcc::InputError(fmt::format("{}:{}: the row belongs to another study (its sweep definition differs); "
                                         "write this study to another file",
                                         csv.string(), line));
    }
    // The generator version of the row's streams, `after` cells from the end
    // (no cell holds a comma: sweep_row cleans them).
    constexpr auto after = correction::sweep_result_column_count - 1 -
                           static_cast<std::size_t>(correction::SweepColumn::generator_version);
    std::size_t version_end = row.size();
    for (std::size_t k = 0; k < after; ++k) version_end = row.rfind(',', version_end - 1);
    const std::size_t version_start = row.rfind(',', version_end - 1) + 1;
    const std::string_view version = row.substr(version_start, version_end - version_start);
    if (version != std::to_string(awcc::generator_version)) {
      throw awcc::InputError(fmt::format("{}:{}: the run was made by generator version '{}', this pdp's is {}: the same "
                                         "seeds give other scenes; refusing to mix them: write the study to another file",
                                         csv.string(), line, version, awcc::generator_version));
    }
    done.insert(run);
    pos = end + 1;
  }
  return done;
}

}  // namespace study
