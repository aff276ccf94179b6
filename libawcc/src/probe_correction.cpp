#include "awcc/probe_correction.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <numbers>

namespace awcc {

Validation ProbeCorrectionOptions::validate() const {
  struct Positive {
    const char* option;  // the declared name; "" for a member no option sets
    const char* name;
    double value;
  };
  const std::array<Positive, 10> positive{{{"needle-diameter", "needle diameter", needle_diameter},
                                           {"water-density", "water density", water_density},
                                           {"water-viscosity", "water viscosity", water_viscosity},
                                           {"air-density", "air density", air_density},
                                           {"surface-tension", "surface tension", surface_tension},
                                           {"", "gravity", gravity},
                                           {"contact-factor", "contact factor", contact_factor + 1.0},
                                           {"virtual-mass", "virtual mass coefficient", virtual_mass + 1.0},
                                           {"impact-pressure", "impact pressure coefficient", impact_pressure + 1.0},
                                           {"", "void fraction limit", max_void_fraction}}};
  for (const auto& p : positive) {
    if (!(p.value > 0.0) || !std::isfinite(p.value))
      return Validation::invalid(p.option, fmt::format("probe correction: the {} must be positive", p.name));
  }
  for (const auto& [option, value] : {std::pair{"contact-factor", contact_factor}, std::pair{"virtual-mass", virtual_mass},
                                      std::pair{"impact-pressure", impact_pressure}}) {
    if (value < 0.0) return Validation::invalid(option, "probe correction: the force coefficients must be >= 0");
  }
  if (!(air_density < water_density))
    return Validation::invalid("air-density", "probe correction: the air must be lighter than the water");
  if (!(std::fabs(probe_angle) <= std::numbers::pi))
    return Validation::invalid("probe-angle", "probe correction: the probe angle must lie within +/-180 deg");
  if (max_steps < 100) return Validation::invalid("", "probe correction: allow at least 100 integration steps");
  return {};
}

namespace detail {

double drag_coefficient(double relative_speed, double d, const ProbeCorrectionOptions& o) {
  if (relative_speed == 0.0) return 0.0;
  const double re = std::fabs(relative_speed) * d / o.water_viscosity;
  const double eo = o.gravity * (o.water_density - o.air_density) * d * d / o.surface_tension;
  return std::max(std::min(24.0 / re * (1.0 + 0.15 * std::pow(re, 0.687)), 72.0 / re), 8.0 / 3.0 * eo / (eo + 4.0));
}

double deformation_coefficient(double u, double d, const ProbeCorrectionOptions& o) {
  const double rb = d * u / o.water_viscosity;
  return std::max(0.0, -7.2e-8 * rb * rb + 0.002 * rb - 0.589);
}

namespace {

// Brent's method on [a, b] with f(a), f(b) of opposite signs; x tolerance xtol.
double brent(const std::function<double(double)>& f, double a, double b, double fa, double fb, double xtol) {
  double c = a, fc = fa, d = b - a, e = d;
  for (int i = 0; i < 200; ++i) {
    if ((fb > 0) == (fc > 0)) {
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::fabs(fc) < std::fabs(fb)) {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol = 2.0 * std::numeric_limits<double>::epsilon() * std::fabs(b) + 0.5 * xtol;
    const double m = 0.5 * (c - b);
    if (std::fabs(m) <= tol || fb == 0.0) return b;
    if (std::fabs(e) >= tol && std::fabs(fa) > std::fabs(fb)) {
      double p, q, r;
      const double s = fb / fa;
      if (a == c) {
        p = 2.0 * m * s;
        q = 1.0 - s;
      } else {
        q = fa / fc;
        r = fb / fc;
        p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0));
        q = (q - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0) q = -q;
      p = std::fabs(p);
      if (2.0 * p < std::min(3.0 * m * q - std::fabs(tol * q), std::fabs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = m;
        e = d;
      }
    } else {
      d = m;
      e = d;
    }
    a = b;
    fa = fb;
    b += std::fabs(d) > tol ? d : (m > 0 ? tol : -tol);
    fb = f(b);
  }
  return b;
}

}  // namespace

double rise_velocity(double d, const ProbeCorrectionOptions& o) {
  const double cosine = std::cos(o.probe_angle);
  if (std::fabs(cosine) < 1e-15) return 0.0;
  // The fixed point u = sqrt(4 d g |cos| (rho_c - rho_d) / (3 C_D(u) rho_c)):
  // below it the right side is larger (C_D ~ 1 / u), above it smaller.
  const auto excess = [&](double u) {
    const double cd = drag_coefficient(u, d, o);
    return u - std::sqrt(4.0 * d * o.gravity * std::fabs(cosine) * (o.water_density - o.air_density) /
                         (3.0 * cd * o.water_density));
  };
  double lo = 1e-12, hi = 1.0;
  double flo = excess(lo), fhi = excess(hi);
  while (fhi < 0.0 && hi < 1e3) {
    hi *= 4.0;
    fhi = excess(hi);
  }
  const double u = brent(excess, lo, hi, flo, fhi, 1e-14);
  return cosine > 0.0 ? u : -u;
}

namespace {

// The force balance of one bubble (diameter and carrier fixed), its
// constants computed once: the integrator evaluates it thousands of times.
struct BubbleModel {
  BubbleModel(double d, double carrier_velocity, const ProbeCorrectionOptions& o) : carrier(carrier_velocity) {
    const double m = o.air_density + o.virtual_mass * o.water_density;
    const double d3 = d * d * d;
    reynolds_per_speed = d / o.water_viscosity;
    const double eo = o.gravity * (o.water_density - o.air_density) * d * d / o.surface_tension;
    eotvos_drag = 8.0 / 3.0 * eo / (eo + 4.0);
    drag = 3.0 * o.water_density / (4.0 * m * d);
    constant = (o.air_density - o.water_density) * o.gravity * std::cos(o.probe_angle) / m -
               6.0 * o.contact_factor * o.surface_tension * o.needle_diameter / (m * d3);
    impact = 3.0 * o.impact_pressure * o.air_density * o.needle_diameter * o.needle_diameter / (4.0 * m * d3);
    deformation = 6.0 * o.surface_tension / (std::numbers::pi * d * d * m);
    weber_per_u2 = o.air_density * d / o.surface_tension;
  }
  double operator()(double u) const {
    const double relative = carrier - u;
    double cd = 0.0;
    if (relative != 0.0) {
      // Tomiyama: max(min(24/Re (1 + 0.15 Re^0.687), 72/Re), 8/3 Eo/(Eo + 4));
      // above Re = 50 the min is 72/Re (the bracket exceeds 3 from Re = 43.4).
      const double re = std::fabs(relative) * reynolds_per_speed;
      const double viscous = re < 50.0 ? std::min(24.0 / re * (1.0 + 0.15 * std::pow(re, 0.687)), 72.0 / re) : 72.0 / re;
      cd = std::max(viscous, eotvos_drag);
    }
    const double rb = reynolds_per_speed * u;
    const double cs = std::max(0.0, -7.2e-8 * rb * rb + 0.002 * rb - 0.589);
    const double deform = cs > 0.0 ? cs * deformation * std::sqrt(std::sqrt(weber_per_u2 * u * u)) : 0.0;
    return drag * cd * relative * std::fabs(relative) + constant - impact * u * u - deform;
  }
  double carrier, reynolds_per_speed, eotvos_drag, drag, constant, impact, deformation, weber_per_u2;
};

}  // namespace

double bubble_acceleration(double u, double d, double carrier, const ProbeCorrectionOptions& o) {
  return BubbleModel(d, carrier, o)(u);
}

std::optional<double> integrate_velocity(const std::function<double(double)>& f, double u0, double t1, double rtol,
                                         int max_steps) {
  // Dormand-Prince 5(4): the fifth-order solution advances, the difference
  // to the fourth-order one estimates the error of the step.
  static constexpr double a21 = 1.0 / 5, a31 = 3.0 / 40, a32 = 9.0 / 40, a41 = 44.0 / 45, a42 = -56.0 / 15,
                          a43 = 32.0 / 9, a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                          a54 = -212.0 / 729, a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
                          a64 = 49.0 / 176, a65 = -5103.0 / 18656, b1 = 35.0 / 384, b3 = 500.0 / 1113,
                          b4 = 125.0 / 192, b5 = -2187.0 / 6784, b6 = 11.0 / 84, e1 = 71.0 / 57600,
                          e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200, e6 = 22.0 / 525,
                          e7 = -1.0 / 40;
  double t = 0.0, u = u0, h = t1 / 64.0;
  const double atol = rtol * std::fabs(u0) * 1e-3;
  double k1 = f(u);
  for (int step = 0; step < max_steps; ++step) {
    if (t >= t1) return u;
    h = std::min(h, t1 - t);
    const double k2 = f(u + h * a21 * k1);
    const double k3 = f(u + h * (a31 * k1 + a32 * k2));
    const double k4 = f(u + h * (a41 * k1 + a42 * k2 + a43 * k3));
    const double k5 = f(u + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4));
    const double k6 = f(u + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5));
    const double next = u + h * (b1 * k1 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6);
    const double k7 = f(next);
    const double error = std::fabs(h * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7));
    const double scale = atol + rtol * std::max(std::fabs(u), std::fabs(next));
    const double ratio = error / scale;
    if (!std::isfinite(next) || !std::isfinite(ratio)) {
      h *= 0.25;
      continue;
    }
    if (ratio <= 1.0) {
      t += h;
      u = next;
      k1 = k7;  // first same as last
      if (!(u > 0.0)) return std::nullopt;  // the bubble stopped before t1
    }
    h *= std::clamp(0.9 * std::pow(std::max(ratio, 1e-10), -0.2), 0.2, 5.0);
  }
  return t >= t1 ? std::optional<double>(u) : std::nullopt;
}

}  // namespace detail

WindowCorrection correct_window(double measured_velocity, double void_fraction, double count_rate, double dx,
                                const ProbeCorrectionOptions& o) {
  WindowCorrection out;
  if (void_fraction > o.max_void_fraction) {
    out.outcome = CorrectionOutcome::not_bubbly;
    out.velocity = measured_velocity;
    return out;
  }
  if (!(measured_velocity > 0.0) || !(count_rate > 0.0) || !(void_fraction > 0.0) || !(dx > 0.0)) {
    out.why = "no positive velocity, void fraction and count rate to correct";
    return out;
  }
  const double um = measured_velocity, t1 = dx / um;
  bool stopped = false;
  // h(u0) = u0 + u(T1; u0) - 2 u_m; a bubble that stops counts as leaving at 0.
  auto residual = [&](double u0) {
    const double d = 1.5 * u0 * void_fraction / count_rate;
    const double carrier = u0 - detail::rise_velocity(d, o);
    const detail::BubbleModel model(d, carrier, o);
    const auto exit = detail::integrate_velocity(std::cref(model), u0, t1, 1e-12, o.max_steps);
    stopped = !exit;
    return u0 + exit.value_or(0.0) - 2.0 * um;
  };
  // Bracket: the bubble is slowed (u0 above u_m) unless buoyancy speeds it up.
  double a = um, fa = residual(um);
  double b = a, fb = fa;
  // Steps of 15 % (the toolbox's first guess) growing geometrically: u0 up to
  // 8.1 u_m, or down to 0.28 u_m when buoyancy speeds the bubble up.
  for (int k = 1; k <= 15 && (fa > 0) == (fb > 0); ++k) {
    if (fa < 0) {
      a = b;
      fa = fb;
      b = um * std::pow(1.15, k);
    } else {
      a = b;
      fa = fb;
      b = um * std::pow(0.92, k);
    }
    fb = residual(b);
  }
  if ((fa > 0) == (fb > 0)) {
    out.why = fmt::format("no undisturbed velocity between {:.3g} and {:.3g} m/s meets the force balance", std::min(a, b),
                          std::max(a, b));
    return out;
  }
  const double u0 = detail::brent(residual, a, b, fa, fb, 1e-13 * um);
  const double r = residual(u0);
  if (stopped) {
    out.why = "the bubble stops before it reaches the trailing tip";
    return out;
  }
  if (!(std::fabs(r) <= 1e-9 * um)) {
    out.why = fmt::format("the force balance was not met (residual {:.2g} m/s)", r);
    return out;
  }
  out.outcome = CorrectionOutcome::corrected;
  out.velocity = u0;
  return out;
}

}  // namespace awcc
