#include "correction/quantile_forest.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>

namespace {

using correction::ForestOptions;
using correction::QuantileForest;
using correction::TrainingData;

// Levels as exact fractions num/den, so that the order statistic index
// ceil(alpha m) is computed in integers, independently of the forest's
// floating-point cumulative weights.
struct Level {
  int num, den;
  [[nodiscard]] double value() const { return static_cast<double>(num) / den; }
};
const std::vector<Level> levels{{1, 40}, {1, 10}, {1, 4}, {1, 2}, {3, 4}, {9, 10}, {39, 40}, {1, 1}};

TrainingData random_data(std::size_t n, int features, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  TrainingData d;
  d.features = features;
  for (std::size_t i = 0; i < n; ++i) {
    double s = 0.0;
    for (int j = 0; j < features; ++j) {
      const double v = std::round(u(g) * 50.0) / 50.0;  // ties on purpose
      d.x.push_back(v);
      s += (j + 1) * v;
    }
    d.y.push_back(s + 0.3 * u(g));
  }
  return d;
}

TEST(QuantileForest, AMixtureHalvesEachWeightAndKeepsTheValuesInOrder) {
  // The mixture of {1, 2} (1/2 each) and {1.5, 3} (1/4, 3/4): values 1, 1.5,
  // 2, 3 with weights 1/4, 1/8, 1/4, 3/8; its quantiles are those of the
  // merged sample, brute-forced here.
  correction::WeightedDistribution a{{1.0, 2.0}, {0.5, 0.5}}, b{{1.5, 3.0}, {0.25, 0.75}};
  const auto m = correction::mixture(a, b);
  EXPECT_EQ(m.values, (std::vector<double>{1.0, 1.5, 2.0, 3.0}));
  EXPECT_EQ(m.weights, (std::vector<double>{0.25, 0.125, 0.25, 0.375}));
  for (double alpha : {0.1, 0.25, 0.3, 0.5, 0.625, 0.7, 0.99}) {
    // P(T <= y) = (P_a(y) + P_b(y)) / 2 at the smallest y reaching alpha.
    double want = 0.0;
    for (double y : {1.0, 1.5, 2.0, 3.0}) {
      const double pa = (y >= 1.0 ? 0.5 : 0.0) + (y >= 2.0 ? 0.5 : 0.0);
      const double pb = (y >= 1.5 ? 0.25 : 0.0) + (y >= 3.0 ? 0.75 : 0.0);
      if ((pa + pb) / 2 >= alpha - 1e-12) {
        want = y;
        break;
      }
    }
    EXPECT_EQ(m.quantile(alpha), want) << alpha;
  }
  EXPECT_EQ(correction::mixture(a, a).quantile(0.5), a.quantile(0.5));
}

TEST(QuantileForest, SingleTreeWeightsReproduceTheLeafsEmpiricalQuantiles) {
  const auto data = random_data(200, 3, 7);
  ForestOptions o;
  o.trees = 1;
  o.min_leaf = 4;
  o.seed = 11;
  const auto forest = QuantileForest::train(data, o);
  ASSERT_EQ(forest.trees().size(), 1u);
  const auto trees = forest.trees();
  const auto& tree = trees[0];
  int leaves_checked = 0;
  for (std::size_t i = 0; i < data.rows(); i += 3) {
    const auto x = data.row(i);
    const auto leaf = tree.leaf(x);
    const auto rows = tree.rows(leaf);
    // Dense weights: c_i / |L| on the leaf's rows, zero elsewhere.
    std::map<std::uint32_t, int> held;
    for (auto r : rows) ++held[r];
    const auto w = forest.weights(x);
    for (std::size_t r = 0; r < w.size(); ++r) {
      const auto it = held.find(static_cast<std::uint32_t>(r));
      const double expected = it == held.end() ? 0.0 : static_cast<double>(it->second) / static_cast<double>(rows.size());
      ASSERT_NEAR(w[r], expected, 1e-15) << "row " << r;
    }
    // Quantiles: the order statistic Y_(ceil(alpha m)) of the leaf's targets.
    std::vector<double> targets;
    for (auto r : rows) targets.push_back(data.y[r]);
    std::sort(targets.begin(), targets.end());
    const int m = static_cast<int>(targets.size());
    std::vector<double> alphas;
    for (const auto& l : levels) alphas.push_back(l.value());
    const auto q = forest.quantiles(x, alphas);
    for (std::size_t k = 0; k < levels.size(); ++k) {
      const int index = (levels[k].num * m + levels[k].den - 1) / levels[k].den;  // ceil, integers
      EXPECT_EQ(q[k], targets[static_cast<std::size_t>(std::max(index, 1) - 1)])
          << "alpha " << alphas[k] << " leaf of " << m;
    }
    ++leaves_checked;
  }
  EXPECT_GT(leaves_checked, 50);
}

TEST(QuantileForest, EveryBootstrapDrawLandsInTheLeafItsFeaturesReach) {
  const auto data = random_data(300, 4, 3);
  ForestOptions o;
  o.trees = 5;
  o.min_leaf = 3;
  const auto forest = QuantileForest::train(data, o);
  for (const auto& tree : forest.trees()) {
    EXPECT_EQ(tree.leaf_rows.size(), data.rows());  // sample_fraction 1
    for (std::uint32_t node = 0; node < tree.nodes.size(); ++node) {
      if (tree.nodes[node].feature >= 0) continue;
      const auto rows = tree.rows(node);
      EXPECT_GE(rows.size(), 3u);
      for (auto r : rows) ASSERT_EQ(tree.leaf(data.row(r)), node);
    }
  }
  // Weights sum to one.
  const auto w = forest.weights(data.row(17));
  double sum = 0.0;
  for (double v : w) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

// A stump (max_depth 1, every feature tried) must split where a brute-force
// search over every feature and every gap between distinct values, in long
// double, finds the least sum of squared errors of the bootstrap sample.
TEST(QuantileForest, RootSplitIsTheBruteForceLeastSquaresSplit) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto data = random_data(60, 3, 100 + seed);
    ForestOptions o;
    o.trees = 1;
    o.max_depth = 1;
    o.min_leaf = 2;
    o.features_per_split = 3;
    o.seed = seed;
    const auto forest = QuantileForest::train(data, o);
    const auto trees = forest.trees();
    const auto& tree = trees[0];
    ASSERT_EQ(tree.nodes.size(), 3u);
    const auto& root = tree.nodes[0];
    std::vector<std::uint32_t> sample(tree.leaf_rows.begin(), tree.leaf_rows.end());
    auto sse_of = [&](int f, double threshold) {
      long double sl = 0, sr = 0, ql = 0, qr = 0;
      long nl = 0, nr = 0;
      for (auto r : sample) {
        const long double y = data.y[r];
        if (data.row(r)[static_cast<std::size_t>(f)] <= threshold) {
          sl += y, ql += y * y, ++nl;
        } else {
          sr += y, qr += y * y, ++nr;
        }
      }
      if (nl < 2 || nr < 2) return std::numeric_limits<long double>::infinity();
      return ql - sl * sl / nl + qr - sr * sr / nr;
    };
    long double best = std::numeric_limits<long double>::infinity();
    for (int f = 0; f < 3; ++f) {
      std::vector<double> values;
      for (auto r : sample) values.push_back(data.row(r)[static_cast<std::size_t>(f)]);
      std::sort(values.begin(), values.end());
      for (std::size_t k = 0; k + 1 < values.size(); ++k) {
        if (values[k] < values[k + 1]) best = std::min(best, sse_of(f, values[k]));
      }
    }
    const long double chosen = sse_of(root.feature, root.threshold);
    EXPECT_LE(static_cast<double>(chosen - best), 1e-9 * static_cast<double>(best)) << "seed " << seed;
  }
}

// Known conditional distribution: Y | X is N(0, 1) for x1 < 0.5 and
// 3 + Exp(1) for x1 >= 0.5; x2 is noise. The forest's quantile at x is a
// weighted empirical quantile of draws from the right half (the split at 0.5
// is found: the means differ by 4 sd). Sampling error of a weighted sample
// quantile: with n_eff = 1 / sum w_i^2 the effective sample size, its
// standard deviation is sqrt(alpha (1 - alpha) / n_eff) / f(q_alpha)
// (Bahadur; f the density at the true quantile). Bootstrap resampling and
// overlapping leaves correlate the weights across trees but n_eff computed from
// the final weights already accounts for that. Allow 4 sd: weights that are
// not normalised per leaf, or leaves that mix in the other half's data, move
// the estimate by many sd. (The exact order-statistic rule is pinned by the
// single-tree test above.)
TEST(QuantileForest, RecoversAKnownConditionalDistributionWithinSamplingError) {
  std::mt19937_64 g(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::exponential_distribution<double> exponential(1.0);
  TrainingData data;
  data.features = 2;
  for (int i = 0; i < 6000; ++i) {
    const double x1 = u(g), x2 = u(g);
    data.x.push_back(x1);
    data.x.push_back(x2);
    data.y.push_back(x1 < 0.5 ? normal(g) : 3.0 + exponential(g));
  }
  ForestOptions o;
  o.trees = 200;
  o.min_leaf = 40;
  o.features_per_split = 1;
  o.seed = 5;
  const auto forest = QuantileForest::train(data, o);
  const std::vector<double> alphas{0.025, 0.1, 0.25, 0.5, 0.75, 0.9, 0.975};
  const double pi = std::acos(-1.0);
  for (const double x1 : {0.2, 0.8}) {
    for (const double x2 : {0.3, 0.7}) {
      const std::vector<double> x{x1, x2};
      const auto w = forest.weights(x);
      double s2 = 0.0;
      for (double v : w) s2 += v * v;
      const double n_eff = 1.0 / s2;
      EXPECT_GT(n_eff, 100.0);
      const auto q = forest.quantiles(x, alphas);
      for (std::size_t k = 0; k < alphas.size(); ++k) {
        const double a = alphas[k];
        double truth, density;
        if (x1 < 0.5) {
          // Inverse normal by bisection on erfc (independent of the forest).
          double lo = -10, hi = 10;
          for (int it = 0; it < 200; ++it) {
            const double mid = 0.5 * (lo + hi);
            (0.5 * std::erfc(-mid / std::sqrt(2.0)) < a ? lo : hi) = mid;
          }
          truth = 0.5 * (lo + hi);
          density = std::exp(-0.5 * truth * truth) / std::sqrt(2 * pi);
        } else {
          truth = 3.0 - std::log(1.0 - a);
          density = 1.0 - a;
        }
        const double sd = std::sqrt(a * (1 - a) / n_eff) / density;
        EXPECT_NEAR(q[k], truth, 4.0 * sd) << "x1 " << x1 << " alpha " << a << " n_eff " << n_eff;
      }
    }
  }
}

TEST(QuantileForest, SameSeedSameForestWhateverTheThreads) {
  const auto data = random_data(500, 4, 9);
  ForestOptions o;
  o.trees = 16;
  o.seed = 77;
  o.threads = 1;
  const auto a = QuantileForest::train(data, o);
  o.threads = 4;
  const auto b = QuantileForest::train(data, o);
  o.seed = 78;
  const auto c = QuantileForest::train(data, o);
  // The whole forest, byte for byte (every node, threshold, held row and target).
  auto same = [](const QuantileForest& x, const QuantileForest& y) { return std::ranges::equal(x.bytes(), y.bytes()); };
  EXPECT_TRUE(same(a, b));
  EXPECT_FALSE(same(a, c));
}

TEST(QuantileForest, QuantilesDoNotCrossAndStayWithinTheTargets) {
  const auto data = random_data(400, 2, 21);
  const auto forest = QuantileForest::train(data, {});
  const auto [lo, hi] = std::minmax_element(data.y.begin(), data.y.end());
  const std::vector<double> alphas{0.025, 0.1, 0.25, 0.5, 0.75, 0.9, 0.975};
  for (std::size_t i = 0; i < data.rows(); i += 7) {
    const auto q = forest.quantiles(data.row(i), alphas);
    EXPECT_GE(q.front(), *lo);
    EXPECT_LE(q.back(), *hi);
    EXPECT_TRUE(std::is_sorted(q.begin(), q.end()));
  }
}

// Degenerate data: one row, identical features, constant targets, extreme
// magnitudes. Each must give a valid forest whose quantiles are the only
// values there are, without dividing by zero or splitting on nothing.
TEST(QuantileForest, DegenerateDataGivesSingleLeaves) {
  const std::vector<double> alphas{0.025, 0.5, 0.975};
  TrainingData one;
  one.features = 3;
  one.x = {1, 2, 3};
  one.y = {4.5};
  auto f = QuantileForest::train(one, {});
  EXPECT_EQ(f.quantiles(one.row(0), alphas), (std::vector<double>{4.5, 4.5, 4.5}));
  EXPECT_EQ(f.trees()[0].nodes.size(), 1u);

  TrainingData same;
  same.features = 2;
  for (int i = 0; i < 50; ++i) {
    same.x.insert(same.x.end(), {0.5, 0.5});
    same.y.push_back(i);  // no feature separates them
  }
  f = QuantileForest::train(same, {});
  for (const auto& t : f.trees()) EXPECT_EQ(t.nodes.size(), 1u);
  const auto q = f.quantiles(same.row(0), alphas);
  EXPECT_GE(q[0], 0.0);
  EXPECT_LE(q[2], 49.0);

  TrainingData flat = random_data(100, 2, 8);
  for (auto& y : flat.y) y = 1e-300;  // constant and tiny
  f = QuantileForest::train(flat, {});
  for (const auto& t : f.trees()) EXPECT_EQ(t.nodes.size(), 1u);
  EXPECT_EQ(f.quantiles(flat.row(3), alphas)[1], 1e-300);

  TrainingData huge = random_data(200, 2, 9);
  for (auto& y : huge.y) y *= 1e300;  // sums of squares would overflow uncentred
  f = QuantileForest::train(huge, {});
  const auto qh = f.quantiles(huge.row(5), alphas);
  for (double v : qh) EXPECT_TRUE(std::isfinite(v));
  EXPECT_GT(f.trees()[0].nodes.size(), 1u);
}

TEST(QuantileForest, RefusesBadOptionsAndData) {
  ForestOptions o;
  o.trees = 0;
  EXPECT_NE(o.validate().message.find("trees"), std::string::npos);
  EXPECT_EQ(o.validate().quantity, "trees");
  o.trees = 1;  // the limit
  EXPECT_TRUE(o.validate().ok());
  o = {};
  o.min_leaf = 0;
  EXPECT_NE(o.validate().message.find("min_leaf"), std::string::npos);
  EXPECT_EQ(o.validate().quantity, "min-leaf");
  auto data = random_data(20, 2, 1);
  data.x[5] = std::nan("");
  EXPECT_THROW((void)QuantileForest::train(data, {}), std::invalid_argument);
  TrainingData empty;
  empty.features = 2;
  EXPECT_THROW((void)QuantileForest::train(empty, {}), std::invalid_argument);
}

TEST(QuantileForest, AssembleRefusesTreesThatPointNowhere) {
  correction::RegressionTree t;
  t.nodes.resize(3);
  t.nodes[0] = {0, 0.5, 1, 2};
  t.nodes[1] = {-1, 0.0, 0, 1};
  t.nodes[2] = {-1, 0.0, 1, 1};
  t.leaf_rows = {0, 1};
  EXPECT_NO_THROW((void)QuantileForest::assemble(1, {1.0, 2.0}, {t}));
  auto loop = t;
  loop.nodes[0].right = 0;  // a cycle
  EXPECT_THROW((void)QuantileForest::assemble(1, {1.0, 2.0}, {loop}), std::invalid_argument);
  auto row = t;
  row.leaf_rows[1] = 9;
  EXPECT_THROW((void)QuantileForest::assemble(1, {1.0, 2.0}, {row}), std::invalid_argument);
  auto feature = t;
  feature.nodes[0].feature = 3;
  EXPECT_THROW((void)QuantileForest::assemble(1, {1.0, 2.0}, {feature}), std::invalid_argument);
}

TEST(QuantileForest, PinballLossIsLeastAtTheTrueQuantile) {
  // Exact values: y = 1, q = 0 at alpha 0.9 costs 0.9; q = 2 costs 0.1.
  const std::vector<double> a{0.9};
  EXPECT_DOUBLE_EQ(correction::pinball_loss(std::vector<double>{0.0}, a, 1.0), 0.9);
  EXPECT_DOUBLE_EQ(correction::pinball_loss(std::vector<double>{2.0}, a, 1.0), 0.1);
}

}  // namespace
