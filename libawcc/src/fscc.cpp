#include "awcc/fscc.hpp"

#include "awcc/detail/fscc_steps.hpp"
#include "overlap_impulses.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

namespace awcc {

std::string FsccOptions::validate() const {
  if (segments < 1) return fmt::format("segments = {}: at least 1", segments);
  if (!felder_lags && !(max_lag > 0.0 && std::isfinite(max_lag))) return fmt::format("max lag {} s must be > 0", max_lag);
  return {};
}

std::string_view to_string(Subsample subsample) { return subsample == Subsample::parabolic ? "parabolic" : "none"; }

std::string_view to_string(FsccStatus status) {
  switch (status) {
    case FsccStatus::ok: return "ok";
    case FsccStatus::constant_leading: return "constant_leading";
    case FsccStatus::constant_trailing: return "constant_trailing";
    case FsccStatus::no_common_segment: return "no_common_segment";
    case FsccStatus::no_positive_peak: return "no_positive_peak";
    case FsccStatus::non_positive_lag: return "non_positive_lag";
    case FsccStatus::tips_swapped: return "tips_swapped";
    case FsccStatus::peak_at_lag_range_end: return "peak_at_lag_range_end";
    case FsccStatus::no_tip_separation: return "no_tip_separation";
  }
  return "?";
}

namespace detail {

std::int64_t air_samples_in(const AirIntervals& s, std::int64_t a, std::int64_t b) {
  a = std::max<std::int64_t>(a, 0);
  b = std::min(b, s.sample_count);
  if (a >= b) return 0;
  auto it = std::partition_point(s.intervals.begin(), s.intervals.end(),
                                 [a](const AirInterval& iv) { return iv.stop <= a; });
  std::int64_t total = 0;
  for (; it != s.intervals.end() && it->start < b; ++it) total += std::min(it->stop, b) - std::max(it->start, a);
  return total;
}

namespace {

// S(k) from the pairs of air intervals within the lag range (see
// overlap_impulses.hpp). Exact integers; the cost grows with the pairs.
std::vector<double> lagged_products_by_intervals(const AirIntervals& x, const AirIntervals& y, std::int64_t t0,
                                                 std::int64_t t1, std::int64_t k_min, std::int64_t k_max) {
  const auto lags = static_cast<std::size_t>(k_max - k_min + 1);
  std::vector<std::int64_t> impulse(lags, 0);
  detail::OverlapImpulses<std::int64_t> sum{k_min, k_max, impulse};
  const auto& yi = y.intervals;
  std::size_t first = 0;
  for (const auto& iv : x.intervals) {
    const std::int64_t a0 = std::max(iv.start, t0), a1 = std::min(iv.stop, t1);
    if (a0 >= a1) continue;
    // y intervals that can overlap a shifted by a lag in range: b1 > a0 + k_min, b0 <= a1 + k_max.
    while (first < yi.size() && yi[first].stop <= a0 + k_min) ++first;
    for (std::size_t j = first; j < yi.size() && yi[j].start <= a1 + k_max; ++j) {
      sum.add_pair(a0, a1, yi[j].start, yi[j].stop);
    }
  }
  std::int64_t slope = sum.slope, value = sum.value;
  std::vector<double> out(lags);
  for (std::size_t i = 0; i < lags; ++i) {
    out[i] = static_cast<double>(value);  // f(k_min + i)
    slope += impulse[i];
    value += slope;
  }
  return out;
}

std::vector<double> lagged_products_by_fft(const AirIntervals& x, const AirIntervals& y, std::int64_t t0,
                                           std::int64_t t1, std::int64_t k_min, std::int64_t k_max,
                                           FftPlanCache& plans) {
  const auto lags = static_cast<std::size_t>(k_max - k_min + 1);
  std::vector<double> out(lags, 0.0);
  // Blocks of x of length B against y over [b + k_min, b + B + k_max): a
  // circular correlation of size M >= B + K - 1 holds lags 0..K-1 unwrapped.
  const std::size_t block = std::max<std::size_t>(4 * lags, 1 << 15);
  const std::size_t m = fast_fft_size(block + lags - 1);
  FftPlan& plan = plans.get(m);
  std::vector<std::complex<double>> xs(m / 2 + 1);
  std::vector<std::uint8_t> dense(block + lags - 1);
  for (std::int64_t b = t0; b < t1; b += static_cast<std::int64_t>(block)) {
    const auto len = static_cast<std::size_t>(std::min<std::int64_t>(static_cast<std::int64_t>(block), t1 - b));
    x.render(b, std::span<std::uint8_t>(dense.data(), len));
    auto r = plan.real();
    std::fill(r.begin(), r.end(), 0.0);
    bool any = false;
    for (std::size_t i = 0; i < len; ++i) {
      r[i] = dense[i];
      any = any || dense[i];
    }
    if (!any) continue;
    plan.forward();
    std::copy(plan.spectrum().begin(), plan.spectrum().end(), xs.begin());
    const std::int64_t y0 = b + k_min;
    const std::size_t ylen = len + lags - 1;
    std::fill(r.begin(), r.end(), 0.0);
    const std::int64_t lo = std::max<std::int64_t>(y0, 0);
    const std::int64_t hi = std::min<std::int64_t>(y0 + static_cast<std::int64_t>(ylen), y.sample_count);
    if (hi > lo) {
      y.render(lo, std::span<std::uint8_t>(dense.data(), static_cast<std::size_t>(hi - lo)));
      for (std::int64_t i = lo; i < hi; ++i) r[static_cast<std::size_t>(i - y0)] = dense[static_cast<std::size_t>(i - lo)];
    }
    plan.forward();
    auto spec = plan.spectrum();
    for (std::size_t i = 0; i < spec.size(); ++i) spec[i] *= std::conj(xs[i]);
    plan.inverse();
    const double scale = 1.0 / static_cast<double>(m);
    for (std::size_t j = 0; j < lags; ++j) out[j] += r[j] * scale;
  }
  // The products of 0/1 signals are whole numbers: remove FFT rounding.
  for (auto& v : out) v = std::nearbyint(v);
  return out;
}

}  // namespace

std::vector<double> lagged_products(const AirIntervals& x, const AirIntervals& y, std::int64_t t0, std::int64_t t1,
                                    std::int64_t k_min, std::int64_t k_max, FftPlanCache& plans, ProductPath path) {
  if (t1 <= t0) return std::vector<double>(static_cast<std::size_t>(k_max - k_min + 1), 0.0);
  if (path == ProductPath::intervals) return lagged_products_by_intervals(x, y, t0, t1, k_min, k_max);
  if (path == ProductPath::fft) return lagged_products_by_fft(x, y, t0, t1, k_min, k_max, plans);
  // Both are exact; pick the cheaper. Pairs within the lag range, against
  // about 15 operations per sample and lag-block of the FFT path.
  const double span = static_cast<double>(t1 - t0);
  const double nx = static_cast<double>(x.intervals.size()), ny = static_cast<double>(y.intervals.size());
  const double lag_span = static_cast<double>(k_max - k_min + 1);
  const double pairs = nx * ny * std::min(1.0, (lag_span + 2.0 * span / std::max(1.0, ny)) / static_cast<double>(y.sample_count));
  const double fft_cost = 15.0 * span * std::log2(std::max(2.0, 8.0 * lag_span));
  if (4.0 * pairs < fft_cost) return lagged_products_by_intervals(x, y, t0, t1, k_min, k_max);
  return lagged_products_by_fft(x, y, t0, t1, k_min, k_max, plans);
}

}  // namespace detail

namespace {

using detail::lagged_products;

// Air samples before any sample index in O(log n): cumulative chord lengths.
class AirPrefix {
 public:
  explicit AirPrefix(const AirIntervals& s) : s_(s), cumulative_(s.intervals.size() + 1, 0) {
    for (std::size_t i = 0; i < s.intervals.size(); ++i)
      cumulative_[i + 1] = cumulative_[i] + (s.intervals[i].stop - s.intervals[i].start);
  }
  std::int64_t below(std::int64_t t) const {
    const auto& iv = s_.intervals;
    const auto it = std::partition_point(iv.begin(), iv.end(), [t](const AirInterval& a) { return a.stop <= t; });
    const auto i = static_cast<std::size_t>(it - iv.begin());
    std::int64_t total = cumulative_[i];
    if (it != iv.end() && it->start < t) total += t - it->start;
    return total;
  }
  std::int64_t in(std::int64_t a, std::int64_t b) const {
    a = std::clamp<std::int64_t>(a, 0, s_.sample_count);
    b = std::clamp<std::int64_t>(b, 0, s_.sample_count);
    return b > a ? below(b) - below(a) : 0;
  }

 private:
  const AirIntervals& s_;
  std::vector<std::int64_t> cumulative_;
};

struct Functions {
  std::vector<double> r11, r12;
  std::int64_t k11_min = 0, k12_min = 0;
  FsccStatus status = FsccStatus::ok;  // ok: the functions exist
  std::string message;
};

// Full-record normalised correlations (METHOD 3).
Functions full_record(const AirIntervals& x, const AirIntervals& y, std::int64_t k11_max, std::int64_t k12_min,
                      std::int64_t k12_max, FftPlanCache& plans) {
  Functions f;
  f.k11_min = 0;
  f.k12_min = k12_min;
  const std::int64_t n = x.sample_count;
  const double sx = static_cast<double>(x.air_samples()), sy = static_cast<double>(y.air_samples());
  const double mx = sx / static_cast<double>(n), my = sy / static_cast<double>(n);
  // Sum of squares of a mean-removed 0/1 signal: n m (1 - m).
  const double qx = static_cast<double>(n) * mx * (1 - mx), qy = static_cast<double>(n) * my * (1 - my);
  if (!(qx > 0.0) || !(qy > 0.0)) {
    f.status = qx > 0.0 ? FsccStatus::constant_trailing : FsccStatus::constant_leading;
    f.message = qx > 0.0 ? "the trailing tip's signal is constant (no bubble)" : "the leading tip's signal is constant (no bubble)";
    return f;
  }
  const AirPrefix px(x), py(y);
  auto normalised = [&](const AirIntervals& a, const AirIntervals& b, const AirPrefix& pa, const AirPrefix& pb,
                        double ma, double mb, double qa, double qb, std::int64_t kmin, std::int64_t kmax) {
    const auto sums = lagged_products(a, b, 0, n, kmin, kmax, plans);
    std::vector<double> r(sums.size());
    for (std::size_t j = 0; j < sums.size(); ++j) {
      const std::int64_t k = kmin + static_cast<std::int64_t>(j);
      // t in [max(0, -k), min(n, n - k)) and t + k in range.
      const std::int64_t t0 = std::max<std::int64_t>(0, -k), t1 = std::min(n, n - k);
      const double count = static_cast<double>(std::max<std::int64_t>(0, t1 - t0));
      const double sa = static_cast<double>(pa.in(t0, t1));
      const double sb = static_cast<double>(pb.in(t0 + k, t1 + k));
      const double centred = sums[j] - ma * sb - mb * sa + count * ma * mb;
      r[j] = centred / std::sqrt(qa * qb);
    }
    return r;
  };
  f.r11 = normalised(x, x, px, px, mx, mx, qx, qx, 0, k11_max);
  f.r12 = normalised(x, y, px, py, mx, my, qx, qy, k12_min, k12_max);
  return f;
}

// Felder's segmented Pearson coefficients, averaged over the segments.
Functions segmented(const AirIntervals& x, const AirIntervals& y, int segments, std::int64_t k11_max,
                    std::int64_t k12_min, std::int64_t k12_max, FftPlanCache& plans) {
  Functions f;
  f.k12_min = k12_min;
  const std::int64_t n = x.sample_count;
  const std::int64_t length = n / segments;
  f.r11.assign(static_cast<std::size_t>(k11_max + 1), 0.0);
  f.r12.assign(static_cast<std::size_t>(k12_max - k12_min + 1), 0.0);
  int used11 = 0, used12 = 0;
  const AirPrefix px(x), py(y);
  auto pearson = [&](const AirIntervals& a, const AirIntervals& b, const AirPrefix& pa, const AirPrefix& pb,
                     std::int64_t s0, std::int64_t kmin,
                     std::int64_t kmax, std::vector<double>& acc) {
    const std::int64_t t0 = s0 + std::max<std::int64_t>(0, -kmin);
    const std::int64_t t1 = s0 + length - std::max<std::int64_t>(0, kmax);
    const std::int64_t w = t1 - t0;
    if (w < 2) return false;
    const double wd = static_cast<double>(w);
    const double ma = static_cast<double>(pa.in(t0, t1)) / wd;
    const double va = ma * (1 - ma);
    if (!(va > 0.0)) return false;
    const auto sums = lagged_products(a, b, t0, t1, kmin, kmax, plans);
    std::vector<double> r(sums.size());
    for (std::size_t j = 0; j < sums.size(); ++j) {
      const std::int64_t k = kmin + static_cast<std::int64_t>(j);
      const double mb = static_cast<double>(pb.in(t0 + k, t1 + k)) / wd;
      const double vb = mb * (1 - mb);
      if (!(vb > 0.0)) return false;
      r[j] = (sums[j] / wd - ma * mb) / std::sqrt(va * vb);
    }
    for (std::size_t j = 0; j < r.size(); ++j) acc[j] += r[j];
    return true;
  };
  for (int s = 0; s < segments; ++s) {
    const std::int64_t s0 = static_cast<std::int64_t>(s) * length;
    used11 += pearson(x, x, px, px, s0, 0, k11_max, f.r11);
    used12 += pearson(x, y, px, py, s0, k12_min, k12_max, f.r12);
  }
  if (used11 == 0 || used12 == 0) {
    f.status = FsccStatus::no_common_segment;
    f.message = "no segment holds bubbles on both tips";
    return f;
  }
  for (auto& v : f.r11) v /= used11;
  for (auto& v : f.r12) v /= used12;
  return f;
}

// Lag (in samples, fractional) where r first falls to `level` going from
// index `from` in direction `step`; empty when it never does.
std::optional<double> crossing(const std::vector<double>& r, std::size_t from, int step, double level) {
  std::int64_t i = static_cast<std::int64_t>(from);
  const auto n = static_cast<std::int64_t>(r.size());
  while (true) {
    const std::int64_t next = i + step;
    if (next < 0 || next >= n) return std::nullopt;
    const double a = r[static_cast<std::size_t>(i)], b = r[static_cast<std::size_t>(next)];
    if (b <= level) {
      const double frac = a == b ? 0.0 : (a - level) / (a - b);
      return static_cast<double>(i) + step * frac;
    }
    i = next;
  }
}

// Integral (in samples) of r from index `from` to its first zero, trapezoid rule.
std::optional<double> integral_to_zero(const std::vector<double>& r, std::size_t from) {
  double sum = 0.0;
  for (std::size_t i = from; i + 1 < r.size(); ++i) {
    if (r[i + 1] <= 0.0) {
      const double frac = r[i] / (r[i] - r[i + 1]);
      return sum + 0.5 * r[i] * frac;
    }
    sum += 0.5 * (r[i] + r[i + 1]);
  }
  return std::nullopt;
}

}  // namespace

FsccResult fscc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const FsccOptions& options) {
  if (const auto why = options.validate(); !why.empty()) throw std::invalid_argument(why);
  if (leading.sample_count != trailing.sample_count || leading.fs != trailing.fs) {
    throw std::invalid_argument("FSCC needs two signals of the same length and sampling rate");
  }
  FsccResult out;
  const double fs = leading.fs;
  const std::int64_t n = leading.sample_count;
  std::int64_t k11_max, k12_min, k12_max;
  if (options.felder_lags) {
    k11_max = 999;
    k12_min = -199;
    k12_max = 800;
  } else {
    k11_max = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::llround(options.max_lag * fs)));
    k12_min = -k11_max;
    k12_max = k11_max;
  }
  const std::int64_t limit = std::max<std::int64_t>(1, n / std::max(1, options.segments) / 2);
  k11_max = std::min(k11_max, limit);
  k12_max = std::min(k12_max, limit);
  k12_min = std::max(k12_min, -limit);

  FftPlanCache plans;
  Functions f = options.segments == 1 ? full_record(leading, trailing, k11_max, k12_min, k12_max, plans)
                                      : segmented(leading, trailing, options.segments, k11_max, k12_min, k12_max, plans);
  out.r11 = std::move(f.r11);
  out.r12 = std::move(f.r12);
  out.r11_first_lag = f.k11_min;
  out.r12_first_lag = f.k12_min;
  if (f.status != FsccStatus::ok) {
    out.status = f.status;
    out.message = f.message;
    return out;
  }
  // Peak: the maximum (first occurrence), or Felder's first lag within 1e-5 of it.
  const auto max_it = std::max_element(out.r12.begin(), out.r12.end());
  std::size_t peak = static_cast<std::size_t>(max_it - out.r12.begin());
  if (options.felder_lags) {
    for (std::size_t j = 0; j < out.r12.size(); ++j) {
      if (*max_it - out.r12[j] < 1e-5) {
        peak = j;
        break;
      }
    }
  }
  out.r12_max = out.r12[peak];
  out.lag_samples = f.k12_min + static_cast<std::int64_t>(peak);
  double lag = static_cast<double>(out.lag_samples);
  if (options.subsample == Subsample::parabolic && peak > 0 && peak + 1 < out.r12.size()) {
    const double a = out.r12[peak - 1], b = out.r12[peak], c = out.r12[peak + 1];
    const double denom = a - 2 * b + c;
    if (denom < 0.0) lag += 0.5 * (a - c) / denom;
  }
  out.lag = lag / fs;
  if (!(out.r12_max > 0.0)) {
    out.status = FsccStatus::no_positive_peak;
    out.message = "the cross-correlation has no positive peak: the tips' signals are unrelated";
  } else if (out.lag_samples <= 0) {
    out.status = out.lag_samples < 0 ? FsccStatus::tips_swapped : FsccStatus::non_positive_lag;
    out.message = fmt::format("the cross-correlation peaks at lag {} samples (not positive): no physical velocity; "
                              "check the tip order",
                              out.lag_samples);
  } else if (out.lag_samples == f.k12_min + static_cast<std::int64_t>(out.r12.size()) - 1) {
    out.status = FsccStatus::peak_at_lag_range_end;
    out.message = "the cross-correlation peaks at the end of the lag range: the delay lies beyond the lags searched, "
                  "or dx's unit or the sampling rate is wrong; check them, or widen the lag range";
  } else if (!(dx > 0.0)) {
    out.status = FsccStatus::no_tip_separation;
    out.message = "no tip separation given: the velocity cannot be computed";
  } else {
    out.status = FsccStatus::ok;
    out.velocity = dx / out.lag;
    if (out.velocity > 100.0) {
      out.warnings.push_back(fmt::format("FSCC velocity {:.4g} m/s is above 100 m/s, beyond air-water flows: check dx's "
                                         "unit, the sampling rate and the lag range",
                                         out.velocity));
    }
  }
  // Time scales.
  std::string notes;
  if (auto k = crossing(out.r11, 0, +1, 0.5)) out.t05 = *k / fs;
  else notes += "R11 never falls to 0.5 within the lags searched; ";
  if (auto i = integral_to_zero(out.r11, 0)) out.txx = *i / fs;
  if (out.r12_max > 0.0) {
    const auto right = crossing(out.r12, peak, +1, 0.5 * out.r12_max);
    const auto left = crossing(out.r12, peak, -1, 0.5 * out.r12_max);
    if (right && left) out.tau05 = 0.5 * (*right - *left) / fs;
    else if (right) out.tau05 = (*right - static_cast<double>(peak)) / fs;
    else if (left) out.tau05 = (static_cast<double>(peak) - *left) / fs;
    if (auto i = integral_to_zero(out.r12, peak)) out.txy = *i / fs;
  }
  if (out.ok() && out.t05 && out.tau05) {
    if (*out.tau05 > *out.t05) {
      out.turbulence_intensity_chanson = 0.851 * std::sqrt(*out.tau05 * *out.tau05 - *out.t05 * *out.t05) / out.lag;
    } else {
      notes += "tau05 <= T05: Chanson's turbulence intensity is undefined; ";
    }
  }
  if (!notes.empty()) notes.resize(notes.size() - 2);
  out.note = notes;
  return out;
}

}  // namespace awcc
