#include "awcc/awcc.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>

namespace awcc {

std::string_view to_string(WindowFate fate) {
  switch (fate) {
    case WindowFate::accepted: return "accepted";
    case WindowFate::correlation: return "correlation";
    case WindowFate::lag: return "lag";
    case WindowFate::roc: return "roc";
    case WindowFate::constant: return "constant";
  }
  return "?";
}

std::string AwccOptions::validate() const {
  if (np < 1 || np > 1000) return fmt::format("np = {}: particles per window must lie in [1, 1000]", np);
  if (!(filter_a >= 0.0 && filter_a <= 1.0)) return fmt::format("filter A = {} must lie in [0, 1]", filter_a);
  if (!(prominence_fraction >= 0.0 && prominence_fraction <= 1.0))
    return fmt::format("prominence fraction {} must lie in [0, 1]", prominence_fraction);
  if (velocity_min.has_value() != velocity_max.has_value()) return "give both ends of the velocity range";
  if (velocity_min && !(*velocity_min > 0.0 && *velocity_max > *velocity_min))
    return fmt::format("velocity range {} to {} m/s must satisfy 0 < min < max", *velocity_min, *velocity_max);
  return {};
}

std::vector<AwccWindow> awcc_windows(const AirIntervals& leading, int np) {
  const std::int64_t n = leading.sample_count;
  std::vector<std::int64_t> transitions;
  transitions.reserve(2 * leading.intervals.size());
  for (const auto& iv : leading.intervals) {
    if (iv.start > 0) transitions.push_back(iv.start);
    if (iv.stop < n) transitions.push_back(iv.stop);
  }
  const auto per_window = static_cast<std::size_t>(2 * np);
  const std::size_t count = transitions.size() / per_window;
  std::vector<AwccWindow> windows(count);
  const double fs = leading.fs;
  std::size_t interval = 0;
  for (std::size_t i = 0; i < count; ++i) {
    AwccWindow& w = windows[i];
    w.start = i == 0 ? 0 : transitions[i * per_window - 1];
    const std::int64_t end = i + 1 < count ? transitions[(i + 1) * per_window - 1] : n;
    w.length = end - w.start;
    w.start_time = static_cast<double>(w.start) / fs;
    w.duration = static_cast<double>(w.length) / fs;
    // Particles and air of the leading tip in the window.
    std::int64_t air = 0;
    int particles = 0;
    while (interval < leading.intervals.size() && leading.intervals[interval].stop <= w.start) ++interval;
    for (std::size_t k = interval; k < leading.intervals.size() && leading.intervals[k].start < end; ++k) {
      const auto& iv = leading.intervals[k];
      air += std::min(iv.stop, end) - std::max(iv.start, w.start);
      if (iv.start >= w.start && iv.start > 0) ++particles;
    }
    w.particles = particles;
    w.void_fraction = static_cast<double>(air) / static_cast<double>(w.length);
    w.count_rate = static_cast<double>(particles) / w.duration;
  }
  return windows;
}

namespace {

// Air intervals of s clipped to [start, start + length), relative to start.
void clip(const AirIntervals& s, std::int64_t start, std::int64_t length, std::vector<AirInterval>& out) {
  out.clear();
  const std::int64_t end = start + length;
  auto it = std::partition_point(s.intervals.begin(), s.intervals.end(),
                                 [start](const AirInterval& iv) { return iv.stop <= start; });
  for (; it != s.intervals.end() && it->start < end; ++it) {
    out.push_back({std::max(it->start, start) - start, std::min(it->stop, end) - start});
  }
}

// prefix[m] = air samples in [0, m), m = 0..length.
void air_prefix(const std::vector<AirInterval>& iv, std::int64_t length, std::vector<double>& prefix) {
  prefix.assign(static_cast<std::size_t>(length + 1), 0.0);
  std::int64_t m = 0;
  double acc = 0.0;
  for (const auto& a : iv) {
    for (; m <= a.start; ++m) prefix[static_cast<std::size_t>(m)] = acc;
    for (; m <= a.stop; ++m) prefix[static_cast<std::size_t>(m)] = acc + static_cast<double>(m - a.start);
    acc += static_cast<double>(a.stop - a.start);
  }
  for (; m <= length; ++m) prefix[static_cast<std::size_t>(m)] = acc;
}

}  // namespace

std::vector<double> window_correlation_intervals(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                                 std::int64_t length, std::int64_t k_min, std::int64_t k_max) {
  thread_local std::vector<AirInterval> a, b;
  thread_local std::vector<double> px, py;
  thread_local std::vector<std::int64_t> impulses;
  clip(x, start, length, a);
  clip(y, start, length, b);
  const double L = static_cast<double>(length);
  double ax = 0, ay = 0;
  for (const auto& iv : a) ax += static_cast<double>(iv.stop - iv.start);
  for (const auto& iv : b) ay += static_cast<double>(iv.stop - iv.start);
  const double mx = ax / L, my = ay / L;
  const double qx = L * mx * (1 - mx), qy = L * my * (1 - my);
  if (!(qx > 0.0) || !(qy > 0.0)) return {};
  // Sum of overlaps of every pair of air intervals, as a function of the lag:
  // each pair's overlap is a trapezoid in k whose second difference is +1 at
  // b0 - a1, -1 at b0 - a0 and at b1 - a1, +1 at b1 - a0. Impulses live on
  // [k_min - 1, k_max]; earlier ones are folded into the starting slope and value.
  const std::int64_t origin = k_min - 1;
  const auto size = static_cast<std::size_t>(k_max - origin + 1);
  impulses.assign(size, 0);
  std::int64_t slope0 = 0;   // slope s(origin - 1) contribution from impulses before origin
  std::int64_t value0 = 0;   // f(origin) from impulses before origin
  auto add = [&](std::int64_t k, std::int64_t w) {
    if (k > k_max) return;
    if (k < origin) {
      // An impulse at k < origin adds w to every slope s(j), j >= k, so to
      // f(origin) it adds w (origin - k) and to the starting slope w.
      slope0 += w;
      value0 += w * (origin - k);
      return;
    }
    impulses[static_cast<std::size_t>(k - origin)] += w;
  };
  for (const auto& ia : a) {
    for (const auto& ib : b) {
      // Trapezoids that end at or before the first lag add nothing there
      // (their impulses cancel in slope and value), nor do those starting
      // after the last lag.
      if (ib.stop - ia.start <= origin) continue;
      if (ib.start - ia.stop > k_max) continue;
      add(ib.start - ia.stop, +1);
      add(ib.start - ia.start, -1);
      add(ib.stop - ia.stop, -1);
      add(ib.stop - ia.start, +1);
    }
  }
  air_prefix(a, length, px);
  air_prefix(b, length, py);
  std::vector<double> r(static_cast<std::size_t>(k_max - k_min + 1));
  const double norm = 1.0 / std::sqrt(qx * qy);
  std::int64_t slope = slope0, value = value0;  // f(origin)
  // Walk k from origin: f(k + 1) = f(k) + s(k), s(k) = s(k - 1) + impulse(k).
  for (std::int64_t k = origin; k < k_max; ++k) {
    slope += impulses[static_cast<std::size_t>(k - origin)];
    value += slope;
    const std::int64_t lag = k + 1;  // value is now f(lag)
    const std::int64_t t0 = std::max<std::int64_t>(0, -lag), t1 = std::min(length, length - lag);
    double sxy = static_cast<double>(value);
    double sx = 0, sy = 0, n = 0;
    if (t1 > t0) {
      sx = px[static_cast<std::size_t>(t1)] - px[static_cast<std::size_t>(t0)];
      sy = py[static_cast<std::size_t>(t1 + lag)] - py[static_cast<std::size_t>(t0 + lag)];
      n = static_cast<double>(t1 - t0);
    } else {
      sxy = 0;
    }
    r[static_cast<std::size_t>(lag - k_min)] = (sxy - mx * sy - my * sx + n * mx * my) * norm;
  }
  return r;
}

std::vector<double> window_correlation_fft(std::span<const double> x, std::span<const double> y, std::int64_t k_min,
                                           std::int64_t k_max, FftPlanCache& plans) {
  const std::size_t n = x.size();
  if (n == 0 || y.size() != n) return {};
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double qx = 0, qy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    qx += (x[i] - mx) * (x[i] - mx);
    qy += (y[i] - my) * (y[i] - my);
  }
  // A segment is constant when its variance is nothing but rounding.
  if (!(qx > 1e-20 * static_cast<double>(n) * (1.0 + mx * mx)) || !(qy > 1e-20 * static_cast<double>(n) * (1.0 + my * my)))
    return {};
  const std::size_t m = fast_fft_size(2 * n - 1);
  FftPlan& plan = plans.get(m);
  thread_local std::vector<std::complex<double>> xs;
  auto r = plan.real();
  std::fill(r.begin(), r.end(), 0.0);
  for (std::size_t i = 0; i < n; ++i) r[i] = x[i] - mx;
  plan.forward();
  xs.assign(plan.spectrum().begin(), plan.spectrum().end());
  std::fill(r.begin(), r.end(), 0.0);
  for (std::size_t i = 0; i < n; ++i) r[i] = y[i] - my;
  plan.forward();
  auto spec = plan.spectrum();
  for (std::size_t i = 0; i < spec.size(); ++i) spec[i] *= std::conj(xs[i]);
  plan.inverse();
  const double norm = 1.0 / (static_cast<double>(m) * std::sqrt(qx * qy));
  std::vector<double> out(static_cast<std::size_t>(k_max - k_min + 1));
  const auto sm = static_cast<std::int64_t>(m);
  for (std::int64_t k = k_min; k <= k_max; ++k) {
    const std::int64_t index = k >= 0 ? k : sm + k;
    out[static_cast<std::size_t>(k - k_min)] = r[static_cast<std::size_t>(index)] * norm;
  }
  return out;
}

std::vector<std::pair<std::size_t, double>> peak_prominences(std::span<const double> r) {
  const std::size_t n = r.size();
  std::vector<std::pair<std::size_t, double>> peaks;
  if (n < 3) return peaks;
  // Local maxima, flat tops at their middle (as findpeaks / scipy).
  std::vector<std::size_t> at;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (!(r[i - 1] < r[i])) continue;
    std::size_t j = i;
    while (j + 1 < n && r[j + 1] == r[i]) ++j;
    if (j + 1 < n && r[j + 1] < r[i]) at.push_back((i + j) / 2);
    i = j;
  }
  if (at.empty()) return peaks;
  // Bases in O(n): for each sample, the minimum of r between it and the
  // nearest strictly higher sample on one side (or the end), with a stack of
  // strictly decreasing values whose entries carry the minimum of the samples
  // they covered.
  auto bases = [&](bool from_left) {
    std::vector<double> base(n);
    struct Entry {
      double value;
      double gap_min;  // minimum over the samples between this entry and the next one up
    };
    std::vector<Entry> stack;
    double bottom_min = std::numeric_limits<double>::infinity();
    for (std::size_t step = 0; step < n; ++step) {
      const std::size_t i = from_left ? step : n - 1 - step;
      double covered = std::numeric_limits<double>::infinity();
      while (!stack.empty() && stack.back().value <= r[i]) {
        covered = std::min({covered, stack.back().value, stack.back().gap_min});
        stack.pop_back();
      }
      if (stack.empty()) {
        bottom_min = std::min(bottom_min, covered);
        base[i] = std::min(bottom_min, r[i]);
      } else {
        stack.back().gap_min = std::min(stack.back().gap_min, covered);
        base[i] = std::min(stack.back().gap_min, r[i]);
      }
      stack.push_back({r[i], std::numeric_limits<double>::infinity()});
    }
    return base;
  };
  const auto left = bases(true), right = bases(false);
  for (std::size_t i : at) peaks.emplace_back(i, r[i] - std::max(left[i], right[i]));
  return peaks;
}

CorrelationPeak analyse_correlation(std::span<const double> r, Subsample subsample, double prominence_fraction) {
  CorrelationPeak p;
  if (r.empty()) return p;
  p.index = static_cast<std::size_t>(std::max_element(r.begin(), r.end()) - r.begin());
  p.height = r[p.index];
  p.refined_index = static_cast<double>(p.index);
  if (subsample == Subsample::parabolic && p.index > 0 && p.index + 1 < r.size()) {
    const double a = r[p.index - 1], b = r[p.index], c = r[p.index + 1];
    const double denom = a - 2 * b + c;
    if (denom < 0.0) p.refined_index += 0.5 * (a - c) / denom;
  }
  const auto peaks = peak_prominences(r);
  if (peaks.size() < 2) return p;
  // The tallest peak and its prominence; keep peaks prominent enough; the
  // second tallest kept one over the tallest.
  std::size_t tallest = 0;
  for (std::size_t i = 1; i < peaks.size(); ++i)
    if (r[peaks[i].first] > r[peaks[tallest].first]) tallest = i;
  const double min_prominence = prominence_fraction * peaks[tallest].second;
  double second = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < peaks.size(); ++i) {
    if (i == tallest || peaks[i].second < min_prominence) continue;
    second = std::max(second, r[peaks[i].first]);
  }
  const double top = r[peaks[tallest].first];
  if (std::isfinite(second) && top > 0.0) p.spr = std::max(0.0, second / top);
  return p;
}

int robust_outlier_cutoff(std::span<const double> u, std::vector<bool>& keep) {
  int iterations = 0;
  std::vector<double> values, deviations;
  for (;;) {
    values.clear();
    for (std::size_t i = 0; i < u.size(); ++i)
      if (keep[i]) values.push_back(u[i]);
    const std::size_t n = values.size();
    if (n < 3) return iterations;
    auto median = [](std::vector<double>& v) {
      const std::size_t h = v.size() / 2;
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
      const double upper = v[h];
      if (v.size() % 2) return upper;
      return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
    };
    const double centre = median(values);
    deviations.clear();
    for (double v : values) deviations.push_back(std::fabs(v - centre));
    const double s = 1.4826 * median(deviations);
    const double limit = std::sqrt(2.0 * std::log(static_cast<double>(n))) * s;
    ++iterations;
    bool rejected = false;
    for (std::size_t i = 0; i < u.size(); ++i) {
      if (keep[i] && std::fabs(u[i] - centre) > limit) {
        keep[i] = false;
        rejected = true;
      }
    }
    if (!rejected) return iterations;
  }
}

std::pair<std::int64_t, std::int64_t> awcc_lag_range(std::int64_t length, double dx, double fs,
                                                      const AwccOptions& options) {
  if (options.velocity_min && options.velocity_max && dx > 0.0) {
    const auto lo = static_cast<std::int64_t>(std::floor(dx * fs / *options.velocity_max));
    const auto hi = static_cast<std::int64_t>(std::ceil(dx * fs / *options.velocity_min));
    return {std::max<std::int64_t>(lo, -(length - 1)), std::min<std::int64_t>(hi, length - 1)};
  }
  return {-(length - 1), length - 1};
}

void analyse_window(AwccWindow& w, std::span<const double> r, std::int64_t first_lag, double dx, double fs,
                    const AwccOptions& options) {
  if (r.empty()) {
    w.fate = WindowFate::constant;
    return;
  }
  const CorrelationPeak p = analyse_correlation(r, options.subsample, options.prominence_fraction);
  w.r12_max = p.height;
  w.spr = p.spr;
  w.lag_samples = first_lag + static_cast<std::int64_t>(p.index);
  w.lag = (static_cast<double>(first_lag) + p.refined_index) / fs;
  if (w.lag_samples <= 0 || !(w.lag > 0.0)) {
    w.fate = WindowFate::lag;
    w.velocity = 0.0;
    return;
  }
  w.velocity = dx / w.lag;
  w.fate = w.r12_max / (w.spr * w.spr + 1.0) < options.filter_a ? WindowFate::correlation : WindowFate::accepted;
}

void awcc_summarise(AwccResult& result, const AwccOptions& options) {
  auto& windows = result.windows;
  result.windows_total = static_cast<std::int64_t>(windows.size());
  std::vector<double> u(windows.size());
  std::vector<bool> keep(windows.size());
  for (std::size_t i = 0; i < windows.size(); ++i) {
    u[i] = windows[i].velocity;
    keep[i] = windows[i].fate == WindowFate::accepted;
  }
  if (options.roc) {
    result.roc_iterations = robust_outlier_cutoff(u, keep);
    for (std::size_t i = 0; i < windows.size(); ++i)
      if (windows[i].fate == WindowFate::accepted && !keep[i]) windows[i].fate = WindowFate::roc;
  }
  result.windows_accepted = result.rejected_correlation = result.rejected_lag = result.rejected_roc =
      result.rejected_constant = result.lag_zero_windows = 0;
  double sw = 0, swu = 0;
  for (const auto& w : windows) {
    switch (w.fate) {
      case WindowFate::accepted: ++result.windows_accepted; break;
      case WindowFate::correlation: ++result.rejected_correlation; break;
      case WindowFate::lag: ++result.rejected_lag; break;
      case WindowFate::roc: ++result.rejected_roc; break;
      case WindowFate::constant: ++result.rejected_constant; break;
    }
    if (w.fate == WindowFate::lag && w.lag_samples == 0) ++result.lag_zero_windows;
    if (w.fate != WindowFate::accepted) continue;
    const double weight = options.weighting == Weighting::duration ? w.duration : 1.0;
    sw += weight;
    swu += weight * w.velocity;
  }
  result.defined = false;
  result.velocity = result.velocity_rms = result.turbulence_intensity = 0.0;
  result.velocity_ci95 = result.velocity_rms_ci95 = result.turbulence_intensity_ci95 = {};
  if (result.windows_total == 0) {
    result.reason = fmt::format("fewer than Np = {} particles on the leading tip: no window can be formed", options.np);
    return;
  }
  if (result.windows_accepted < 2) {
    if (result.lag_zero_windows * 2 > result.windows_total) {
      result.reason = "most windows peak at lag 0: the tip-to-tip delay is shorter than one sample, so the velocity "
                      "cannot be resolved at this sampling rate (sample faster or use a larger dx)";
    } else {
      result.reason = fmt::format(
          "{} of {} windows accepted ({} rejected by the correlation filter, {} by a non-positive lag, {} by the "
          "outlier cutoff, {} constant): too few for statistics",
          result.windows_accepted, result.windows_total, result.rejected_correlation, result.rejected_lag,
          result.rejected_roc, result.rejected_constant);
    }
    return;
  }
  const double mean = swu / sw;
  double swd = 0;
  for (const auto& w : windows) {
    if (w.fate != WindowFate::accepted) continue;
    const double weight = options.weighting == Weighting::duration ? w.duration : 1.0;
    swd += weight * (w.velocity - mean) * (w.velocity - mean);
  }
  const double rms = std::sqrt(swd / sw);
  const double n = static_cast<double>(result.windows_accepted);
  result.defined = true;
  result.reason.clear();
  result.velocity = mean;
  result.velocity_rms = rms;
  result.turbulence_intensity = rms / mean;
  const double tu = result.turbulence_intensity;
  const double hu = 1.96 * rms / std::sqrt(n);
  const double hr = 1.96 * rms / std::sqrt(2.0 * n);
  const double ht = 1.96 * std::sqrt(tu * tu * (tu * tu / n + 1.0 / (2.0 * n)));
  result.velocity_ci95 = {mean - hu, mean + hu};
  result.velocity_rms_ci95 = {rms - hr, rms + hr};
  result.turbulence_intensity_ci95 = {tu - ht, tu + ht};
}

AwccResult awcc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const AwccOptions& options) {
  if (auto why = options.validate(); !why.empty()) throw std::invalid_argument(why);
  if (leading.sample_count != trailing.sample_count || leading.fs != trailing.fs) {
    throw std::invalid_argument("AWCC needs two signals of the same length and sampling rate");
  }
  AwccResult result;
  result.windows = awcc_windows(leading, options.np);
  const double fs = leading.fs;
  const bool use_fft = options.path == CorrelationPath::fft;
  FftPlanCache plans;
  std::vector<std::uint8_t> dense_x, dense_y;
  std::vector<double> xs, ys;
  for (auto& w : result.windows) {
    const auto [k_min, k_max] = awcc_lag_range(w.length, dx, fs, options);
    std::vector<double> r;
    if (k_max >= k_min) {
      if (use_fft) {
        const auto n = static_cast<std::size_t>(w.length);
        dense_x.resize(n);
        dense_y.resize(n);
        leading.render(w.start, dense_x);
        trailing.render(w.start, dense_y);
        xs.assign(dense_x.begin(), dense_x.end());
        ys.assign(dense_y.begin(), dense_y.end());
        r = window_correlation_fft(xs, ys, k_min, k_max, plans);
      } else {
        r = window_correlation_intervals(leading, trailing, w.start, w.length, k_min, k_max);
      }
    }
    analyse_window(w, r, k_min, dx, fs, options);
  }
  awcc_summarise(result, options);
  return result;
}

}  // namespace awcc
