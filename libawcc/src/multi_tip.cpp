#include "awcc/multi_tip.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "awcc/detail/awcc_steps.hpp"
#include "awcc/detail/multi_tip_steps.hpp"
#include "awcc/errors.hpp"

namespace awcc {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr Vec3 kNaN3{kNaN, kNaN, kNaN};

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Vec3 times(const std::array<Vec3, 3>& m, const Vec3& b) { return {dot(m[0], b), dot(m[1], b), dot(m[2], b)}; }

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

void no_solution(BubbleVector& v, VectorFate fate) {
  v.velocity = v.velocity_spread = v.normal_front = v.normal_rear = kNaN3;
  v.diameter_front = v.diameter_rear = v.area_share = kNaN;
  v.fate = fate;
}

// Running mean and spread of a bubble's combination solutions; deviations
// from the first solution keep the spread exact (0) for equal solutions and
// free of cancellation for nearly equal ones.
struct Combined {
  int count = 0;
  detail::CombinationSolution first{}, sum{};
  Vec3 squares{};
  void add(const detail::CombinationSolution& s) {
    if (count++ == 0) first = s;
    for (std::size_t j = 0; j < 3; ++j) {
      const double d = s.velocity[j] - first.velocity[j];
      sum.velocity[j] += d;
      squares[j] += d * d;
      sum.normal_front[j] += s.normal_front[j];
      sum.normal_rear[j] += s.normal_rear[j];
    }
    sum.diameter_front += s.diameter_front;
    sum.diameter_rear += s.diameter_rear;
    sum.area_share += s.area_share;
  }
  void into(BubbleVector& v) const {
    const double m = count;
    for (std::size_t j = 0; j < 3; ++j) {
      const double mean_d = sum.velocity[j] / m;
      v.velocity[j] = first.velocity[j] + mean_d;
      v.velocity_spread[j] = std::sqrt(std::max(0.0, squares[j] / m - mean_d * mean_d));
    }
    const double nf = std::sqrt(dot(sum.normal_front, sum.normal_front));
    const double nr = std::sqrt(dot(sum.normal_rear, sum.normal_rear));
    for (std::size_t j = 0; j < 3; ++j) {
      v.normal_front[j] = sum.normal_front[j] / nf;
      v.normal_rear[j] = sum.normal_rear[j] / nr;
    }
    v.diameter_front = sum.diameter_front / m;
    v.diameter_rear = sum.diameter_rear / m;
    v.area_share = sum.area_share / m;
  }
};

std::string fate_counts(const MultiTipResult& r) {
  std::string out;
  for (std::size_t f = 0; f < vector_fate_count; ++f) {
    if (r.bubbles_by_fate[f] == 0) continue;
    out += fmt::format("{}{} {}", out.empty() ? "" : ", ", r.bubbles_by_fate[f], vector_fate_names[f]);
  }
  return out.empty() ? std::string("none") : out;
}

}  // namespace

std::string_view to_string(VelocityAlgorithm algorithm) {
  switch (algorithm) {
    case VelocityAlgorithm::shen_nakamura: return "shen-nakamura";
    case VelocityAlgorithm::tian: return "tian";
  }
  return "?";
}

std::string_view to_string(VectorFate fate) { return vector_fate_names[static_cast<std::size_t>(fate)]; }

std::string_view to_string(MultiTipStatus status) {
  switch (status) {
    case MultiTipStatus::ok: return "ok";
    case MultiTipStatus::too_few_bubbles: return "too_few_bubbles";
  }
  return "?";
}

void PiercedBubbles::reserve(std::size_t bubbles) {
  leading.reserve(bubbles);
  trailing.reserve(bubbles * trailing_tips);
}

void PiercedBubbles::add(const Crossing& at_leading, std::span<const std::optional<Crossing>> partners) {
  if (partners.size() != trailing_tips) {
    throw std::invalid_argument(fmt::format("a bubble with {} partners added to bubbles of {} trailing tips",
                                            partners.size(), trailing_tips));
  }
  leading.push_back(at_leading);
  trailing.insert(trailing.end(), partners.begin(), partners.end());
}

Validation MultiTipOptions::validate() const {
  if (!(conditioning_min > 0.0 && conditioning_min <= 1.0)) {
    return Validation::invalid("conditioning-min",
                               fmt::format("conditioning-min = {} must lie in (0, 1]: 0 would solve tips in one plane "
                                           "with the leading tip, and |det A_0| of unit vectors never exceeds 1",
                                           conditioning_min));
  }
  if (vectors_reported < 2) {
    return Validation::invalid("vectors-reported", fmt::format("vectors-reported = {}: a Reynolds stress needs at "
                                                               "least 2 bubbles",
                                                               vectors_reported));
  }
  return {};
}

namespace detail {

bool solve_combination(const TipCombination& c, const Crossing& leading, const std::array<const Crossing*, 3>& trailing,
                       VelocityAlgorithm algorithm, CombinationSolution& out) {
  const double chord0 = leading.rear - leading.front;
  Vec3 front{}, rear{}, b{};
  double scale = std::max(std::fabs(leading.front), std::fabs(leading.rear));
  double largest = 0.0;
  for (std::size_t r = 0; r < 3; ++r) {
    front[r] = trailing[r]->front - leading.front;
    rear[r] = trailing[r]->rear - leading.rear;
    const double mean_lag = 0.5 * (front[r] + rear[r]);
    b[r] = algorithm == VelocityAlgorithm::tian ? mean_lag : mean_lag / c.lengths[r];
    scale = std::max({scale, std::fabs(trailing[r]->front), std::fabs(trailing[r]->rear)});
    largest = std::max(largest, std::fabs(mean_lag));
  }
  // Lags within the rounding of the times themselves carry no direction.
  if (!(largest > 8.0 * std::numeric_limits<double>::epsilon() * scale)) return false;
  const Vec3 w = times(algorithm == VelocityAlgorithm::tian ? c.inverse_offsets : c.inverse_cosines, b);
  const double w2 = dot(w, w);
  if (!(w2 > 0.0) || !std::isfinite(w2)) return false;
  out.velocity = {w[0] / w2, w[1] / w2, w[2] / w2};
  if (!finite(out.velocity)) return false;
  if (algorithm == VelocityAlgorithm::tian) {
    out.diameter_front = out.diameter_rear = out.area_share = kNaN;
    out.normal_front = out.normal_rear = kNaN3;
    return true;
  }
  const double v2 = 1.0 / w2;  // |V|^2
  Vec3 e_front{}, e_rear{};
  for (std::size_t r = 0; r < 3; ++r) {
    const double s = c.lengths[r];
    e_front[r] = v2 * front[r] * (rear[r] + chord0) / s - s;  // Eq. 43
    e_rear[r] = v2 * rear[r] * (front[r] - chord0) / s - s;   // Eq. 44
  }
  const Vec3 dn_front = times(c.inverse_cosines, e_front);  // D n (det B_0j / det A_0)
  const Vec3 dn_rear = times(c.inverse_cosines, e_rear);
  out.diameter_front = std::sqrt(dot(dn_front, dn_front));  // Eq. 50
  out.diameter_rear = std::sqrt(dot(dn_rear, dn_rear));
  if (!(out.diameter_front > 0.0 && std::isfinite(out.diameter_front))) return false;
  if (!(out.diameter_rear > 0.0 && std::isfinite(out.diameter_rear))) return false;
  for (std::size_t j = 0; j < 3; ++j) {  // Eq. 51
    out.normal_front[j] = dn_front[j] / out.diameter_front;
    out.normal_rear[j] = dn_rear[j] / out.diameter_rear;
  }
  out.area_share = w2 * out.diameter_front / std::fabs(dot(w, dn_front));  // Eq. 54
  return out.area_share > 0.0 && std::isfinite(out.area_share);
}

void multi_tip_summarise(MultiTipResult& result, const MultiTipOptions& options) {
  auto& bubbles = result.bubbles;
  std::vector<bool> keep(bubbles.size());
  for (std::size_t i = 0; i < bubbles.size(); ++i) keep[i] = bubbles[i].fate == VectorFate::solved;
  result.roc_passes = 0;
  if (options.roc) {
    std::vector<double> u(bubbles.size());
    for (bool rejected = true; rejected;) {
      rejected = false;
      ++result.roc_passes;
      for (std::size_t j = 0; j < 3; ++j) {
        for (std::size_t i = 0; i < bubbles.size(); ++i) u[i] = bubbles[i].velocity[j];
        const auto before = std::count(keep.begin(), keep.end(), true);
        robust_outlier_cutoff(u, keep);
        if (std::count(keep.begin(), keep.end(), true) != before) rejected = true;
      }
    }
    for (std::size_t i = 0; i < bubbles.size(); ++i)
      if (bubbles[i].fate == VectorFate::solved && !keep[i]) bubbles[i].fate = VectorFate::roc;
  }
  result.bubbles_total = static_cast<std::int64_t>(bubbles.size());
  result.bubbles_by_fate.fill(0);
  for (const auto& b : bubbles) ++result.bubbles_by_fate[static_cast<std::size_t>(b.fate)];
  result.bubbles_accepted = result.count(VectorFate::solved);
  result.velocity = result.velocity_rms = result.turbulence_intensity = {};
  result.reynolds_stress = {};
  result.speed = 0.0;
  result.velocity_ci95 = result.velocity_rms_ci95 = result.turbulence_intensity_ci95 = {};
  result.diameter_front = result.diameter_rear = result.interfacial_area = result.interfacial_area_paired = std::nullopt;
  result.interfacial_area_ci95 = std::nullopt;
  result.caution.clear();
  result.bubbles_complete = result.bubbles_total - result.count(VectorFate::censored);
  if (result.bubbles_accepted < options.vectors_reported) {
    result.status = MultiTipStatus::too_few_bubbles;
    result.message = fmt::format("{} of {} leading bubbles have an accepted velocity vector ({}): too few for "
                                 "statistics (fewer than vectors-reported = {})",
                                 result.bubbles_accepted, result.bubbles_total, fate_counts(result),
                                 options.vectors_reported);
    return;
  }
  // Two passes: the mean, then the fluctuations about it.
  double weights = 0.0;
  Vec3 sum{};
  for (const auto& b : bubbles) {
    if (b.fate != VectorFate::solved) continue;
    weights += b.weight;
    for (std::size_t j = 0; j < 3; ++j) sum[j] += b.weight * b.velocity[j];
  }
  for (std::size_t j = 0; j < 3; ++j) result.velocity[j] = sum[j] / weights;
  std::array<Vec3, 3> stress{};
  double diameter_front = 0.0, diameter_rear = 0.0, shares = 0.0;
  // 1 / |v| of the accepted bubbles: Welford's running mean and sum of
  // squared deviations.
  double slowness = 0.0, slowness_m2 = 0.0;
  std::int64_t slow_count = 0;
  std::vector<double> speeds;
  speeds.reserve(static_cast<std::size_t>(result.bubbles_accepted));
  for (const auto& b : bubbles) {
    if (b.fate != VectorFate::solved) continue;
    speeds.push_back(std::sqrt(dot(b.velocity, b.velocity)));
    const double u = 1.0 / speeds.back();
    const double du = u - slowness;
    slowness += du / static_cast<double>(++slow_count);
    slowness_m2 += du * (u - slowness);
    Vec3 d{};
    for (std::size_t j = 0; j < 3; ++j) d[j] = b.velocity[j] - result.velocity[j];
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t k = j; k < 3; ++k) stress[j][k] += b.weight * d[j] * d[k];
    diameter_front += b.diameter_front;
    diameter_rear += b.diameter_rear;
    shares += b.area_share;
  }
  for (std::size_t j = 0; j < 3; ++j)
    for (std::size_t k = j; k < 3; ++k) result.reynolds_stress[j][k] = result.reynolds_stress[k][j] = stress[j][k] / weights;
  result.speed = std::sqrt(dot(result.velocity, result.velocity));
  const double n = static_cast<double>(result.bubbles_accepted);
  for (std::size_t j = 0; j < 3; ++j) {
    const double rms = std::sqrt(result.reynolds_stress[j][j]);
    const auto intervals = detail::moment_intervals95(result.velocity[j], rms, result.bubbles_accepted, result.speed);
    result.velocity_rms[j] = rms;
    result.turbulence_intensity[j] = intervals.turbulence_intensity;
    result.velocity_ci95[j] = intervals.mean;
    result.velocity_rms_ci95[j] = intervals.rms;
    result.turbulence_intensity_ci95[j] = intervals.tu;
  }
  {
    // a = 4 N_0 m / T and its interval (multi_tip.hpp).
    const double n0 = static_cast<double>(result.bubbles_complete);
    const double a = 4.0 * n0 * slowness / result.record_length;
    const double sample_variance = slowness_m2 / (n - 1.0);
    const double relative = std::sqrt(1.0 / n0 + sample_variance / (n * slowness * slowness));
    result.interfacial_area = a;
    result.interfacial_area_ci95 = Interval95{a * (1.0 - 1.96 * relative), a * (1.0 + 1.96 * relative)};
  }
  {
    // The checks of `caution` (multi_tip.hpp).
    const auto middle = speeds.begin() + static_cast<std::ptrdiff_t>(speeds.size() / 2);
    std::nth_element(speeds.begin(), middle, speeds.end());
    const double tail = slowness * *middle;
    const std::int64_t cut = result.count(VectorFate::roc);
    std::vector<std::string> reasons;
    if (tail > 1.25) {
      reasons.push_back(fmt::format("the mean of 1/|v| is {:.3g} times 1/(median speed), above 1.25: a tail of slow "
                                    "vectors, as mis-paired partners give, rules it",
                                    tail));
    }
    if (2 * cut > cut + result.bubbles_accepted) {
      reasons.push_back(fmt::format("the outlier cutoff rejected {} of {} solved vectors: the accepted ones may be a "
                                    "cluster of mis-paired ones",
                                    cut, cut + result.bubbles_accepted));
    }
    if (20 * result.bubbles_accepted < result.bubbles_complete) {
      reasons.push_back(fmt::format("only {} of {} complete leading bubbles have an accepted vector (below 5 %): where "
                                    "bubbles are this dense the pairing refuses most (ambiguous lag windows) and the "
                                    "few accepted are a selection, some of them mis-paired",
                                    result.bubbles_accepted, result.bubbles_complete));
    }
    for (const auto& r : reasons) result.caution += (result.caution.empty() ? "" : "; ") + r;
    if (!result.caution.empty()) {
      result.caution += "; the vectors and the interfacial area are likely wrong: check the pairing against the truth "
                        "for this geometry (pdp validate)";
    }
  }
  if (options.algorithm == VelocityAlgorithm::shen_nakamura) {
    result.diameter_front = diameter_front / n;
    result.diameter_rear = diameter_rear / n;
    result.interfacial_area_paired = 2.0 * shares / result.record_length;
  }
  result.status = MultiTipStatus::ok;
  result.message.clear();
}

}  // namespace detail

MultiTipResult multi_tip(const ProbeGeometry& geometry, const PiercedBubbles& bubbles, double record_length,
                         const MultiTipOptions& options) {
  options.validate().throw_if_failed();
  geometry.check(options.conditioning_min).throw_if_failed();
  if (!(record_length > 0.0 && std::isfinite(record_length)))
    throw OptionError(fmt::format("record length T = {} s: the interfacial area needs a positive duration", record_length));
  const std::size_t k_tips = geometry.trailing_tips().size();
  if (bubbles.trailing_tips != k_tips || bubbles.trailing.size() != bubbles.size() * k_tips) {
    throw std::invalid_argument(fmt::format("bubbles paired at {} trailing tips ({} partners for {} bubbles) for a "
                                            "probe of {} trailing tips",
                                            bubbles.trailing_tips, bubbles.trailing.size(), bubbles.size(), k_tips));
  }
  MultiTipResult result;
  result.options = options;
  result.record_length = record_length;
  result.leading_tip = geometry.leading();
  result.bubbles.resize(bubbles.size());
  const auto& combinations = geometry.combinations();
  std::vector<const Crossing*> usable(k_tips);
  for (std::size_t h = 0; h < bubbles.size(); ++h) {
    BubbleVector& v = result.bubbles[h];
    const Crossing& lead = bubbles.leading[h];
    v.time = lead.front;
    if (lead.censored) {
      no_solution(v, VectorFate::censored);
      continue;
    }
    int paired = 0;
    double last = lead.rear;
    for (std::size_t k = 0; k < k_tips; ++k) {
      const auto& p = bubbles.partner(h, k);
      usable[k] = nullptr;
      if (!p) continue;
      if (p->censored) {
        ++result.partners_censored;
        continue;
      }
      usable[k] = &*p;
      ++paired;
      last = std::max(last, p->rear);
    }
    v.weight = last - lead.front;
    if (paired < 3) {
      no_solution(v, VectorFate::too_few_tips);
      continue;
    }
    Combined combined;
    int degenerate = 0;
    for (const auto& c : combinations) {
      const std::array<const Crossing*, 3> at{usable[c.trailing[0]], usable[c.trailing[1]], usable[c.trailing[2]]};
      if (!at[0] || !at[1] || !at[2]) continue;
      if (c.conditioning() < options.conditioning_min) {
        ++v.combinations_skipped;
        continue;
      }
      detail::CombinationSolution s;
      if (detail::solve_combination(c, lead, at, options.algorithm, s)) {
        combined.add(s);
      } else {
        ++degenerate;
      }
    }
    result.combinations_ill_conditioned += v.combinations_skipped;
    result.combinations_degenerate += degenerate;
    result.combinations_solved += combined.count;
    v.combinations = combined.count;
    if (combined.count == 0 || !(v.weight > 0.0 && std::isfinite(v.weight))) {
      no_solution(v, degenerate > 0 || combined.count > 0 ? VectorFate::degenerate : VectorFate::ill_conditioned);
      continue;
    }
    combined.into(v);
    v.fate = VectorFate::solved;
  }
  detail::multi_tip_summarise(result, options);
  return result;
}

std::string MultiTipResult::report() const {
  std::string out = fmt::format("multi-tip ({}), leading tip {}, T = {:.6g} s: {} leading bubbles, {} accepted ({})\n",
                                to_string(options.algorithm), leading_tip, record_length, bubbles_total,
                                bubbles_accepted, fate_counts(*this));
  out += fmt::format("combinations of three trailing tips: {} solved, {} skipped below conditioning-min = {:g}, {} "
                     "degenerate; {} paired crossings cut by the record's ends\n",
                     combinations_solved, combinations_ill_conditioned, options.conditioning_min,
                     combinations_degenerate, partners_censored);
  if (!ok()) return out + "no statistics: " + message + "\n";
  if (!caution.empty()) out += "caution: " + caution + "\n";
  static constexpr const char* axis = "xyz";
  out += fmt::format("mean velocity ({:.4g}, {:.4g}, {:.4g}) m/s, |V| = {:.4g} m/s\n", velocity[0], velocity[1],
                     velocity[2], speed);
  for (std::size_t j = 0; j < 3; ++j) {
    out += fmt::format("  V_{} = {:.4g} m/s [{:.4g}, {:.4g}], rms {:.4g} m/s, Tu_{} = {:.4g} [{:.4g}, {:.4g}]\n",
                       axis[j], velocity[j], velocity_ci95[j].lower, velocity_ci95[j].upper, velocity_rms[j], axis[j],
                       turbulence_intensity[j], turbulence_intensity_ci95[j].lower,
                       turbulence_intensity_ci95[j].upper);
  }
  out += "Reynolds stresses (m2/s2):\n";
  for (std::size_t j = 0; j < 3; ++j) {
    out += fmt::format("  {:11.4g} {:11.4g} {:11.4g}\n", reynolds_stress[j][0], reynolds_stress[j][1],
                       reynolds_stress[j][2]);
  }
  if (interfacial_area && interfacial_area_ci95) {
    out += fmt::format("interfacial area {:.4g} 1/m [{:.4g}, {:.4g}] (4 N_0 <1/|v|> / T, N_0 = {} complete leading "
                       "bubbles)\n",
                       *interfacial_area, interfacial_area_ci95->lower, interfacial_area_ci95->upper,
                       bubbles_complete);
  }
  if (interfacial_area_paired && diameter_front && diameter_rear) {
    out += fmt::format("mean diameter {:.4g} mm (front interfaces), {:.4g} mm (rear); interfacial area of the bubbles "
                       "with a vector {:.4g} 1/m (Shen & Nakamura Eq. 54: a lower bound, ",
                       1e3 * *diameter_front, 1e3 * *diameter_rear, *interfacial_area_paired);
    // Spheres pierced off-centre miss the trailing tips first, and those are
    // the ones with the largest 1 / |V . n|: the sum under-counts.
    out += fmt::format("{} of {} complete leading bubbles add nothing to it)\n", bubbles_complete - bubbles_accepted,
                       bubbles_complete);
  } else {
    out += "no sizes or normals: Tian et al. 2015 gives velocities only\n";
  }
  return out;
}

namespace {

// The least conditioning |det A_0| of a combination the pairing's diameter
// check solves through: MultiTipOptions' default (pair_probe does not see
// the solver's options; a combination below it gives no trustworthy D).
constexpr double kPairingConditioning = MultiTipOptions{}.conditioning_min;

// Window of the centre lag to trailing tip k (multi_tip.hpp, pairing).
struct LagWindow {
  double earliest = 0.0, latest = 0.0;  // s, relative to the leading centre
};

LagWindow lag_window(const Vec3& s, double v_ref, const EventOptions& o) {
  constexpr double pi = 3.14159265358979323846;
  const double length = std::sqrt(dot(s, s));
  const double beta = o.probe_angle_max * pi / 180.0;
  const double theta = std::acos(std::clamp(s[0] / length, -1.0, 1.0));  // S_0k against x
  // lag = |S| cos(angle between S and v) / |v|, the angle within theta +/- beta.
  const double near = std::cos(std::max(theta - beta, 0.0));
  const double far = std::cos(std::min(theta + beta, pi));
  LagWindow w;
  w.latest = length * near / ((near > 0.0 ? o.probe_speed_min : o.probe_speed_max) * v_ref);
  w.earliest = length * far / ((far > 0.0 ? o.probe_speed_max : o.probe_speed_min) * v_ref);
  return w;
}

// Whether the slowness w = v / |v|^2 lies in the cone and speed band.
bool in_band(const Vec3& w, double v_ref, double tan_max, const EventOptions& o) {
  const double w2 = dot(w, w);
  if (!(w[0] > 0.0) || !std::isfinite(w2)) return false;
  if (std::hypot(w[1], w[2]) > tan_max * w[0]) return false;
  const double speed = 1.0 / std::sqrt(w2);
  return speed >= o.probe_speed_min * v_ref && speed <= o.probe_speed_max * v_ref;
}

// The joint test of one bubble's unique candidates at the tips in `use`
// (multi_tip.hpp, pairing): the least-squares slowness of their centre lags
// in the band and cone, and every well-conditioned combination's Shen &
// Nakamura diameters alike. False also when no combination of them is well
// conditioned (nothing to test against).
bool one_bubble(const ProbeGeometry& g, const Crossing& lead, const std::vector<const Crossing*>& at,
                const std::vector<bool>& use, double v_ref, double tan_max, const EventOptions& o) {
  // Normal equations (sum S S^T) w = sum S lag; exact for three tips.
  std::array<Vec3, 3> m{};
  Vec3 b{};
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (!use[k]) continue;
    const Vec3 s = g.offset(k);
    const double lag = at[k]->centre() - lead.centre();
    for (std::size_t i = 0; i < 3; ++i) {
      b[i] += s[i] * lag;
      for (std::size_t j = 0; j < 3; ++j) m[i][j] += s[i] * s[j];
    }
  }
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  int tested = 0;
  for (const auto& c : g.combinations()) {
    if (!use[c.trailing[0]] || !use[c.trailing[1]] || !use[c.trailing[2]]) continue;
    if (c.conditioning() < kPairingConditioning) continue;
    ++tested;
    detail::CombinationSolution s;
    const std::array<const Crossing*, 3> three{at[c.trailing[0]], at[c.trailing[1]], at[c.trailing[2]]};
    if (!detail::solve_combination(c, lead, three, VelocityAlgorithm::shen_nakamura, s)) return false;
    const double mean = 0.5 * (s.diameter_front + s.diameter_rear);
    if (std::fabs(s.diameter_front - s.diameter_rear) > o.probe_diameter_mismatch * mean) return false;
  }
  if (tested == 0 || !(det != 0.0)) return false;
  Vec3 w{};
  for (std::size_t i = 0; i < 3; ++i) {
    std::array<Vec3, 3> mi = m;
    for (std::size_t r = 0; r < 3; ++r) mi[r][i] = b[r];
    w[i] = (mi[0][0] * (mi[1][1] * mi[2][2] - mi[1][2] * mi[2][1]) - mi[0][1] * (mi[1][0] * mi[2][2] - mi[1][2] * mi[2][0]) +
            mi[0][2] * (mi[1][0] * mi[2][1] - mi[1][1] * mi[2][0])) /
           det;
  }
  return in_band(w, v_ref, tan_max, o);
}

}  // namespace

ProbePairing pair_probe(const ProbeGeometry& geometry, std::span<const std::vector<Crossing>> tips,
                        const EventOptions& options, std::optional<double> first_velocity) {
  if (tips.size() != geometry.tip_count()) {
    throw std::invalid_argument(fmt::format("pair_probe: {} tips' crossings for a probe of {} tips", tips.size(),
                                            geometry.tip_count()));
  }
  options.validate().throw_if_failed();
  const std::vector<Crossing>& leading = tips[geometry.leading()];
  const std::vector<std::size_t>& trailing = geometry.trailing_tips();
  const std::size_t k_tips = trailing.size();
  ProbePairing out;
  out.bubbles = PiercedBubbles(k_tips);
  if (!first_velocity || !(*first_velocity > 0.0) || !std::isfinite(*first_velocity)) {
    out.status = EventStatus::no_first_velocity;
    out.message = first_velocity
                      ? fmt::format("multi-tip pairing needs a positive first velocity; {} m/s was given",
                                    *first_velocity)
                      : std::string("multi-tip pairing needs a first velocity (FSCC's of the tip pair) for its lag "
                                    "windows, and none was given: the leading tip paired with each trailing tip "
                                    "alone takes unrelated bubbles as partners");
    return out;
  }
  const double v_ref = *first_velocity;
  constexpr double pi = 3.14159265358979323846;
  const double tan_max = std::tan(options.probe_angle_max * pi / 180.0);
  std::vector<LagWindow> windows;
  for (std::size_t k = 0; k < k_tips; ++k) windows.push_back(lag_window(geometry.offset(k), v_ref, options));

  // Per bubble and tip: the chosen candidate (an index) and the fate.
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  std::vector<std::size_t> chosen(leading.size() * k_tips, none);
  std::vector<BubbleFate> fate(leading.size() * k_tips, BubbleFate::no_partner);
  std::vector<std::size_t> first(k_tips, 0);  // first crossing not before the window, per tip
  std::vector<const Crossing*> at(k_tips);
  std::vector<bool> use(k_tips);
  for (std::size_t h = 0; h < leading.size(); ++h) {
    const Crossing& a = leading[h];
    std::size_t present = 0;
    for (std::size_t k = 0; k < k_tips; ++k) {
      const std::vector<Crossing>& c = tips[trailing[k]];
      // Window starts increase with h (leading centres do): one pass a tip.
      std::size_t& j = first[k];
      while (j < c.size() && c[j].centre() < a.centre() + windows[k].earliest) ++j;
      std::size_t n = 0;
      while (j + n < c.size() && n < 2 && c[j + n].centre() <= a.centre() + windows[k].latest) ++n;
      const std::size_t i = h * k_tips + k;
      at[k] = nullptr;
      use[k] = false;
      if (a.censored) {
        fate[i] = BubbleFate::censored;
      } else if (n == 0) {
        fate[i] = BubbleFate::no_partner;
      } else if (n > 1) {
        fate[i] = BubbleFate::ambiguous;
      } else if (c[j].censored) {
        fate[i] = BubbleFate::censored;
      } else {
        fate[i] = BubbleFate::paired;
        chosen[i] = j;
        at[k] = &c[j];
        use[k] = true;
        ++present;
      }
    }
    // Fewer than three: no vector, nothing to test them against; listed.
    if (present < 3 || one_bubble(geometry, a, at, use, v_ref, tan_max, options)) continue;
    // More than three: the one tip whose removal leaves one bubble, if
    // exactly one does.
    std::optional<std::size_t> drop;
    int drops = 0;
    for (std::size_t k = 0; present > 3 && k < k_tips; ++k) {
      if (!use[k]) continue;
      use[k] = false;
      if (one_bubble(geometry, a, at, use, v_ref, tan_max, options)) {
        drop = k;
        ++drops;
      }
      use[k] = true;
    }
    for (std::size_t k = 0; k < k_tips; ++k) {
      const std::size_t i = h * k_tips + k;
      if (!use[k] || (drops == 1 && k != *drop)) continue;
      fate[i] = BubbleFate::inconsistent;
      chosen[i] = none;
    }
  }
  // A trailing crossing chosen by two leading bubbles: neither keeps it (at
  // most one is its bubble, and the times do not say which). Choices never
  // decrease with h, so the claims on one crossing are consecutive.
  for (std::size_t k = 0; k < k_tips; ++k) {
    std::size_t previous = none;
    for (std::size_t h = 0; h < leading.size(); ++h) {
      const std::size_t i = h * k_tips + k;
      if (chosen[i] == none) continue;
      if (previous != none && chosen[previous * k_tips + k] == chosen[i]) {
        fate[previous * k_tips + k] = fate[i] = BubbleFate::claimed_twice;
      }
      previous = h;
    }
    for (std::size_t h = 0; h < leading.size(); ++h) {
      const std::size_t i = h * k_tips + k;
      if (fate[i] == BubbleFate::claimed_twice) chosen[i] = none;
    }
  }
  out.fates.assign(k_tips, {});
  out.bubbles.reserve(leading.size());
  std::vector<std::optional<Crossing>> partners(k_tips);
  for (std::size_t h = 0; h < leading.size(); ++h) {
    for (std::size_t k = 0; k < k_tips; ++k) {
      const std::size_t i = h * k_tips + k;
      ++out.fates[k][static_cast<std::size_t>(fate[i])];
      partners[k].reset();
      if (chosen[i] != none) partners[k] = tips[trailing[k]][chosen[i]];
    }
    out.bubbles.add(leading[h], partners);
  }
  return out;
}

}  // namespace awcc
