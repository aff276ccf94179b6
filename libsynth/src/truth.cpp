#include "synth/truth.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace synth {

double VelocityHistory::displacement(double t) const {
  if (size_ < 2) return 0.0;
  const double position = std::clamp(t / step_, 0.0, static_cast<double>(size_ - 1));
  auto k = static_cast<std::size_t>(position);
  k = std::min(k, size_ - 2);
  const double frac = position - static_cast<double>(k);
  return at(k) + (at(k + 1) - at(k)) * frac;
}

double VelocityHistory::mean_velocity(double t0, double t1) const {
  if (size_ < 2) return 0.0;
  if (t1 > t0) return (displacement(t1) - displacement(t0)) / (t1 - t0);
  const double position = std::clamp(t0 / step_, 0.0, static_cast<double>(size_ - 2));
  const auto k = std::min(static_cast<std::size_t>(position), size_ - 2);
  return (at(k + 1) - at(k)) / step_;
}

namespace {

std::string opt(const std::optional<double>& v, std::string_view format_unit, double scale = 1.0) {
  if (!v) return "n/a (no fluctuation)";
  return fmt::format(fmt::runtime(format_unit), *v * scale);
}

}  // namespace

std::string Truth::report() const {
  using awcc::Dimension;
  using awcc::format_quantity;
  const Scene& s = imposed;
  std::string out;
  auto line = [&out](std::string text) { out += text + "\n"; };
  line(fmt::format("Synthetic probe truth: {} at {}, {} samples a tip, seed {}", format_quantity(s.duration, Dimension::time),
                   format_quantity(s.fs, Dimension::frequency), sample_count, s.seed));
  line(fmt::format("  realisation step {}, {} velocity steps in the record", format_quantity(realisation_step, Dimension::time),
                   realised.steps));
  line("  velocity            imposed          realised");
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    line(fmt::format("    mean u_{}        {:>9.4f} m/s   {:>9.4f} m/s", names[i], i == 0 ? s.velocity : 0.0,
                     realised.mean_velocity[static_cast<std::size_t>(i)]));
  }
  for (int i = 0; i < 3; ++i) {
    line(fmt::format("    Tu_{}            {:>9.4f}        {:>9.4f}", names[i], s.tu_of(i),
                     realised.turbulence_intensity[static_cast<std::size_t>(i)]));
  }
  for (int i = 0; i < 3; ++i) {
    line(fmt::format("    T_{}             {:>9.4f} ms     {}", names[i], s.time_scale_of(i) * 1e3,
                     opt(realised.integral_time_scale[static_cast<std::size_t>(i)], "{:>9.4f} ms", 1e3)));
  }
  line(fmt::format("    rho_xy          {:>9.4f}        {}", s.rho_xy, opt(realised.rho_xy, "{:>9.4f}")));
  line(fmt::format("    rho_xz          {:>9.4f}        {}", s.rho_xz, opt(realised.rho_xz, "{:>9.4f}")));
  line(fmt::format("    rho_yz          {:>9.4f}        {}", s.rho_yz, opt(realised.rho_yz, "{:>9.4f}")));
  const std::string_view particles = to_string(dispersed_phase);
  if (dispersed_phase == DispersedPhase::droplets) {
    line(fmt::format("  spray region: the tips pierce water droplets at the volume fraction 1 - c = {:.4f}; air is "
                     "outside them",
                     dispersed_fraction(s.void_fraction)));
  }
  line(fmt::format("  {}: d_b {}, {} generated in the record ({:.1f} /s into a {:.2f} x {:.2f} x {:.2f} mm "
                   "control volume), {} overlaps unresolved",
                   particles, format_quantity(s.bubble_diameter, Dimension::length), bubbles_generated, bubble_rate,
                   control_volume[0] * 1e3, control_volume[1] * 1e3, control_volume[2] * 1e3, overlaps_unresolved));
  if (overlaps_unresolved > 0) {
    const bool space_rule = s.arrival == ArrivalRule::equal_space || s.arrival == ArrivalRule::poisson_space;
    if (space_rule) {
      line(fmt::format("  the overlapping {} share {:.5f} of the flow's volume, given back by arrivals brought forward",
                       particles, compensated_volume_fraction));
    } else {
      line(fmt::format("  the overlapping {} piled up while the flow was slow: their shared volume is lost to the "
                       "realised fraction (time arrival rules)",
                       particles));
    }
  }
  line(fmt::format("  tips (imposed c {:.4f}, expected pierce rate {:.2f} /s):", s.void_fraction, expected_pierce_rate));
  for (std::size_t j = 0; j < tips.size(); ++j) {
    const auto& t = tips[j];
    line(fmt::format("    tip {} at ({:.3f}, {:.3f}, {:.3f}) mm: void fraction {:.5f}, {} {} pierced "
                     "({:.2f} /s), {} chords{}",
                     j, t.position.x * 1e3, t.position.y * 1e3, t.position.z * 1e3, t.void_fraction, t.bubbles_pierced,
                     particles,
                     static_cast<double>(t.bubbles_pierced) / s.duration, t.chords,
                     t.interfacial_area ? fmt::format(", interfacial area {:.2f} 1/m (expected {:.2f})",
                                                      *t.interfacial_area, expected_interfacial_area)
                                        : std::string()));
  }
  for (const auto& p : pairs) {
    line(fmt::format("    tips {} and {}: {} {} pierced by both", p.first, p.second, p.pierced_by_both, particles));
  }
  if (reentries_missed > 0) {
    line(fmt::format("  WARNING: {} steps where a retired bubble could have re-entered (flow reversal beyond the "
                     "allowance); piercings may be missing",
                     reentries_missed));
  }
  return out;
}

}  // namespace synth
