// Speed of the bias-correction model (issue 7): training two forests of 100
// trees on 20,000 runs, and correcting a 30-row profile.
// Usage: qrf_bench SWEEP.csv MODEL.qrf [threads]
// The 20,000 training rows are drawn with replacement from the sweep's usable
// runs (features jittered by 1e-6 relative so that the trees split as on
// distinct runs); the hyperparameters are those of MODEL.qrf's provenance
// defaults (min leaf 5, all 7 features per split: the costliest of the CV grid
// at that leaf size).
#include <fmt/format.h>

#include <cstdio>
#include <random>

#include "correction/model.hpp"
#include "bench_util.hpp"
#include "correction/training.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: qrf_bench SWEEP.csv MODEL.qrf [threads]\n");
    return 2;
  }
  const int threads = argc > 3 ? std::atoi(argv[3]) : 0;
  const auto set = correction::load_training_set({argv[1]}, 100);
  std::mt19937_64 g(1);
  std::uniform_int_distribution<std::size_t> pick(0, set.rows.size() - 1);
  std::uniform_real_distribution<double> jitter(-1e-6, 1e-6);
  std::vector<correction::TrainingRow> rows;
  for (int i = 0; i < 20000; ++i) {
    auto r = set.rows[pick(g)];
    auto& f = r.features;
    for (double* v : {&f.velocity, &f.turbulence_intensity, &f.void_fraction, &f.d32, &f.dx, &f.dy}) *v *= 1.0 + jitter(g);
    r.run = i;
    rows.push_back(r);
  }
  correction::ForestOptions o;
  o.trees = 100;
  o.min_leaf = 5;
  o.features_per_split = 7;
  o.threads = threads;
  for (int rep = 0; rep < 2; ++rep) {
    const double t0 = bench::now();
    const auto m = correction::fit_model(rows, correction::TargetForm::ratio, correction::TargetForm::difference, o, o, 100);
    const double t1 = bench::now();
    fmt::print("train: 20,000 runs, 2 forests x 100 trees (min leaf 5, 7 features per split): {:.2f} s, model {:.1f} MB, "
               "peak {:.0f} MB\n", t1 - t0, static_cast<double>(m.serialise().size()) / 1e6, bench::peak_mb());
  }
  // Correcting 30 rows with the shipped model: load + 30 corrections.
  std::vector<double> load, correct;
  for (int rep = 0; rep < 20; ++rep) {
    const double t0 = bench::now();
    const auto model = correction::CorrectionModel::load(argv[2]);
    const double t1 = bench::now();
    int in_range = 0;
    for (std::size_t i = 0; i < 30; ++i) in_range += model.correct(set.rows[i * 7 % set.rows.size()].features).corrected();
    const double t2 = bench::now();
    load.push_back(t1 - t0);
    correct.push_back(t2 - t1);
    if (rep == 0) fmt::print("profile: {} of 30 rows in range\n", in_range);
  }
  fmt::print("correct a 30-row profile: model load {:.1f} ms + 30 corrections {:.2f} ms (medians of 20)\n",
             1e3 * bench::median(load), 1e3 * bench::median(correct));
  return 0;
}
