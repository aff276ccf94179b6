// Synthesises a short scene through the installed libraries and checks a
// property of the result, so that linking alone is not mistaken for success.
#include <awcc/quantile_forest.hpp>
#include <awcc/units.hpp>
#include <awcc/version.hpp>
#include <cstdio>
#include <vector>
#include <synth/synthesiser.hpp>

int main() {
  synth::Scene scene;
  scene.duration = awcc::parse_quantity("0.1s", awcc::Dimension::time);
  scene.fs = awcc::parse_quantity("100kHz", awcc::Dimension::frequency);
  const auto result = synth::synthesise(scene);
  const double c = result.signals.at(0).void_fraction();
  // A one-tree forest on a step: the quantiles at each side are that side's.
  awcc::TrainingData d;
  d.features = 1;
  for (int i = 0; i < 20; ++i) {
    d.x.push_back(i);
    d.y.push_back(i < 10 ? 1.0 : 2.0);
  }
  awcc::ForestOptions o;
  o.trees = 1;
  o.sample_fraction = 5.0;  // every row drawn, with near certainty
  const auto forest = awcc::QuantileForest::train(d, o);
  const std::vector<double> x0{2.0}, x1{17.0}, median{0.5};
  const bool forest_ok = forest.quantiles(x0, median)[0] == 1.0 && forest.quantiles(x1, median)[0] == 2.0;
  std::printf("awcc %s: %zu tips, void fraction %.3f, forest %s\n", awcc::version, result.signals.size(), c,
              forest_ok ? "ok" : "wrong");
  return (result.signals.size() == 2 && c > 0.0 && c < 1.0 && forest_ok) ? 0 : 1;
}
