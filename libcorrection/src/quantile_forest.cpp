#include "correction/quantile_forest.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
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

// The quantities are the training options' declared names that set these
// (training_option_fields()); max_depth and sample_fraction have none.
awcc::Validation ForestOptions::validate() const {
  using awcc::Validation;
  if (trees < 1) return Validation::invalid("trees", fmt::format("trees = {}: give at least 1", trees));
  if (min_leaf < 1) return Validation::invalid("min-leaf", fmt::format("min_leaf = {}: give at least 1", min_leaf));
  if (max_depth < 0) return Validation::invalid("", fmt::format("max_depth = {}: give 0 (unlimited) or more", max_depth));
  if (features_per_split < 0) {
    return Validation::invalid("features-per-split",
                               fmt::format("features_per_split = {}: give 0 (p/3) or more", features_per_split));
  }
  if (!(sample_fraction > 0.0 && sample_fraction <= 10.0))
    return Validation::invalid("", fmt::format("sample_fraction = {}: give a value in (0, 10]", sample_fraction));
  if (threads < 0) return Validation::invalid("threads", fmt::format("threads = {}: give 0 (all cores) or more", threads));
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

WeightedDistribution mixture(const WeightedDistribution& a, const WeightedDistribution& b) {
  WeightedDistribution out;
  out.values.reserve(a.values.size() + b.values.size());
  out.weights.reserve(a.values.size() + b.values.size());
  std::size_t i = 0, j = 0;
  while (i < a.values.size() || j < b.values.size()) {
    const bool from_a = j == b.values.size() || (i < a.values.size() && a.values[i] <= b.values[j]);
    out.values.push_back(from_a ? a.values[i] : b.values[j]);
    out.weights.push_back(0.5 * (from_a ? a.weights[i++] : b.weights[j++]));
  }
  return out;
}

QuantileForest QuantileForest::train(const TrainingData& data, const ForestOptions& options) {
  if (auto v = options.validate(); !v.ok()) throw awcc::OptionError("forest options: " + v.message, v.quantity);
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
  std::vector<RegressionTree> trees(static_cast<std::size_t>(options.trees));
  awcc::parallel_for(static_cast<std::size_t>(options.trees), options.threads, [&](std::size_t t) {
    // The tree's stream depends on (seed, t) only.
    SplitMix mix{options.seed ^ (0xd1b54a32d192ed03ull * (static_cast<std::uint64_t>(t) + 1))};
    TreeBuilder builder(data, options, mtry, mix.next());
    trees[t] = builder.build();
  });
  return assemble(data.features, data.y, std::move(trees));
}

namespace {

// Little-endian values read and written by their bytes, whatever the machine.
std::uint32_t load_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
std::uint64_t load_u64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(load_u32(p)) | static_cast<std::uint64_t>(load_u32(p + 4)) << 32;
}
double load_f64(const std::uint8_t* p) { return std::bit_cast<double>(load_u64(p)); }
// Held row k of a tree whose rows are `width` (2 or 4) bytes each.
std::uint32_t held_row(const std::uint8_t* rows, int width, std::uint64_t k) {
  return width == 2 ? static_cast<std::uint32_t>(rows[2 * k]) | static_cast<std::uint32_t>(rows[2 * k + 1]) << 8
                    : load_u32(rows + 4 * k);
}
void put_u32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}
void put_u64(std::vector<std::uint8_t>& b, std::uint64_t v) {
  put_u32(b, static_cast<std::uint32_t>(v));
  put_u32(b, static_cast<std::uint32_t>(v >> 32));
}
void put_f64(std::vector<std::uint8_t>& b, double v) { put_u64(b, std::bit_cast<std::uint64_t>(v)); }

constexpr std::size_t node_bytes = 12;
constexpr std::uint32_t leaf_tag = 0xffu << 24;
constexpr std::uint32_t max_nodes = 1u << 24;

}  // namespace

QuantileForest QuantileForest::assemble(int features, std::vector<double> targets, std::vector<RegressionTree> trees) {
  if (features < 1) throw std::invalid_argument("forest: no features");
  if (features >= 255) throw std::invalid_argument("forest: 255 features or more");
  if (trees.empty()) throw std::invalid_argument("forest: no trees");
  for (std::size_t t = 0; t < trees.size(); ++t) {
    const auto& tree = trees[t];
    const auto count = tree.nodes.size();
    if (count == 0) throw std::invalid_argument(fmt::format("forest: tree {} has no nodes", t));
    if (count >= max_nodes) throw std::invalid_argument(fmt::format("forest: tree {} has 2^24 nodes or more", t));
    for (std::size_t i = 0; i < count; ++i) {
      const auto& node = tree.nodes[i];
      if (node.feature < 0) {
        if (node.right == 0 || static_cast<std::uint64_t>(node.left) + node.right > tree.leaf_rows.size()) {
          throw std::invalid_argument(fmt::format("forest: tree {} leaf {} refers to rows outside the tree", t, i));
        }
      } else {
        // Children come after their parent (the walk from the root ends), side by side.
        if (node.feature >= features || node.left <= i || node.right != node.left + 1 || node.right >= count ||
            !std::isfinite(node.threshold)) {
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
  auto block = std::make_shared<std::vector<std::uint8_t>>();
  auto& b = *block;
  put_u32(b, static_cast<std::uint32_t>(features));
  put_u64(b, targets.size());
  for (double y : targets) put_f64(b, y);
  put_u32(b, static_cast<std::uint32_t>(trees.size()));
  const bool narrow = targets.size() <= 65536;
  b.push_back(narrow ? 2 : 4);
  for (const auto& tree : trees) {
    put_u32(b, static_cast<std::uint32_t>(tree.nodes.size()));
    for (const auto& n : tree.nodes) {
      if (n.feature < 0) {
        put_u32(b, n.left);
        put_u32(b, n.right);
        put_u32(b, leaf_tag);
      } else {
        put_f64(b, n.threshold);
        put_u32(b, static_cast<std::uint32_t>(n.feature) << 24 | n.left);
      }
    }
    put_u64(b, tree.leaf_rows.size());
    for (auto r : tree.leaf_rows) {
      b.push_back(static_cast<std::uint8_t>(r));
      b.push_back(static_cast<std::uint8_t>(r >> 8));
      if (!narrow) {
        b.push_back(static_cast<std::uint8_t>(r >> 16));
        b.push_back(static_cast<std::uint8_t>(r >> 24));
      }
    }
  }
  const std::span<const std::uint8_t> bytes(b.data(), b.size());
  return view(std::move(block), bytes);
}

QuantileForest QuantileForest::view(std::shared_ptr<const void> owner, std::span<const std::uint8_t> block) {
  const std::uint8_t* p = block.data();
  const std::uint8_t* const end = block.data() + block.size();
  auto need = [&](std::uint64_t bytes, const char* what) {
    if (bytes > static_cast<std::uint64_t>(end - p)) throw std::invalid_argument(fmt::format("forest: {} beyond its bytes", what));
  };
  QuantileForest f;
  need(12, "the header");
  f.features_ = static_cast<int>(load_u32(p));
  const auto n = load_u64(p + 4);
  p += 12;
  if (f.features_ < 1 || f.features_ >= 255) throw std::invalid_argument(fmt::format("forest: {} features", f.features_));
  // Counts are checked against the bytes left before anything is sized by them.
  if (n >= std::numeric_limits<std::uint32_t>::max()) throw std::invalid_argument("forest: too many targets");
  need(n * 8 + 5, "the targets");
  f.targets_ = p;
  f.target_count_ = static_cast<std::size_t>(n);
  for (std::size_t i = 0; i < f.target_count_; ++i) {
    if (!std::isfinite(load_f64(p + 8 * i))) throw std::invalid_argument(fmt::format("forest: target {} is not finite", i));
  }
  p += n * 8;
  const auto tree_count = load_u32(p);
  f.row_bytes_ = p[4];
  p += 5;
  if (tree_count == 0) throw std::invalid_argument("forest: no trees");
  need(static_cast<std::uint64_t>(tree_count) * (4 + node_bytes + 8), "the trees");  // each at least one node
  if (f.row_bytes_ != 2 && f.row_bytes_ != 4) throw std::invalid_argument(fmt::format("forest: held rows of {} bytes", f.row_bytes_));
  f.trees_.reserve(tree_count);
  for (std::uint32_t t = 0; t < tree_count; ++t) {
    TreeView v;
    need(4, "a tree");
    v.node_count = load_u32(p);
    p += 4;
    if (v.node_count == 0 || v.node_count >= max_nodes) throw std::invalid_argument(fmt::format("forest: tree {} has {} nodes", t, v.node_count));
    need(static_cast<std::uint64_t>(v.node_count) * node_bytes + 8, "a tree's nodes");
    v.nodes = p;
    p += static_cast<std::size_t>(v.node_count) * node_bytes;
    v.row_count = load_u64(p);
    p += 8;
    if (v.row_count > static_cast<std::uint64_t>(end - p) || v.row_count >= (std::uint64_t{1} << 32)) {
      throw std::invalid_argument("forest: a tree's held rows beyond its bytes");
    }
    need(v.row_count * static_cast<std::uint64_t>(f.row_bytes_), "a tree's held rows");
    v.rows = p;
    p += v.row_count * static_cast<std::uint64_t>(f.row_bytes_);
    for (std::uint32_t i = 0; i < v.node_count; ++i) {
      const std::uint8_t* q = v.nodes + static_cast<std::size_t>(i) * node_bytes;
      const auto info = load_u32(q + 8);
      if (info == leaf_tag) {
        const auto first = load_u32(q), count = load_u32(q + 4);
        if (count == 0 || static_cast<std::uint64_t>(first) + count > v.row_count) {
          throw std::invalid_argument(fmt::format("forest: tree {} leaf {} refers to rows outside the tree", t, i));
        }
      } else {
        const auto feature = info >> 24, left = info & (max_nodes - 1);
        if (static_cast<int>(feature) >= f.features_ || left <= i || left + 1 >= v.node_count || !std::isfinite(load_f64(q))) {
          throw std::invalid_argument(fmt::format("forest: tree {} node {} is malformed", t, i));
        }
      }
    }
    // The largest held row first (a loop the compiler vectorises: reading a
    // model checks every row of every tree); the offending row only when
    // there is one.
    std::uint32_t largest = 0;
    if (f.row_bytes_ == 2) {
      for (std::uint64_t k = 0; k < v.row_count; ++k) {
        largest = std::max(largest, static_cast<std::uint32_t>(v.rows[2 * k]) |
                                        static_cast<std::uint32_t>(v.rows[2 * k + 1]) << 8);
      }
    } else {
      for (std::uint64_t k = 0; k < v.row_count; ++k) largest = std::max(largest, load_u32(v.rows + 4 * k));
    }
    if (largest >= n) {
      for (std::uint64_t k = 0; k < v.row_count; ++k) {
        const std::uint32_t r = held_row(v.rows, f.row_bytes_, k);
        if (r >= n) throw std::invalid_argument(fmt::format("forest: tree {} holds row {} of {}", t, r, n));
      }
    }
    f.trees_.push_back(v);
  }
  if (p != end) throw std::invalid_argument("forest: bytes after the last tree");
  f.owner_ = std::move(owner);
  f.block_ = block;
  return f;
}

double QuantileForest::target(std::size_t i) const { return load_f64(targets_ + 8 * i); }

std::vector<double> QuantileForest::targets() const {
  std::vector<double> out(target_count_);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = target(i);
  return out;
}

std::vector<RegressionTree> QuantileForest::trees() const {
  std::vector<RegressionTree> out;
  for (const auto& v : trees_) {
    RegressionTree t;
    for (std::uint32_t i = 0; i < v.node_count; ++i) {
      const std::uint8_t* q = v.nodes + static_cast<std::size_t>(i) * node_bytes;
      RegressionTree::Node n;
      const auto info = load_u32(q + 8);
      if (info == leaf_tag) {
        n.feature = -1;
        n.left = load_u32(q);
        n.right = load_u32(q + 4);
      } else {
        n.feature = static_cast<std::int32_t>(info >> 24);
        n.threshold = load_f64(q);
        n.left = info & (max_nodes - 1);
        n.right = n.left + 1;
      }
      t.nodes.push_back(n);
    }
    for (std::uint64_t k = 0; k < v.row_count; ++k) {
      t.leaf_rows.push_back(held_row(v.rows, row_bytes_, k));
    }
    out.push_back(std::move(t));
  }
  return out;
}

std::uint32_t QuantileForest::leaf(const TreeView& t, std::span<const double> x) const {
  std::uint32_t i = 0;
  for (;;) {
    const std::uint8_t* q = t.nodes + static_cast<std::size_t>(i) * node_bytes;
    const auto info = load_u32(q + 8);
    if (info == leaf_tag) return i;
    const auto left = info & (max_nodes - 1);
    i = x[info >> 24] <= load_f64(q) ? left : left + 1;
  }
}

template <class Fn>
void QuantileForest::for_each_held(const TreeView& t, std::uint32_t leaf, Fn&& fn) const {
  const std::uint8_t* q = t.nodes + static_cast<std::size_t>(leaf) * node_bytes;
  if (load_u32(q + 8) != leaf_tag) return;
  const std::size_t first = load_u32(q), count = load_u32(q + 4);
  for (std::size_t k = first; k < first + count; ++k) {
    fn(held_row(t.rows, row_bytes_, k));
  }
}

std::vector<double> QuantileForest::weights(std::span<const double> x) const {
  if (x.size() < static_cast<std::size_t>(features_)) throw std::invalid_argument("forest: fewer features than the forest takes");
  std::vector<double> w(target_count_, 0.0);
  const double per_tree = 1.0 / static_cast<double>(trees_.size());
  for (const auto& tree : trees_) {
    const auto l = leaf(tree, x);
    const double each = per_tree / static_cast<double>(load_u32(tree.nodes + static_cast<std::size_t>(l) * node_bytes + 4));
    for_each_held(tree, l, [&](std::uint32_t r) { w[r] += each; });
  }
  return w;
}

WeightedDistribution QuantileForest::distribution(std::span<const double> x) const {
  if (x.size() < static_cast<std::size_t>(features_)) throw std::invalid_argument("forest: fewer features than the forest takes");
  // The held rows of the T leaves, sorted by target: the same F as the dense
  // weights, at a cost of the leaves' sizes instead of n.
  std::vector<std::pair<double, double>> held;
  const double per_tree = 1.0 / static_cast<double>(trees_.size());
  for (const auto& tree : trees_) {
    const auto l = leaf(tree, x);
    const double each = per_tree / static_cast<double>(load_u32(tree.nodes + static_cast<std::size_t>(l) * node_bytes + 4));
    for_each_held(tree, l, [&](std::uint32_t r) { held.emplace_back(target(r), each); });
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
