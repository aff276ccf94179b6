#include "study/profile.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "awcc/random.hpp"
#include "awcc/settings_file.hpp"
#include "awcc/units.hpp"
#include "correction/profile_rows.hpp"
#include "awcc/serialise.hpp"
#include "study/clock.hpp"

namespace study {
namespace {

using awcc::ConcentrationModelKind;
using awcc::Dimension;

std::string_view model_name(ConcentrationModelKind kind) {
  return kind == ConcentrationModelKind::smooth_chute ? "smooth-chute" : "stepped-chute";
}

ConcentrationModelKind parse_model(std::string_view text) {
  if (text == "smooth-chute") return ConcentrationModelKind::smooth_chute;
  if (text == "stepped-chute") return ConcentrationModelKind::stepped_chute;
  throw std::invalid_argument(fmt::format("'{}' is not a model; use smooth-chute (Chanson 1997) or stepped-chute "
                                          "(Chanson & Toombes 2002)",
                                          text));
}

double number(std::string_view text) { return awcc::parse_quantity(text, Dimension::dimensionless); }

#define PDP_PROFILE_QUANTITY(NAME, MEMBER, DIM, UNIT, HELP)                                                   \
  awcc::OptionField<ProfileSpec> {                                                                            \
    NAME, UNIT, HELP, [](ProfileSpec& s, std::string_view t) { s.MEMBER = awcc::parse_quantity(t, DIM); },    \
        [](const ProfileSpec& s) { return awcc::format_quantity(s.MEMBER, DIM); }                             \
  }

const awcc::OptionField<ProfileSpec> kFields[] = {
    {"model", "", "air-concentration law below Y90: stepped-chute (Chanson & Toombes 2002) or smooth-chute "
                  "(Chanson 1997)",
     [](ProfileSpec& s, std::string_view t) { s.model = parse_model(t); },
     [](const ProfileSpec& s) { return std::string(model_name(s.model)); }},
    {"diffusivity", "-", "the model's dimensionless diffusivity, D_0 (stepped) or D' (smooth)",
     [](ProfileSpec& s, std::string_view t) { s.diffusivity = number(t); },
     [](const ProfileSpec& s) { return fmt::format("{:g}", s.diffusivity); }},
    PDP_PROFILE_QUANTITY("y90", y90, Dimension::length, "m", "Y90, where the law's c is 0.9, m"),
    PDP_PROFILE_QUANTITY("u90", u90, Dimension::velocity, "m/s", "velocity at Y90, m/s"),
    {"power-law-n", "-", "N of the velocity law u = u90 (y / Y90)^(1/N)",
     [](ProfileSpec& s, std::string_view t) { s.power_law_n = number(t); },
     [](const ProfileSpec& s) { return fmt::format("{:g}", s.power_law_n); }},
    {"tu-invert", "-", "streamwise turbulence intensity at the invert (linear in y to Y90's)",
     [](ProfileSpec& s, std::string_view t) { s.tu_invert = number(t); },
     [](const ProfileSpec& s) { return fmt::format("{:g}", s.tu_invert); }},
    {"tu-y90", "-", "streamwise turbulence intensity at Y90 and above",
     [](ProfileSpec& s, std::string_view t) { s.tu_y90 = number(t); },
     [](const ProfileSpec& s) { return fmt::format("{:g}", s.tu_y90); }},
    PDP_PROFILE_QUANTITY("bubble-diameter-invert", bubble_diameter_invert, Dimension::length, "m",
                         "bubble (droplet) diameter at the invert (linear in y to Y90's), m"),
    PDP_PROFILE_QUANTITY("bubble-diameter-y90", bubble_diameter_y90, Dimension::length, "m",
                         "bubble (droplet) diameter at Y90 and above, m"),
    {"positions", "m", "distance from the invert of each recording, increasing (\"3mm,6mm,...\")",
     [](ProfileSpec& s, std::string_view t) {
       s.positions.clear();
       std::size_t start = 0;
       while (start <= t.size()) {
         const auto comma = t.find(',', start);
         auto item = t.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
         while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
         while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
         if (item.empty()) throw std::invalid_argument("an empty position in the list; give lengths like 3mm,6mm");
         s.positions.push_back(awcc::parse_quantity(item, Dimension::length));
         if (comma == std::string_view::npos) break;
         start = comma + 1;
       }
     },
     [](const ProfileSpec& s) {
       std::string out;
       for (const double y : s.positions) out += (out.empty() ? "" : ",") + awcc::format_quantity(y, Dimension::length);
       return out;
     }},
};

#undef PDP_PROFILE_QUANTITY

// The scene fields the laws own.
constexpr std::string_view kLawFields[] = {"void-fraction", "velocity", "tu", "bubble-diameter"};


// Composite Simpson's rule of f on [a, b] with `panels` (even) panels.
template <class F>
double simpson(F&& f, double a, double b, int panels) {
  const double h = (b - a) / panels;
  double sum = f(a) + f(b);
  for (int i = 1; i < panels; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(a + h * i);
  return sum * h / 3.0;
}

constexpr int kPanels = 4096;

// The law's slope at Y90 from below, 1/m: a central difference on the model,
// whose formula lives in awcc::ConcentrationModel alone.
double slope_at_y90(const ProfileSpec& spec) {
  const awcc::ConcentrationModel m{spec.model, spec.diffusivity, spec.y90};
  const double h = 1e-5 * spec.y90;
  return (m(spec.y90 + h) - m(spec.y90 - h)) / (2 * h);
}

}  // namespace

std::span<const awcc::OptionField<ProfileSpec>> profile_spec_fields() { return kFields; }

double profile_void_fraction(const ProfileSpec& spec, double y) {
  if (y <= spec.y90) return awcc::ConcentrationModel{spec.model, spec.diffusivity, spec.y90}(std::max(y, 0.0));
  return 1.0 - 0.1 * std::exp(-(y - spec.y90) * slope_at_y90(spec) / 0.1);
}

double profile_velocity(const ProfileSpec& spec, double y) {
  return y <= 0.0 ? 0.0 : spec.u90 * std::pow(y / spec.y90, 1.0 / spec.power_law_n);
}

synth::Scene position_scene(const ProfileSpec& spec, std::size_t i) {
  synth::Scene s = spec.scene;
  const double y = spec.positions.at(i);
  const double f = std::min(y / spec.y90, 1.0);
  const double tu = spec.tu_invert + (spec.tu_y90 - spec.tu_invert) * f;
  // Tu_y and Tu_z keep their ratios to Tu_x (a base scene without streamwise
  // fluctuation keeps its own lateral ones).
  if (spec.scene.tu > 0.0) {
    s.tu_y = spec.scene.tu_y * tu / spec.scene.tu;
    s.tu_z = spec.scene.tu_z * tu / spec.scene.tu;
  }
  s.tu = tu;
  s.void_fraction = profile_void_fraction(spec, y);
  s.velocity = profile_velocity(spec, y);
  s.bubble_diameter = spec.bubble_diameter_invert + (spec.bubble_diameter_y90 - spec.bubble_diameter_invert) * f;
  s.seed = awcc::derive_seed(spec.scene.seed, i);
  return s;
}

awcc::Validation ProfileSpec::validate() const {
  using V = awcc::Validation;
  auto finite = [](double x) { return std::isfinite(x); };
  if (!(finite(diffusivity) && diffusivity >= 0.01 && diffusivity <= 10.0))
    return V::invalid("diffusivity", fmt::format("diffusivity {:g}: it must lie in [0.01, 10] (chutes: 0.05-1)",
                                                 diffusivity));
  if (!(finite(y90) && y90 > 0.0)) return V::invalid("y90", fmt::format("y90 {:g} m: it must be positive", y90));
  if (!(finite(u90) && u90 > 0.0)) return V::invalid("u90", fmt::format("u90 {:g} m/s: it must be positive", u90));
  if (!(finite(power_law_n) && power_law_n >= 1.0 && power_law_n <= 50.0))
    return V::invalid("power-law-n", fmt::format("power-law-n {:g}: it must lie in [1, 50] (chutes: 3-12)",
                                                 power_law_n));
  for (const auto& [name, value] : {std::pair{"tu-invert", tu_invert}, std::pair{"tu-y90", tu_y90}}) {
    if (!(finite(value) && value >= 0.0 && value <= 0.35))
      return V::invalid(name, fmt::format("{} {:g}: it must lie in [0, 0.35], the synthetic probe's range", name, value));
  }
  for (const auto& [name, value] : {std::pair{"bubble-diameter-invert", bubble_diameter_invert},
                                    std::pair{"bubble-diameter-y90", bubble_diameter_y90}}) {
    if (!(finite(value) && value > 0.0))
      return V::invalid(name, fmt::format("{} {:g} m: it must be positive", name, value));
  }
  if (positions.size() < 2)
    return V::invalid("positions", fmt::format("{} position(s): a profile needs two or more", positions.size()));
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!(finite(positions[i]) && positions[i] > 0.0))
      return V::invalid("positions", fmt::format("position {} is {:g} m: positions lie above the invert (> 0)", i + 1,
                                                 positions[i]));
    if (i > 0 && !(positions[i] > positions[i - 1]))
      return V::invalid("positions", fmt::format("positions {} and {} ({:g} and {:g} m) do not increase; list them "
                                                 "from the invert up, each once",
                                                 i, i + 1, positions[i - 1], positions[i]));
  }
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const auto at = position_scene(*this, i);
    if (const auto v = at.validate(); !v.ok()) {
      return V::invalid("positions", fmt::format("position {} (y = {:g} m, c = {:.4g}, u = {:.4g} m/s): its scene is "
                                                 "refused: {}",
                                                 i + 1, positions[i], at.void_fraction, at.velocity, v.message));
    }
  }
  return {};
}

ProfileSpec load_profile_spec(const std::filesystem::path& path) {
  ProfileSpec spec;
  bool seen_profile = false;
  for (const auto& table : awcc::read_setting_tables(path)) {
    if (table.name == "profile") {
      seen_profile = true;
      std::vector<awcc::OptionSetting> settings;
      for (const auto& s : table.settings) {
        settings.push_back({s.key, s.text, fmt::format("{}:{}", path.string(), s.line)});
      }
      std::vector<bool> used(settings.size(), false);
      try {
        awcc::apply_settings(profile_spec_fields(), std::span<const awcc::OptionSetting>(settings), spec, used);
      } catch (const awcc::OptionError& e) {
        throw awcc::InputError(e.what(), e.quantity());
      }
      for (std::size_t i = 0; i < settings.size(); ++i) {
        if (used[i]) continue;
        std::string names;
        for (const auto& f : kFields) names += (names.empty() ? "" : ", ") + std::string(f.name);
        throw awcc::InputError(fmt::format("{}: unknown profile field '{}'; use one of: {}", settings[i].origin,
                                           settings[i].name, names),
                               settings[i].name);
      }
    } else if (table.name == "scene") {
      for (const auto& s : table.settings) {
        if (std::find(std::begin(kLawFields), std::end(kLawFields), s.key) != std::end(kLawFields)) {
          throw awcc::InputError(fmt::format("{}:{}: [scene] {}: the profile's laws give each position's {}; set "
                                             "them in [profile] (model, diffusivity, u90, power-law-n, tu-invert, "
                                             "tu-y90, bubble-diameter-invert, bubble-diameter-y90)",
                                             path.string(), s.line, s.key, s.key),
                                 s.key);
        }
        try {
          synth::set_scene_field(spec.scene, s.key, s.text);
        } catch (const std::invalid_argument& e) {
          throw awcc::InputError(fmt::format("{}:{}: [scene] {}: {}", path.string(), s.line, s.key, e.what()), s.key);
        }
      }
    } else if (!table.settings.empty()) {
      throw awcc::InputError(fmt::format("{}:{}: {} outside a table; a profile file has a [profile] table and "
                                         "optionally a [scene] table",
                                         path.string(), table.settings.front().line,
                                         table.name.empty() ? "keys" : "table [" + table.name + "]"),
                             table.name.empty() ? table.settings.front().key : table.name);
    }
  }
  if (!seen_profile) {
    throw awcc::InputError(fmt::format("{}: no [profile] table; a profile file describes the cross-section there "
                                       "(model, diffusivity, y90, u90, power-law-n, positions, ...)",
                                       path.string()),
                           "profile");
  }
  return spec;
}

ProfileTruth profile_truth(const ProfileSpec& spec, std::span<const double> levels) {
  ProfileTruth t;
  t.y90 = spec.y90;
  t.model = spec.model;
  t.diffusivity = spec.diffusivity;
  t.power_law_n = spec.power_law_n;
  t.u90 = spec.u90;
  auto c = [&](double y) { return profile_void_fraction(spec, y); };
  t.c_mean = simpson(c, 0.0, spec.y90, kPanels) / spec.y90;
  t.clear_water_depth = (1.0 - t.c_mean) * spec.y90;
  // y = Y90 s^N: dy = N Y90 s^(N-1) ds, u = u90 s.
  const double n = spec.power_law_n;
  auto flux = [&](double s, bool air) {
    const double y = spec.y90 * std::pow(s, n);
    const double share = air ? c(y) : 1.0 - c(y);
    return share * spec.u90 * s * n * spec.y90 * std::pow(s, n - 1.0);
  };
  t.water_discharge = simpson([&](double s) { return flux(s, false); }, 0.0, 1.0, kPanels);
  t.air_discharge = simpson([&](double s) { return flux(s, true); }, 0.0, 1.0, kPanels);
  // The law rises monotonically (header): bisection on [0, y_max], y_max
  // where c is within 1e-9 of 1.
  const double y_max = spec.y90 + 0.1 / slope_at_y90(spec) * std::log(0.1 / 1e-9);
  for (const double level : levels) {
    t.levels.push_back(level);
    if (c(0.0) >= level) {
      t.depths.emplace_back();
      continue;
    }
    double lo = 0.0, hi = y_max;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * spec.y90; ++it) {
      const double mid = 0.5 * (lo + hi);
      (c(mid) < level ? lo : hi) = mid;
    }
    t.depths.emplace_back(0.5 * (lo + hi));
  }
  return t;
}

std::optional<double> ProfileComparison::error() const {
  if (!measured.value || truth == 0.0) return std::nullopt;
  return *measured.value / truth - 1.0;
}

std::optional<bool> ProfileComparison::covered() const {
  if (!measured.ci95) return std::nullopt;
  return measured.ci95->lower <= truth && truth <= measured.ci95->upper;
}

namespace {

// The laws' truth of a profile quantity (by its awcc::flow_quantity_names
// pointer), where the laws give one: the continuity error and the residual
// head have none, and of the diffusivities only the profile's own model's.
std::optional<double> truth_of(std::string_view pointer, const ProfileSpec& spec, const ProfileTruth& t) {
  const bool stepped = spec.model == awcc::ConcentrationModelKind::stepped_chute;
  if (pointer == "/y90") return t.y90;
  if (pointer == "/c_mean") return t.c_mean;
  if (pointer == "/clear_water_depth") return t.clear_water_depth;
  if (pointer == "/power_law/n") return t.power_law_n;
  if (pointer == "/power_law/u90") return t.u90;
  if (pointer == "/water_discharge") return t.water_discharge;
  if (pointer == "/air_discharge") return t.air_discharge;
  if (pointer == (stepped ? "/stepped_chute" : "/smooth_chute")) return t.diffusivity;
  return std::nullopt;
}

// The profile quantities with a truth, in the order of the quantities'
// table (awcc/profile_flow.hpp, its one owner of names and units), each
// depth level after Y90; the key is the quantity's JSON pointer in words
// ("/power_law/n": "power_law_n").
std::vector<ProfileComparison> compare(const ProfileSpec& spec, const ProfileTruth& t,
                                       const awcc::ProfileFlowResult& measured, const awcc::ProfileFlowResult& exact) {
  std::vector<ProfileComparison> out;
  for (const auto& q : awcc::flow_quantity_names) {
    const auto truth = truth_of(q.pointer, spec, t);
    if (!truth) continue;
    std::string key(q.pointer.substr(1));
    std::replace(key.begin(), key.end(), '/', '_');
    out.push_back({std::string(q.symbol), key, std::string(q.unit), *truth, q.of(exact).value, q.of(measured)});
    if (q.pointer != "/y90") continue;
    for (std::size_t i = 0; i < measured.levels.size() && i < t.levels.size(); ++i) {
      if (!t.depths[i]) continue;
      out.push_back({fmt::format("Y{:g}", 100 * t.levels[i]), fmt::format("y{:g}", 100 * t.levels[i]), "m",
                     *t.depths[i], i < exact.levels.size() ? exact.levels[i].depth.value : std::nullopt,
                     measured.levels[i].depth});
    }
  }
  return out;
}

}  // namespace

ProfileValidation validate_profile(const ProfileSpec& spec, const ProfileValidateOptions& options,
                                   const std::function<void(double)>& progress) {
  spec.validate().throw_if_failed();
  const auto start = std::chrono::steady_clock::now();
  ProfileValidation v;
  v.spec = spec;
  v.truth = profile_truth(spec, options.flow.levels);
  std::vector<correction::ProfileRowOf> rows;
  std::vector<awcc::ProfileRow> exact;
  for (std::size_t i = 0; i < spec.positions.size(); ++i) {
    v.runs.push_back(run_scene(position_scene(spec, i), options.run));
    const correction::Correction* corrected = nullptr;
    if (options.correction) {
      v.corrections.push_back(options.correction->correct(v.runs.back().measurement));
      corrected = &v.corrections.back();
    }
    auto r = correction::profile_row(v.runs.back().processed, spec.positions[i], corrected);
    r.row.name = fmt::format("position {} (y = {})", i + 1, awcc::format_quantity(spec.positions[i], Dimension::length));
    awcc::ProfileRow e;
    e.name = r.row.name;
    rows.push_back(std::move(r));
    e.y = spec.positions[i];
    e.c = profile_void_fraction(spec, e.y);
    e.c_ci95 = {e.c, e.c};
    e.u = profile_velocity(spec, e.y);
    e.u_ci95 = awcc::Interval95{*e.u, *e.u};
    exact.push_back(std::move(e));
    if (progress) progress(static_cast<double>(i + 1) / static_cast<double>(spec.positions.size()));
  }
  auto flow_options = options.flow;
  flow_options.discharge = v.truth.water_discharge;
  // The flow builder of every profile (its rows' notes in its notes and alerts).
  v.flow = correction::profile_flow_of(std::move(rows), flow_options);
  auto exact_options = flow_options;
  exact_options.draws = 0;
  v.exact_flow = awcc::profile_flow(std::move(exact), exact_options);
  v.comparisons = compare(spec, v.truth, v.flow, v.exact_flow);
  v.seconds = seconds_since(start);
  return v;
}

std::string ProfileValidation::report() const {
  std::string out = fmt::format("profile: {} chute law, D = {:g}, Y90 = {}, u90 = {:g} m/s, N = {:g}, {} positions\n",
                                spec.model == awcc::ConcentrationModelKind::stepped_chute ? "stepped" : "smooth",
                                spec.diffusivity, awcc::format_quantity(spec.y90, Dimension::length), spec.u90,
                                spec.power_law_n, spec.positions.size());
  out += fmt::format("{:<8} {:>12} {:>12} {:>12} {:>27} {:>9} {:>8}\n", "quantity", "truth", "exact rows", "measured",
                     "95 % interval", "error", "covered");
  for (const auto& c : comparisons) {
    const auto value = c.measured.value ? fmt::format("{:.6g}", *c.measured.value) : std::string("none");
    const auto ci = c.measured.ci95 ? fmt::format("[{:.6g}, {:.6g}]", c.measured.ci95->lower, c.measured.ci95->upper)
                                    : std::string("none");
    const auto err = c.error() ? fmt::format("{:+.2f} %", 100 * *c.error()) : std::string("-");
    const auto cov = c.covered() ? (*c.covered() ? "yes" : "NO") : "-";
    out += fmt::format("{:<8} {:>12.6g} {:>12} {:>12} {:>27} {:>9} {:>8}   {}\n", c.name, c.truth,
                       c.exact_rows ? fmt::format("{:.6g}", *c.exact_rows) : std::string("none"), value, ci, err, cov,
                       c.unit);
    if (!c.measured.reason.empty()) out += fmt::format("         {}\n", c.measured.reason);
  }
  out += fmt::format("{:>10} {:>8} {:>8} {:>8} {:>9} {:>9} {:>9} {:>16}\n", "y (m)", "c law", "c tip", "c meas",
                     "u law", "u flow", "u meas", "velocity");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& row = flow.rows[i];
    const auto& r = runs[i];
    out += fmt::format("{:>10.5f} {:>8.4f} {:>8.4f} {:>8.4f} {:>9.4f} {:>9.4f} {:>9} {:>16}\n", spec.positions[i],
                       r.scene.void_fraction, r.truth_void_fraction, row.c, r.scene.velocity, r.truth_velocity,
                       row.u ? fmt::format("{:.4f}", *row.u) : std::string("none"),
                       row.u ? std::string(awcc::to_string(row.u_source)) : std::string("-"));
  }
  out += fmt::format("flow status: {}{}\n", awcc::to_string(flow.status), flow.message.empty() ? "" : ": " + flow.message);
  return out;
}

nlohmann::json profile_truth_json(const ProfileSpec& spec, const ProfileTruth& t) {
  nlohmann::json j;
  nlohmann::json s = nlohmann::json::object();
  for (const auto& f : profile_spec_fields()) s[std::string(f.name)] = f.format(spec);
  j["spec"] = s;
  nlohmann::json depths = nlohmann::json::array();
  for (std::size_t i = 0; i < t.levels.size(); ++i) {
    depths.push_back({{"level", t.levels[i]}, {"y", t.depths[i] ? nlohmann::json(*t.depths[i]) : nlohmann::json()}});
  }
  j["truth"] = {{"y90", t.y90},
                {"depths", depths},
                {"c_mean", t.c_mean},
                {"clear_water_depth", t.clear_water_depth},
                {"power_law_n", t.power_law_n},
                {"u90", t.u90},
                {"water_discharge", t.water_discharge},
                {"air_discharge", t.air_discharge},
                {"model", model_name(t.model)},
                {"diffusivity", t.diffusivity}};
  nlohmann::json positions = nlohmann::json::array();
  for (std::size_t i = 0; i < spec.positions.size(); ++i) {
    const auto scene = position_scene(spec, i);
    positions.push_back({{"y", spec.positions[i]},
                         {"void_fraction", scene.void_fraction},
                         {"velocity", scene.velocity},
                         {"tu", scene.tu},
                         {"bubble_diameter", scene.bubble_diameter},
                         {"seed", scene.seed}});
  }
  j["positions"] = positions;
  j["generator_version"] = awcc::generator_version;
  return j;
}

nlohmann::json profile_validation_json(const ProfileValidation& v) {
  auto j = profile_truth_json(v.spec, v.truth);
  nlohmann::json comparisons = nlohmann::json::array();
  for (const auto& c : v.comparisons) {
    nlohmann::json k = {{"name", c.name}, {"key", c.key}, {"unit", c.unit}, {"truth", c.truth}};
    k["exact_rows"] = c.exact_rows ? nlohmann::json(*c.exact_rows) : nlohmann::json();
    k["value"] = c.measured.value ? nlohmann::json(*c.measured.value) : nlohmann::json();
    k["ci95"] = c.measured.ci95 ? nlohmann::json::array({c.measured.ci95->lower, c.measured.ci95->upper})
                                : nlohmann::json();
    k["error"] = c.error() ? nlohmann::json(*c.error()) : nlohmann::json();
    k["covered"] = c.covered() ? nlohmann::json(*c.covered()) : nlohmann::json();
    k["reason"] = c.measured.reason;
    comparisons.push_back(std::move(k));
  }
  j["comparisons"] = comparisons;
  for (std::size_t i = 0; i < v.runs.size() && i < j["positions"].size(); ++i) {
    const auto& r = v.runs[i];
    auto& p = j["positions"][i];
    p["realised_void_fraction"] = r.truth_void_fraction;
    p["realised_velocity"] = r.truth_velocity;
    p["measured_void_fraction"] = v.flow.rows[i].c;
    p["measured_velocity"] = v.flow.rows[i].u ? nlohmann::json(*v.flow.rows[i].u) : nlohmann::json();
    p["velocity_source"] = v.flow.rows[i].u ? nlohmann::json(awcc::to_string(v.flow.rows[i].u_source)) : nlohmann::json();
  }
  j["flow"] = awcc::to_json(v.flow);
  j["seconds"] = v.seconds;
  return j;
}

}  // namespace study
