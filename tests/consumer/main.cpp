// Synthesises a short scene through the installed libraries and checks a
// property of the result, so that linking alone is not mistaken for success.
#include <awcc/units.hpp>
#include <awcc/version.hpp>
#include <cstdio>
#include <synth/synthesiser.hpp>

int main() {
  synth::Scene scene;
  scene.duration = awcc::parse_quantity("0.1s", awcc::Dimension::time);
  scene.fs = awcc::parse_quantity("100kHz", awcc::Dimension::frequency);
  const auto result = synth::synthesise(scene);
  const double c = result.signals.at(0).void_fraction();
  std::printf("awcc %s: %zu tips, void fraction %.3f\n", awcc::version, result.signals.size(), c);
  return (result.signals.size() == 2 && c > 0.0 && c < 1.0) ? 0 : 1;
}
