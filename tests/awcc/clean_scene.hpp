#pragma once
// The synthetic dual-tip scene where the error mechanisms of METHOD 6
// vanish: large bubbles (6 mm against dx = 5 mm), aligned tips (dy = 0),
// weak turbulence (Tu = 0.05) with a long time scale (1 s): no selective
// sampling, no oblique impacts, no decorrelation, no window averaging. AWCC's
// and event detection's tests hold them to the realised truth on it.

#include "synth/scene.hpp"

namespace pdp_test {

inline synth::Scene clean_scene(double duration) {
  synth::Scene s;
  s.bubble_diameter = 6e-3;
  s.dy = 0.0;
  s.tu = 0.05;
  s.tu_y = s.tu_z = 0.025;
  s.time_scale = 1.0;
  s.duration = duration;
  return s;
}

/// The clean four-tip scene (METHOD 11.7: 8 mm spheres, weak turbulence
/// with a long time scale, c = 0.05): three trailing tips 2 mm downstream,
/// two of them offset by 1 mm (|det A_0| = 0.2), 200 kHz. The multi-tip
/// tests, validation and sweep hold pdp to the per-bubble truth on it.
inline synth::Scene clean_four_tip_scene(double duration) {
  synth::Scene s;
  s.velocity = 2.0;
  s.tu = 0.05;
  s.tu_y = s.tu_z = 0.025;
  s.time_scale = 1.0;
  s.void_fraction = 0.05;
  s.bubble_diameter = 8e-3;
  s.tips = {{0, 0, 0}, {2e-3, 0, 0}, {2e-3, 1e-3, 0}, {2e-3, 0, 1e-3}};
  s.fs = 200e3;
  s.duration = duration;
  s.seed = 11;
  return s;
}

}  // namespace pdp_test
