#include "correction/quantile_forest.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "awcc/parallel.hpp"
#include "awcc/random.hpp"

namespace correction {

namespace {

using SplitMix = awcc::SplitMix64;  // one stream per tree

struct Split {
  int feature = -1;
  double threshold = 0.0;
  double gain = 0.0;
};

class TreeBuilder {
 public:
  TreeBuilder(const TrainingData& data, const ForestOptions& o, int mtry, std::uint64_t seed)
      : data_(data), o_(o), mtry_(mtry), rng_{seed} {}

  RegressionTree build() {
    const auto n = data_.rows();
    const auto m = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(o_.sample_fraction * static_cast<double>(n))));
    rows_.resize(m);
    for (auto& r : rows_) r = static_cast<std::uint32_t>(rng_.below(n));
    tree_.nodes.reserve(2 * m / static_cast<std::size_t>(o_.min_leaf) + 1);
    tree_.leaf_rows.reserve(m);
    // Explicit stack: (node, begin, end, depth).
    struct Task {
      std::uint32_t node;
      std::size_t begin, end;
      int depth;
    };
    tree_.nodes.emplace_back();
    std::vector<Task> stack{{0, 0, m, 0}};
    while (!stack.empty()) {
      const Task t = stack.back();
      stack.pop_back();
      const Split s = (o_.max_depth > 0 && t.depth >= o_.max_depth) ? Split{} : best_split(t.begin, t.end);
      if (s.feature < 0) {
        auto& leaf = tree_.nodes[t.node];
        leaf.feature = -1;
        leaf.left = static_cast<std::uint32_t>(tree_.leaf_rows.size());
        leaf.right = static_cast<std::uint32_t>(t.end - t.begin);
        tree_.leaf_rows.insert(tree_.leaf_rows.end(), rows_.begin() + static_cast<std::ptrdiff_t>(t.begin),
                               rows_.begin() + static_cast<std::ptrdiff_t>(t.end));
        continue;
      }
      const auto f = static_cast<std::size_t>(s.feature);
      const auto p = static_cast<std::size_t>(data_.features);
      const auto mid = std::stable_partition(rows_.begin() + static_cast<std::ptrdiff_t>(t.begin),
                                             rows_.begin() + static_cast<std::ptrdiff_t>(t.end),
                                             [&](std::uint32_t r) { return data_.x[r * p + f] <= s.threshold; });
      const auto split_at = static_cast<std::size_t>(mid - rows_.begin());
      const auto left = static_cast<std::uint32_t>(tree_.nodes.size());
      tree_.nodes.emplace_back();
      tree_.nodes.emplace_back();
      auto& node = tree_.nodes[t.node];
      node.feature = s.feature;
      node.threshold = s.threshold;
      node.left = left;
      node.right = left + 1;
      stack.push_back({left + 1, split_at, t.end, t.depth + 1});
      stack.push_back({left, t.begin, split_at, t.depth + 1});
    }
    return std::move(tree_);
  }

 private:
  Split best_split(std::size_t begin, std::size_t end) {
    const std::size_t count = end - begin;
    const auto min_leaf = static_cast<std::size_t>(o_.min_leaf);
    Split best;
    if (count < 2 * min_leaf) return best;
    bool constant = true;
    for (std::size_t i = begin; i < end && constant; ++i) constant = data_.y[rows_[i]] == data_.y[rows_[begin]];
    if (constant) return best;
    // Targets centred on the node mean (a running mean: no overflow) and
    // divided by their largest deviation: the sums then stay within +/- n
    // whatever the targets' magnitude, and the best split is unchanged.
    double mean = 0.0;
    std::size_t seen = 0;
    for (std::size_t i = begin; i < end; ++i) mean += (data_.y[rows_[i]] - mean) / static_cast<double>(++seen);
    double scale = 0.0;
    for (std::size_t i = begin; i < end; ++i) scale = std::max(scale, std::fabs(data_.y[rows_[i]] - mean));
    if (!(scale > 0.0) || !std::isfinite(scale)) return best;
    // Draw mtry distinct features (partial Fisher-Yates).
    const int p = data_.features;
    order_.resize(static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) order_[static_cast<std::size_t>(j)] = j;
    for (int j = 0; j < mtry_; ++j) {
      const auto k = static_cast<std::size_t>(j) + rng_.below(static_cast<std::uint64_t>(p - j));
      std::swap(order_[static_cast<std::size_t>(j)], order_[k]);
    }
    const double total = [&] {
      double s = 0.0;
      for (std::size_t i = begin; i < end; ++i) s += (data_.y[rows_[i]] - mean) / scale;
      return s;
    }();
    const double base = total * total / static_cast<double>(count);
    for (int j = 0; j < mtry_; ++j) {
      const int f = order_[static_cast<std::size_t>(j)];
      pairs_.clear();
      for (std::size_t i = begin; i < end; ++i) {
        const auto r = rows_[i];
        pairs_.emplace_back(data_.x[r * static_cast<std::size_t>(p) + static_cast<std::size_t>(f)], (data_.y[r] - mean) / scale);
      }
      std::sort(pairs_.begin(), pairs_.end());
      if (pairs_.front().first == pairs_.back().first) continue;
      double left_sum = 0.0;
      for (std::size_t k = 0; k + 1 < count; ++k) {
        left_sum += pairs_[k].second;
        const std::size_t nl = k + 1, nr = count - nl;
        if (nl < min_leaf) continue;
        if (nr < min_leaf) break;
        const double a = pairs_[k].first, b = pairs_[k + 1].first;
        if (!(a < b)) continue;
        const double right_sum = total - left_sum;
        const double gain = left_sum * left_sum / static_cast<double>(nl) +
                            right_sum * right_sum / static_cast<double>(nr) - base;
        if (gain > best.gain) {
          double threshold = a + 0.5 * (b - a);
          if (!(threshold < b)) threshold = a;  // adjacent doubles
          best = {f, threshold, gain};
        }
      }
    }
    // A gain lost in rounding is no split (scaled deviations: the total sum of
    // squares is at least 1, so an absolute floor is a relative one).
    if (best.gain <= 1e-12) best.feature = -1;
    return best;
  }

  const TrainingData& data_;
  const ForestOptions& o_;
  int mtry_;
  SplitMix rng_;
  RegressionTree tree_;
  std::vector<std::uint32_t> rows_;
  std::vector<int> order_;
  std::vector<std::pair<double, double>> pairs_;
};

}  // namespace

std::string ForestOptions::validate() const {
  if (trees < 1) return fmt::format("trees = {}: give at least 1", trees);
  if (min_leaf < 1) return fmt::format("min_leaf = {}: give at least 1", min_leaf);
  if (max_depth < 0) return fmt::format("max_depth = {}: give 0 (unlimited) or more", max_depth);
  if (features_per_split < 0) return fmt::format("features_per_split = {}: give 0 (p/3) or more", features_per_split);
  if (!(sample_fraction > 0.0 && sample_fraction <= 10.0)) {
    return fmt::format("sample_fraction = {}: give a value in (0, 10]", sample_fraction);
  }
  if (threads < 0) return fmt::format("threads = {}: give 0 (all cores) or more", threads);
  return {};
}

std::uint32_t RegressionTree::leaf(std::span<const double> x) const {
  std::uint32_t i = 0;
  while (nodes[i].feature >= 0) {
    const auto& n = nodes[i];
    i = x[static_cast<std::size_t>(n.feature)] <= n.threshold ? n.left : n.right;
  }
  return i;
}

std::span<const std::uint32_t> RegressionTree::rows(std::uint32_t leaf) const {
  const auto& n = nodes[leaf];
  return {leaf_rows.data() + n.left, n.right};
}

double WeightedDistribution::quantile(double alpha) const {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  double cumulative = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    cumulative += weights[i];
    if (cumulative >= alpha - 1e-12) return values[i];
  }
  return values.back();
}

QuantileForest QuantileForest::train(const TrainingData& data, const ForestOptions& options) {
  if (auto why = options.validate(); !why.empty()) throw std::invalid_argument("forest options: " + why);
  const auto n = data.rows();
  if (data.features < 1) throw std::invalid_argument("training data: no features");
  if (n == 0) throw std::invalid_argument("training data: no rows");
  if (n >= std::numeric_limits<std::uint32_t>::max()) throw std::invalid_argument("training data: more than 2^32 - 2 rows");
  if (data.x.size() != n * static_cast<std::size_t>(data.features)) {
    throw std::invalid_argument("training data: features and targets disagree in row count");
  }
  for (std::size_t i = 0; i < data.x.size(); ++i) {
    if (!std::isfinite(data.x[i])) {
      throw std::invalid_argument(fmt::format("training data: row {} feature {} is not finite", i / static_cast<std::size_t>(data.features),
                                              i % static_cast<std::size_t>(data.features)));
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(data.y[i])) throw std::invalid_argument(fmt::format("training data: target of row {} is not finite", i));
  }
  const int mtry = options.features_per_split > 0 ? std::min(options.features_per_split, data.features)
                                                  : (data.features + 2) / 3;
  QuantileForest forest;
  forest.features_ = data.features;
  forest.targets_ = data.y;
  forest.trees_.resize(static_cast<std::size_t>(options.trees));
  awcc::parallel_for(static_cast<std::size_t>(options.trees), options.threads, [&](std::size_t t) {
    // The tree's stream depends on (seed, t) only.
    SplitMix mix{options.seed ^ (0xd1b54a32d192ed03ull * (static_cast<std::uint64_t>(t) + 1))};
    TreeBuilder builder(data, options, mtry, mix.next());
    forest.trees_[t] = builder.build();
  });
  return forest;
}

QuantileForest QuantileForest::assemble(int features, std::vector<double> targets, std::vector<RegressionTree> trees) {
  if (features < 1) throw std::invalid_argument("forest: no features");
  if (trees.empty()) throw std::invalid_argument("forest: no trees");
  for (std::size_t t = 0; t < trees.size(); ++t) {
    const auto& tree = trees[t];
    const auto count = tree.nodes.size();
    if (count == 0) throw std::invalid_argument(fmt::format("forest: tree {} has no nodes", t));
    for (std::size_t i = 0; i < count; ++i) {
      const auto& node = tree.nodes[i];
      if (node.feature < 0) {
        if (node.right == 0 || static_cast<std::uint64_t>(node.left) + node.right > tree.leaf_rows.size()) {
          throw std::invalid_argument(fmt::format("forest: tree {} leaf {} refers to rows outside the tree", t, i));
        }
      } else {
        // Children come after their parent: the walk from the root ends.
        if (node.feature >= features || node.left <= i || node.right <= i || node.left >= count ||
            node.right >= count || !std::isfinite(node.threshold)) {
          throw std::invalid_argument(fmt::format("forest: tree {} node {} is malformed", t, i));
        }
      }
    }
    for (auto r : tree.leaf_rows) {
      if (r >= targets.size()) throw std::invalid_argument(fmt::format("forest: tree {} holds row {} of {}", t, r, targets.size()));
    }
  }
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (!std::isfinite(targets[i])) throw std::invalid_argument(fmt::format("forest: target {} is not finite", i));
  }
  QuantileForest forest;
  forest.features_ = features;
  forest.targets_ = std::move(targets);
  forest.trees_ = std::move(trees);
  return forest;
}

std::vector<double> QuantileForest::weights(std::span<const double> x) const {
  std::vector<double> w(targets_.size(), 0.0);
  const double per_tree = 1.0 / static_cast<double>(trees_.size());
  for (const auto& tree : trees_) {
    const auto rows = tree.rows(tree.leaf(x));
    const double each = per_tree / static_cast<double>(rows.size());
    for (auto r : rows) w[r] += each;
  }
  return w;
}

WeightedDistribution QuantileForest::distribution(std::span<const double> x) const {
  // The held rows of the T leaves, sorted by target: the same F as the dense
  // weights, at a cost of the leaves' sizes instead of n.
  std::vector<std::pair<double, double>> held;
  const double per_tree = 1.0 / static_cast<double>(trees_.size());
  for (const auto& tree : trees_) {
    const auto rows = tree.rows(tree.leaf(x));
    const double each = per_tree / static_cast<double>(rows.size());
    for (auto r : rows) held.emplace_back(targets_[r], each);
  }
  std::sort(held.begin(), held.end());
  WeightedDistribution d;
  for (const auto& [v, w] : held) {
    if (!d.values.empty() && d.values.back() == v) {
      d.weights.back() += w;
    } else {
      d.values.push_back(v);
      d.weights.push_back(w);
    }
  }
  return d;
}

std::vector<double> QuantileForest::quantiles(std::span<const double> x, std::span<const double> levels) const {
  const auto d = distribution(x);
  std::vector<double> q;
  q.reserve(levels.size());
  for (double a : levels) q.push_back(d.quantile(a));
  return q;
}

double pinball_loss(std::span<const double> q, std::span<const double> levels, double y) {
  double sum = 0.0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    const double e = y - q[k];
    sum += std::max(levels[k] * e, (levels[k] - 1.0) * e);
  }
  return sum / static_cast<double>(q.size());
}

}  // namespace correction
