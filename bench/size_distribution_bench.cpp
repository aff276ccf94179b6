// The size-distribution inversion on log-normal sizes (issue 31): bias and
// spread over draws of the number median and d32 at 50, 200 and 5,000
// chords, the time per inversion, and a CSV of drawn against inverted
// distributions for scripts/size-inversion-figure.
//
//   size_distribution_bench [--seeds 40] [--csv docs/figures/size-inversion.csv]
//   size_distribution_bench --sampling   chord times rounded to whole samples (size-samples-min)
//   size_distribution_bench --cost       a 300 s base-case record's 375,000 chords
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "awcc/random.hpp"
#include "awcc/size_distribution.hpp"
#include "bench_util.hpp"

namespace {

// Pierced bubbles of a log-normal n (ln D ~ N(mu, s^2)) have ln D ~ N(mu + 2 s^2, s^2);
// a sphere's chord is D sqrt(u), u uniform on (0, 1] (tests/awcc/size_distribution_test.cpp).
struct Draw {
  std::vector<double> pierced, chords;
  // The drawn population: pierced bubbles weighted by 1 / D^2 are a sample of n.
  [[nodiscard]] double number_median() const {
    std::vector<std::pair<double, double>> dw;
    double total = 0.0;
    for (double d : pierced) dw.emplace_back(d, 1.0 / (d * d)), total += 1.0 / (d * d);
    std::sort(dw.begin(), dw.end());
    double c = 0.0;
    for (const auto& p : dw) {
      if ((c += p.second) >= 0.5 * total) return p.first;
    }
    return dw.back().first;
  }
  [[nodiscard]] double sauter() const {  // the mean pierced diameter
    double s = 0.0;
    for (double d : pierced) s += d;
    return s / static_cast<double>(pierced.size());
  }
};
Draw draw(double median, double sigma, int n, std::uint64_t seed) {
  awcc::Rng rng(seed, 31);
  Draw d;
  for (int i = 0; i < n; ++i) {
    const double D = median * std::exp(2.0 * sigma * sigma + sigma * rng.normal());
    d.pierced.push_back(D);
    d.chords.push_back(D * std::sqrt(rng.uniform_open_low()));
  }
  return d;
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
double sd(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 40;
  std::string csv;
  bool sampling = false, cost = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--sampling")) sampling = true;
    if (!std::strcmp(argv[i], "--cost")) cost = true;
    if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc) seeds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv = argv[++i];
  }
  const double median = 2e-3;
  if (sampling) {
    // Chord times are whole samples: a chord of length l at sample spacing
    // delta (u / fs) covers floor(l / delta + U) sample instants, U uniform
    // (the interface's phase on the grid); 0 is a chord never seen. The
    // inversion of the rounded lengths against the population, by the grid
    // floor's chord in samples.
    std::printf("chords rounded to whole samples, 5,000 chords, %d draws; relative errors against the population\n",
                seeds);
    std::printf("%6s %10s | %12s | %8s %8s %8s | %8s %8s\n", "sigma", "D50/delta", "floor samples", "med bias",
                "med sd", "med max", "d32 bias", "d32 max");
    for (double sigma : {0.3, 0.6}) {
      for (double per : {2.0, 4.0, 8.0, 16.0, 32.0, 64.0}) {
        const double delta = median / per;
        std::vector<double> em, ed, fl;
        for (int s = 0; s < seeds; ++s) {
          auto d = draw(median, sigma, 5000, static_cast<std::uint64_t>(5000 + s));
          awcc::Rng rng(static_cast<std::uint64_t>(7000 + s), 32);
          for (double& l : d.chords) l = std::floor(l / delta + rng.uniform()) * delta;
          const auto r = awcc::size_distribution(d.chords);
          if (!r.ok()) continue;
          em.push_back(r.median / median - 1.0);
          ed.push_back(r.d32 / (median * std::exp(2.5 * sigma * sigma)) - 1.0);
          fl.push_back(r.edges.front() / delta);
        }
        double mm = 0.0, md = 0.0;
        for (std::size_t k = 0; k < em.size(); ++k) mm = std::max(mm, std::fabs(em[k])), md = std::max(md, std::fabs(ed[k]));
        std::printf("%6.2f %10.0f | %12.1f | %+7.1f%% %7.1f%% %7.1f%% | %+7.1f%% %7.1f%%\n", sigma, per, mean(fl),
                    100 * mean(em), 100 * sd(em), 100 * mm, 100 * mean(ed), 100 * md);
      }
    }
    return 0;
  }
  if (cost) {
    // The 300 s base case's leading tip: about 375,000 chords. All lengths
    // distinct (each bubble its own velocity), and whole samples times one
    // velocity (the record's: 20 kHz... 100 kHz grids).
    const int n = 375000;
    for (double sigma : {0.3, 0.6}) {
      const auto d = draw(median, sigma, n, 99);
      double t0 = bench::now();
      const auto a = awcc::size_distribution(d.chords);
      const double distinct_s = bench::now() - t0;
      auto rounded = d.chords;
      const double delta = median / 40.0;
      for (double& l : rounded) l = std::max(1.0, std::round(l / delta)) * delta;
      t0 = bench::now();
      const auto b = awcc::size_distribution(rounded);
      const double rounded_s = bench::now() - t0;
      std::printf("sigma %.2f, %d chords: all distinct %.3f s (%d iterations, %zu bins); whole samples of one velocity "
                  "%.3f s (%d iterations)\n",
                  sigma, n, distinct_s, a.iterations, a.diameters.size(), rounded_s, b.iterations);
    }
    return 0;
  }
  awcc::SizeDistributionOptions few;
  few.chords_min = 10;  // measure below the default minimum too

  std::printf("log-normal n(D), median %.3g mm; relative errors against the population (exp(mu), exp(mu + 2.5 s^2)) "
              "over %d draws\n",
              1e3 * median, seeds);
  std::printf("%6s %6s | %8s %8s %8s | %8s %8s %8s | %9s %6s %6s %9s | %8s %8s\n", "chords", "sigma", "med bias", "med sd",
              "med max", "d32 bias", "d32 sd", "d32 max", "1.5l/d32", "iter", "maxit", "s/inv", "drawn:med", "d32");
  for (int n : {50, 200, 5000}) {
    for (double sigma : {0.3, 0.45, 0.6}) {
      std::vector<double> em, ed, ec, it, dm, dd;
      double seconds = 0.0;
      for (int s = 0; s < seeds; ++s) {
        const auto d = draw(median, sigma, n, static_cast<std::uint64_t>(1000 + s));
        const double t0 = bench::now();
        const auto r = awcc::size_distribution(d.chords, few);
        seconds += bench::now() - t0;
        if (!r.ok()) {
          std::fprintf(stderr, "n %d sigma %g seed %d: %s\n", n, sigma, s, r.message.c_str());
          continue;
        }
        em.push_back(r.median / median - 1.0);
        ed.push_back(r.d32 / (median * std::exp(2.5 * sigma * sigma)) - 1.0);
        ec.push_back(r.sauter_from_chords / r.d32 - 1.0);
        dm.push_back(std::fabs(r.median / d.number_median() - 1.0));
        dd.push_back(std::fabs(r.d32 / d.sauter() - 1.0));
        it.push_back(r.iterations);
      }
      double mm = 0.0, md = 0.0, mc = 0.0, mi = 0.0;
      const double drawn_median_max = *std::max_element(dm.begin(), dm.end());
      const double drawn_d32_max = *std::max_element(dd.begin(), dd.end());
      for (std::size_t k = 0; k < em.size(); ++k) {
        mm = std::max(mm, std::fabs(em[k]));
        md = std::max(md, std::fabs(ed[k]));
        mc = std::max(mc, std::fabs(ec[k]));
        mi = std::max(mi, it[k]);
      }
      std::printf("%6d %6.2f | %+7.1f%% %7.1f%% %7.1f%% | %+7.1f%% %7.1f%% %7.1f%% | %8.2f%% %6.0f %6.0f %9.4f | %7.1f%% %7.1f%%\n", n,
                  sigma, 100 * mean(em), 100 * sd(em), 100 * mm, 100 * mean(ed), 100 * sd(ed), 100 * md, 100 * mc,
                  mean(it), mi, seconds / seeds, 100 * drawn_median_max, 100 * drawn_d32_max);
    }
  }

  {
    // What the stopping rule leaves: the same chords to tolerance 1e-13.
    double worst = 0.0;
    for (double sigma : {0.3, 0.6}) {
      const auto d = draw(median, sigma, 5000, 1000);
      awcc::SizeDistributionOptions tight;
      tight.tolerance = 1e-13;
      tight.iterations_max = 100000;
      const auto a = awcc::size_distribution(d.chords), b = awcc::size_distribution(d.chords, tight);
      worst = std::max({worst, std::fabs(a.median / b.median - 1.0), std::fabs(a.d32 / b.d32 - 1.0)});
      std::printf("sigma %.2f: tolerance 1e-9 against 1e-13 (%d against %d iterations): median %+.2e, d32 %+.2e\n",
                  sigma, a.iterations, b.iterations, a.median / b.median - 1.0, a.d32 / b.d32 - 1.0);
    }
  }

  if (!csv.empty()) {
    // Per case and draw: the inverted density on its grid next to the drawn
    // population's (the log-normal it was drawn from), per unit ln D.
    std::FILE* f = std::fopen(csv.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "cannot write %s\n", csv.c_str());
      return 1;
    }
    std::fprintf(f, "chords,sigma,seed,diameter_mm,inverted_per_lnD,drawn_per_lnD,inverted_cumulative,drawn_cumulative\n");
    for (int n : {200, 5000}) {
      for (double sigma : {0.3, 0.6}) {
        for (int s = 0; s < 5; ++s) {
          const auto d = draw(median, sigma, n, static_cast<std::uint64_t>(1000 + s));
          const auto r = awcc::size_distribution(d.chords, few);
          for (std::size_t j = 0; j < r.diameters.size(); ++j) {
            const double D = r.diameters[j], z = std::log(D / median) / sigma;
            const double drawn = std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * M_PI));
            // Within a bin the number fraction grows as 1 / a - 1 / D (n ~ 1 / D^2 there).
            const double a = r.edges[j], b = r.edges[j + 1];
            const double cum_inv = r.cumulative[j] + (r.cumulative[j + 1] - r.cumulative[j]) * (1.0 / a - 1.0 / D) /
                                                         (1.0 / a - 1.0 / b);
            std::fprintf(f, "%d,%.2f,%d,%.6g,%.6g,%.6g,%.6g,%.6g\n", n, sigma, s, 1e3 * D, r.density[j] * D, drawn,
                         cum_inv, 0.5 * std::erfc(-z / std::sqrt(2.0)));
          }
        }
      }
    }
    std::fclose(f);
    std::printf("wrote %s\n", csv.c_str());
  }
  return 0;
}
