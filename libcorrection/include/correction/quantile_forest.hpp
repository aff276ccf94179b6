#pragma once
// Quantile regression forest (Meinshausen 2006), METHOD.md 7.
//
// Training: every tree grows on a bootstrap sample (m = round(f n) draws with
// replacement of the n training rows). A node splits on the feature and
// threshold, among `features_per_split` features drawn at random, that most
// reduce the squared error of the targets (variance reduction), subject to
// each child holding at least `min_leaf` draws; it becomes a leaf at
// `max_depth`, below 2 min_leaf draws, on constant targets, or when no split
// reduces the error. A leaf keeps the training rows it holds (a row drawn twice
// is held twice).
//
// Prediction at x: with L_t(x) the leaf of tree t reached by x, c_ti(x) the
// number of times row i is held by it and |L_t(x)| its size, the weight of
// training target Y_i is
//   w_i(x) = (1/T) sum_t c_ti(x) / |L_t(x)|,        sum_i w_i(x) = 1,
// the conditional distribution F(y | x) = sum_i w_i(x) 1{Y_i <= y}, and the
// alpha-quantile
//   Q_alpha(x) = inf { y : F(y | x) >= alpha }
// (no interpolation: with one tree it is the leaf's empirical quantile, the
// order statistic Y_(ceil(alpha |L|))). Quantiles of one x never cross.
//
// Determinism: tree t draws its bootstrap and features from its own stream,
// seeded by (seed, t), so a seed gives the same forest whatever the thread
// count.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "awcc/validation.hpp"

namespace correction {

struct ForestOptions {
  int trees = 100;                  ///< trees in the forest
  int min_leaf = 5;                 ///< least bootstrap draws per leaf
  int max_depth = 0;                ///< deepest split level; 0 = unlimited (min_leaf bounds the tree)
  int features_per_split = 0;       ///< features tried per split; 0 = ceil(p / 3)
  double sample_fraction = 1.0;     ///< bootstrap draws per tree / training rows
  std::uint64_t seed = 1;           ///< a seed gives the same forest
  int threads = 0;                  ///< training threads; 0 = all cores

  [[nodiscard]] awcc::Validation validate() const;
};

/// Training rows: features row-major (rows x features), one target per row.
struct TrainingData {
  int features = 0;
  std::vector<double> x;            ///< row i, feature j at x[i * features + j]
  std::vector<double> y;
  [[nodiscard]] std::size_t rows() const { return y.size(); }
  [[nodiscard]] std::span<const double> row(std::size_t i) const {
    return {x.data() + i * static_cast<std::size_t>(features), static_cast<std::size_t>(features)};
  }
};

/// One regression tree held flat: node 0 is the root.
struct RegressionTree {
  struct Node {
    std::int32_t feature = -1;      ///< -1: leaf
    double threshold = 0.0;         ///< x[feature] <= threshold goes to `left`
    std::uint32_t left = 0, right = 0;  ///< child nodes; for a leaf: first and count in `leaf_rows`
  };
  std::vector<Node> nodes;
  std::vector<std::uint32_t> leaf_rows;  ///< training rows held by the leaves, leaf by leaf

  /// The leaf reached by x (its node index).
  [[nodiscard]] std::uint32_t leaf(std::span<const double> x) const;
  /// The training rows that leaf holds.
  [[nodiscard]] std::span<const std::uint32_t> rows(std::uint32_t leaf) const;
};

/// A weighted sample: values ascending, weights summing to 1.
struct WeightedDistribution {
  std::vector<double> values, weights;
  /// inf { y : F(y) >= alpha } (F within 1e-12 of alpha counts as reaching it).
  [[nodiscard]] double quantile(double alpha) const;
};

/// The mixture of two distributions, each weighted one half: its quantiles
/// are those of a truth drawn from either with equal probability.
WeightedDistribution mixture(const WeightedDistribution& a, const WeightedDistribution& b);

/// A forest held as one block of bytes, read in place (so that a model file
/// mapped into memory is used as it lies, with nothing built). Little-endian
/// whatever the machine, every value read by copying its bytes (no alignment):
///   u32 features, u64 target count n, f64 targets[n], u32 tree count,
///   u8 held-row width (2 bytes when n <= 65,536, else 4); per tree: u32 node
///   count, nodes of 12 bytes, u64 held-row count, held rows.
/// A split node: f64 threshold, u32 feature << 24 | left child (the right
/// child is left + 1); a leaf: u32 first held row, u32 count, u32 0xff << 24.
/// Trees of 2^24 nodes or more, or 255 features or more, are refused.
class QuantileForest {
 public:
  QuantileForest() = default;
  /// Grows the forest; throws std::invalid_argument on bad options or data
  /// (non-finite values, no rows, more rows than 2^32 - 1).
  static QuantileForest train(const TrainingData& data, const ForestOptions& options);
  /// A forest from its parts (format 1 and 2 model files, tests); throws
  /// std::invalid_argument when a tree refers to a node, feature or row that
  /// does not exist.
  static QuantileForest assemble(int features, std::vector<double> targets, std::vector<RegressionTree> trees);
  /// A forest read in place from `block` (the layout above), which `owner`
  /// keeps alive; checks every node, row and target (throws
  /// std::invalid_argument naming the fault) and builds nothing but an index
  /// of the trees.
  static QuantileForest view(std::shared_ptr<const void> owner, std::span<const std::uint8_t> block);

  [[nodiscard]] int features() const { return features_; }
  /// The block (what a model file stores).
  [[nodiscard]] std::span<const std::uint8_t> bytes() const { return block_; }
  [[nodiscard]] std::size_t target_count() const { return target_count_; }
  [[nodiscard]] double target(std::size_t i) const;
  /// The training targets and trees, decoded (tests and inspection; prediction does not need them).
  [[nodiscard]] std::vector<double> targets() const;
  [[nodiscard]] std::vector<RegressionTree> trees() const;

  /// w_i(x) for every training row i (the definition above, dense).
  [[nodiscard]] std::vector<double> weights(std::span<const double> x) const;
  /// F(. | x) as a weighted sample (only the rows with weight).
  [[nodiscard]] WeightedDistribution distribution(std::span<const double> x) const;
  /// Q_alpha(x) for each level alpha in (0, 1].
  [[nodiscard]] std::vector<double> quantiles(std::span<const double> x, std::span<const double> levels) const;

 private:
  struct TreeView {
    const std::uint8_t* nodes = nullptr;
    std::uint32_t node_count = 0;
    const std::uint8_t* rows = nullptr;
    std::uint64_t row_count = 0;
  };
  // The leaf x reaches, and its held rows passed to fn one by one.
  [[nodiscard]] std::uint32_t leaf(const TreeView& t, std::span<const double> x) const;
  template <class Fn>
  void for_each_held(const TreeView& t, std::uint32_t leaf, Fn&& fn) const;

  int features_ = 0;
  std::shared_ptr<const void> owner_;
  std::span<const std::uint8_t> block_;
  const std::uint8_t* targets_ = nullptr;
  std::size_t target_count_ = 0;
  int row_bytes_ = 4;
  std::vector<TreeView> trees_;
};

/// Mean pinball (quantile) loss of predicted quantiles q at levels alpha for
/// the truth y: (1/K) sum_k max(alpha_k (y - q_k), (alpha_k - 1)(y - q_k)).
/// A proper score: its expectation is least at the true quantiles.
double pinball_loss(std::span<const double> q, std::span<const double> levels, double y);

}  // namespace correction
