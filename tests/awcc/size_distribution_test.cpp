// The size-distribution inversion (awcc/size_distribution.hpp): the forward
// model by a KS test, the bin kernel and the moments against brute-force
// integrals, log-normal sizes recovered, d32 against 1.5 x mean chord, the
// status for too few chords, determinism and the options.
#include "awcc/size_distribution.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/random.hpp"

namespace {

using awcc::SizeDistribution;
using awcc::SizeDistributionOptions;
using awcc::SizeStatus;

// A chord of a sphere of diameter D pierced uniformly over its cross-section:
// the offset from the axis is r D / 2 with P(r <= x) = x^2 (area), i.e. r^2
// uniform, and l = D sqrt(1 - r^2) with 1 - r^2 uniform on (0, 1]:
// P(l <= x) = (x / D)^2, density 2 l / D^2.
double chord(double D, awcc::Rng& rng) { return D * std::sqrt(rng.uniform_open_low()); }

// The pierced bubbles of a log-normal number distribution n (ln D ~ N(mu,
// sigma^2)) are area-weighted: g(D) ~ D^2 n(D), and exp(2x) phi((x - mu) /
// sigma) = phi((x - mu - 2 sigma^2) / sigma) x const, so ln D of a pierced
// bubble is N(mu + 2 sigma^2, sigma^2).
struct Draw {
  std::vector<double> pierced;  // diameters of the pierced bubbles, m
  std::vector<double> chords;   // m
  // The drawn population's number median and d32: the pierced bubbles
  // weighted by 1 / D^2 are a sample of n.
  [[nodiscard]] double number_median() const {
    std::vector<std::pair<double, double>> dw;
    double total = 0.0;
    for (double d : pierced) {
      dw.emplace_back(d, 1.0 / (d * d));
      total += 1.0 / (d * d);
    }
    std::sort(dw.begin(), dw.end());
    double c = 0.0;
    for (const auto& p : dw) {
      c += p.second;
      if (c >= 0.5 * total) return p.first;
    }
    return dw.back().first;
  }
  // d32 = sum n D^3 / sum n D^2 = the mean pierced diameter.
  [[nodiscard]] double sauter() const {
    return std::accumulate(pierced.begin(), pierced.end(), 0.0) / static_cast<double>(pierced.size());
  }
};

Draw log_normal_chords(double median, double sigma, int n, std::uint64_t seed) {
  awcc::Rng rng(seed, 31);
  Draw d;
  for (int i = 0; i < n; ++i) {
    const double D = median * std::exp(2.0 * sigma * sigma + sigma * rng.normal());
    d.pierced.push_back(D);
    d.chords.push_back(chord(D, rng));
  }
  return d;
}

// Kolmogorov-Smirnov statistic of a sample against the CDF F.
double ks_statistic(std::vector<double> x, const std::function<double(double)>& F) {
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = F(x[i]);
    d = std::max({d, static_cast<double>(i + 1) / n - f, f - static_cast<double>(i) / n});
  }
  return d;
}

// Simpson's rule with n (even) intervals.
double simpson(const std::function<double(double)>& f, double a, double b, int n = 2000) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + h * i);
  return s * h / 3.0;
}

// ---- the forward model ------------------------------------------------------

TEST(SizeDistribution, ChordsOfOneSphereFollowTwoLOverDSquaredByKs) {
  // KS: for n = 4000 the asymptotic 0.1 % critical value of sqrt(n) D_n is
  // 1.949 (Kolmogorov), so D_n < 1.949 / sqrt(n) = 0.031 fails once in a
  // thousand seeds if the chords follow F(l) = (l / D)^2.
  const double D = 2e-3;
  const int n = 4000;
  awcc::Rng rng(7, 31);
  std::vector<double> l(n);
  for (auto& x : l) x = chord(D, rng);
  const double bound = 1.949 / std::sqrt(static_cast<double>(n));
  EXPECT_LT(ks_statistic(l, [&](double x) { return std::min(1.0, (x / D) * (x / D)); }), bound);
  // The test has power: offsets uniform in r rather than in r^2 (a bubble
  // met along a line, not over its area) give P(l <= x) = 1 - sqrt(1 -
  // (x/D)^2), at a KS distance of 0.25 from (x / D)^2 (at x / D = 0.71),
  // eight times the bound.
  EXPECT_GT(ks_statistic(l, [&](double x) { return 1.0 - std::sqrt(std::max(0.0, 1.0 - (x / D) * (x / D))); }),
            4.0 * bound);
}

TEST(SizeDistribution, MeanChordOfAreaWeightedLogNormalIsTwoThirdsOfD32) {
  // E[l] = (2/3) E_g[D] = (2/3) d32, with d32 = exp(mu + 2.5 sigma^2) for a
  // log-normal n. The sample mean of 20,000 chords has a standard error
  // sd(l) / sqrt(n) (estimated from the sample): 4 of them fail once in
  // 16,000. Without the area weighting the mean is (2/3) exp(mu + sigma^2 /
  // 2), 18 % lower at sigma = 0.5: 30 standard errors.
  const double median = 1.5e-3, sigma = 0.5;
  const auto d = log_normal_chords(median, sigma, 20000, 3);
  double s = 0.0, s2 = 0.0;
  for (double l : d.chords) s += l, s2 += l * l;
  const double n = static_cast<double>(d.chords.size()), mean = s / n;
  const double se = std::sqrt((s2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, (2.0 / 3.0) * median * std::exp(2.5 * sigma * sigma), 4.0 * se);
}

TEST(SizeDistribution, BinKernelIsTheIntegralOverTheBinOfTwoLOverDSquared) {
  // K(l) = (1 / (b - a)) int_max(l, a)^b 2 l / D^2 dD, by Simpson's rule
  // (error ~ h^4 f'''' / 180: below 1e-12 relative with 2000 intervals).
  const double a = 1e-3, b = 1.3e-3;
  for (double l : {1e-5, 5e-4, 1e-3, 1.1e-3, 1.29e-3, 1.3e-3, 2e-3}) {
    const double lower = std::max(l, a);
    const double ref = lower < b ? simpson([&](double D) { return 2.0 * l / (D * D); }, lower, b) / (b - a) : 0.0;
    EXPECT_NEAR(awcc::bin_chord_density(l, a, b), ref, 1e-10 * std::max(ref, 1.0)) << l;
  }
  // A density: it integrates to 1 over (0, b] (kink at a: two pieces).
  const auto K = [&](double l) { return awcc::bin_chord_density(l, a, b); };
  EXPECT_NEAR(simpson(K, 0.0, a) + simpson(K, a, b), 1.0, 1e-10);
  EXPECT_EQ(awcc::bin_chord_density(0.0, a, b), 0.0);
  EXPECT_EQ(awcc::bin_chord_density(-1e-3, a, b), 0.0);
}

// ---- the inversion ------------------------------------------------------------

TEST(SizeDistribution, MomentsMedianAndMeanChordMatchBruteForceIntegralsOfTheModel) {
  // The moments and the median are written once in closed form per bin; here
  // they are integrated numerically from the model's n(D) = sum_j w_j / ((b_j
  // - a_j) D^2) on each bin, and the model's mean chord from f(l): mean(l) =
  // (2/3) d32 holds exactly for the model (E[l | D] = 2 D / 3).
  const auto d = log_normal_chords(2e-3, 0.45, 3000, 11);
  const auto r = awcc::size_distribution(d.chords);
  ASSERT_TRUE(r.ok()) << r.message;
  const std::size_t J = r.pierced.size();
  std::vector<double> M(4, 0.0);
  for (std::size_t j = 0; j < J; ++j) {
    const double a = r.edges[j], b = r.edges[j + 1], u = r.pierced[j] / (b - a);
    for (int k = 0; k < 4; ++k) M[k] += simpson([&](double D) { return u * std::pow(D, k - 2); }, a, b, 200);
  }
  EXPECT_NEAR(r.d10 / (M[1] / M[0]), 1.0, 1e-9);
  EXPECT_NEAR(r.d20 / std::sqrt(M[2] / M[0]), 1.0, 1e-9);
  EXPECT_NEAR(r.d30 / std::cbrt(M[3] / M[0]), 1.0, 1e-9);
  EXPECT_NEAR(r.d32 / (M[3] / M[2]), 1.0, 1e-9);
  // Number fraction below the median.
  double below = 0.0;
  for (std::size_t j = 0; j < J && r.edges[j] < r.median; ++j) {
    const double a = r.edges[j], b = std::min(r.edges[j + 1], r.median), u = r.pierced[j] / (r.edges[j + 1] - a);
    below += simpson([&](double D) { return u / (D * D); }, a, b, 200);
  }
  EXPECT_NEAR(below / M[0], 0.5, 1e-9);
  for (std::size_t j = 0; j < J; ++j) EXPECT_LE(r.cumulative[j], r.cumulative[j + 1]);
  EXPECT_EQ(r.cumulative.front(), 0.0);
  EXPECT_EQ(r.cumulative.back(), 1.0);
  // The model's chords: a density whose mean is (2/3) d32 (pieces between edges, f kinks there).
  double mass = simpson([&](double l) { return r.chord_density(l); }, 0.0, r.edges[0]);
  double first = simpson([&](double l) { return l * r.chord_density(l); }, 0.0, r.edges[0]);
  for (std::size_t j = 0; j < J; ++j) {
    mass += simpson([&](double l) { return r.chord_density(l); }, r.edges[j], r.edges[j + 1], 200);
    first += simpson([&](double l) { return l * r.chord_density(l); }, r.edges[j], r.edges[j + 1], 200);
  }
  EXPECT_NEAR(mass, 1.0, 1e-9);
  EXPECT_NEAR(first / ((2.0 / 3.0) * r.d32), 1.0, 1e-9);
}

TEST(SizeDistribution, RecoversLogNormalMedianAndD32WithinTenPercentFrom5000Chords) {
  // The requirement: 10 %. Sampling theory of the target: the drawn
  // population's d32 (the mean of 5,000 pierced diameters) has a relative
  // standard error sigma_g / sqrt(n) <= 0.66 / 71 ~ 1 %; the inversion adds
  // its own: measured over 40 draws (bench/size_distribution_bench) the
  // relative error against the population has sd <= 3.6 % (median, at sigma
  // = 0.6) and <= 1.1 % (d32), bias <= 0.6 %; against the drawn population
  // the worst of 40 draws was 6.5 % and 1.8 %. 10 % is 2.8 of the median's
  // standard deviations at sigma = 0.6 (more elsewhere), while a method
  // that mistook the pierced for the number distribution (median high by
  // exp(2 sigma^2) - 1 = 20-105 %) or broadened it (low by 26-60 %, the
  // smoothed EM, header) fails it.
  for (double sigma : {0.3, 0.45, 0.6}) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const auto d = log_normal_chords(2e-3, sigma, 5000, seed);
      const auto r = awcc::size_distribution(d.chords);
      ASSERT_TRUE(r.ok()) << r.message;
      EXPECT_NEAR(r.median / d.number_median(), 1.0, 0.10) << "sigma " << sigma << " seed " << seed;
      EXPECT_NEAR(r.d32 / d.sauter(), 1.0, 0.10) << "sigma " << sigma << " seed " << seed;
      EXPECT_LT(r.iterations, r.options.iterations_max);
      // d10 < d20 < d30 < d32 for any non-degenerate distribution (power means).
      EXPECT_LT(r.d10, r.d20);
      EXPECT_LT(r.d20, r.d30);
      EXPECT_LT(r.d30, r.d32);
    }
  }
}

TEST(SizeDistribution, D32OfTheInversionAgreesWithOneAndAHalfMeanChord) {
  // METHOD 12: mean(l) = (2/3) d32 for spheres, so 1.5 mean(l) and the
  // inversion's d32 estimate the same number. The model's own mean chord is
  // exactly (2/3) d32 (test above); a fit of the chord distribution that
  // is consistent with the data reproduces their mean within its sampling
  // error. Bound: two standard errors of 1.5 mean(l), 1.5 sd(l) / sqrt(n)
  // (a fitted mean two SE off would itself be rejected at 5 % by the data).
  // Measured: within 0.2 % at 5,000 chords against an SE of ~0.9 %.
  for (double sigma : {0.3, 0.6}) {
    const auto d = log_normal_chords(1e-3, sigma, 5000, 21);
    const auto r = awcc::size_distribution(d.chords);
    ASSERT_TRUE(r.ok()) << r.message;
    double s2 = 0.0;
    for (double l : d.chords) s2 += (l - r.mean_chord) * (l - r.mean_chord);
    const double se = 1.5 * std::sqrt(s2 / static_cast<double>(d.chords.size())) /
                      std::sqrt(static_cast<double>(d.chords.size()));
    EXPECT_NEAR(r.d32, r.sauter_from_chords, 2.0 * se) << sigma;
    EXPECT_DOUBLE_EQ(r.sauter_from_chords, 1.5 * r.mean_chord);
  }
}

TEST(SizeDistribution, TooFewChordsIsAStatusWithNoDistribution) {
  SizeDistributionOptions o;
  const auto d = log_normal_chords(2e-3, 0.4, o.chords_min, 5);
  std::vector<double> few(d.chords.begin(), d.chords.end() - 1);
  // Unusable chords are counted, not used: they do not make up the minimum.
  for (double bad : {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    few.push_back(bad);
  }
  const auto r = awcc::size_distribution(few, o);
  EXPECT_EQ(r.status, SizeStatus::too_few_chords);
  EXPECT_EQ(r.chords_given, o.chords_min + 3);
  EXPECT_EQ(r.chords_used, o.chords_min - 1);
  EXPECT_TRUE(r.pierced.empty() && r.edges.empty() && r.cumulative.empty());
  EXPECT_EQ(r.median, 0.0);
  EXPECT_NE(r.message.find("size-chords-min"), std::string::npos) << r.message;
  EXPECT_NE(r.report().find("no distribution"), std::string::npos);
  EXPECT_GT(r.sauter_from_chords, 0.0);  // d32 without inversion is still given
  // One more usable chord and it runs.
  few.push_back(d.chords.back());
  const auto ok = awcc::size_distribution(few, o);
  EXPECT_TRUE(ok.ok()) << ok.message;
  EXPECT_EQ(ok.chords_used, o.chords_min);
  EXPECT_EQ(awcc::size_distribution(std::vector<double>{}, o).status, SizeStatus::too_few_chords);
}

TEST(SizeDistribution, SameChordsSameNumbersInAnyOrder) {
  const auto d = log_normal_chords(2e-3, 0.5, 1000, 8);
  auto shuffled = d.chords;
  std::reverse(shuffled.begin(), shuffled.end());
  std::rotate(shuffled.begin(), shuffled.begin() + 337, shuffled.end());
  const auto a = awcc::size_distribution(d.chords), b = awcc::size_distribution(d.chords),
             c = awcc::size_distribution(shuffled);
  for (const auto* x : {&b, &c}) {
    EXPECT_EQ(a.pierced, x->pierced);
    EXPECT_EQ(a.edges, x->edges);
    EXPECT_EQ(a.median, x->median);
    EXPECT_EQ(a.d32, x->d32);
    EXPECT_EQ(a.iterations, x->iterations);
  }
}

TEST(SizeDistribution, DistinctLengthsWithCountsGiveTheIdenticalResult) {
  // Chords of one velocity are whole samples times it: 5,000 chords on a
  // grid of 40 um repeat ~150 lengths. The weighted call over the distinct
  // lengths (in another order, one length split over two entries, a zero
  // count and a non-finite length among them) equals the call on every
  // chord, to the last bit.
  const auto d = log_normal_chords(2e-3, 0.5, 5000, 21);
  const double delta = 40e-6;
  std::vector<double> all;
  for (double l : d.chords) all.push_back(std::max(1.0, std::round(l / delta)) * delta);
  std::vector<double> sorted = all;
  std::sort(sorted.begin(), sorted.end());
  std::vector<double> lengths;
  std::vector<std::int64_t> counts;
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t k = i;
    while (k < sorted.size() && sorted[k] == sorted[i]) ++k;
    const auto n = static_cast<std::int64_t>(k - i);
    if (n >= 2 && lengths.size() % 3 == 0) {  // the same length in two entries
      lengths.push_back(sorted[i]);
      counts.push_back(1);
      lengths.push_back(sorted[i]);
      counts.push_back(n - 1);
    } else {
      lengths.push_back(sorted[i]);
      counts.push_back(n);
    }
    i = k;
  }
  ASSERT_LT(lengths.size(), all.size() / 10);
  std::reverse(lengths.begin(), lengths.end());
  std::reverse(counts.begin(), counts.end());
  lengths.push_back(1e-3);
  counts.push_back(0);
  lengths.push_back(std::numeric_limits<double>::quiet_NaN());
  counts.push_back(0);
  const auto a = awcc::size_distribution(all);
  const auto b = awcc::size_distribution(lengths, counts);
  ASSERT_TRUE(a.ok()) << a.message;
  EXPECT_EQ(a.chords_used, b.chords_used);
  EXPECT_EQ(a.chords_given, b.chords_given);
  EXPECT_EQ(a.mean_chord, b.mean_chord);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.pierced, b.pierced);
  EXPECT_EQ(a.density, b.density);
  EXPECT_EQ(a.cumulative, b.cumulative);
  EXPECT_EQ(a.median, b.median);
  EXPECT_EQ(a.d32, b.d32);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.log_likelihood, b.log_likelihood);
  EXPECT_THROW((void)awcc::size_distribution(lengths, std::vector<std::int64_t>(3, 1)), std::invalid_argument);
}

TEST(SizeDistribution, PrefixSumLikelihoodEqualsTheKernelSumOverEveryBin) {
  // The EM evaluates f(l_i) by prefix and suffix sums over the ordered bins;
  // chord_density() sums w_j K_j(l) over every bin directly. The result's
  // log-likelihood (the former) equals sum log chord_density(l_i) (the
  // latter) to rounding, on chords that fall inside bins, at their edges and
  // below the grid's floor.
  const auto d = log_normal_chords(2e-3, 0.6, 3000, 5);
  const auto r = awcc::size_distribution(d.chords);
  ASSERT_TRUE(r.ok()) << r.message;
  double ll = 0.0;
  for (double l : d.chords) ll += std::log(r.chord_density(l));
  EXPECT_NEAR(r.log_likelihood, ll, 1e-9 * std::fabs(ll));
  // A chord exactly at an inner edge (l <= a: the linear branch of bin j).
  std::vector<double> with_edges = d.chords;
  for (int k = 0; k < 50; ++k) with_edges.push_back(r.edges[static_cast<std::size_t>(10 + k % 20)]);
  const auto e = awcc::size_distribution(with_edges);
  double lle = 0.0;
  for (double l : with_edges) lle += std::log(e.chord_density(l));
  EXPECT_NEAR(e.log_likelihood, lle, 1e-9 * std::fabs(lle));
}

TEST(SizeDistribution, ScalingTheChordsScalesTheDiameters) {
  // Nothing in the estimator has a length scale (the grid is in ln D, the
  // penalty dimensionless): chords x 1024 give diameters x 1024 and the same
  // fractions. A power of two scales every length without rounding, so the
  // iterations are the same up to the rounding of log f (which moves by ln
  // 1024 per chord): the same iterate, to 1e-12.
  const auto d = log_normal_chords(2e-3, 0.4, 800, 9);
  auto scaled = d.chords;
  for (auto& l : scaled) l *= 1024.0;
  const auto a = awcc::size_distribution(d.chords), b = awcc::size_distribution(scaled);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a.pierced.size(), b.pierced.size());
  EXPECT_EQ(a.iterations, b.iterations);
  for (std::size_t j = 0; j < a.pierced.size(); ++j) EXPECT_NEAR(a.pierced[j], b.pierced[j], 1e-12) << j;
  EXPECT_NEAR(b.median / a.median, 1024.0, 1024.0 * 1e-12);
  EXPECT_NEAR(b.d10 / a.d10, 1024.0, 1024.0 * 1e-12);
  EXPECT_NEAR(b.d32 / a.d32, 1024.0, 1024.0 * 1e-12);
}

TEST(SizeDistribution, NotConvergedIsAStatusWithAReason) {
  SizeDistributionOptions o;
  o.iterations_max = 2;
  const auto d = log_normal_chords(2e-3, 0.4, 1000, 4);
  const auto r = awcc::size_distribution(d.chords, o);
  EXPECT_EQ(r.status, SizeStatus::not_converged);
  EXPECT_NE(r.message.find("size-iterations-max"), std::string::npos);
  EXPECT_NE(r.report().find("caution"), std::string::npos);
}

TEST(SizeDistribution, OptionsAreValidatedByName) {
  const auto bad = [](auto set, const char* name) {
    SizeDistributionOptions o;
    set(o);
    const auto v = o.validate();
    EXPECT_FALSE(v.ok()) << name;
    EXPECT_EQ(v.quantity, name);
    EXPECT_THROW(awcc::size_distribution(std::vector<double>(300, 1e-3), o), awcc::OptionError) << name;
  };
  EXPECT_TRUE(SizeDistributionOptions{}.validate().ok());
  bad([](auto& o) { o.bin_width = 0.0; }, "size-bin-width");
  bad([](auto& o) { o.floor_quantile = 0.5; }, "size-floor-quantile");
  bad([](auto& o) { o.floor_rank_min = 0; }, "size-floor-rank-min");
  bad([](auto& o) { o.ceiling_factor = 0.9; }, "size-ceiling-factor");
  bad([](auto& o) { o.penalty = 0.0; }, "size-penalty");
  bad([](auto& o) { o.chords_min = 5; }, "size-chords-min");
  bad([](auto& o) { o.iterations_max = 0; }, "size-iterations-max");
  bad([](auto& o) { o.tolerance = 0.0; }, "size-tolerance");
  bad([](auto& o) { o.bins_max = 3; }, "size-bins-max");
}

}  // namespace
