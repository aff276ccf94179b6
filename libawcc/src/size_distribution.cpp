#include "awcc/size_distribution.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace awcc {

namespace {

// Per bin: what K_j(l) needs.
struct Bin {
  double a, b, inv_a, inv_b, scale;  // scale = 2 / (b - a)
  [[nodiscard]] double kernel(double l) const {
    if (!(l < b)) return 0.0;
    return l <= a ? scale * l * (inv_a - inv_b) : scale * (1.0 - l * inv_b);
  }
};

double log_sum_exp(const std::vector<double>& beta) {
  const double m = *std::max_element(beta.begin(), beta.end());
  double s = 0.0;
  for (double x : beta) s += std::exp(x - m);
  return m + std::log(s);
}

// Solves H x = g in place (H symmetric positive definite, n x n row-major)
// by Eigen's Cholesky (LLT); false when H is not numerically positive definite.
bool cholesky_solve(const std::vector<double>& H, std::vector<double>& g, std::size_t n) {
  const auto size = static_cast<Eigen::Index>(n);
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> matrix(H.data(), size,
                                                                                                        size);
  const Eigen::LLT<Eigen::MatrixXd> llt(matrix);
  if (llt.info() != Eigen::Success) return false;
  Eigen::Map<Eigen::VectorXd> x(g.data(), size);
  x = llt.solve(x);
  return true;
}

// The chords as distinct values (ascending) with their multiplicities:
// chord times are whole samples, so a single velocity repeats lengths.
struct Chords {
  std::vector<double> value;
  std::vector<double> count;
  double total = 0.0;
};

Chords distinct(std::vector<double> sorted) {
  Chords c;
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t k = i;
    while (k < sorted.size() && sorted[k] == sorted[i]) ++k;
    c.value.push_back(sorted[i]);
    c.count.push_back(static_cast<double>(k - i));
    i = k;
  }
  c.total = static_cast<double>(sorted.size());
  return c;
}

}  // namespace

std::string_view to_string(SizeStatus status) {
  switch (status) {
    case SizeStatus::ok: return "ok";
    case SizeStatus::too_few_chords: return "too_few_chords";
    case SizeStatus::not_converged: return "not_converged";
  }
  return "?";
}

double bin_chord_density(double l, double a, double b) {
  if (!(l > 0.0)) return 0.0;
  const Bin bin{a, b, 1.0 / a, 1.0 / b, 2.0 / (b - a)};
  return bin.kernel(l);
}

Validation SizeDistributionOptions::validate() const {
  if (!(bin_width > 0.0 && bin_width <= 0.5)) {
    return Validation::invalid("size-bin-width",
                               fmt::format("size-bin-width = {} must lie in (0, 0.5]: the width of a diameter bin in "
                                           "ln D (0.05 = 5 % steps)",
                                           bin_width));
  }
  if (!(floor_quantile >= 0.0 && floor_quantile < 0.5)) {
    return Validation::invalid("size-floor-quantile",
                               fmt::format("size-floor-quantile = {} must lie in [0, 0.5): the chord quantile where the "
                                           "diameter grid starts",
                                           floor_quantile));
  }
  if (floor_rank_min < 1) {
    return Validation::invalid("size-floor-rank-min",
                               fmt::format("size-floor-rank-min = {} must be at least 1 (the shortest chord)",
                                           floor_rank_min));
  }
  if (!(ceiling_factor >= 1.0) || !std::isfinite(ceiling_factor)) {
    return Validation::invalid("size-ceiling-factor",
                               fmt::format("size-ceiling-factor = {} must be at least 1: no bubble is smaller than the "
                                           "longest chord it gave",
                                           ceiling_factor));
  }
  if (!(penalty > 0.0) || !std::isfinite(penalty)) {
    return Validation::invalid("size-penalty",
                               fmt::format("size-penalty = {} must be positive: without it the inversion puts most "
                                           "bubbles at the shortest chords",
                                           penalty));
  }
  if (chords_min < std::max(floor_rank_min, 10)) {
    return Validation::invalid("size-chords-min",
                               fmt::format("size-chords-min = {} must be at least 10 and at least size-floor-rank-min "
                                           "= {}",
                                           chords_min, floor_rank_min));
  }
  if (iterations_max < 1) {
    return Validation::invalid("size-iterations-max", fmt::format("size-iterations-max = {} must be at least 1",
                                                                  iterations_max));
  }
  if (!(tolerance > 0.0)) {
    return Validation::invalid("size-tolerance", fmt::format("size-tolerance = {} must be positive", tolerance));
  }
  if (bins_max < 4) {
    return Validation::invalid("size-bins-max",
                               fmt::format("size-bins-max = {} must be at least 4: the penalty takes third differences",
                                           bins_max));
  }
  return {};
}

double SizeDistribution::chord_density(double l) const {
  double f = 0.0;
  for (std::size_t j = 0; j < pierced.size(); ++j) f += pierced[j] * bin_chord_density(l, edges[j], edges[j + 1]);
  return f;
}

std::string SizeDistribution::report() const {
  std::string out = fmt::format("bubble sizes from chord lengths: {} chords given, {} used, mean chord {:.4g} mm, "
                                "1.5 x mean chord {:.4g} mm\n",
                                chords_given, chords_used, 1e3 * mean_chord, 1e3 * sauter_from_chords);
  if (status == SizeStatus::too_few_chords) return out + "no distribution: " + message + "\n";
  if (status == SizeStatus::not_converged) out += "caution: " + message + "\n";
  out += fmt::format("number distribution on {} bins {:.4g}-{:.4g} mm: median {:.4g} mm, d10 {:.4g} mm, d20 {:.4g} mm, "
                     "d30 {:.4g} mm, d32 {:.4g} mm\n",
                     diameters.size(), 1e3 * edges.front(), 1e3 * edges.back(), 1e3 * median, 1e3 * d10, 1e3 * d20,
                     1e3 * d30, 1e3 * d32);
  out += fmt::format("penalised EM (penalty {:g}): {} iterations, log-likelihood {:.6g}\n", options.penalty, iterations,
                     log_likelihood);
  return out;
}

namespace {

SizeDistribution invert(Chords chords, std::int64_t given, const SizeDistributionOptions& options);

}  // namespace

SizeDistribution size_distribution(std::span<const double> chord_lengths, const SizeDistributionOptions& options) {
  options.validate().throw_if_failed();
  std::vector<double> sorted;
  sorted.reserve(chord_lengths.size());
  for (double l : chord_lengths) {
    if (std::isfinite(l) && l > 0.0) sorted.push_back(l);
  }
  std::sort(sorted.begin(), sorted.end());
  return invert(distinct(std::move(sorted)), static_cast<std::int64_t>(chord_lengths.size()), options);
}

SizeDistribution size_distribution(std::span<const double> chord_lengths, std::span<const std::int64_t> counts,
                                   const SizeDistributionOptions& options) {
  options.validate().throw_if_failed();
  if (counts.size() != chord_lengths.size()) {
    throw std::invalid_argument(fmt::format("size_distribution: {} chord lengths but {} counts", chord_lengths.size(),
                                            counts.size()));
  }
  std::vector<std::pair<double, std::int64_t>> pairs;
  std::int64_t given = 0;
  for (std::size_t i = 0; i < chord_lengths.size(); ++i) {
    if (counts[i] < 0) throw std::invalid_argument(fmt::format("size_distribution: count {} is negative", counts[i]));
    given += counts[i];
    if (counts[i] > 0 && std::isfinite(chord_lengths[i]) && chord_lengths[i] > 0.0) {
      pairs.emplace_back(chord_lengths[i], counts[i]);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  Chords c;
  std::int64_t total = 0;
  for (const auto& [l, n] : pairs) {
    if (c.value.empty() || c.value.back() != l) {
      c.value.push_back(l);
      c.count.push_back(0.0);
    }
    c.count.back() += static_cast<double>(n);  // whole numbers below 2^53: exact, as distinct() counts them
    total += n;
  }
  c.total = static_cast<double>(total);
  return invert(std::move(c), given, options);
}

namespace {

SizeDistribution invert(Chords chords, std::int64_t given, const SizeDistributionOptions& options) {
  SizeDistribution r;
  r.options = options;
  r.chords_given = given;
  r.chords_used = static_cast<std::int64_t>(chords.total);
  if (r.chords_used > 0) {
    double s = 0.0;
    for (std::size_t i = 0; i < chords.value.size(); ++i) s += chords.count[i] * chords.value[i];  // ascending
    r.mean_chord = s / chords.total;
    r.sauter_from_chords = 1.5 * r.mean_chord;
  }
  if (r.chords_used < options.chords_min) {
    r.status = SizeStatus::too_few_chords;
    r.message = fmt::format("{} usable chords ({} given), fewer than size-chords-min = {}: the number distribution "
                            "would be mostly the penalty's log-normal shape (its median spreads by 16-34 % over "
                            "draws at 50 chords); 1.5 x mean chord = {:.4g} mm is d32 without inversion",
                            r.chords_used, r.chords_given, options.chords_min, 1e3 * r.sauter_from_chords);
    return r;
  }

  // The grid (options' why).
  const auto n = static_cast<std::size_t>(r.chords_used);
  const auto floor_rank = std::min(n, std::max<std::size_t>(
      static_cast<std::size_t>(options.floor_rank_min),
      static_cast<std::size_t>(std::ceil(options.floor_quantile * static_cast<double>(n)))));
  double lo = chords.value.back();  // the floor_rank-th shortest chord
  {
    double below = 0.0;
    for (std::size_t i = 0; i < chords.value.size(); ++i) {
      below += chords.count[i];
      if (below >= static_cast<double>(floor_rank)) {
        lo = chords.value[i];
        break;
      }
    }
  }
  const double hi = options.ceiling_factor * chords.value.back();
  const double span = std::log(hi / lo);
  auto bins = static_cast<std::size_t>(std::ceil(span / options.bin_width - 1e-9));
  bins = std::clamp<std::size_t>(bins, 4, static_cast<std::size_t>(options.bins_max));
  const double h = span > 0.0 ? span / static_cast<double>(bins) : options.bin_width;
  r.edges.resize(bins + 1);
  for (std::size_t j = 0; j <= bins; ++j) r.edges[j] = lo * std::exp(h * static_cast<double>(j));
  if (span <= 0.0) {  // every usable chord above the floor is the same: centre the grid on it
    for (std::size_t j = 0; j <= bins; ++j) r.edges[j] = lo * std::exp(h * (static_cast<double>(j) - 0.5 * static_cast<double>(bins)));
  }
  r.edges.back() = std::max(r.edges.back(), hi);
  std::vector<Bin> bin(bins);
  for (std::size_t j = 0; j < bins; ++j) {
    const double a = r.edges[j], b = r.edges[j + 1];
    bin[j] = {a, b, 1.0 / a, 1.0 / b, 2.0 / (b - a)};
  }

  const std::size_t m = chords.value.size();
  const double N = chords.total;
  // K_j(l) is l alpha_j (alpha_j = scale_j (1 / a_j - 1 / b_j)) for l <= a_j,
  // scale_j (1 - l / b_j) inside (a_j, b_j), 0 from b_j on. With the chords
  // and the bins both ascending, f(l_i) = l_i sum_{a_j >= l_i} w_j alpha_j
  // plus the one bin holding l_i, and the E-step's sums split the same way:
  // O(chords + bins) an iteration instead of O(chords x bins), which
  // matters where every chord has its own velocity (all lengths distinct).
  std::vector<double> alpha(bins);
  for (std::size_t j = 0; j < bins; ++j) alpha[j] = bin[j].scale * (bin[j].inv_a - bin[j].inv_b);
  // Per chord: the first bin with a_j >= l_i (bins when none), and the bin
  // holding l_i strictly inside (a_j, b_j), or bins when none.
  std::vector<std::size_t> first_above(m), inside(m);
  for (std::size_t i = 0; i < m; ++i) {
    const double l = chords.value[i];
    const auto k = static_cast<std::size_t>(std::lower_bound(r.edges.begin(), r.edges.end() - 1, l) - r.edges.begin());
    first_above[i] = k;
    inside[i] = (k > 0 && l > bin[k - 1].a && l < bin[k - 1].b) ? k - 1 : bins;
  }
  // Chords (a prefix of the ascending list) at or below each bin's lower edge.
  std::vector<std::size_t> at_or_below(bins);
  for (std::size_t j = 0; j < bins; ++j) {
    at_or_below[j] = static_cast<std::size_t>(std::upper_bound(chords.value.begin(), chords.value.end(), bin[j].a) -
                                              chords.value.begin());
  }
  std::vector<double> suffix(bins + 1), prefix(m + 1), in_bin(bins);

  // P = (lambda / h^5) D3' D3 + (N / J^2) 1 1'.
  const double weight = options.penalty / std::pow(h, 5);
  std::vector<double> P(bins * bins, N / (static_cast<double>(bins) * static_cast<double>(bins)));
  static constexpr double d3[4] = {-1.0, 3.0, -3.0, 1.0};
  for (std::size_t row = 0; row + 3 < bins; ++row) {
    for (std::size_t p = 0; p < 4; ++p) {
      for (std::size_t q = 0; q < 4; ++q) P[(row + p) * bins + row + q] += weight * d3[p] * d3[q];
    }
  }
  const auto quad = [&](const std::vector<double>& beta) {
    double s = 0.0;
    for (std::size_t i = 0; i < bins; ++i) {
      double t = 0.0;
      for (std::size_t k = 0; k < bins; ++k) t += P[i * bins + k] * beta[k];
      s += beta[i] * t;
    }
    return 0.5 * s;
  };

  std::vector<double> beta(bins, 0.0), w(bins, 1.0 / static_cast<double>(bins)), f(m), c(bins);
  const auto mixture = [&] {  // f_i = sum_j w_j K_j(l_i); returns sum count_i log f_i
    suffix[bins] = 0.0;
    for (std::size_t j = bins; j-- > 0;) suffix[j] = suffix[j + 1] + w[j] * alpha[j];
    for (std::size_t i = 0; i < m; ++i) {
      const double l = chords.value[i];
      f[i] = l * suffix[first_above[i]];
      if (const std::size_t j = inside[i]; j < bins) f[i] += w[j] * bin[j].scale * (1.0 - l * bin[j].inv_b);
    }
    double ll = 0.0;
    for (std::size_t i = 0; i < m; ++i) ll += chords.count[i] * std::log(f[i]);
    return ll;
  };
  const auto softmax = [&] {
    const double z = log_sum_exp(beta);
    for (std::size_t j = 0; j < bins; ++j) w[j] = std::exp(beta[j] - z);
  };

  double objective = mixture() - quad(beta);
  r.status = SizeStatus::not_converged;
  for (int it = 1; it <= options.iterations_max; ++it) {
    r.iterations = it;
    // E-step: expected chords per bin.
    prefix[0] = 0.0;
    std::fill(in_bin.begin(), in_bin.end(), 0.0);
    for (std::size_t i = 0; i < m; ++i) {
      const double l = chords.value[i], weight_i = chords.count[i] / f[i];
      prefix[i + 1] = prefix[i] + weight_i * l;
      if (const std::size_t j = inside[i]; j < bins) in_bin[j] += weight_i * (1.0 - l * bin[j].inv_b);
    }
    for (std::size_t j = 0; j < bins; ++j) {
      c[j] = w[j] * (alpha[j] * prefix[at_or_below[j]] + bin[j].scale * in_bin[j]);
    }
    // M-step: Newton on Q(beta) = c . beta - N lse(beta) - beta' P beta / 2 (concave).
    const auto Q = [&](const std::vector<double>& b) {
      double s = 0.0;
      for (std::size_t j = 0; j < bins; ++j) s += c[j] * b[j];
      return s - N * log_sum_exp(b) - quad(b);
    };
    double q = Q(beta);
    for (int newton = 0; newton < 30; ++newton) {
      softmax();
      std::vector<double> g(bins), H(P);
      for (std::size_t j = 0; j < bins; ++j) {
        double pb = 0.0;
        for (std::size_t k = 0; k < bins; ++k) pb += P[j * bins + k] * beta[k];
        g[j] = c[j] - N * w[j] - pb;
        for (std::size_t k = 0; k < bins; ++k) H[j * bins + k] += N * ((j == k ? w[j] : 0.0) - w[j] * w[k]);
      }
      if (!cholesky_solve(H, g, bins)) break;  // g now holds the step
      std::vector<double> trial(bins);
      double t = 1.0, q_trial = -std::numeric_limits<double>::infinity();
      for (; t > 1e-6; t *= 0.5) {
        for (std::size_t j = 0; j < bins; ++j) trial[j] = beta[j] + t * g[j];
        q_trial = Q(trial);
        if (q_trial >= q) break;
      }
      if (!(q_trial >= q)) break;
      beta = trial;
      const double rise = q_trial - q;
      q = q_trial;
      if (rise < 1e-10 * N) break;
    }
    softmax();
    const double next = mixture() - quad(beta);
    const double rise = next - objective;
    objective = next;
    if (rise < options.tolerance * N) {
      r.status = SizeStatus::ok;
      break;
    }
  }
  if (r.status == SizeStatus::not_converged) {
    r.message = fmt::format("the penalised EM did not converge in size-iterations-max = {} iterations: the values are "
                            "the last iterate's",
                            options.iterations_max);
  }

  // The distribution and its moments, exact for the piecewise model.
  r.pierced = w;
  r.log_likelihood = mixture();
  double M0 = 0.0, M1 = 0.0, M2 = 0.0, M3 = 0.0;
  std::vector<double> number(bins);
  for (std::size_t j = 0; j < bins; ++j) {
    const double a = bin[j].a, b = bin[j].b, u = w[j] / (b - a);
    number[j] = u * (1.0 / a - 1.0 / b);
    M0 += number[j];
    M1 += u * std::log(b / a);
    M2 += w[j];
    M3 += u * 0.5 * (b * b - a * a);
  }
  r.d10 = M1 / M0;
  r.d20 = std::sqrt(M2 / M0);
  r.d30 = std::cbrt(M3 / M0);
  r.d32 = M3 / M2;
  r.diameters.resize(bins);
  r.density.resize(bins);
  r.cumulative.assign(bins + 1, 0.0);
  for (std::size_t j = 0; j < bins; ++j) {
    const double a = bin[j].a, b = bin[j].b, d = std::sqrt(a * b);
    r.diameters[j] = d;
    r.density[j] = w[j] / ((b - a) * d * d) / M0;
    r.cumulative[j + 1] = r.cumulative[j] + number[j] / M0;
  }
  r.cumulative.back() = 1.0;
  for (std::size_t j = 0; j < bins; ++j) {
    if (r.cumulative[j + 1] >= 0.5) {
      // Within the bin: C(D) = C(a) + w / (b - a) (1 / a - 1 / D) / M0.
      const double a = bin[j].a, b = bin[j].b;
      r.median = 1.0 / (1.0 / a - (0.5 - r.cumulative[j]) * M0 * (b - a) / w[j]);
      r.median = std::clamp(r.median, a, b);
      break;
    }
  }
  return r;
}

}  // namespace

}  // namespace awcc
