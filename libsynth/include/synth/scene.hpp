#pragma once
// The scene of the synthetic probe (METHOD.md section 5): the flow, the
// bubbles, the probe and the acquisition. The defaults are the base case of
// Buergler et al. (2024). Each field has one name, used alike as TOML key and
// as command-line option (--name), listed with its unit by scene_fields().

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/units.hpp"
#include "awcc/validation.hpp"

namespace synth {

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
  friend bool operator==(const Vec3&, const Vec3&) = default;
};

/// When bubbles (droplets, above c = 0.5) enter the control volume. Under
/// the time rules the particle flux is constant while the velocity
/// fluctuates, so a tip sees the dispersed fraction c_d (1 + Tu_x^2) (c_d = c
/// for bubbles, 1 - c for droplets: void fraction 1 - (1 - c)(1 + Tu_x^2));
/// under the space rules it sees c_d itself (METHOD 5.2).
enum class ArrivalRule {
  equal_time,     ///< equal inter-arrival times (the paper's rule, default)
  poisson_time,   ///< Poisson process in time
  equal_space,    ///< equally spaced along the flow (enter as the flow advances)
  poisson_space,  ///< Poisson process along the flow
};

/// Whether a particle's entry point avoids the particles already in the
/// control volume. `avoid` is pdp's rule (METHOD 5.2: retry lateral
/// positions, wait, compensate the volume lost; synth/synthesiser.hpp,
/// "Dense placement"); `allow` is the convention of simulators that draw the
/// entry point uniformly over the inlet and keep it: particles overlap where
/// they fall and the volume they share is lost, so the realised void fraction
/// falls below c as c grows (the truth reports what was realised).
enum class OverlapRule {
  avoid,  ///< retry, wait and compensate (default)
  allow,  ///< one uniform entry point, kept whatever it overlaps
};
std::string_view to_string(OverlapRule rule);

/// What the probe's tips pierce, decided by the void fraction alone. Up to
/// c = 0.5 the dispersed phase is air: bubbles in water. Above it, water:
/// droplets carried through air (the spray region of a self-aerated flow),
/// at the volume fraction 1 - c, with the same size model (bubble_diameter,
/// diameter_log_sd, aspect_ratio describe the droplet), velocity field,
/// arrival rules, overlap avoidance and piercing; a tip's signal is then the
/// complement, air outside the droplets. One scene type so covers c from
/// 0.005 to 0.99 with the truth defined alike (air samples / samples, air
/// chords).
enum class DispersedPhase {
  bubbles,   ///< c <= 0.5: air bubbles in water
  droplets,  ///< c > 0.5: water droplets in air
};

/// The dispersed phase of a void fraction c: bubbles for c <= 0.5, droplets above.
[[nodiscard]] DispersedPhase dispersed_phase(double void_fraction);
/// The dispersed phase's volume fraction: c for bubbles, 1 - c for droplets.
[[nodiscard]] double dispersed_fraction(double void_fraction);
std::string_view to_string(DispersedPhase phase);

/// Time stepping of the Ornstein-Uhlenbeck velocity.
enum class VelocityUpdate {
  exact,  ///< u' a + sigma sqrt(1 - a^2) eta, a = exp(-dt/T): exact for every dt/T
  euler,  ///< the paper's Euler step, for comparison; refused for dt/T > 2
};

struct Scene {
  // Flow.
  double velocity = 10.0;                 ///< mean streamwise velocity, m/s
  double tu = 0.25;                       ///< streamwise turbulence intensity Tu_x, -
  double tu_y = 0.125;                    ///< transverse intensity Tu_y, -
  double tu_z = 0.125;                    ///< vertical intensity Tu_z, -
  double time_scale = 0.1;                ///< integral time scale T_x, s
  std::optional<double> time_scale_y;     ///< T_y, s (default: time_scale)
  std::optional<double> time_scale_z;     ///< T_z, s (default: time_scale)
  double rho_xy = 0.0;                    ///< velocity correlation u_x u_y, -
  double rho_xz = -0.45;                  ///< velocity correlation u_x u_z, -
  double rho_yz = 0.0;                    ///< velocity correlation u_y u_z, -
  // The dispersed phase (bubbles, or droplets above c = 0.5: DispersedPhase).
  double void_fraction = 0.25;            ///< c, - (0, 0.99]; the dispersed fraction is c or 1 - c
  /// Volume-equivalent (median) diameter d_b of the dispersed particle, m:
  /// the bubble's, or the droplet's in the spray region; so are the two below.
  double bubble_diameter = 3e-3;
  double diameter_log_sd = 0.0;           ///< std of ln(d_b); 0 = all equal, > 0 = log-normal
  double aspect_ratio = 1.0;              ///< ellipsoid semi-axis along x over the lateral ones
  ArrivalRule arrival = ArrivalRule::equal_time;
  int overlap_retries = 30;               ///< lateral positions tried to avoid an overlap
  OverlapRule overlap = OverlapRule::avoid;  ///< avoid overlaps, or allow them (foreign simulators' rule)
  // Probe.
  double dx = 5e-3;                       ///< trailing tip minus leading tip, streamwise, m
  double dy = 1e-3;                       ///< ... lateral, m
  double dz = 0.0;                        ///< ... vertical, m
  std::vector<Vec3> tips;                 ///< explicit tips (m); when set, dx/dy/dz are ignored
  // Acquisition.
  double fs = 500e3;                      ///< sampling rate per channel, Hz
  double duration = 300.0;                ///< record length, s
  std::uint64_t seed = 1;                 ///< random seed
  // Numerics.
  VelocityUpdate velocity_update = VelocityUpdate::exact;
  double realisation_step = 0.0;          ///< velocity step dt_r, s; 0 = automatic
  // Raw-voltage rendering (--signal voltage).
  double voltage_water = 4.0;             ///< water level, V (conductivity probe: water high)
  double voltage_air = 0.3;               ///< air level, V
  double voltage_time_constant = 2e-6;    ///< first-order rise/fall time constant, s
  double voltage_noise = 0.02;            ///< Gaussian noise std, V
  double voltage_full_scale = 5.0;        ///< int16 full scale (32768 counts), V

  /// Tip positions in metres: `tips` when given, else {0, (dx, dy, dz)}.
  [[nodiscard]] std::vector<Vec3> probe_tips() const;
  /// The separation a dual-tip processing sees: second tip minus first,
  /// streamwise (x), and laterally as the distance across the flow,
  /// hypot(y, z); m. The geometry recorded is the one processed.
  [[nodiscard]] double streamwise_separation() const;
  [[nodiscard]] double lateral_separation() const;
  [[nodiscard]] double time_scale_of(int component) const;
  [[nodiscard]] double tu_of(int component) const;
  /// Velocity time step actually used: realisation_step, or when 0,
  /// min(T_min / 50, transit / 10) with transit = max tip spread / velocity
  /// (bubble diameter / velocity for a one-tip probe), so that the step
  /// resolves both the integral time scale and the tip-to-tip transit; then
  /// shrunk to duration / ceil(duration / step) so the record holds a whole
  /// number of steps.
  [[nodiscard]] double effective_realisation_step() const;
  /// Record length in samples, round(duration * fs).
  [[nodiscard]] std::int64_t sample_count() const;

  /// ok, or every problem found, one per line, each naming the field, its
  /// value and the allowed range (a scene is often wrong in several fields at
  /// once, and one run should name them all). quantity: the field(s) of the
  /// problem when there is one ("rho-xy,rho-xz,rho-yz"); empty when there
  /// are several, as no single option fixes them.
  [[nodiscard]] awcc::Validation validate() const;
};

/// A scene field as the user writes it.
struct SceneField {
  std::string_view name;        ///< TOML key and CLI option name
  awcc::Dimension dimension;    ///< unit family for parsing "5mm" etc.
  std::string_view help;        ///< one line, with the unit
  /// Sets the field from text ("5mm", "0.25", "poisson-time", "0,0,0;5mm,1mm,0").
  /// Throws std::invalid_argument naming the problem.
  void (*parse)(Scene&, std::string_view);
  /// Current value as text with its unit (for --help defaults and reports).
  std::string (*format)(const Scene&);
};

/// Every user-settable field of Scene, in the order shown by --help.
std::span<const SceneField> scene_fields();

/// Sets one field by name; throws std::invalid_argument (unknown field or bad value).
void set_scene_field(Scene& scene, std::string_view name, std::string_view text);

/// The error a front end or the synthesiser raises for a scene that failed
/// validate(): "invalid scene:" and each problem on its own indented line.
[[nodiscard]] awcc::OptionError invalid_scene(const awcc::Validation& validation);

/// Reads a scene TOML file over `scene` (fields absent from the file keep their
/// values). Keys are the field names; values are numbers in SI units or strings
/// with units ("5mm"). Throws InputError naming the file, the line, the key
/// and the fix (quantity(): the field). Does not validate: call Scene::validate() afterwards.
void load_scene_toml(const std::filesystem::path& path, Scene& scene);

std::string_view to_string(ArrivalRule rule);
std::string_view to_string(VelocityUpdate update);

}  // namespace synth
