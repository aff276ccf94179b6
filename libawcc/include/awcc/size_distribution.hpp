#pragma once
// The number distribution of bubble diameters from chord lengths (METHOD.md
// 12, "Bubble sizes, not only d32"; issue 31).
//
// Forward model. A sphere of diameter D pierced at a point uniform over its
// cross-section (offset r D / 2, r^2 uniform on [0, 1]) gives the chord
// l = D sqrt(1 - r^2), so (l / D)^2 is uniform and p(l | D) = 2 l / D^2 on
// (0, D]. The tip meets bubbles in proportion to their projected area, so
// the pierced diameters have density g(D) = D^2 n(D) / int n D^2 dD and the
// chords
//   f(l) = int g(D) p(l | D) dD = 2 l int_l^inf n(D) dD / int n(D) D^2 dD.
// Since E[l | D] = 2 D / 3, mean(l) = (2/3) E_g[D] = (2/3) d32 exactly.
//
// Discretisation. Bins j = 0..J-1 with edges a_j < b_j equally spaced in
// ln D (width h); within a bin the pierced density is uniform in D, with
// probability w_j (sum 1). A bin's chord density is then exact:
//   K_j(l) = 2 l / (b - a) (1 / max(l, a) - 1 / b) for l < b, 0 otherwise,
// and f(l) = sum_j w_j K_j(l). The number distribution follows from
// n(D) = g(D) / D^2 (normalised): within bin j, n(D) = w_j / ((b - a) D^2) / M_0,
// and its moments M_k = sum_j w_j / (b - a) int_a^b D^(k-2) dD are exact:
// d10 = M_1 / M_0, d20 = sqrt(M_2 / M_0), d30 = cbrt(M_3 / M_0),
// d32 = M_3 / M_2 (= the model's mean chord x 1.5), the median where the
// cumulative number fraction (exact within a bin) reaches 1/2.
//
// Estimator: penalised maximum likelihood, w_j = exp(beta_j) / sum exp(beta),
//   maximise  sum_i log f(l_i) - (lambda / (2 h^5)) sum_j (Delta^3 beta)_j^2,
// the penalty being the discrete form of (lambda / 2) int (beta''')^2 d(ln D)
// (third differences of h-spaced samples are h^3 beta''', summed over 1 / h
// bins per unit of ln D: a weight independent of the grid). Solved by EM
// (Green 1990, penalised EM): the E-step gives each bin its expected chords
// c_j = sum_i w_j K_j(l_i) / f(l_i); the M-step maximises the concave
//   c . beta - N log sum exp(beta) - (1/2) beta' P beta
// by Newton's method with a backtracking line search (P the penalty matrix
// plus N (sum beta)^2 / J^2, which pins the free shift of beta and nothing
// else). Each EM iteration raises the penalised likelihood.
//
// Why this and not another regularised method (measured on log-normal sizes,
// 5,000 chords, with the numpy prototype of this estimator):
//  - The unpenalised maximum likelihood (and EM stopped early) puts tiny
//    pierced masses at small D to explain single short chords: a chord l
//    from a bubble of D ~ l has density ~ 2 / l against 2 l / D^2 from the
//    large bubbles. n = g / D^2 turns a pierced mass of 1e-5 at D_median / 50
//    into a quarter of all bubbles: the number median came out 17-96 % low.
//  - Smoothing the pierced or the number distribution (EMS, Silverman et
//    al. 1990) does not cure it: weak smoothing leaves the spikes, strong
//    smoothing broadens the pierced distribution, and the number median
//    moves as exp(-2 x the added log-variance): 26-60 % low at every width
//    tried.
//  - The penalty on the third derivative of ln g in ln D is zero for any
//    log-normal g (its logarithm is quadratic in ln D), and n = g / D^2 is
//    then log-normal too: the penalty shrinks towards "log-normal sizes",
//    the shape bubbly flows usually have, without biasing their median or
//    width, while it makes every spike expensive. With few chords the
//    estimate is nearly the log-normal fit; with many it follows the data
//    (a bimodal population is not forced into one mode).
//
// What the chords cannot say. Bubbles much smaller than the short chords of
// the large ones are invisible: the pierced fraction below D is at most the
// chord fraction below D, and n = g / D^2 makes that small pierced
// fraction a large number fraction. The grid therefore starts at the chord
// of quantile floor_quantile (at least the floor_rank_min-th shortest): the
// distribution is that of the bubbles above it, and the smallest chords are
// still explained by the bins above (every K_j covers (0, b_j]).
//
// Measured (bench/size_distribution_bench, scripts/size-inversion):
// log-normal n(D), sigma of ln D 0.3 / 0.45 / 0.6, 40 draws each; relative
// error against the population (median exp(mu), d32 exp(mu + 2.5 sigma^2)):
//   chords  number median: bias, sd, worst   d32: bias, sd, worst
//   5,000   -0.0..+0.6 %, 1.1-3.6 %, 8.7 %   -0.1..0.0 %, 0.6-1.1 %, 2.4 %
//   200     -0.8..+1.7 %, 6.0-13 %, 30 %     +0.5..+0.8 %, 3.4-6.0 %, 22 %
//   50      +0.3..+2.0 %, 16-34 %, 122 %     +0.9..+1.4 %, 6.2-10 %, 27 %
// (the spread grows with sigma: the number median sits where few bubbles
// are pierced). No bias to speak of at any count: few chords widen the
// spread, they do not shift the answer. 1.5 mean(l) and the inversion's d32
// differ by at most 0.4 % at 5,000 chords, 2.7 % at 200, 6.3 % at 50.
// 5-9 ms per inversion of 50-200 chords, 24-34 ms of 5,000 (35-45 EM
// iterations; measured with an E-step of O(chords x bins)). The E-step and
// the mixture are now O(distinct chords + bins) an iteration (the kernel is
// linear in l below a bin and the bins are ordered: prefix and suffix sums),
// and repeated lengths are inverted once with their count; the Newton
// M-step is O(bins^3). docs/performance.md gives the cost on a record.
// so chords_min = 200 (below: status too_few_chords, no distribution).

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/validation.hpp"

namespace awcc {

struct SizeDistributionOptions {
  /// Width of a diameter bin in ln D, -. 0.05 (5 % steps): well below the
  /// width of any measured size distribution (sigma of ln D 0.3-0.6), so
  /// the bins do not broaden it; the cost is linear in the bins.
  double bin_width = 0.05;
  /// The grid starts at the chord of this quantile, -. 0.02: the pierced
  /// bubbles below it are at most 2 % of the pierced ones and are not
  /// resolved from the short chords of larger bubbles; starting at the
  /// shortest chord let one short chord of 200 bend ln g up at the grid's
  /// end and put most bubbles there (number median 99.7 % low in 1 of 30
  /// draws, measured with the prototype).
  double floor_quantile = 0.02;
  /// ... but at least the floor_rank_min-th shortest chord: with 50 chords
  /// the 2 % quantile is the shortest one.
  int floor_rank_min = 3;
  /// The grid ends at this multiple of the longest chord, -. A chord is never
  /// longer than its bubble, so the largest bubble is at least the longest
  /// chord; 1.2 leaves room for the bins above it, which the data then
  /// empty (a bubble much above the longest chord would have given longer
  /// chords).
  double ceiling_factor = 1.2;
  /// lambda, the weight of (1/2) int (d^3 ln g / d(ln D)^3)^2 d(ln D), -.
  /// Dimensionless and independent of the grid. 1: on log-normal sizes
  /// with 5,000 chords (prototype, 6 draws), 0.01 and 0.1 left spikes at
  /// small D (number median 26-60 % low on average), 1 and 10 gave the same
  /// accuracy (median within 4 %); 1 is
  /// the weakest that is stable, which leaves the most freedom to shapes
  /// that are not log-normal.
  double penalty = 1.0;
  /// Fewest chords inverted (status too_few_chords below): see the header's
  /// measured spreads. At 200 the number median's standard deviation over
  /// draws is 6-13 % (d32 3-6 %); at 50 it is 16-34 % and one draw in 40
  /// is off by a factor two: a distribution that cannot be told from the
  /// penalty's log-normal shape. 1.5 x mean chord is d32 below it.
  int chords_min = 200;
  /// Most EM iterations (status not_converged beyond). Measured 21-49 on
  /// average, at most 280 (50 chords), on log-normal sizes.
  int iterations_max = 2000;
  /// EM stops when the penalised log-likelihood rises by less than this per
  /// chord in one iteration, -. 1e-9: against 1e-13 the median moved by
  /// 1.5e-4 and d32 by 2e-6 (relative; measured, 5,000 chords).
  double tolerance = 1e-9;
  /// Most diameter bins; a wider range than bins_max x bin_width in ln D
  /// widens the bins instead. 400 bins of 0.05 span a factor 5e8.
  int bins_max = 400;

  [[nodiscard]] Validation validate() const;
};

enum class SizeStatus {
  ok,
  too_few_chords,  ///< fewer usable chords than chords_min: no distribution
  not_converged,   ///< iterations_max reached: the values are the last iterate's
};
std::string_view to_string(SizeStatus status);

/// The chord density of bin [a, b] (pierced diameters uniform on it) at l, 1/m:
/// 2 l / (b - a) (1 / max(l, a) - 1 / b) for 0 < l < b, else 0.
double bin_chord_density(double l, double a, double b);

struct SizeDistribution {
  SizeStatus status = SizeStatus::too_few_chords;
  std::string message;  ///< why not ok (empty when ok)
  [[nodiscard]] bool ok() const { return status == SizeStatus::ok; }
  SizeDistributionOptions options;

  std::int64_t chords_given = 0;  ///< as passed
  std::int64_t chords_used = 0;   ///< finite and positive
  double mean_chord = 0.0;        ///< of the chords used, m
  /// 1.5 x mean chord, m: d32 for spheres without inverting (METHOD 12).
  double sauter_from_chords = 0.0;

  // Empty or 0 below unless the inversion ran (ok or not_converged).
  std::vector<double> edges;       ///< J + 1 bin edges, m (equal steps in ln D)
  std::vector<double> diameters;   ///< J geometric bin centres, m
  std::vector<double> density;     ///< J: number density n(D) at the centres, 1/m (integrates to 1)
  std::vector<double> cumulative;  ///< J + 1: number fraction below each edge (0 ... 1)
  std::vector<double> pierced;     ///< J: w_j, the fraction of pierced bubbles per bin
  double d10 = 0.0, d20 = 0.0, d30 = 0.0, d32 = 0.0;  ///< m
  double median = 0.0;             ///< number median diameter, m
  int iterations = 0;              ///< EM iterations
  double log_likelihood = 0.0;     ///< sum log f(l_i) of the result (f in 1/m)

  /// The fitted model's chord density f(l), 1/m (0 unless the inversion ran).
  [[nodiscard]] double chord_density(double l) const;
  /// A few readable lines: counts, moments, median, convergence.
  [[nodiscard]] std::string report() const;
};

/// Inverts chord lengths (m; each at its bubble's own velocity where event
/// detection gives one: the caller's choice) into the number distribution
/// of sphere diameters. Non-finite and non-positive chords are not used
/// (counted). Deterministic: the result depends on the multiset of chords
/// only, not their order. Throws OptionError when the options are refused.
SizeDistribution size_distribution(std::span<const double> chord_lengths, const SizeDistributionOptions& options = {});
/// The same from distinct lengths and how often each occurred (any order; a
/// length given twice adds its counts): the identical result as the
/// lengths repeated, without materialising them. Chords of one velocity are
/// whole sample counts times it, so a record's chords repeat a few hundred
/// lengths. chords_given is the sum of the counts. Throws
/// std::invalid_argument for a negative count or spans of different sizes.
SizeDistribution size_distribution(std::span<const double> chord_lengths, std::span<const std::int64_t> counts,
                                   const SizeDistributionOptions& options = {});

}  // namespace awcc
