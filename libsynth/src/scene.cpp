#include "synth/scene.hpp"

#include <Eigen/Dense>
#include <array>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>
#include "awcc/errors.hpp"
#include "awcc/settings_file.hpp"

namespace synth {

using awcc::Dimension;
using awcc::format_quantity;
using awcc::parse_quantity;

std::vector<Vec3> Scene::probe_tips() const {
  if (!tips.empty()) return tips;
  return {Vec3{0.0, 0.0, 0.0}, Vec3{dx, dy, dz}};
}

double Scene::streamwise_separation() const {
  const auto p = probe_tips();
  return p.size() < 2 ? 0.0 : p[1].x - p[0].x;
}

double Scene::lateral_separation() const {
  const auto p = probe_tips();
  return p.size() < 2 ? 0.0 : std::hypot(p[1].y - p[0].y, p[1].z - p[0].z);
}

double Scene::time_scale_of(int component) const {
  if (component == 1 && time_scale_y) return *time_scale_y;
  if (component == 2 && time_scale_z) return *time_scale_z;
  return time_scale;
}

double Scene::tu_of(int component) const {
  return component == 0 ? tu : (component == 1 ? tu_y : tu_z);
}

double Scene::effective_realisation_step() const {
  // Shrunk to duration / (a whole number of steps) so that the steps tile the
  // record exactly and the realised statistics are time averages over it.
  auto tile = [this](double step) { return duration / std::ceil(duration / step - 1e-9); };
  if (realisation_step > 0.0) return tile(realisation_step);
  const double t_min = std::min({time_scale_of(0), time_scale_of(1), time_scale_of(2)});
  const auto p = probe_tips();
  double spread = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      spread = std::max(spread, std::hypot(p[i].x - p[j].x, p[i].y - p[j].y, p[i].z - p[j].z));
    }
  }
  if (spread <= 0.0) spread = bubble_diameter;
  return tile(std::min(t_min / 50.0, spread / velocity / 10.0));
}

std::int64_t Scene::sample_count() const {
  return static_cast<std::int64_t>(std::llround(duration * fs));
}

std::string_view to_string(ArrivalRule rule) {
  switch (rule) {
    case ArrivalRule::equal_time: return "equal-time";
    case ArrivalRule::poisson_time: return "poisson-time";
    case ArrivalRule::equal_space: return "equal-space";
    case ArrivalRule::poisson_space: return "poisson-space";
  }
  return "?";
}

std::string_view to_string(OverlapRule rule) { return rule == OverlapRule::avoid ? "avoid" : "allow"; }

DispersedPhase dispersed_phase(double void_fraction) {
  return void_fraction > 0.5 ? DispersedPhase::droplets : DispersedPhase::bubbles;
}

double dispersed_fraction(double void_fraction) {
  return dispersed_phase(void_fraction) == DispersedPhase::droplets ? 1.0 - void_fraction : void_fraction;
}

std::string_view to_string(DispersedPhase phase) {
  return phase == DispersedPhase::bubbles ? "bubbles" : "droplets";
}

std::string_view to_string(VelocityUpdate update) {
  return update == VelocityUpdate::exact ? "exact" : "euler";
}

namespace {

bool finite(double v) { return std::isfinite(v); }

std::string q(double v, Dimension d) { return format_quantity(v, d); }

}  // namespace

awcc::Validation Scene::validate() const {
  // Every problem with the field(s) that fix it.
  std::vector<std::pair<std::string, std::string>> errors;
  auto bad = [&](std::string_view field, std::string value, std::string_view allowed, std::string_view quantity = {}) {
    errors.emplace_back(std::string(quantity.empty() ? field : quantity),
                        fmt::format("{} = {} is out of range: {}", field, value, allowed));
  };
  if (!(finite(velocity) && velocity > 0.0))
    bad("velocity", q(velocity, Dimension::velocity), "it must be > 0 m/s (studied range 1-50 m/s)");
  const std::pair<std::string_view, double> intensities[] = {{"tu", tu}, {"tu-y", tu_y}, {"tu-z", tu_z}};
  for (const auto& [name, v] : intensities) {
    if (!(finite(v) && v >= 0.0 && v <= 1.0)) bad(name, fmt::format("{}", v), "it must lie in [0, 1] (studied range 0-0.35)");
  }
  const std::pair<std::string_view, double> scales[] = {
      {"time-scale", time_scale}, {"time-scale-y", time_scale_of(1)}, {"time-scale-z", time_scale_of(2)}};
  for (const auto& [name, v] : scales) {
    if (!(finite(v) && v > 0.0)) bad(name, q(v, Dimension::time), "it must be > 0 s (studied range 1 ms-1 s)");
  }
  const std::pair<std::string_view, double> rhos[] = {{"rho-xy", rho_xy}, {"rho-xz", rho_xz}, {"rho-yz", rho_yz}};
  bool rho_ok = true;
  for (const auto& [name, v] : rhos) {
    if (!(finite(v) && v > -1.0 && v < 1.0)) {
      bad(name, fmt::format("{}", v), "a correlation coefficient must lie in (-1, 1)");
      rho_ok = false;
    }
  }
  if (rho_ok) {
    Eigen::Matrix3d r;
    r << 1.0, rho_xy, rho_xz, rho_xy, 1.0, rho_yz, rho_xz, rho_yz, 1.0;
    const double min_eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(r).eigenvalues().minCoeff();
    if (!(min_eig > 1e-12)) {
      errors.emplace_back("rho-xy,rho-xz,rho-yz", fmt::format(
          "rho-xy = {}, rho-xz = {}, rho-yz = {}: the velocity correlation matrix is not positive "
          "definite (smallest eigenvalue {:.3g}); choose coefficients with 1 + 2 rxy rxz ryz - rxy^2 - "
          "rxz^2 - ryz^2 > 0",
          rho_xy, rho_xz, rho_yz, min_eig));
    }
  }
  // Above 0.99 the droplets (at 1 - c) grow too rare for a record of any
  // practical length to hold a statistic of them.
  if (!(finite(void_fraction) && void_fraction > 0.0 && void_fraction <= 0.99))
    bad("void-fraction", fmt::format("{}", void_fraction),
        "it must lie in (0, 0.99] (studied range 0.005-0.99: bubbles up to 0.5, droplets at 1 - c above)");
  if (!(finite(bubble_diameter) && bubble_diameter > 0.0 && bubble_diameter <= 1.0))
    bad("bubble-diameter", q(bubble_diameter, Dimension::length), "it must lie in (0, 1 m] (studied range 0.5-20 mm)");
  if (!(finite(diameter_log_sd) && diameter_log_sd >= 0.0 && diameter_log_sd <= 1.0))
    bad("diameter-log-sd", fmt::format("{}", diameter_log_sd), "it must lie in [0, 1] (0 gives equal diameters)");
  if (!(finite(aspect_ratio) && aspect_ratio >= 0.1 && aspect_ratio <= 10.0))
    bad("aspect-ratio", fmt::format("{}", aspect_ratio), "it must lie in [0.1, 10] (1 is a sphere)");
  if (overlap_retries < 0 || overlap_retries > 1000)
    bad("overlap-retries", fmt::format("{}", overlap_retries), "it must lie in [0, 1000]");

  const auto p = probe_tips();
  const std::string_view tip_field = tips.empty() ? "dx/dy/dz" : "tips";
  const std::string_view tip_quantity = tips.empty() ? "dx,dy,dz" : "tips";
  if (p.empty() || p.size() > 64) {
    bad("tips", fmt::format("{} tips", p.size()), "a probe has 1 to 64 tips");
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(finite(p[i].x) && finite(p[i].y) && finite(p[i].z) && std::fabs(p[i].x) < 1.0 &&
          std::fabs(p[i].y) < 1.0 && std::fabs(p[i].z) < 1.0)) {
      bad(tip_field, fmt::format("tip {} at ({}, {}, {}) m", i, p[i].x, p[i].y, p[i].z),
          "tip coordinates must be finite and within 1 m of the origin", tip_quantity);
    }
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      if (std::hypot(p[i].x - p[j].x, p[i].y - p[j].y, p[i].z - p[j].z) < 1e-9) {
        errors.emplace_back(std::string(tip_quantity), fmt::format(
            "{}: tips {} and {} are at the same point ({}, {}, {}) m; separate them (for a two-tip "
            "probe, set a nonzero dx)",
            tip_field, i, j, p[i].x, p[i].y, p[i].z));
      }
    }
  }
  if (!(finite(fs) && fs > 0.0)) bad("fs", q(fs, Dimension::frequency), "it must be > 0 Hz (studied range 10 kHz-2 MHz)");
  if (!(finite(duration) && duration > 0.0)) {
    bad("duration", q(duration, Dimension::time), "it must be > 0 s");
  } else if (finite(fs) && fs > 0.0 && duration * fs < 1.0) {
    bad("duration", q(duration, Dimension::time),
        fmt::format("it is shorter than one sample at fs = {}; make it at least {}", q(fs, Dimension::frequency),
                    q(1.0 / fs, Dimension::time)));
  } else if (finite(fs) && duration * fs > 4e18) {
    bad("duration", q(duration, Dimension::time), "duration * fs exceeds 4e18 samples");
  }
  if (!(finite(realisation_step) && realisation_step >= 0.0))
    bad("realisation-step", q(realisation_step, Dimension::time), "it must be >= 0 s (0 chooses it automatically)");
  if (!(finite(voltage_full_scale) && voltage_full_scale > 0.0))
    bad("voltage-full-scale", q(voltage_full_scale, Dimension::voltage), "it must be > 0 V");
  const std::pair<std::string_view, double> levels[] = {{"voltage-water", voltage_water}, {"voltage-air", voltage_air}};
  for (const auto& [name, v] : levels) {
    if (!(finite(v) && std::fabs(v) <= voltage_full_scale))
      bad(name, q(v, Dimension::voltage), fmt::format("it must lie within +/- voltage-full-scale ({})", q(voltage_full_scale, Dimension::voltage)));
  }
  if (!(finite(voltage_time_constant) && voltage_time_constant >= 0.0))
    bad("voltage-time-constant", q(voltage_time_constant, Dimension::time), "it must be >= 0 s");
  if (!(finite(voltage_noise) && voltage_noise >= 0.0))
    bad("voltage-noise", q(voltage_noise, Dimension::voltage), "it must be >= 0 V");

  if (errors.empty()) {
    const double dt = effective_realisation_step();
    const double steps = duration / dt;
    if (!(steps < 1e10)) {
      bad("realisation-step", q(dt, Dimension::time),
          fmt::format("{:.3g} velocity steps are too many; raise realisation-step or shorten duration", steps));
    }
    if (velocity_update == VelocityUpdate::euler) {
      for (int i = 0; i < 3; ++i) {
        const double h = dt / time_scale_of(i);
        if (h > 2.0) {
          errors.emplace_back("velocity-update,realisation-step", fmt::format(
              "velocity-update = euler is unstable here: realisation-step / time-scale{} = {:.3g} > 2; use "
              "velocity-update = exact (exact for every step) or a realisation-step below {}",
              i == 0 ? "" : (i == 1 ? "-y" : "-z"), h, q(2.0 * time_scale_of(i), Dimension::time)));
          break;
        }
      }
    }
  }
  if (errors.empty()) return {};
  if (errors.size() == 1) return awcc::Validation::invalid(errors.front().first, errors.front().second);
  std::string all;
  for (const auto& e : errors) all += (all.empty() ? "" : "\n") + e.second;
  return awcc::Validation::invalid({}, all);
}

awcc::OptionError invalid_scene(const awcc::Validation& validation) {
  std::string text = "invalid scene:";
  std::string_view rest = validation.message;
  while (!rest.empty()) {
    const auto end = std::min(rest.find('\n'), rest.size());
    text += "\n  " + std::string(rest.substr(0, end));
    rest.remove_prefix(std::min(end + 1, rest.size()));
  }
  return awcc::OptionError(text, validation.quantity);
}

// ---------------------------------------------------------------------------
// Field table.

namespace {

double number(std::string_view text, Dimension d) { return parse_quantity(text, d); }

std::int64_t integer(std::string_view text, std::string_view name) {
  const double v = parse_quantity(text, Dimension::dimensionless);
  if (v != std::floor(v) || std::fabs(v) > 9.0e15)
    throw std::invalid_argument(fmt::format("'{}' is not a whole number for {}", text, name));
  return static_cast<std::int64_t>(v);
}

// The tips' text is read and written by libcore's point lists (awcc/units.hpp),
// as pdp process reads its `tips` option: one form of a probe for both.
std::vector<Vec3> parse_tips(std::string_view text) {
  std::vector<Vec3> tips;
  for (const auto& p : awcc::parse_points(text)) tips.push_back({p[0], p[1], p[2]});
  return tips;
}

std::string format_tips(const Scene& s) {
  if (s.tips.empty()) return "(two tips from dx, dy, dz)";
  std::vector<std::array<double, 3>> points;
  for (const auto& t : s.tips) points.push_back({t.x, t.y, t.z});
  return awcc::format_points(points);
}

#define PDP_QUANTITY_FIELD(NAME, MEMBER, DIM, HELP)                                               \
  SceneField {                                                                                   \
    NAME, DIM, HELP, [](Scene& s, std::string_view t) { s.MEMBER = number(t, DIM); },            \
        [](const Scene& s) { return format_quantity(s.MEMBER, DIM); }                            \
  }

const SceneField kFields[] = {
    PDP_QUANTITY_FIELD("velocity", velocity, Dimension::velocity, "mean streamwise velocity, m/s"),
    PDP_QUANTITY_FIELD("tu", tu, Dimension::dimensionless, "streamwise turbulence intensity Tu_x = u_rms / u, -"),
    PDP_QUANTITY_FIELD("tu-y", tu_y, Dimension::dimensionless, "transverse turbulence intensity Tu_y, -"),
    PDP_QUANTITY_FIELD("tu-z", tu_z, Dimension::dimensionless, "vertical turbulence intensity Tu_z, -"),
    PDP_QUANTITY_FIELD("time-scale", time_scale, Dimension::time, "integral time scale T_x of the velocity, s"),
    SceneField{"time-scale-y", Dimension::time, "integral time scale T_y, s (default: time-scale)",
               [](Scene& s, std::string_view t) { s.time_scale_y = number(t, Dimension::time); },
               [](const Scene& s) {
                 return s.time_scale_y ? format_quantity(*s.time_scale_y, Dimension::time) : std::string("time-scale");
               }},
    SceneField{"time-scale-z", Dimension::time, "integral time scale T_z, s (default: time-scale)",
               [](Scene& s, std::string_view t) { s.time_scale_z = number(t, Dimension::time); },
               [](const Scene& s) {
                 return s.time_scale_z ? format_quantity(*s.time_scale_z, Dimension::time) : std::string("time-scale");
               }},
    PDP_QUANTITY_FIELD("rho-xy", rho_xy, Dimension::dimensionless, "correlation of u_x and u_y, -"),
    PDP_QUANTITY_FIELD("rho-xz", rho_xz, Dimension::dimensionless, "correlation of u_x and u_z, -"),
    PDP_QUANTITY_FIELD("rho-yz", rho_yz, Dimension::dimensionless, "correlation of u_y and u_z, -"),
    PDP_QUANTITY_FIELD("void-fraction", void_fraction, Dimension::dimensionless,
                       "void fraction c in (0, 0.99]: bubbles in water up to 0.5, water droplets in air at 1 - c "
                       "above (the spray region), -"),
    PDP_QUANTITY_FIELD("bubble-diameter", bubble_diameter, Dimension::length,
                       "volume-equivalent diameter d_b (median if log-normal) of the dispersed particle: bubble, "
                       "or droplet for c > 0.5, m"),
    PDP_QUANTITY_FIELD("diameter-log-sd", diameter_log_sd, Dimension::dimensionless,
                       "standard deviation of ln(d_b) of bubbles or droplets: 0 = equal diameters, > 0 = "
                       "log-normal, -"),
    PDP_QUANTITY_FIELD("aspect-ratio", aspect_ratio, Dimension::dimensionless,
                       "bubble's or droplet's ellipsoid semi-axis along x over lateral semi-axes (volume kept), "
                       "1 = sphere, -"),
    SceneField{"arrival", Dimension::dimensionless,
               "bubble arrivals: equal-time | poisson-time | equal-space | poisson-space",
               [](Scene& s, std::string_view t) {
                 for (auto r : {ArrivalRule::equal_time, ArrivalRule::poisson_time, ArrivalRule::equal_space,
                                ArrivalRule::poisson_space}) {
                   if (to_string(r) == t) {
                     s.arrival = r;
                     return;
                   }
                 }
                 throw std::invalid_argument(fmt::format(
                     "'{}' is not an arrival rule; write equal-time, poisson-time, equal-space or poisson-space", t));
               },
               [](const Scene& s) { return std::string(to_string(s.arrival)); }},
    SceneField{"overlap-retries", Dimension::dimensionless, "lateral positions tried to avoid overlapping bubbles",
               [](Scene& s, std::string_view t) { s.overlap_retries = static_cast<int>(integer(t, "overlap-retries")); },
               [](const Scene& s) { return fmt::format("{}", s.overlap_retries); }},
    SceneField{"overlap", Dimension::dimensionless,
               "entry points: avoid (retry, wait, compensate the volume lost) | allow (uniform, kept where they "
               "overlap: other simulators' rule)",
               [](Scene& s, std::string_view t) {
                 for (auto r : {OverlapRule::avoid, OverlapRule::allow}) {
                   if (to_string(r) == t) {
                     s.overlap = r;
                     return;
                   }
                 }
                 throw std::invalid_argument(fmt::format("'{}' is not an overlap rule; write avoid or allow", t));
               },
               [](const Scene& s) { return std::string(to_string(s.overlap)); }},
    PDP_QUANTITY_FIELD("dx", dx, Dimension::length, "streamwise tip separation (trailing minus leading), m"),
    PDP_QUANTITY_FIELD("dy", dy, Dimension::length, "lateral tip separation, m"),
    PDP_QUANTITY_FIELD("dz", dz, Dimension::length, "vertical tip separation, m"),
    SceneField{"tips", Dimension::length,
               "explicit tip positions 'x,y,z;x,y,z;...' (m, units allowed); replaces dx/dy/dz",
               [](Scene& s, std::string_view t) { s.tips = parse_tips(t); }, &format_tips},
    PDP_QUANTITY_FIELD("fs", fs, Dimension::frequency, "sampling rate per channel, Hz"),
    PDP_QUANTITY_FIELD("duration", duration, Dimension::time, "record length, s"),
    SceneField{"seed", Dimension::dimensionless, "random seed (a whole number >= 0)",
               [](Scene& s, std::string_view t) {
                 // Seeds span all 64 bits (pdp sweep derives them so and prints
                 // them whole): digits are read exactly, never through a double,
                 // so that any run of a sweep CSV can be replayed.
                 const auto first = t.find_first_not_of(" \t");
                 const auto last = t.find_last_not_of(" \t");
                 const std::string_view digits =
                     first == std::string_view::npos ? t : t.substr(first, last - first + 1);
                 if (!digits.empty() && digits.find_first_not_of("0123456789") == std::string_view::npos) {
                   std::uint64_t v = 0;
                   const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
                   if (ec != std::errc{} || end != digits.data() + digits.size())
                     throw std::invalid_argument(fmt::format("seed '{}' is above 2^64 - 1", t));
                   s.seed = v;
                   return;
                 }
                 const auto v = integer(t, "seed");
                 if (v < 0) throw std::invalid_argument(fmt::format("seed '{}' must be >= 0", t));
                 s.seed = static_cast<std::uint64_t>(v);
               },
               [](const Scene& s) { return fmt::format("{}", s.seed); }},
    SceneField{"velocity-update", Dimension::dimensionless, "velocity time stepping: exact | euler",
               [](Scene& s, std::string_view t) {
                 if (t == "exact") s.velocity_update = VelocityUpdate::exact;
                 else if (t == "euler") s.velocity_update = VelocityUpdate::euler;
                 else throw std::invalid_argument(fmt::format("'{}' is not a velocity update; write exact or euler", t));
               },
               [](const Scene& s) { return std::string(to_string(s.velocity_update)); }},
    PDP_QUANTITY_FIELD("realisation-step", realisation_step, Dimension::time,
                       "velocity time step dt_r, s; 0 = min(T/50, tip transit/10)"),
    PDP_QUANTITY_FIELD("voltage-water", voltage_water, Dimension::voltage, "raw signal: water level, V"),
    PDP_QUANTITY_FIELD("voltage-air", voltage_air, Dimension::voltage, "raw signal: air level, V"),
    PDP_QUANTITY_FIELD("voltage-time-constant", voltage_time_constant, Dimension::time,
                       "raw signal: first-order rise/fall time constant, s"),
    PDP_QUANTITY_FIELD("voltage-noise", voltage_noise, Dimension::voltage, "raw signal: Gaussian noise std, V"),
    PDP_QUANTITY_FIELD("voltage-full-scale", voltage_full_scale, Dimension::voltage,
                       "raw signal: voltage of int16 full scale (32768 counts), V"),
};

#undef PDP_QUANTITY_FIELD

}  // namespace

std::span<const SceneField> scene_fields() { return kFields; }

void set_scene_field(Scene& scene, std::string_view name, std::string_view text) {
  for (const auto& f : kFields) {
    if (f.name == name) {
      f.parse(scene, text);
      return;
    }
  }
  throw std::invalid_argument(fmt::format("unknown scene field '{}'", name));
}

void load_scene_toml(const std::filesystem::path& path, Scene& scene) {
  // A [scene] table is accepted as well as top-level keys.
  for (const auto& setting : awcc::read_settings(path, "scene")) {
    const SceneField* field = nullptr;
    for (const auto& f : kFields) {
      if (f.name == setting.key) field = &f;
    }
    if (!field) {
      std::string names;
      for (const auto& f : kFields) names += (names.empty() ? "" : ", ") + std::string(f.name);
      throw awcc::InputError(fmt::format("{}:{}: unknown scene field '{}'; use one of the known fields: {}",
                                         path.string(), setting.line, setting.key, names));
    }
    try {
      field->parse(scene, setting.text);
    } catch (const std::invalid_argument& e) {
      throw awcc::InputError(fmt::format("{}:{}: field '{}': {}", path.string(), setting.line, setting.key, e.what()),
                             setting.key);
    }
  }
}

}  // namespace synth
