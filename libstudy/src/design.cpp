#include "study/design.hpp"

#include "definition.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <tuple>

#include "awcc/atomic_output.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/random.hpp"
#include "awcc/settings_file.hpp"
#include "awcc/units.hpp"
#include "awcc/probe_correction.hpp"
#include "correction/features.hpp"
#include "study/clock.hpp"
#include "study/run.hpp"
#include "synth/random.hpp"
#include "synth/synthesiser.hpp"

namespace study {
namespace {

// The flow quantities of a condition that may be ranges.
const std::set<std::string> kRangeable{"velocity", "tu", "anisotropy", "time-scale", "void-fraction",
                                       "bubble-diameter"};

using detail::dimension_of;
using detail::is_scene_field;

std::string num(double v) { return fmt::format("{:.10g}", v); }
std::string num(const std::optional<double>& v) { return v ? num(*v) : std::string(); }

}  // namespace

std::string describe(const DesignCandidate& c) {
  return fmt::format("dx {:g} mm, dy {:g} mm, Np {}, {:g} kHz, {:g} s{}", c.dx * 1e3, c.dy * 1e3, c.np, c.fs / 1e3,
                     c.duration, c.needle > 0.0 ? fmt::format(", needle {:g} mm", c.needle * 1e3) : "");
}

namespace {

// The checks of a design file, each naming the file, the table and key, and the fix.
struct DesignFile {
  std::string file;

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw awcc::OptionError(fmt::format("{}: {}: {}", file, where, what));
  }
  double quantity(const std::string& where, const std::string& text, awcc::Dimension dim) const {
    try {
      return awcc::parse_quantity(text, dim);
    } catch (const std::exception& e) {
      fail(where, e.what());
    }
  }
  long long whole(const std::string& where, const std::string& text, std::int64_t lo, std::int64_t hi) const {
    try {
      return awcc::parse_whole(text, lo, hi);
    } catch (const std::exception&) {
      fail(where, fmt::format("must be a whole number from {} to {}", lo, hi));
    }
  }

  void read_design(const awcc::SettingTable& t, DesignDefinition& d) const {
    for (const auto& s : t.settings) {
      const std::string where = "[design] " + s.key;
      if (s.key == "seeds") d.seeds = static_cast<int>(whole(where, s.text, 2, 1000));
      else if (s.key == "seed") d.seed = static_cast<std::uint64_t>(whole(where, s.text, 0, std::int64_t{1} << 53));
      else if (s.key == "objective") {
        if (s.text != "worst-case" && s.text != "mean") fail(where, "write \"worst-case\" or \"mean\"");
        d.objective = s.text;
      } else if (s.key == "values") {
        if (s.text != "corrected" && s.text != "raw") fail(where, "write \"corrected\" or \"raw\"");
        d.values = s.text;
      } else if (s.key == "model") {
        d.model = s.text;
      } else {
        fail(where, "unknown key; use seeds, seed, objective, values, model");
      }
    }
  }

  DesignCondition read_condition(const awcc::SettingTable& t) const {
    DesignCondition c;
    c.name = t.name.substr(11);
    if (c.name.empty() || c.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_") !=
                              std::string::npos) {
      fail("[" + t.name + "]", "a condition's name is letters, digits, - and _");
    }
    for (const auto& s : t.settings) {
      const std::string where = "[" + t.name + "] " + s.key;
      if (s.key != "anisotropy" && !is_scene_field(s.key)) fail(where, "unknown field; use a scene field's name (velocity, tu, time-scale, void-fraction, bubble-diameter, ...) or anisotropy");
      if (s.key == "seed" || s.key == "dx" || s.key == "dy" || s.key == "dz" || s.key == "tips" || s.key == "fs" ||
          s.key == "duration") {
        fail(where, "the probe and the record are candidates: give them in [candidates]");
      }
      if (s.items.size() >= 2) {
        if (!kRangeable.count(s.key)) fail(where, "only velocity, tu, anisotropy, time-scale, void-fraction and bubble-diameter take ranges");
        const bool log = s.items.size() == 3 && s.items[2] == "log";
        if (s.items.size() != 2 && !log) fail(where, "write a value, [min, max] or [min, max, \"log\"]");
        const double lo = quantity(where, s.items[0], dimension_of(s.key));
        const double hi = quantity(where, s.items[1], dimension_of(s.key));
        if (!(lo <= hi)) fail(where, "min must not exceed max");
        if (log && !(lo > 0.0)) fail(where, "a log-uniform range needs min > 0");
        c.ranges[s.key] = {lo, hi};
        if (log) c.log_ranges.insert(s.key);
      } else {
        if (s.key == "anisotropy") quantity(where, s.text, awcc::Dimension::dimensionless);
        else {
          synth::Scene probe;
          try {
            synth::set_scene_field(probe, s.key, s.text);
          } catch (const std::exception& e) {
            fail(where, e.what());
          }
        }
        c.values[s.key] = s.text;
      }
    }
    // Tu errors are relative: a condition needs Tu well above zero.
    const double tu_min = c.ranges.count("tu") ? c.ranges["tu"].first
                          : c.values.count("tu") ? quantity("[" + t.name + "] tu", c.values["tu"], awcc::Dimension::dimensionless)
                                                 : synth::Scene{}.tu;
    if (!(tu_min >= 0.02)) fail("[" + t.name + "] tu", "Tu below 0.02: its error is relative (Tu / Tu_true - 1); give Tu >= 0.02");
    return c;
  }

  // [candidates]: the lists of settings tried. dx and dy (a grid, which
  // replaces the default one) or probes (a list of geometries).
  struct CandidateLists {
    std::vector<double> dxs{1e-3, 2e-3, 3e-3, 5e-3, 7.5e-3, 10e-3}, dys{0.0, 0.5e-3, 1e-3, 2e-3};
    bool probes_given = false, grid_given = false;
  };
  void read_candidates(const awcc::SettingTable& t, DesignDefinition& d, CandidateLists& lists) const {
    for (const auto& s : t.settings) {
      const std::string where = "[candidates] " + s.key;
      if (s.items.empty()) fail(where, "must be a non-empty list");
      if (s.key == "dx" || s.key == "dy") {
        auto& list = s.key == "dx" ? lists.dxs : lists.dys;
        list.clear();
        for (const auto& x : s.items) list.push_back(quantity(where, x, awcc::Dimension::length));
        lists.grid_given = true;
      } else if (s.key == "probes") {
        for (const auto& x : s.items) {
          const auto cells = awcc::split_cells(x);
          if (cells.size() != 2) fail(where, fmt::format("'{}': write each probe as \"dx,dy\", e.g. \"5mm,1mm\"", x));
          d.geometries.push_back({quantity(where, cells[0], awcc::Dimension::length),
                                  quantity(where, cells[1], awcc::Dimension::length)});
        }
        lists.probes_given = true;
      } else if (s.key == "np") {
        d.nps.clear();
        for (const auto& x : s.items) d.nps.push_back(static_cast<int>(whole(where, x, awcc::np_min, awcc::np_max)));
      } else if (s.key == "fs") {
        d.fss.clear();
        for (const auto& x : s.items) d.fss.push_back(quantity(where, x, awcc::Dimension::frequency));
      } else if (s.key == "duration") {
        d.durations.clear();
        for (const auto& x : s.items) d.durations.push_back(quantity(where, x, awcc::Dimension::time));
      } else if (s.key == "needle") {
        d.needles.clear();
        for (const auto& x : s.items) {
          d.needles.push_back(quantity(where, x, awcc::Dimension::length));
          if (!(d.needles.back() >= 0.0 && d.needles.back() < 0.01)) fail(where, "a needle diameter is 0 (none) to 10 mm");
        }
      } else {
        fail(where, "unknown key; use dx, dy, probes, np, fs, duration, needle");
      }
    }
  }

  DesignCandidate read_current(const awcc::SettingTable& t) const {
    DesignCandidate c;
    std::set<std::string> given;
    for (const auto& s : t.settings) {
      const std::string where = "[current] " + s.key;
      given.insert(s.key);
      if (s.key == "dx") c.dx = quantity(where, s.text, awcc::Dimension::length);
      else if (s.key == "dy") c.dy = quantity(where, s.text, awcc::Dimension::length);
      else if (s.key == "np") c.np = static_cast<int>(whole(where, s.text, awcc::np_min, awcc::np_max));
      else if (s.key == "fs") c.fs = quantity(where, s.text, awcc::Dimension::frequency);
      else if (s.key == "duration") c.duration = quantity(where, s.text, awcc::Dimension::time);
      else if (s.key == "needle") c.needle = quantity(where, s.text, awcc::Dimension::length);
      else fail(where, "unknown key; use dx, dy, np, fs, duration, needle");
    }
    for (const char* k : {"dx", "dy", "np", "fs", "duration"}) {
      if (!given.count(k)) fail("[current]", fmt::format("give {} (the current probe needs dx, dy, np, fs and duration)", k));
    }
    return c;
  }

  // The candidates' lists complete and checked: the default grid unless
  // probes were given, and the current probe's settings among them.
  void finish_candidates(DesignDefinition& d, const CandidateLists& lists) const {
    if (d.conditions.empty()) fail("[conditions.NAME]", "give at least one condition, e.g. [conditions.wall] with velocity, tu, void-fraction ...");
    if (lists.probes_given && lists.grid_given) fail("[candidates]", "give either probes or dx and dy, not both");
    if (!lists.probes_given) {
      for (double dx : lists.dxs)
        for (double dy : lists.dys) d.geometries.push_back({dx, dy});
    }
    for (const auto& [dx, dy] : d.geometries) {
      if (!(dx > 0.0 && dx < 0.1)) fail("[candidates] dx", fmt::format("{} m: a streamwise separation is above 0 and below 100 mm", dx));
      if (!(dy >= 0.0 && dy < 0.1)) fail("[candidates] dy", fmt::format("{} m: a lateral separation is 0 to 100 mm", dy));
    }
    for (double fs : d.fss)
      if (!(fs >= 1e3 && fs <= 1e8)) fail("[candidates] fs", fmt::format("{} Hz: give 1 kHz to 100 MHz", fs));
    for (double t : d.durations)
      if (!(t > 0.0 && t <= 3600.0)) fail("[candidates] duration", fmt::format("{} s: give up to an hour", t));
    if (d.current) {
      const auto& c = *d.current;
      if (std::find(d.geometries.begin(), d.geometries.end(), std::pair{c.dx, c.dy}) == d.geometries.end()) {
        d.geometries.push_back({c.dx, c.dy});
      }
      if (std::find(d.nps.begin(), d.nps.end(), c.np) == d.nps.end()) d.nps.push_back(c.np);
      if (std::find(d.fss.begin(), d.fss.end(), c.fs) == d.fss.end()) d.fss.push_back(c.fs);
      if (std::find(d.durations.begin(), d.durations.end(), c.duration) == d.durations.end()) d.durations.push_back(c.duration);
      if (std::find(d.needles.begin(), d.needles.end(), c.needle) == d.needles.end()) d.needles.push_back(c.needle);
    }
    if (d.geometries.size() > 63) fail("[candidates]", fmt::format("{} geometries: a simulated probe has at most 63 trailing tips", d.geometries.size()));
  }
};

// The canonical text of what the rows depend on (not the objective, the
// values ranked on or the model's name: changing those re-ranks the same rows).
std::string canonical_text(const DesignDefinition& d) {
  std::string c = fmt::format("seeds={};seed={};", d.seeds, d.seed);
  for (const auto& cond : d.conditions) {
    c += "condition=" + cond.name + ";";
    for (const auto& [k, v] : cond.values) c += k + "=" + v + ";";
    for (const auto& [k, r] : cond.ranges) c += fmt::format("{}={:.17g},{:.17g}{};", k, r.first, r.second, cond.log_ranges.count(k) ? ",log" : "");
  }
  for (const auto& [dx, dy] : d.geometries) c += fmt::format("g={:.17g},{:.17g};", dx, dy);
  for (int np : d.nps) c += fmt::format("np={};", np);
  for (double fs : d.fss) c += fmt::format("fs={:.17g};", fs);
  for (double t : d.durations) c += fmt::format("duration={:.17g};", t);
  // Not the needles: they scale the rows at ranking, and the rows stay valid.
  return c;
}

}  // namespace

DesignDefinition load_design(const std::filesystem::path& path) {
  DesignDefinition d;
  const DesignFile file{path.string()};
  DesignFile::CandidateLists lists;
  for (const auto& t : detail::definition_tables(path, {"conditions"})) {
    if (t.name.empty()) {
      if (!t.settings.empty()) file.fail(t.settings.front().key, "must be in a table: [design], [conditions.NAME], [candidates] or [current]");
    } else if (t.name == "design") {
      file.read_design(t, d);
    } else if (t.name.rfind("conditions.", 0) == 0) {
      d.conditions.push_back(file.read_condition(t));
    } else if (t.name == "candidates") {
      file.read_candidates(t, d, lists);
    } else if (t.name == "current") {
      d.current = file.read_current(t);
    } else {
      file.fail("[" + t.name + "]", "unknown table; use [design], [conditions.NAME], [candidates] and [current]");
    }
  }
  file.finish_candidates(d, lists);
  d.canonical = canonical_text(d);
  return d;
}

std::uint64_t design_id(const DesignDefinition& d) { return detail::definition_id(d.canonical); }

std::int64_t DesignDefinition::tasks() const {
  return static_cast<std::int64_t>(conditions.size() * fss.size() * durations.size()) * seeds;
}

std::int64_t DesignDefinition::rows_per_task() const {
  return static_cast<std::int64_t>(geometries.size() * nps.size());
}

std::vector<DesignCandidate> DesignDefinition::candidates() const {
  std::vector<DesignCandidate> out;
  for (const auto& [dx, dy] : geometries)
    for (int np : nps)
      for (double fs : fss)
        for (double t : durations)
          for (double needle : needles) out.push_back({dx, dy, np, fs, t, needle});
  return out;
}

DesignTask DesignDefinition::task(std::int64_t index) const {
  DesignTask t;
  t.index = index;
  std::int64_t i = index;
  t.record = static_cast<int>(i % seeds);
  i /= seeds;
  t.duration = durations[static_cast<std::size_t>(i % static_cast<std::int64_t>(durations.size()))];
  i /= static_cast<std::int64_t>(durations.size());
  t.fs = fss[static_cast<std::size_t>(i % static_cast<std::int64_t>(fss.size()))];
  i /= static_cast<std::int64_t>(fss.size());
  t.condition = static_cast<std::size_t>(i);
  const auto& c = conditions.at(t.condition);
  // The record's flow and bubbles depend on the condition and the record
  // number only: every setting and geometry sees the same flow.
  const std::uint64_t key = seed ^ detail::fnv1a(c.name);
  synth::Scene s;
  for (const auto& [k, v] : c.values) {
    if (k == "anisotropy") t.anisotropy = awcc::parse_quantity(v, awcc::Dimension::dimensionless);
    else synth::set_scene_field(s, k, v);
  }
  synth::Rng rng(awcc::derive_seed(key, static_cast<std::uint64_t>(t.record)), synth::Stream::bubbles);
  for (const auto& [k, r] : c.ranges) {
    const double u = rng.uniform();
    const double v = c.log_ranges.count(k) ? std::exp(std::log(r.first) + (std::log(r.second) - std::log(r.first)) * u)
                                           : r.first + (r.second - r.first) * u;
    if (k == "anisotropy") t.anisotropy = v;
    else synth::set_scene_field(s, k, fmt::format("{:.17g}{}", v, awcc::si_unit(dimension_of(k))));
  }
  if (!c.values.count("tu-y") && !c.ranges.count("tu-y")) s.tu_y = t.anisotropy * s.tu;
  if (!c.values.count("tu-z") && !c.ranges.count("tu-z")) s.tu_z = t.anisotropy * s.tu;
  s.seed = awcc::derive_seed(key ^ 0x5eedull, static_cast<std::uint64_t>(t.record));
  s.fs = t.fs;
  s.duration = t.duration;
  s.tips.clear();
  s.tips.push_back({0.0, 0.0, 0.0});
  double closest = std::numeric_limits<double>::infinity();
  for (const auto& [dx, dy] : geometries) {
    s.tips.push_back({dx, dy, 0.0});
    closest = std::min(closest, std::hypot(dx, dy));
  }
  if (!(s.realisation_step > 0.0)) {
    const double t_min = std::min({s.time_scale_of(0), s.time_scale_of(1), s.time_scale_of(2)});
    s.realisation_step = std::min(t_min / 50.0, closest / s.velocity / 10.0);
  }
  t.scene = s;
  return t;
}

std::vector<DesignRow> run_design_task(const DesignDefinition& d, const DesignTask& task,
                                       const correction::CorrectionModel* model, const awcc::AwccOptions& processing) {
  synth::Synthesis syn;
  const double seconds_synth = cost([&] { syn = synth::synthesise(task.scene); });
  std::vector<DesignRow> rows;
  for (std::size_t g = 0; g < d.geometries.size(); ++g) {
    const double dx = d.geometries[g].first, dy = d.geometries[g].second;
    RunOptions reading;
    reading.awcc = processing;
    const auto record =
        awcc::binary_recording({syn.signals.at(0), syn.signals.at(g + 1)}, processing_options(reading, dx, dy));
    for (int np : d.nps) {
      RunOptions run;
      run.awcc = processing;
      run.awcc.np = np;
      const auto options = processing_options(run, dx, dy);
      DesignRow r;
      r.task = task.index;
      r.condition = d.conditions[task.condition].name;
      r.record = task.record;
      r.seed = task.scene.seed;
      r.candidate = {dx, dy, np, task.fs, task.duration};
      r.truth_velocity = syn.truth.realised.mean_velocity[0];
      r.truth_turbulence_intensity = syn.truth.realised.turbulence_intensity[0];
      r.seconds_synth = seconds_synth;
      awcc::ProcessResult res;
      r.seconds_awcc = cost([&] { res = awcc::process_binarised(record, options); });
      const auto& lead = res.tips.at(0).phase;
      r.void_fraction = lead.void_fraction;
      r.count_rate = lead.bubble_count_rate;
      const auto& a = *res.awcc;
      if (a.ok()) {
        r.awcc_velocity = a.velocity;
        r.awcc_turbulence_intensity = a.turbulence_intensity;
      }
      r.windows_accepted = a.windows_accepted;
      r.windows_total = a.windows_total;
      if (model) {
        correction::Correction c;
        r.seconds_awcc += cost([&] { c = model->correct(correction::measurement_of(res)); });
        r.correction_status = std::string(correction::to_string(c.status));
        if (c.corrected()) {
          r.correction_forest = c.forest;
          if (c.velocity) r.corrected_velocity = c.velocity->median();
          // Not a Tu that trust rule (e) holds back (correction/model.hpp).
          if (c.turbulence_corrected()) r.corrected_turbulence_intensity = c.turbulence_intensity->median();
        }
      }
      rows.push_back(std::move(r));
    }
  }
  return rows;
}

std::string design_rows_header() {
  return "design,task,condition,record,seed,dx,dy,np,fs,duration,truth_velocity,truth_turbulence_intensity,"
         "void_fraction,count_rate,awcc_velocity,awcc_turbulence_intensity,windows_accepted,windows_total,corrected_velocity,"
         "corrected_turbulence_intensity,correction_status,correction_forest,seconds_awcc,seconds_synth";
}

std::string design_row_text(const DesignRow& r, std::uint64_t design) {
  return fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.4f},{:.4f}", design, r.task,
                     r.condition, r.record, r.seed, num(r.candidate.dx), num(r.candidate.dy), r.candidate.np,
                     num(r.candidate.fs), num(r.candidate.duration), num(r.truth_velocity),
                     num(r.truth_turbulence_intensity), num(r.void_fraction), num(r.count_rate), num(r.awcc_velocity), num(r.awcc_turbulence_intensity),
                     r.windows_accepted, r.windows_total, num(r.corrected_velocity),
                     num(r.corrected_turbulence_intensity), r.correction_status, r.correction_forest, r.seconds_awcc,
                     r.seconds_synth);
}

std::vector<DesignRow> read_design_rows(const std::filesystem::path& csv, std::uint64_t design) {
  std::vector<DesignRow> out;
  std::ifstream in(csv, std::ios::binary);
  if (!in) return out;
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.empty()) return out;
  // A crash while writing leaves a partial last line: it is not a row.
  if (text.back() != '\n') text.erase(text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1);
  std::size_t pos = 0;
  std::int64_t line_number = 0;
  const std::string file = csv.string();
  while (pos < text.size()) {
    const auto end = text.find('\n', pos);
    const std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    if (line_number == 1) {
      if (line != design_rows_header()) {
        throw awcc::InputError(fmt::format("{}: not the runs file of pdp design (its header differs); write the runs to "
                                           "another file or remove this one",
                                           file));
      }
      continue;
    }
    const auto cells = awcc::split_cells(line);
    const auto where = fmt::format("{}:{}", file, line_number);
    if (cells.size() != 24) throw awcc::InputError(fmt::format("{}: {} cells where the header has 24", where, cells.size()));
    auto number = [&](std::size_t i) {
      const auto v = awcc::cell_number(cells[i]);
      if (!v) throw awcc::InputError(fmt::format("{}: column {} = '{}' is not a number", where, i + 1, cells[i]));
      return *v;
    };
    auto optional = [&](std::size_t i) -> std::optional<double> {
      if (cells[i].empty()) return std::nullopt;
      return number(i);
    };
    if (cells[0] != std::to_string(design)) {
      throw awcc::InputError(fmt::format("{}: a row of another design ({}); the definition changed since these rows "
                                         "were written: write the runs to another file or remove this one",
                                         where, cells[0]));
    }
    DesignRow r;
    r.task = static_cast<std::int64_t>(number(1));
    r.condition = cells[2];
    r.record = static_cast<int>(number(3));
    r.seed = std::stoull(cells[4]);
    r.candidate = {number(5), number(6), static_cast<int>(number(7)), number(8), number(9)};
    r.truth_velocity = number(10);
    r.truth_turbulence_intensity = number(11);
    r.void_fraction = number(12);
    r.count_rate = number(13);
    r.awcc_velocity = optional(14);
    r.awcc_turbulence_intensity = optional(15);
    r.windows_accepted = static_cast<std::int64_t>(number(16));
    r.windows_total = static_cast<std::int64_t>(number(17));
    r.corrected_velocity = optional(18);
    r.corrected_turbulence_intensity = optional(19);
    r.correction_status = cells[20];
    r.correction_forest = cells[21];
    r.seconds_awcc = number(22);
    r.seconds_synth = number(23);
    out.push_back(std::move(r));
  }
  return out;
}

DesignResume resume_design(const DesignDefinition& d, const std::vector<std::filesystem::path>& runs,
                           std::uint64_t design) {
  DesignResume out;
  std::map<std::int64_t, std::int64_t> counts;
  for (const auto& file : runs)
    for (const auto& r : read_design_rows(file, design)) ++counts[r.task];
  std::set<std::int64_t> partial;
  for (const auto& [task, n] : counts) (n == d.rows_per_task() ? out.done : partial).insert(task);
  out.cut_short = static_cast<std::int64_t>(partial.size());
  if (runs.empty()) return out;
  const auto& first = runs.front();
  if (!partial.empty()) {
    std::string text = design_rows_header() + "\n";
    for (const auto& r : read_design_rows(first, design))
      if (!partial.count(r.task)) text += design_row_text(r, design) + "\n";
    awcc::write_text_atomically(first, text);
  }
  std::error_code ec;
  if (!std::filesystem::exists(first, ec) || std::filesystem::file_size(first, ec) == 0) {
    awcc::write_text_atomically(first, design_rows_header() + "\n");
  }
  return out;
}

double estimate_design_seconds(const DesignDefinition& d, const std::vector<std::int64_t>& tasks,
                               const correction::CorrectionModel* model, const awcc::AwccOptions& processing,
                               double pilot_seconds) {
  std::map<std::pair<std::size_t, double>, double> pilot;  // seconds per simulated second
  double total = 0.0;
  for (auto t : tasks) {
    const auto task = d.task(t);
    const auto key = std::pair{task.condition, task.fs};
    if (!pilot.count(key)) {
      auto short_task = task;
      short_task.scene.duration = std::min(pilot_seconds, task.duration);
      const auto start = std::chrono::steady_clock::now();
      try {
        (void)run_design_task(d, short_task, model, processing);
      } catch (const std::exception&) {
        // The record itself will say what is wrong.
      }
      pilot[key] = seconds_since(start) / short_task.scene.duration;
    }
    total += pilot[key] * task.duration;
  }
  return total;
}

ErrorStats error_stats(const std::vector<double>& errors) {
  ErrorStats s;
  s.count = static_cast<std::int64_t>(errors.size());
  if (errors.empty()) return s;
  double sum = 0.0, squares = 0.0;
  for (double e : errors) sum += e, squares += e * e;
  const auto n = static_cast<double>(errors.size());
  s.bias = sum / n;
  s.rms = std::sqrt(squares / n);
  if (errors.size() > 1) {
    double ss = 0.0;
    for (double e : errors) ss += (e - s.bias) * (e - s.bias);
    s.spread = std::sqrt(ss / (n - 1.0));
  }
  return s;
}

double needle_velocity_ratio(double true_velocity, double void_fraction, double count_rate, double dx, double needle) {
  if (!(needle > 0.0) || !(true_velocity > 0.0)) return 1.0;
  awcc::ProbeCorrectionOptions o;
  o.enabled = true;
  o.needle_diameter = needle;
  if (void_fraction > o.max_void_fraction) return 1.0;
  // u0(u_m) >= u_m rises with u_m: bisect u0(u_m) = u_true on (0, u_true].
  auto undisturbed = [&](double measured) -> std::optional<double> {
    const auto c = awcc::correct_window(measured, void_fraction, count_rate, dx, o);
    if (c.outcome != awcc::CorrectionOutcome::corrected) return std::nullopt;
    return c.velocity;
  };
  double hi = true_velocity, lo = 0.5 * true_velocity;
  const auto at_hi = undisturbed(hi);
  if (!at_hi || *at_hi <= true_velocity) return 1.0;  // no slowing predicted
  for (int k = 0;; ++k) {  // lower lo until u0(lo) < u_true
    const auto at_lo = undisturbed(lo);
    if (at_lo && *at_lo < true_velocity) break;
    if (k == 7) return 1.0;
    hi = lo;
    lo *= 0.5;
  }
  for (int k = 0; k < 60 && hi - lo > 1e-9 * true_velocity; ++k) {
    const double mid = 0.5 * (lo + hi);
    const auto at = undisturbed(mid);
    if (!at) return 1.0;
    (*at < true_velocity ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi) / true_velocity;
}

namespace {

// The needle's ratio per record, pair and needle (every Np shares it), kept
// across the rankings of the bootstrap.
using NeedleRatios = std::map<std::tuple<std::int64_t, double, double, double>, double>;

std::vector<RankedCandidate> rank_with(const DesignDefinition& d, const std::vector<const DesignRow*>& rows,
                                       NeedleRatios& ratios) {
  // Rows do not depend on the needle: it scales their velocities below.
  std::map<std::pair<DesignCandidate, std::string>, std::vector<const DesignRow*>> groups;
  for (const DesignRow* r : rows) {
    auto key = r->candidate;
    key.needle = 0.0;
    groups[{key, r->condition}].push_back(r);
  }
  auto ratio = [&](const DesignRow& r, double needle) {
    if (!(needle > 0.0)) return 1.0;
    const auto key = std::tuple{r.task, r.candidate.dx, r.candidate.dy, needle};
    if (auto it = ratios.find(key); it != ratios.end()) return it->second;
    const double v = needle_velocity_ratio(r.truth_velocity, r.void_fraction, r.count_rate, r.candidate.dx, needle);
    ratios[key] = v;
    return v;
  };
  const bool corrected = d.values == "corrected";
  std::vector<RankedCandidate> out;
  for (const auto& candidate : d.candidates()) {
    RankedCandidate rc;
    rc.candidate = candidate;
    rc.current = d.current && *d.current == candidate;
    double worst = 0.0, sum = 0.0;
    for (const auto& condition : d.conditions) {
      ConditionScore cs;
      cs.condition = condition.name;
      std::vector<double> ru, rt, cu, ct;
      double yield = 0.0, seconds = 0.0, corrected_count = 0.0;
      auto key = candidate;
      key.needle = 0.0;
      const auto it = groups.find({key, condition.name});
      if (it != groups.end()) {
        for (const DesignRow* r : it->second) {
          ++cs.records;
          seconds += r->seconds_awcc;
          const double slowed = ratio(*r, candidate.needle);
          if (r->windows_total > 0) yield += static_cast<double>(r->windows_accepted) / static_cast<double>(r->windows_total);
          if (r->awcc_velocity) ru.push_back(slowed * *r->awcc_velocity / r->truth_velocity - 1.0);
          if (r->awcc_turbulence_intensity) rt.push_back(*r->awcc_turbulence_intensity / r->truth_turbulence_intensity - 1.0);
          // Reported values: the model's median where it corrected, AWCC's elsewhere.
          const auto u = r->corrected_velocity ? r->corrected_velocity : r->awcc_velocity;
          const auto tu = r->corrected_turbulence_intensity ? r->corrected_turbulence_intensity : r->awcc_turbulence_intensity;
          if (r->corrected_velocity) ++corrected_count;
          if (u) cu.push_back(slowed * *u / r->truth_velocity - 1.0);
          if (tu) ct.push_back(*tu / r->truth_turbulence_intensity - 1.0);
          const bool has = corrected ? (u && tu) : (r->awcc_velocity && r->awcc_turbulence_intensity);
          if (!has) ++cs.failures;
        }
      }
      if (cs.records > 0) {
        const auto n = static_cast<double>(cs.records);
        cs.data_yield = yield / n;
        cs.seconds = seconds / n;
        cs.corrected_fraction = corrected_count / n;
      }
      cs.raw_u = error_stats(ru);
      cs.raw_tu = error_stats(rt);
      cs.corrected_u = error_stats(cu);
      cs.corrected_tu = error_stats(ct);
      cs.score = corrected ? cs.corrected_u.rms + cs.corrected_tu.rms : cs.raw_u.rms + cs.raw_tu.rms;
      // A condition without a single scored record cannot be ranked on.
      if (cs.records == 0 || (corrected ? cs.corrected_u.count == 0 || cs.corrected_tu.count == 0
                                        : cs.raw_u.count == 0 || cs.raw_tu.count == 0)) {
        cs.score = std::numeric_limits<double>::infinity();
        cs.failures = std::max<std::int64_t>(cs.failures, 1);
      }
      rc.failures += cs.failures;
      worst = std::max(worst, cs.score);
      sum += cs.score;
      rc.seconds += cs.seconds / static_cast<double>(d.conditions.size());
      rc.conditions.push_back(std::move(cs));
    }
    rc.objective = d.objective == "mean" ? sum / static_cast<double>(d.conditions.size()) : worst;
    out.push_back(std::move(rc));
  }
  // Ties (equal objectives) go to the cheaper record: the shorter one, then
  // the lower rate. Not to the measured CPU seconds, which differ from run
  // to run: the same rows must give the same ranking.
  std::stable_sort(out.begin(), out.end(), [](const RankedCandidate& a, const RankedCandidate& b) {
    if (a.failures != b.failures) return a.failures < b.failures;
    if (a.objective != b.objective) return a.objective < b.objective;
    if (a.candidate.duration != b.candidate.duration) return a.candidate.duration < b.candidate.duration;
    if (a.candidate.fs != b.candidate.fs) return a.candidate.fs < b.candidate.fs;
    return a.candidate < b.candidate;
  });
  for (std::size_t i = 0; i < out.size(); ++i) out[i].rank = static_cast<int>(i + 1);
  return out;
}

}  // namespace

std::vector<RankedCandidate> rank_candidates(const DesignDefinition& d, const std::vector<DesignRow>& rows) {
  std::vector<const DesignRow*> all;
  for (const auto& r : rows) all.push_back(&r);
  NeedleRatios ratios;
  auto ranked = rank_with(d, all, ratios);
  // How sure the ranking is: the records of each condition resampled with
  // replacement (the same draw for every candidate, which shares the records),
  // the candidates ranked again; a candidate's share is how often it came first.
  std::map<std::pair<std::string, int>, std::vector<const DesignRow*>> records;
  for (const auto& r : rows) records[{r.condition, r.record}].push_back(&r);
  std::map<std::string, std::vector<int>> numbers;  // each condition's record numbers
  for (const auto& [key, unused] : records) numbers[key.first].push_back(key.second);
  std::map<DesignCandidate, double> firsts;
  std::uint64_t state = awcc::derive_seed(d.seed, 0xb007);
  for (int b = 0; b < kBootstrapResamples; ++b) {
    std::vector<const DesignRow*> sample;
    for (const auto& [condition, list] : numbers) {
      for (std::size_t k = 0; k < list.size(); ++k) {
        state = awcc::derive_seed(state, static_cast<std::uint64_t>(b));
        const int record = list[state % list.size()];
        const auto& rs = records[{condition, record}];
        sample.insert(sample.end(), rs.begin(), rs.end());
      }
    }
    firsts[rank_with(d, sample, ratios).front().candidate] += 1.0;
  }
  for (auto& r : ranked) {
    const auto it = firsts.find(r.candidate);
    r.best_share = it == firsts.end() ? 0.0 : it->second / kBootstrapResamples;
  }
  return ranked;
}

namespace {

// Bias, spread and RMS; empty cells where no record gave a value (not 0).
std::string stats_cells(const ErrorStats& s) {
  if (s.count == 0) return ",,";
  return fmt::format("{},{},{}", num(s.bias), s.count > 1 ? num(s.spread) : std::string(), num(s.rms));
}

}  // namespace

namespace {

const RankedColumn kRankedColumns[] = {
    {"rank", "-", "the candidate's rank, 1 = recommended"},
    {"objective", "-", "what the candidates are ranked on: the score's worst or mean over the conditions (ranking)"},
    {"ranking", "text", "worst-case (the largest score over the conditions) or mean: the design's objective"},
    {"values", "text", "corrected (the model's median where it corrects, AWCC's elsewhere) or raw: the values ranked on"},
    {"failures", "-", "records without a value, over the conditions"},
    {"best_share", "-", "share of the bootstrap resamples of the records in which the candidate ranks first"},
    {"current", "-", "1 for the lab's current probe, else 0"},
    {"dx", "m", "streamwise tip separation"},
    {"dy", "m", "lateral tip separation"},
    {"np", "-", "points per AWCC window"},
    {"fs", "Hz", "sampling rate"},
    {"duration", "s", "record duration"},
    {"needle", "m", "the leading needle's diameter, 0 for point tips"},
    {"seconds_awcc", "s", "mean AWCC CPU seconds per record (differs from run to run; not ranked on)"},
    {"condition", "text", "the condition's name; the columns after it are the condition's"},
    {"records", "-", "records simulated in the condition"},
    {"condition_failures", "-", "records of the condition without a value"},
    {"score", "-", "RMS_u + RMS_Tu of the values ranked on, relative"},
    {"u_bias", "-", "bias of the velocity ranked on, relative"},
    {"u_spread", "-", "spread of the velocity ranked on, relative"},
    {"u_rms", "-", "RMS error of the velocity ranked on, relative"},
    {"tu_bias", "-", "bias of Tu ranked on, relative"},
    {"tu_spread", "-", "spread of Tu ranked on, relative"},
    {"tu_rms", "-", "RMS error of Tu ranked on, relative"},
    {"raw_u_bias", "-", "raw AWCC's velocity bias, relative"},
    {"raw_u_spread", "-", "raw AWCC's velocity spread, relative"},
    {"raw_u_rms", "-", "raw AWCC's velocity RMS error, relative"},
    {"raw_tu_bias", "-", "raw AWCC's Tu bias, relative"},
    {"raw_tu_spread", "-", "raw AWCC's Tu spread, relative"},
    {"raw_tu_rms", "-", "raw AWCC's Tu RMS error, relative"},
    {"corrected_fraction", "-", "share of the records the model corrected"},
    {"data_yield", "-", "mean accepted / formed AWCC windows"},
};

}  // namespace

std::span<const RankedColumn> ranked_columns() { return kRankedColumns; }

std::string ranked_csv(const std::vector<RankedCandidate>& ranked, const DesignDefinition& d) {
  std::string out;
  for (const auto& c : kRankedColumns) out += (out.empty() ? "" : ",") + std::string(c.name);
  out += "\n";
  const bool corrected = d.values == "corrected";
  for (const auto& r : ranked) {
    for (const auto& c : r.conditions) {
      const auto& u = corrected ? c.corrected_u : c.raw_u;
      const auto& t = corrected ? c.corrected_tu : c.raw_tu;
      out += fmt::format("{},{},{},{},{},{:.3g},{},{},{},{},{},{},{},{:.4g},{},{},{},{},{},{},{},{},{:.4g},{:.4g}\n", r.rank,
                         num(r.objective), d.objective, d.values, r.failures, r.best_share, r.current ? 1 : 0,
                         num(r.candidate.dx), num(r.candidate.dy), r.candidate.np, num(r.candidate.fs),
                         num(r.candidate.duration), num(r.candidate.needle), r.seconds, c.condition, c.records,
                         c.failures, num(c.score), stats_cells(u), stats_cells(t), stats_cells(c.raw_u),
                         stats_cells(c.raw_tu), c.corrected_fraction, c.data_yield);
    }
  }
  return out;
}

std::string design_summary(const std::vector<RankedCandidate>& ranked, const DesignDefinition& d,
                           const std::string& model_note) {
  std::string out;
  if (ranked.empty()) return out;
  const bool corrected = d.values == "corrected";
  const auto& best = ranked.front();
  out += fmt::format("{} candidates x {} conditions, {} records each; ranked on the {} of |u error| + |Tu error| "
                     "(RMS over the records, relative) {} ({})\n",
                     ranked.size(), d.conditions.size(), d.seeds, d.objective == "mean" ? "mean over the conditions" : "worst condition",
                     corrected ? "of the reported values: the corrected median where the model corrects, AWCC's elsewhere"
                               : "of raw AWCC",
                     model_note);
  out += fmt::format("Recommended: {}: {} {:.3f}{}\n", describe(best.candidate),
                     d.objective == "mean" ? "mean" : "worst-case", best.objective,
                     best.failures ? fmt::format(" ({} records without a value)", best.failures) : "");
  out += "  condition             u bias  u spread   Tu bias  Tu spread   raw u bias  raw Tu bias   yield  corrected\n";
  for (const auto& c : best.conditions) {
    const auto& u = corrected ? c.corrected_u : c.raw_u;
    const auto& t = corrected ? c.corrected_tu : c.raw_tu;
    out += fmt::format("  {:<20} {:+6.1f} % {:7.1f} % {:+7.1f} % {:8.1f} %   {:+8.1f} % {:+9.1f} %  {:5.0f} %  {:6.0f} %\n",
                       c.condition, 100 * u.bias, 100 * u.spread, 100 * t.bias, 100 * t.spread, 100 * c.raw_u.bias,
                       100 * c.raw_tu.bias, 100 * c.data_yield, 100 * c.corrected_fraction);
  }
  // How sure: the recommendation's share of the bootstrap, and any other
  // candidate that came first in at least 5 % of the resamples.
  std::string others;
  for (std::size_t i = 1; i < ranked.size(); ++i) {
    if (ranked[i].best_share >= 0.05) {
      others += fmt::format("{}{} ({:.0f} %)", others.empty() ? "" : "; ", describe(ranked[i].candidate),
                            100 * ranked[i].best_share);
    }
  }
  out += fmt::format("Stability: first in {:.0f} % of {} bootstrap resamples of the records{}\n", 100 * best.best_share,
                     kBootstrapResamples,
                     others.empty() ? "" : "; also first: " + others + " (more seeds would separate them)");
  auto versus = [&](const RankedCandidate& other, const char* what) {
    std::string ratio = std::isfinite(other.objective) && best.objective > 0.0
                            ? fmt::format("{:.1f}x the recommended error", other.objective / best.objective)
                            : "no value in some records";
    out += fmt::format("{}: {} (rank {} of {}): {:.3f}{}; {}\n", what, describe(other.candidate), other.rank,
                       ranked.size(), other.objective,
                       other.failures ? fmt::format(", {} records without a value", other.failures) : "", ratio);
  };
  versus(ranked.back(), "Worst");
  for (const auto& r : ranked)
    if (r.current) versus(r, "Current probe");
  return out;
}

}  // namespace study
