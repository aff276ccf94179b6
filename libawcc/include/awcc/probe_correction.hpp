#pragma once
// Bubble-probe interaction correction (Hohermuth et al. 2021, Nature
// Communications; METHOD.md 9; Kramer's toolbox v1.3).
//
// A bubble pierced by the leading needle is slowed before the trailing tip
// sees it, so dx / tau underestimates the undisturbed velocity u0. Per AWCC
// window, with the measured velocity u_m, the window's void fraction C and
// count rate F: bubble diameter d = 1.5 u0 C / F; rise velocity u_r solving
// u_r = sqrt(4 d g |cos gamma| (rho_c - rho_d) / (3 C_D(u_r d / nu_c) rho_c)),
// signed by cos gamma; carrier velocity u_c = u0 - u_r; with
// m = rho_d + c_VM rho_c the bubble's velocity obeys
//   du/dt = 3 C_D rho_c (u_c - u)|u_c - u| / (4 m d)            drag
//         + (rho_d - rho_c) g cos(gamma) / m                      buoyancy
//         - 6 b sigma d_n / (m d^3)                               contact
//         - 3 C_p rho_d u^2 d_n^2 / (4 m d^3)                     impact pressure
//         - 6 C_s sigma (rho_d u^2 d / sigma)^(1/4) / (pi d^2 m)   deformation,
// u(0) = u0, over the transit time T1 = dx / u_m; Tomiyama's drag
// C_D = max(min(24/Re (1 + 0.15 Re^0.687), 72/Re), 8/3 Eo/(Eo + 4)),
// Re = |u_c - u| d / nu_c, Eo = g (rho_c - rho_d) d^2 / sigma (C_D = 0 when
// u = u_c); C_s = max(0, a Rb^2 + b' Rb + c), Rb = d u / nu_c, a = -7.2e-8,
// b' = 0.002, c = -0.589. u0 is the root of u0 + u(T1; u0) = 2 u_m (the
// measured velocity is the mean of entry and exit velocities).
//
// Decision (METHOD 9): only u_m > 0 enters (the toolbox's solver never
// returns on negative ones); the root is bracketed and found by Brent's
// method, the ODE integrated by an adaptive Runge-Kutta scheme (Dormand-Prince
// 5(4)) with error control and a step budget; a bubble that stops before T1,
// a root that cannot be bracketed or a spent budget fail the window, which is
// then rejected (fate `correction`), never hangs. Windows with C > 0.3 are not
// bubbly flow and stay as measured.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "awcc/validation.hpp"

namespace awcc {

struct ProbeCorrectionOptions {
  bool enabled = false;                ///< correct every accepted AWCC window
  double needle_diameter = 0.6e-3;     ///< outer electrode diameter d_n, m (toolbox default)
  double probe_angle = 0.785398163397448;  ///< gamma between probe axis and gravity, rad (45 deg)
  double water_density = 998.0;        ///< rho_c, kg/m3
  double water_viscosity = 1e-6;       ///< nu_c, m2/s
  double air_density = 1.12;           ///< rho_d, kg/m3
  double surface_tension = 0.073;      ///< sigma, N/m
  double contact_factor = 1.0;         ///< b, -
  double virtual_mass = 0.5;           ///< c_VM, -
  double impact_pressure = 1.0;        ///< C_p, -
  double gravity = 9.81;               ///< g, m/s2
  /// Windows above this void fraction are not bubbly flow: left as measured.
  double max_void_fraction = 0.3;
  /// Runge-Kutta steps allowed per integration: a bound on the time per window.
  int max_steps = 20000;

  [[nodiscard]] Validation validate() const;
};

enum class CorrectionOutcome {
  corrected,   ///< u0 found
  not_bubbly,  ///< C above max_void_fraction: left as measured
  failed,      ///< no u0: the window is rejected (fate `correction`)
};

struct WindowCorrection {
  CorrectionOutcome outcome = CorrectionOutcome::failed;
  double velocity = 0.0;   ///< u0 (corrected), or u_m when not bubbly, m/s
  std::string why;         ///< why it failed
};

/// The correction of one window: measured velocity (m/s), void fraction,
/// count rate (1/s), tip separation dx (m).
WindowCorrection correct_window(double measured_velocity, double void_fraction, double count_rate, double dx,
                                const ProbeCorrectionOptions& options);

namespace detail {

/// Tomiyama's drag coefficient at a relative speed (m/s) for diameter d.
double drag_coefficient(double relative_speed, double d, const ProbeCorrectionOptions& o);
/// C_s of the deformation force at bubble velocity u.
double deformation_coefficient(double u, double d, const ProbeCorrectionOptions& o);
/// The signed rise velocity of a bubble of diameter d, m/s.
double rise_velocity(double d, const ProbeCorrectionOptions& o);
/// du/dt of a bubble of diameter d at velocity u in a carrier moving at u_c.
double bubble_acceleration(double u, double d, double carrier, const ProbeCorrectionOptions& o);

/// u(t1) for du/dt = f(u), u(0) = u0, by Dormand-Prince 5(4) with relative
/// tolerance rtol; empty when u falls to 0 or below (the bubble stops), or
/// when max_steps are spent.
std::optional<double> integrate_velocity(const std::function<double(double)>& f, double u0, double t1, double rtol,
                                         int max_steps);

}  // namespace detail
}  // namespace awcc
