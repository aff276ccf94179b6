#include "awcc/profile_flow.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "awcc/order_statistics.hpp"
#include "awcc/random.hpp"

namespace awcc {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kY90Level = 0.9;
constexpr double kZ975 = 1.959963984540054;  // Phi^-1(0.975)
// Most draws a quantity may lack and still have an interval (header).
constexpr double kUndefinedShareMax = 0.01;
// The scan of ln D for the concentration models (header): [1e-3, 1e2] in 40
// steps of a factor 1.33, then golden section over the two steps around the
// best point. 50 golden steps shrink that bracket (0.58 in ln D) by 0.618^50
// = 4e-11.
constexpr double kDiffusivityMin = 1e-3, kDiffusivityMax = 1e2;
constexpr int kScanSteps = 40, kGoldenSteps = 50;

bool is_finite(double x) { return std::isfinite(x); }

// Phi^-1(p) for p in (0, 1): Acklam's rational approximation (relative error
// 1.15e-9) and one Halley step on erfc, which brings it to rounding.
double normal_quantile(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                                 1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                 6.680131188771972e+01,  -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                 -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                 3.754408661907416e+00};
  constexpr double low = 0.02425;
  double x;
  if (p < low) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p <= 1 - low) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  } else {
    const double q = std::sqrt(-2 * std::log(1 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2 * std::numbers::pi) * std::exp(x * x / 2);
  return x - u / (1 + x * u / 2);
}

// A row's value as knots (normal score, value) of its inverse distribution
// function (header): three for an interval, one per quantile.
struct Knots {
  std::vector<double> z, v;
  [[nodiscard]] double at(double score) const {
    std::size_t j = 1;
    while (j + 1 < z.size() && score > z[j]) ++j;
    // Segment [j-1, j]; the end segments extend beyond the knots.
    return v[j - 1] + (score - z[j - 1]) * (v[j] - v[j - 1]) / (z[j] - z[j - 1]);
  }
};

Knots interval_knots(double value, const Interval95& ci) {
  return {{-kZ975, 0.0, kZ975}, {ci.lower, value, ci.upper}};
}

Knots quantile_knots(const std::vector<VelocityQuantile>& quantiles) {
  Knots k;
  for (const auto& q : quantiles) {
    k.z.push_back(normal_quantile(q.probability));
    k.v.push_back(q.value);
  }
  return k;
}

// Trapezoidal rule through (x_i, f_i).
double trapezoid(std::span<const double> x, std::span<const double> f) {
  double sum = 0.0;
  for (std::size_t i = 1; i < x.size(); ++i) sum += 0.5 * (f[i] + f[i - 1]) * (x[i] - x[i - 1]);
  return sum;
}

double model_c(ConcentrationModelKind kind, double diffusivity, double y_rel) {
  const double a = std::atanh(std::sqrt(0.1));
  if (kind == ConcentrationModelKind::smooth_chute) {
    const double t = std::tanh(a + 1.0 / (2 * diffusivity) - y_rel / (2 * diffusivity));
    return 1.0 - t * t;
  }
  const double s = y_rel - 1.0 / 3.0;
  const double k = a + 1.0 / (2 * diffusivity) - 8.0 / (81 * diffusivity);
  const double t = std::tanh(k - y_rel / (2 * diffusivity) + s * s * s / (3 * diffusivity));
  return 1.0 - t * t;
}

double sum_of_squares(ConcentrationModelKind kind, double ln_d, std::span<const double> y_rel,
                      std::span<const double> c) {
  const double diffusivity = std::exp(ln_d);
  double s = 0.0;
  for (std::size_t i = 0; i < y_rel.size(); ++i) {
    const double r = c[i] - model_c(kind, diffusivity, y_rel[i]);
    s += r * r;
  }
  return s;
}

struct ModelFit {
  double diffusivity = kNaN, residual = kNaN;
  bool at_edge = false;
};

ModelFit fit_model(ConcentrationModelKind kind, std::span<const double> y_rel, std::span<const double> c) {
  const double lo = std::log(kDiffusivityMin), step = (std::log(kDiffusivityMax) - lo) / kScanSteps;
  int best = 0;
  double best_s = std::numeric_limits<double>::infinity();
  for (int j = 0; j <= kScanSteps; ++j) {
    const double s = sum_of_squares(kind, lo + j * step, y_rel, c);
    if (s < best_s) best_s = s, best = j;
  }
  ModelFit out;
  if (best == 0 || best == kScanSteps) {
    out.at_edge = true;
    return out;
  }
  constexpr double g = 0.6180339887498949;
  double a = lo + (best - 1) * step, b = lo + (best + 1) * step;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = sum_of_squares(kind, x1, y_rel, c), f2 = sum_of_squares(kind, x2, y_rel, c);
  for (int k = 0; k < kGoldenSteps; ++k) {
    if (f1 <= f2) {
      b = x2, x2 = x1, f2 = f1;
      x1 = b - g * (b - a);
      f1 = sum_of_squares(kind, x1, y_rel, c);
    } else {
      a = x1, x1 = x2, f1 = f2;
      x2 = a + g * (b - a);
      f2 = sum_of_squares(kind, x2, y_rel, c);
    }
  }
  const double ln_d = f1 <= f2 ? x1 : x2;
  out.diffusivity = std::exp(ln_d);
  out.residual = std::sqrt(std::min(f1, f2) / static_cast<double>(y_rel.size()));
  return out;
}

constexpr double kGravity = 9.80665;  // standard gravity, m/s2
const std::string no_chute_angle =
    "no chute angle given (option chute-angle): H_res = d cos(theta) + q_w^2 / (2 g d^2) needs it";

// Every quantity from one set of row values (the rows' own, or one draw).
// `why_*` are written only when `explain` (the point estimate): the draws
// need the numbers alone.
struct Evaluation {
  CharacteristicDepth y90;
  std::vector<CharacteristicDepth> levels;
  double c_mean = kNaN, clear_water_depth = kNaN;
  double n = kNaN, u90 = kNaN, power_residual = kNaN;
  int power_points = 0;
  double q_w = kNaN, q_a = kNaN, continuity = kNaN, residual_head = kNaN;
  std::array<ModelFit, 2> models{};
  int model_points = 0;
  std::string why_y90, why_c_mean, why_power, why_discharge, why_continuity, why_residual_head;
  std::array<std::string, 2> why_model;
};

std::string row_name(const ProfileRow& row, std::size_t input_index) {
  return row.name.empty() ? fmt::format("row {}", input_index + 1) : row.name;
}

class Evaluator {
 public:
  Evaluator(const std::vector<ProfileRow>& rows, const std::vector<std::size_t>& input_index,
            const ProfileFlowOptions& options)
      : rows_(rows), input_index_(input_index), options_(options) {
    for (const auto& r : rows) y_.push_back(r.y);
  }

  Evaluation operator()(std::span<const double> c, std::span<const double> u, bool explain) const {
    Evaluation e;
    e.y90 = characteristic_depth(y_, c, kY90Level);
    for (double level : options_.levels) e.levels.push_back(characteristic_depth(y_, c, level));
    if (e.y90.status != DepthStatus::ok) {
      if (explain) {
        const std::string why = e.y90.status == DepthStatus::not_reached
                                    ? fmt::format("no Y90: {}", e.y90.message)
                                    : fmt::format("Y90 is only bounded: {}", e.y90.message);
        e.why_y90 = e.why_c_mean = e.why_power = e.why_discharge = e.why_continuity = why;
        e.why_residual_head = options_.chute_angle ? why : no_chute_angle;
        e.why_model = {why, why};
      }
      return e;
    }
    const double y90 = *e.y90.y;
    // k: the first row reaching 0.9; rows 0..k-1 lie below Y90, row k at or above it.
    std::size_t k = 0;
    while (c[k] < kY90Level) ++k;
    const bool exact = y_[k] == y90;
    const std::size_t top = exact ? k + 1 : k;  // rows [0, top) have 0 <= y <= Y90
    const double y0 = y_[0];

    // C_mean and d.
    std::vector<double> px(y_.begin(), y_.begin() + static_cast<std::ptrdiff_t>(k)),
        pc(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(k));
    px.push_back(y90);
    pc.push_back(kY90Level);
    double integral = trapezoid(px, pc), span = y90;
    if (options_.invert == InvertRule::held) integral += c[0] * y0;
    if (options_.invert == InvertRule::left_out) span = y90 - y0;
    if (span > 0.0) {
      e.c_mean = integral / span;
      e.clear_water_depth = (1.0 - e.c_mean) * y90;
    } else if (explain) {
      e.why_c_mean = fmt::format("Y90 is the first position (y = {:.6g} m) and the layer below it is left out: "
                                 "nothing to average",
                                 y0);
    }

    // The power law over 0 < y <= Y90.
    std::vector<std::string> without_u;
    {
      double sx = 0, sz = 0, sxx = 0, sxz = 0, szz = 0;
      int m = 0;
      std::string bad;
      for (std::size_t i = 0; i < top; ++i) {
        if (!(y_[i] > 0.0)) continue;
        if (!is_finite(u[i])) {
          if (explain) without_u.push_back(name(i));
          continue;
        }
        if (!(u[i] > 0.0)) {
          if (explain && bad.empty()) bad = fmt::format("u = {:.6g} m/s at {} has no logarithm", u[i], name(i));
          m = -1;
          break;
        }
        const double x = std::log(y_[i] / y90), z = std::log(u[i]);
        sx += x, sz += z, sxx += x * x, sxz += x * z, szz += z * z;
        ++m;
      }
      e.power_points = std::max(m, 0);
      if (m >= 2) {
        const double mean_x = sx / m, mean_z = sz / m;
        const double cxx = sxx - m * mean_x * mean_x, cxz = sxz - m * mean_x * mean_z;
        const double b = cxz / cxx, a = mean_z - b * mean_x;
        if (b > 0.0) {
          e.n = 1.0 / b;
          e.u90 = std::exp(a);
          // Residuals from the centred sums: sum (z - a - b x)^2 = Czz - b Cxz.
          const double czz = szz - m * mean_z * mean_z;
          e.power_residual = std::sqrt(std::max(czz - b * cxz, 0.0) / m);
        } else if (explain) {
          e.why_power =
              fmt::format("the velocity does not grow with y below Y90 (slope 1/N = {:.4g}): no power law", b);
        }
      } else if (explain) {
        e.why_power = m < 0 ? bad
                            : fmt::format("{} row(s) with a velocity and 0 < y <= Y90 = {:.6g} m: a power law needs two",
                                          m, y90);
      }
      if (explain && !without_u.empty() && e.why_power.empty()) {
        e.why_power = fmt::format("rows without a velocity left out: {}", fmt::join(without_u, ", "));
      }
    }

    // Discharges.
    {
      std::string missing;
      for (std::size_t i = 0; i <= k && missing.empty(); ++i) {
        if (!is_finite(u[i])) missing = name(i);
      }
      const bool needs_law = y0 > 0.0 && options_.invert != InvertRule::left_out;
      if (!missing.empty()) {
        if (explain) {
          e.why_discharge = fmt::format("{} has no velocity: every row up to the one bracketing Y90 needs one", missing);
        }
      } else if (needs_law && !is_finite(e.n)) {
        if (explain) {
          e.why_discharge = fmt::format("the layer below the first position (y = {:.6g} m) takes the power law, and "
                                        "there is none: {}",
                                        y0, e.why_power);
        }
      } else {
        const double u_top =
            exact ? u[k] : u[k - 1] + (y90 - y_[k - 1]) / (y_[k] - y_[k - 1]) * (u[k] - u[k - 1]);
        std::vector<double> gw, ga;
        for (std::size_t i = 0; i < k; ++i) {
          gw.push_back((1.0 - c[i]) * u[i]);
          ga.push_back(c[i] * u[i]);
        }
        gw.push_back((1.0 - kY90Level) * u_top);
        ga.push_back(kY90Level * u_top);
        e.q_w = trapezoid(px, gw);
        e.q_a = trapezoid(px, ga);
        if (needs_law) {
          const double layer = e.u90 * y90 * e.n / (e.n + 1.0) * std::pow(y0 / y90, (e.n + 1.0) / e.n);
          const double c_below = options_.invert == InvertRule::held ? c[0] : 0.0;
          e.q_w += (1.0 - c_below) * layer;
          e.q_a += c_below * layer;
        }
        if (options_.discharge) e.continuity = (e.q_w - *options_.discharge) / *options_.discharge;
      }
      if (explain) {
        if (!options_.discharge) e.why_continuity = "no discharge given (option discharge)";
        else if (!is_finite(e.q_w)) e.why_continuity = "no water discharge: " + e.why_discharge;
      }
    }

    // The residual head at the chute's end (spillway design):
    // H_res = d cos(theta) + q_w^2 / (2 g d^2), the specific energy of the
    // equivalent clear-water flow of depth d and velocity q_w / d.
    if (!options_.chute_angle) {
      if (explain) e.why_residual_head = no_chute_angle;
    } else if (!is_finite(e.clear_water_depth) || !(e.clear_water_depth > 0.0)) {
      if (explain) e.why_residual_head = "no clear-water depth d: " + e.why_c_mean;
    } else if (!is_finite(e.q_w)) {
      if (explain) e.why_residual_head = "no water discharge: " + e.why_discharge;
    } else {
      const double d = e.clear_water_depth;
      e.residual_head = d * std::cos(*options_.chute_angle) + e.q_w * e.q_w / (2.0 * kGravity * d * d);
    }

    // Air-concentration models over 0 < y <= Y90.
    std::vector<double> fy, fc;
    for (std::size_t i = 0; i < top; ++i) {
      if (y_[i] > 0.0) fy.push_back(y_[i] / y90), fc.push_back(c[i]);
    }
    e.model_points = static_cast<int>(fy.size());
    for (std::size_t j = 0; j < 2; ++j) {
      const auto kind = j == 0 ? ConcentrationModelKind::smooth_chute : ConcentrationModelKind::stepped_chute;
      if (fy.size() < 2) {
        if (explain) {
          e.why_model[j] = fmt::format("{} row(s) with 0 < y <= Y90: a fit needs two", fy.size());
        }
        continue;
      }
      e.models[j] = fit_model(kind, fy, fc);
      if (e.models[j].at_edge && explain) {
        e.why_model[j] = fmt::format("the least-squares diffusivity lies outside [{:g}, {:g}]: the profile is not "
                                     "of this shape",
                                     kDiffusivityMin, kDiffusivityMax);
      }
    }
    return e;
  }

 private:
  [[nodiscard]] std::string name(std::size_t i) const { return row_name(rows_[i], input_index_[i]); }
  const std::vector<ProfileRow>& rows_;
  const std::vector<std::size_t>& input_index_;
  const ProfileFlowOptions& options_;
  std::vector<double> y_;
};

// A quantity's value from the point evaluation, its interval from the draws.
FlowQuantity summarise(double value, std::string why, std::vector<double>& draws, int draw_count) {
  FlowQuantity q;
  if (!is_finite(value)) {
    q.reason = why.empty() ? "undefined" : std::move(why);
    return q;
  }
  q.value = value;
  q.reason = std::move(why);
  std::erase_if(draws, [](double x) { return !is_finite(x); });
  q.draws_defined = static_cast<int>(draws.size());
  const int undefined = draw_count - q.draws_defined;
  const auto add = [&q](const std::string& s) { q.reason = q.reason.empty() ? s : q.reason + "; " + s; };
  if (draw_count == 0) return q;
  if (undefined > kUndefinedShareMax * draw_count) {
    add(fmt::format("undefined in {} of {} Monte Carlo draws: no 95 % interval", undefined, draw_count));
    return q;
  }
  std::sort(draws.begin(), draws.end());
  q.ci95 = Interval95{quantile_of_sorted(draws, 0.025), quantile_of_sorted(draws, 0.975)};
  if (undefined > 0) {
    add(fmt::format("undefined in {} of {} Monte Carlo draws: interval over the defined ones", undefined,
                    draw_count));
  }
  return q;
}

std::string check_row(const ProfileRow& r, const std::string& name) {
  const auto contains = [](const Interval95& ci, double x) {
    return is_finite(ci.lower) && is_finite(ci.upper) && ci.lower <= x && x <= ci.upper;
  };
  if (!(is_finite(r.y) && r.y >= 0.0)) return fmt::format("{}: y = {} m must be finite and >= 0 (from the invert)", name, r.y);
  if (!(r.c >= 0.0 && r.c <= 1.0)) return fmt::format("{}: c = {} must lie in [0, 1]", name, r.c);
  if (!contains(r.c_ci95, r.c)) {
    return fmt::format("{}: the interval [{}, {}] of c does not contain c = {}", name, r.c_ci95.lower,
                       r.c_ci95.upper, r.c);
  }
  if (!(is_finite(r.bubble_frequency) && r.bubble_frequency >= 0.0)) {
    return fmt::format("{}: F = {} 1/s must be finite and >= 0", name, r.bubble_frequency);
  }
  if (!contains(r.bubble_frequency_ci95, r.bubble_frequency)) {
    return fmt::format("{}: the interval [{}, {}] of F does not contain F = {}", name, r.bubble_frequency_ci95.lower,
                       r.bubble_frequency_ci95.upper, r.bubble_frequency);
  }
  if (!r.u) return {};
  if (!is_finite(*r.u)) return fmt::format("{}: u = {} m/s is not finite", name, *r.u);
  if (!r.u_quantiles.empty()) {
    if (r.u_quantiles.size() < 2) return fmt::format("{}: a velocity distribution needs two quantiles or more", name);
    for (std::size_t j = 0; j < r.u_quantiles.size(); ++j) {
      const auto& q = r.u_quantiles[j];
      if (!(q.probability > 0.0 && q.probability < 1.0) || !is_finite(q.value)) {
        return fmt::format("{}: velocity quantile {} (p = {}, {} m/s) needs p in (0, 1) and a finite value", name,
                           j + 1, q.probability, q.value);
      }
      if (j > 0 && !(q.probability > r.u_quantiles[j - 1].probability && q.value >= r.u_quantiles[j - 1].value)) {
        return fmt::format("{}: velocity quantiles must have increasing probabilities and non-decreasing values "
                           "(quantile {})",
                           name, j + 1);
      }
    }
    if (r.u_sampling_ci95 && !(is_finite(r.u_sampling_ci95->lower) && is_finite(r.u_sampling_ci95->upper) &&
                               r.u_sampling_ci95->lower <= r.u_sampling_ci95->upper)) {
      return fmt::format("{}: the sampling interval [{}, {}] of the corrected velocity needs finite ends, lower <= "
                         "upper",
                         name, r.u_sampling_ci95->lower, r.u_sampling_ci95->upper);
    }
    return {};
  }
  if (!r.u_ci95) {
    return fmt::format("{}: u = {} m/s has neither quantiles nor an interval: its uncertainty is needed (a zero-width "
                       "interval if it is exact)",
                       name, *r.u);
  }
  if (!contains(*r.u_ci95, *r.u)) {
    return fmt::format("{}: the interval [{}, {}] of u does not contain u = {}", name, r.u_ci95->lower,
                       r.u_ci95->upper, *r.u);
  }
  return {};
}

std::string quantity_text(const FlowQuantity& q, double scale, const char* unit) {
  if (!q.value) return "none: " + q.reason;
  std::string out = fmt::format("{:.5g}{}", *q.value * scale, unit);
  if (q.ci95) out += fmt::format(" [{:.5g}, {:.5g}]", q.ci95->lower * scale, q.ci95->upper * scale);
  if (!q.reason.empty()) out += " (" + q.reason + ")";
  return out;
}

}  // namespace

std::string_view to_string(FlowVelocitySource source) {
  switch (source) {
    case FlowVelocitySource::corrected_awcc: return "corrected awcc";
    case FlowVelocitySource::awcc: return "awcc";
    case FlowVelocitySource::fscc: return "fscc";
  }
  return "?";
}

std::string_view to_string(InvertRule rule) {
  switch (rule) {
    case InvertRule::held: return "held";
    case InvertRule::zero: return "zero";
    case InvertRule::left_out: return "left-out";
  }
  return "?";
}

std::string_view to_string(DepthStatus status) {
  switch (status) {
    case DepthStatus::ok: return "ok";
    case DepthStatus::not_reached: return "not_reached";
    case DepthStatus::below_first_position: return "below_first_position";
  }
  return "?";
}

std::string_view to_string(ConcentrationModelKind kind) {
  switch (kind) {
    case ConcentrationModelKind::smooth_chute: return "smooth chute (Chanson 1997)";
    case ConcentrationModelKind::stepped_chute: return "stepped chute (Chanson & Toombes 2002)";
  }
  return "?";
}

std::string_view to_string(ProfileFlowStatus status) {
  switch (status) {
    case ProfileFlowStatus::ok: return "ok";
    case ProfileFlowStatus::incomplete: return "incomplete";
    case ProfileFlowStatus::refused: return "refused";
  }
  return "?";
}

Validation ProfileFlowOptions::validate() const {
  for (std::size_t j = 0; j < levels.size(); ++j) {
    if (!(levels[j] > 0.0 && levels[j] < 1.0)) {
      return Validation::invalid("levels", fmt::format("level {} = {}: a characteristic depth's c lies in (0, 1)",
                                                       j + 1, levels[j]));
    }
  }
  if (discharge && !(is_finite(*discharge) && *discharge > 0.0)) {
    return Validation::invalid("discharge", fmt::format("discharge = {} m2/s: the continuity error divides by it, "
                                                        "so it must be positive",
                                                        *discharge));
  }
  if (chute_angle && !(*chute_angle >= 0.0 && *chute_angle <= 0.5 * std::numbers::pi)) {
    return Validation::invalid("chute-angle", fmt::format("chute angle {:.6g} rad: a chute slopes 0-90 degrees to the "
                                                          "horizontal",
                                                          *chute_angle));
  }
  if (draws < 0) {
    return Validation::invalid("draws", fmt::format("draws = {}: the Monte Carlo draws cannot be negative (0: no "
                                                    "intervals)",
                                                    draws));
  }
  if (draws > 0 && draws < 200) {
    // Below 200 draws the 2.5 % quantile rests on fewer than 5 of them.
    return Validation::invalid("draws", fmt::format("draws = {}: fewer than 200 put the 2.5 % quantile on fewer "
                                                    "than 5 draws (0: no intervals)",
                                                    draws));
  }
  return {};
}

double ConcentrationModel::k_prime() const {
  const double a = std::atanh(std::sqrt(0.1));
  return kind == ConcentrationModelKind::smooth_chute ? a + 1.0 / (2 * diffusivity)
                                                      : a + 1.0 / (2 * diffusivity) - 8.0 / (81 * diffusivity);
}

double ConcentrationModel::operator()(double y) const { return model_c(kind, diffusivity, y / y90); }

CharacteristicDepth characteristic_depth(std::span<const double> y, std::span<const double> c, double level) {
  if (y.size() != c.size() || y.empty()) {
    throw std::invalid_argument(fmt::format("characteristic_depth: {} positions and {} void fractions (need as many, "
                                            "at least one)",
                                            y.size(), c.size()));
  }
  CharacteristicDepth out;
  out.level = level;
  std::size_t k = 0;
  while (k < c.size() && c[k] < level) ++k;
  if (k == c.size()) {
    const auto top = std::max_element(c.begin(), c.end()) - c.begin();
    out.status = DepthStatus::not_reached;
    out.message = fmt::format("the profile never reaches c = {:g} (its highest c is {:.4g} at y = {:.6g} m)", level,
                              c[static_cast<std::size_t>(top)], y[static_cast<std::size_t>(top)]);
    return out;
  }
  if (k == 0) {
    out.y = y[0];
    if (c[0] == level) {
      out.status = DepthStatus::ok;
      return out;
    }
    out.status = DepthStatus::below_first_position;
    out.message = fmt::format("c = {:.4g} > {:g} already at the first position y = {:.6g} m: the crossing lies below "
                              "the measured profile, y = {:.6g} m is only an upper bound",
                              c[0], level, y[0], y[0]);
    return out;
  }
  out.status = DepthStatus::ok;
  out.y = c[k] == level ? y[k] : y[k - 1] + (level - c[k - 1]) * (y[k] - y[k - 1]) / (c[k] - c[k - 1]);
  return out;
}

std::optional<std::pair<std::size_t, std::size_t>> repeated_position_pair(std::span<const double> y) {
  for (std::size_t j = 0; j < y.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      if (y[i] == y[j]) return std::pair{i, j};
    }
  }
  return std::nullopt;
}

std::string repeated_position(std::span<const double> y, std::span<const std::string> names) {
  if (y.size() != names.size()) throw std::invalid_argument("repeated_position: as many names as positions");
  const auto pair = repeated_position_pair(y);
  if (!pair) return {};
  return fmt::format("position y = {:.6g} m given twice ({} and {}): one recording a position", y[pair->second],
                     names[pair->first], names[pair->second]);
}

ProfileFlowResult profile_flow(std::vector<ProfileRow> rows, const ProfileFlowOptions& options) {
  options.validate().throw_if_failed();
  ProfileFlowResult result;
  result.options = options;
  result.status = ProfileFlowStatus::refused;
  if (rows.size() < 2) {
    result.message = fmt::format("a profile of {} position(s): Y90, the integrals and the fits need two or more",
                                 rows.size());
    return result;
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (auto why = check_row(rows[i], row_name(rows[i], i)); !why.empty()) {
      result.message = std::move(why);
      return result;
    }
  }
  std::vector<std::size_t> order(rows.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return rows[a].y < rows[b].y; });
  {
    std::vector<double> y;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      y.push_back(rows[i].y);
      names.push_back(row_name(rows[i], i));
    }
    if (auto why = repeated_position(y, names); !why.empty()) {
      result.message = std::move(why);
      return result;
    }
  }
  if (!std::is_sorted(order.begin(), order.end())) {
    std::vector<std::size_t> numbers;
    for (std::size_t i : order) numbers.push_back(i + 1);
    result.notes.push_back(fmt::format("positions did not come in increasing y: sorted by y (input rows {})",
                                       fmt::join(numbers, ", ")));
    result.alerts.push_back(result.notes.back());
  }
  for (std::size_t i : order) result.rows.push_back(std::move(rows[i]));
  result.input_index = order;
  const auto& sorted = result.rows;

  std::vector<double> c, u;
  for (const auto& r : sorted) {
    c.push_back(r.c);
    u.push_back(r.u ? *r.u : kNaN);
  }
  {
    std::array<std::vector<std::string>, 3> by_source;
    std::vector<std::string> none;
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      const auto name = row_name(sorted[i], order[i]);
      if (sorted[i].u) by_source[static_cast<std::size_t>(sorted[i].u_source)].push_back(name);
      else none.push_back(name);
    }
    std::string text = "velocity of each row:";
    for (auto s : {FlowVelocitySource::corrected_awcc, FlowVelocitySource::awcc, FlowVelocitySource::fscc}) {
      const auto& names = by_source[static_cast<std::size_t>(s)];
      if (!names.empty()) text += fmt::format(" {} ({});", to_string(s), fmt::join(names, ", "));
    }
    if (!none.empty()) text += fmt::format(" none ({});", fmt::join(none, ", "));
    text.pop_back();
    result.notes.push_back(std::move(text));
  }

  const Evaluator evaluate(sorted, order, options);
  const Evaluation point = evaluate(c, u, true);

  // The Monte Carlo draws (header).
  enum Slot : std::size_t { y90, c_mean, depth, n, u90, q_w, q_a, continuity, smooth, stepped, residual_head,
                            slot_count };
  const std::size_t slots = slot_count + options.levels.size();
  std::vector<std::vector<double>> draws(slots);
  for (auto& d : draws) d.reserve(static_cast<std::size_t>(options.draws));
  {
    std::vector<Knots> c_knots, u_knots;
    for (const auto& r : sorted) {
      c_knots.push_back(interval_knots(r.c, r.c_ci95));
      u_knots.push_back(!r.u                      ? Knots{}
                        : !r.u_quantiles.empty() ? quantile_knots(r.u_quantiles)
                                                 : interval_knots(*r.u, *r.u_ci95));
    }
    // The weight a_i of the shared score (header); zero for a row whose
    // spread is all its own.
    std::vector<double> shared(sorted.size(), 0.0);
    bool any_shared = false;
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      const auto& r = sorted[i];
      if (!r.u || r.u_quantiles.empty() || !r.u_sampling_ci95) continue;
      const double sigma = (u_knots[i].at(kZ975) - u_knots[i].at(-kZ975)) / (2 * kZ975);
      const double s = (r.u_sampling_ci95->upper - r.u_sampling_ci95->lower) / (2 * kZ975);
      if (!(sigma > 0.0) || !(s < sigma)) continue;
      shared[i] = std::sqrt(1.0 - (s / sigma) * (s / sigma));
      any_shared = true;
    }
    std::vector<double> cd(sorted.size()), ud(sorted.size()), zu(sorted.size());
    for (int m = 0; m < options.draws; ++m) {
      Rng rng(derive_seed(options.seed, static_cast<std::uint64_t>(m)), 0);
      for (std::size_t i = 0; i < sorted.size(); ++i) {
        const double zc = rng.normal();
        zu[i] = rng.normal();
        cd[i] = std::clamp(c_knots[i].at(zc), 0.0, 1.0);
      }
      // Drawn after the rows' own scores, so that a profile without a shared
      // part draws exactly what it drew before there was one.
      const double z0 = any_shared ? rng.normal() : 0.0;
      for (std::size_t i = 0; i < sorted.size(); ++i) {
        const double z = shared[i] * z0 + std::sqrt(1.0 - shared[i] * shared[i]) * zu[i];
        ud[i] = sorted[i].u ? std::max(u_knots[i].at(z), 0.0) : kNaN;
      }
      const Evaluation e = evaluate(cd, ud, false);
      const auto ok_y = [](const CharacteristicDepth& d) { return d.status == DepthStatus::ok ? *d.y : kNaN; };
      draws[y90].push_back(ok_y(e.y90));
      draws[c_mean].push_back(e.c_mean);
      draws[depth].push_back(e.clear_water_depth);
      draws[n].push_back(e.n);
      draws[u90].push_back(e.u90);
      draws[q_w].push_back(e.q_w);
      draws[q_a].push_back(e.q_a);
      draws[continuity].push_back(e.continuity);
      draws[smooth].push_back(e.models[0].diffusivity);
      draws[stepped].push_back(e.models[1].diffusivity);
      draws[residual_head].push_back(e.residual_head);
      for (std::size_t j = 0; j < options.levels.size(); ++j) draws[slot_count + j].push_back(ok_y(e.levels[j]));
    }
  }
  result.draws = options.draws;

  result.y90_point = point.y90;
  result.y90 = summarise(point.y90.status == DepthStatus::ok ? *point.y90.y : kNaN, point.y90.message, draws[y90],
                         options.draws);
  for (std::size_t j = 0; j < options.levels.size(); ++j) {
    const auto& d = point.levels[j];
    result.levels.push_back({d, summarise(d.status == DepthStatus::ok ? *d.y : kNaN, d.message,
                                          draws[slot_count + j], options.draws)});
  }
  const std::string rule = fmt::format("below the first position: {}", to_string(options.invert));
  result.c_mean = summarise(point.c_mean, point.why_c_mean, draws[c_mean], options.draws);
  result.clear_water_depth = summarise(point.clear_water_depth, point.why_c_mean, draws[depth], options.draws);
  result.power_law.n = summarise(point.n, point.why_power, draws[n], options.draws);
  result.power_law.u90 = summarise(point.u90, point.why_power, draws[u90], options.draws);
  result.power_law.points = point.power_points;
  if (is_finite(point.power_residual)) result.power_law.residual = point.power_residual;
  result.water_discharge = summarise(point.q_w, point.why_discharge, draws[q_w], options.draws);
  result.air_discharge = summarise(point.q_a, point.why_discharge, draws[q_a], options.draws);
  result.continuity_error = summarise(point.continuity, point.why_continuity, draws[continuity], options.draws);
  result.residual_head =
      summarise(point.residual_head, point.why_residual_head, draws[residual_head], options.draws);
  for (std::size_t j = 0; j < 2; ++j) {
    auto& fit = j == 0 ? result.smooth_chute : result.stepped_chute;
    const auto& m = point.models[j];
    fit.diffusivity = summarise(m.diffusivity, point.why_model[j], draws[j == 0 ? smooth : stepped], options.draws);
    fit.points = point.model_points;
    if (is_finite(m.diffusivity)) {
      fit.residual = m.residual;
      fit.curve = ConcentrationModel{
          j == 0 ? ConcentrationModelKind::smooth_chute : ConcentrationModelKind::stepped_chute, m.diffusivity,
          *point.y90.y};
    }
  }

  std::vector<std::string> missing;
  const auto need = [&missing](const FlowQuantity& q, const char* name) {
    if (!q.value) missing.push_back(fmt::format("{} ({})", name, q.reason));
  };
  need(result.y90, "Y90");
  need(result.c_mean, "C_mean");
  need(result.clear_water_depth, "d");
  need(result.power_law.n, "N");
  need(result.water_discharge, "q_w");
  need(result.air_discharge, "q_a");
  if (options.discharge) need(result.continuity_error, "continuity error");
  need(result.smooth_chute.diffusivity, "D'");
  need(result.stepped_chute.diffusivity, "D_0");
  if (missing.empty()) {
    result.status = ProfileFlowStatus::ok;
  } else {
    result.status = ProfileFlowStatus::incomplete;
    result.message = fmt::format("no {}", fmt::join(missing, "; no "));
  }
  result.notes.push_back(rule + " (C_mean, d, q_w, q_a)");
  return result;
}

std::vector<std::string> ProfileFlowResult::warnings() const {
  std::vector<std::string> out;
  if (status == ProfileFlowStatus::refused) out.push_back("profile's flow quantities refused: " + message);
  out.insert(out.end(), alerts.begin(), alerts.end());
  if (y90_point.status == DepthStatus::below_first_position) out.push_back("Y90 flagged: " + y90_point.message);
  for (const auto& l : levels) {
    if (l.point.status == DepthStatus::below_first_position) {
      out.push_back(fmt::format("Y{:g} flagged: {}", 100 * l.point.level, l.point.message));
    }
  }
  return out;
}

std::string ProfileFlowResult::report() const {
  std::string out = fmt::format("profile of {} positions: {}", rows.size(), to_string(status));
  if (status == ProfileFlowStatus::refused) return out + ": " + message + "\n";
  out += fmt::format(" (95 % intervals from {} Monte Carlo draws, seed {})\n", draws, options.seed);
  for (const auto& note : notes) out += "  " + note + "\n";
  if (y90_point.status == DepthStatus::below_first_position) out += "  Y90 flagged: " + y90_point.message + "\n";
  out += "  Y90 = " + quantity_text(y90, 1e3, " mm") + "\n";
  for (const auto& l : levels) {
    out += fmt::format("  Y{:g} = ", 100 * l.point.level);
    out += l.point.status == DepthStatus::below_first_position ? "flagged: " + l.point.message
                                                                : quantity_text(l.depth, 1e3, " mm");
    out += "\n";
  }
  // Without Y90 every quantity taken up to it is none for that one reason:
  // said once, with their names, not once per quantity.
  std::vector<std::string> need_y90;
  const auto for_want_of_y90 = [&](const FlowQuantity& q, std::string_view symbol) {
    if (q.value || !q.reason.starts_with("no Y90")) return false;
    need_y90.emplace_back(symbol);
    return true;
  };
  if (!for_want_of_y90(c_mean, "C_mean")) out += "  C_mean = " + quantity_text(c_mean, 1.0, "") + "\n";
  if (!for_want_of_y90(clear_water_depth, "d")) {
    out += "  d = " + quantity_text(clear_water_depth, 1e3, " mm") + "\n";
  }
  const bool law_wants = for_want_of_y90(power_law.n, "N");
  if (!(law_wants && for_want_of_y90(power_law.u90, "u90"))) {
    out += fmt::format("  power law ({} points): N = {}, u90 = {}", power_law.points,
                       quantity_text(power_law.n, 1.0, ""), quantity_text(power_law.u90, 1.0, " m/s"));
    if (power_law.residual) out += fmt::format(", rms residual of ln u {:.3g}", *power_law.residual);
    out += "\n";
  }
  if (!for_want_of_y90(water_discharge, "q_w")) out += "  q_w = " + quantity_text(water_discharge, 1.0, " m2/s") + "\n";
  if (!for_want_of_y90(air_discharge, "q_a")) out += "  q_a = " + quantity_text(air_discharge, 1.0, " m2/s") + "\n";
  if (options.discharge && !for_want_of_y90(continuity_error, "continuity error")) {
    out += fmt::format("  continuity error against q = {:.5g} m2/s: ", *options.discharge) +
           quantity_text(continuity_error, 100.0, " %") + "\n";
  }
  for (const auto* fit : {&smooth_chute, &stepped_chute}) {
    const bool smooth = fit == &smooth_chute;
    if (for_want_of_y90(fit->diffusivity, smooth ? "D'" : "D_0")) continue;
    out += fmt::format("  {} ({} points): {} = {}", to_string(smooth ? ConcentrationModelKind::smooth_chute
                                                                      : ConcentrationModelKind::stepped_chute),
                       fit->points, smooth ? "D'" : "D_0", quantity_text(fit->diffusivity, 1.0, ""));
    if (fit->residual) out += fmt::format(", rms residual {:.3g}", *fit->residual);
    out += "\n";
  }
  // The quantities listed after the fits, each from its row of flow_quantity_names.
  bool after_fits = false;
  for (const auto& q : flow_quantity_names) {
    if (after_fits && !for_want_of_y90(q.of(*this), q.symbol)) {
      const std::string unit = q.shown_unit == "-" ? std::string() : " " + std::string(q.shown_unit);
      out += fmt::format("  {} = {}\n", q.symbol, quantity_text(q.of(*this), q.shown_scale, unit.c_str()));
    }
    after_fits = after_fits || q.pointer == "/stepped_chute";
  }
  if (!need_y90.empty()) {
    out += fmt::format("  none of {}: each is taken up to Y90, which the profile does not give\n",
                       fmt::join(need_y90, ", "));
  }
  return out;
}

}  // namespace awcc
