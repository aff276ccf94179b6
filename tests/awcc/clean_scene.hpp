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

}  // namespace pdp_test
