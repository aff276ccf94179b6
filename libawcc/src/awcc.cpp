#include "awcc/awcc.hpp"
#include "awcc/velocity_series.hpp"

#include "awcc/detail/awcc_driver.hpp"
#include "awcc/detail/awcc_steps.hpp"
#include "awcc/order_statistics.hpp"
#include "overlap_impulses.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace awcc {

std::string_view to_string(WindowFate fate) {
  const auto i = static_cast<std::size_t>(fate);
  return i < window_fate_names.size() ? window_fate_names[i] : "?";
}

std::string_view to_string(Weighting weighting) { return weighting == Weighting::duration ? "duration" : "none"; }


std::string_view to_string(AwccStatus status) {
  switch (status) {
    case AwccStatus::ok: return "ok";
    case AwccStatus::too_few_particles: return "too_few_particles";
    case AwccStatus::delay_below_one_sample: return "delay_below_one_sample";
    case AwccStatus::too_few_windows: return "too_few_windows";
    case AwccStatus::tips_swapped: return "tips_swapped";
    case AwccStatus::no_tip_separation: return "no_tip_separation";
  }
  return "?";
}

std::string_view to_string(AwccQuality quality) {
  switch (quality) {
    case AwccQuality::ok: return "ok";
    case AwccQuality::low: return "low";
    case AwccQuality::insufficient: return "insufficient";
  }
  return "?";
}

AwccWorkspace::AwccWorkspace() : scratch_(std::make_unique<detail::AwccScratch>()) {}
AwccWorkspace::~AwccWorkspace() = default;
AwccWorkspace::AwccWorkspace(AwccWorkspace&&) noexcept = default;
AwccWorkspace& AwccWorkspace::operator=(AwccWorkspace&&) noexcept = default;

Validation AwccOptions::validate() const {
  if (auto v = probe_correction.validate(); !v.ok()) return v;
  if (np < np_min || np > np_max)
    return Validation::invalid("np", fmt::format("np = {}: particles per window must lie in [{}, {}]", np, np_min,
                                                 np_max));
  if (!(filter_a >= 0.0 && filter_a <= 1.0))
    return Validation::invalid("filter-a", fmt::format("filter A = {} must lie in [0, 1]", filter_a));
  if (!(prominence_fraction >= 0.0 && prominence_fraction <= 1.0))
    return Validation::invalid("", fmt::format("prominence fraction {} must lie in [0, 1]", prominence_fraction));
  if (velocity_min.has_value() != velocity_max.has_value())
    return Validation::invalid("velocity-range", "give both ends of the velocity range");
  if (max_lag_samples < 1) return Validation::invalid("", fmt::format("max lag {} samples must be >= 1", max_lag_samples));
  if (velocity_min && !(*velocity_min > 0.0 && *velocity_max > *velocity_min)) {
    return Validation::invalid("velocity-range", fmt::format("velocity range {} to {} m/s must satisfy 0 < min < max",
                                                             *velocity_min, *velocity_max));
  }
  if (windows_reported < 2) {
    return Validation::invalid("windows-reported",
                               fmt::format("windows reported {}: moments need at least 2 windows", windows_reported));
  }
  if (windows_ok < windows_reported) {
    return Validation::invalid(
        "windows-ok", fmt::format("windows ok {} must be at least windows reported {}", windows_ok, windows_reported));
  }
  if (!(yield_ok >= 0.0 && yield_ok <= 1.0))
    return Validation::invalid("yield-ok", fmt::format("yield ok {} must lie in [0, 1]", yield_ok));
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

namespace detail {

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

}  // namespace

namespace {

// std::popcount without the popcnt instruction (the build targets plain
// x86-64) is a call into libgcc per word; this is inline and vectorises.
inline std::size_t bits_set(std::uint64_t w) {
  w -= (w >> 1) & 0x5555555555555555u;
  w = (w & 0x3333333333333333u) + ((w >> 2) & 0x3333333333333333u);
  w = (w + (w >> 4)) & 0x0f0f0f0f0f0f0f0fu;
  return static_cast<std::size_t>((w * 0x0101010101010101u) >> 56);
}

}  // namespace

double PiecewiseCorrelation::at(std::int64_t lag) const {
  const auto it = std::lower_bound(lags.begin(), lags.end(), lag);
  if (it == lags.end()) return values.back();
  const auto j = static_cast<std::size_t>(it - lags.begin());
  if (*it == lag || j == 0) return values[j];
  const double f = static_cast<double>(lag - lags[j - 1]) / static_cast<double>(lags[j] - lags[j - 1]);
  return values[j - 1] + f * (values[j] - values[j - 1]);
}

std::vector<double> PiecewiseCorrelation::expand() const {
  std::vector<double> out;
  if (lags.empty()) return out;
  out.reserve(static_cast<std::size_t>(lags.back() - lags.front() + 1));
  out.push_back(values[0]);
  for (std::size_t j = 1; j < lags.size(); ++j) {
    const std::int64_t gap = lags[j] - lags[j - 1];
    for (std::int64_t m = 1; m <= gap; ++m) {
      out.push_back(m == gap ? values[j] : values[j - 1] + static_cast<double>(m) / static_cast<double>(gap) * (values[j] - values[j - 1]));
    }
  }
  return out;
}

PiecewiseCorrelation window_correlation_piecewise(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                                  std::int64_t length, std::int64_t k_min, std::int64_t k_max,
                                                  AwccWorkspace& workspace) {
  PiecewiseCorrelation out;
  window_correlation_piecewise(x, y, start, length, k_min, k_max, workspace, out);
  return out;
}

void window_correlation_piecewise(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                  std::int64_t length, std::int64_t k_min, std::int64_t k_max,
                                  AwccWorkspace& workspace, PiecewiseCorrelation& out) {
  auto& scratch = workspace.scratch();
  auto& a = scratch.clipped_x;
  auto& b = scratch.clipped_y;
  out.lags.clear();
  out.values.clear();
  clip(x, start, length, a);
  clip(y, start, length, b);
  const double L = static_cast<double>(length);
  std::int64_t air_x = 0, air_y = 0;
  for (const auto& iv : a) air_x += iv.stop - iv.start;
  for (const auto& iv : b) air_y += iv.stop - iv.start;
  const double ax = static_cast<double>(air_x), ay = static_cast<double>(air_y);
  const double mx = ax / L, my = ay / L;
  const double qx = L * mx * (1 - mx), qy = L * my * (1 - my);
  if (!(qx > 0.0) || !(qy > 0.0) || k_max < k_min) return;

  // Overlap sums from the pairs of air intervals (overlap_impulses.hpp). The
  // mean terms need each tip's air in the range the lag overlaps,
  //   sx(k) = sum_t x(t) W(t + k),  sy(k) = sum_t W(t) y(t + k),
  // W the window's indicator on [0, L): overlap sums too, of each tip's
  // intervals with the window as one interval, so they come from the same
  // impulses, exactly and in integers (two lookups into the prefix sums per
  // breakpoint, with their unpredictable walks, were a third of the sweep).
  // Impulses and every other kink (lag 0, where n = L - |k| turns, and the
  // range's ends) are marked on a bit per lag: cheaper than sorting them.
  // The impulses go to arrays that are zero between windows: the sweep
  // visits every lag holding one and clears it (no 4 bytes per lag to zero
  // per window).
  const auto lags = static_cast<std::size_t>(k_max - k_min + 1);
  auto& impulse = scratch.impulse;
  auto& impulse_x = scratch.impulse_x;
  auto& impulse_y = scratch.impulse_y;
  auto& mark = scratch.mark;
  if (impulse.size() < lags) {
    impulse.resize(lags, 0);
    impulse_x.resize(lags, 0);
    impulse_y.resize(lags, 0);
  }
  mark.assign((lags + 63) / 64, 0);
  // Should the sweep not finish (an allocation failing), the arrays are
  // cleared whole, so that the workspace stays usable.
  struct Clear {
    std::vector<std::int32_t>* arrays[3];
    bool swept = false;
    ~Clear() {
      if (swept) return;
      for (auto* v : arrays) std::fill(v->begin(), v->end(), 0);
    }
  } clear{{&impulse, &impulse_x, &impulse_y}};
  detail::OverlapImpulses<std::int32_t> sum{k_min, k_max, impulse, mark.data()};
  detail::OverlapImpulses<std::int32_t> sum_x{k_min, k_max, impulse_x, mark.data()};
  detail::OverlapImpulses<std::int32_t> sum_y{k_min, k_max, impulse_y, mark.data()};
  for (const auto& ia : a) {
    for (const auto& ib : b) sum.add_pair(ia.start, ia.stop, ib.start, ib.stop);
    sum_x.add_pair(ia.start, ia.stop, 0, length);
  }
  for (const auto& ib : b) sum_y.add_pair(0, length, ib.start, ib.stop);
  auto add_break = [&](std::int64_t k) {
    if (k >= k_min && k <= k_max) {
      const auto i = static_cast<std::size_t>(k - k_min);
      mark[i >> 6] |= std::uint64_t{1} << (i & 63);
    }
  };
  add_break(k_min);
  add_break(k_max);
  add_break(0);

  // Sweep the breaks in lag order: each sum from its slope, which is
  // constant between breaks.
  const double norm = 1.0 / std::sqrt(qx * qy);
  // The outputs sized once (a bit per breakpoint) and written through
  // pointers: push_back's capacity checks and its stores of the vectors' ends
  // kept the sweep's sums in memory.
  std::size_t breaks = 0;
  for (const std::uint64_t w : mark) breaks += bits_set(w);
  out.lags.resize(breaks);
  out.values.resize(breaks);
  std::int64_t* lag_out = out.lags.data();
  double* value_out = out.values.data();
  std::int32_t* const impulses = impulse.data();
  std::int32_t* const impulses_x = impulse_x.data();
  std::int32_t* const impulses_y = impulse_y.data();
  const std::uint64_t* const marks = mark.data();
  const std::size_t words = mark.size();
  std::int64_t slope = sum.slope, value = sum.value;
  std::int64_t slope_x = sum_x.slope, sx = sum_x.value;
  std::int64_t slope_y = sum_y.slope, sy = sum_y.value;
  std::int64_t at = k_min;
  for (std::size_t word = 0; word < words; ++word) {
    for (std::uint64_t bits = marks[word]; bits != 0; bits &= bits - 1) {
      const std::size_t i = word * 64 + static_cast<std::size_t>(std::countr_zero(bits));
      const std::int64_t k = k_min + static_cast<std::int64_t>(i);
      const std::int64_t step = k - at;  // every slope is constant on [at, k)
      value += slope * step;
      sx += slope_x * step;
      sy += slope_y * step;
      at = k;
      const double n = static_cast<double>(length - (k >= 0 ? k : -k));
      *lag_out++ = k;
      *value_out++ = (static_cast<double>(value) - mx * static_cast<double>(sy) - my * static_cast<double>(sx) +
                      n * mx * my) *
                     norm;
      slope += impulses[i];
      slope_x += impulses_x[i];
      slope_y += impulses_y[i];
      impulses[i] = 0;
      impulses_x[i] = 0;
      impulses_y[i] = 0;
    }
  }
  clear.swept = true;
}

std::vector<double> window_correlation_intervals(const AirIntervals& x, const AirIntervals& y, std::int64_t start,
                                                 std::int64_t length, std::int64_t k_min, std::int64_t k_max,
                                                 AwccWorkspace& workspace) {
  return window_correlation_piecewise(x, y, start, length, k_min, k_max, workspace).expand();
}

std::vector<double> window_correlation_fft(std::span<const double> x, std::span<const double> y, std::int64_t k_min,
                                           std::int64_t k_max, AwccWorkspace& workspace) {
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
  auto& scratch = workspace.scratch();
  const FftPlan& plan = scratch.plans.get(m);
  auto& buffers = scratch.fft;
  buffers.resize(m);
  auto& xs = scratch.spectrum;
  auto r = buffers.real();
  std::fill(r.begin(), r.end(), 0.0);
  for (std::size_t i = 0; i < n; ++i) r[i] = x[i] - mx;
  plan.forward(buffers);
  xs.assign(buffers.spectrum().begin(), buffers.spectrum().end());
  std::fill(r.begin(), r.end(), 0.0);
  for (std::size_t i = 0; i < n; ++i) r[i] = y[i] - my;
  plan.forward(buffers);
  auto spec = buffers.spectrum();
  for (std::size_t i = 0; i < spec.size(); ++i) spec[i] *= std::conj(xs[i]);
  plan.inverse(buffers);
  const double norm = 1.0 / (static_cast<double>(m) * std::sqrt(qx * qy));
  std::vector<double> out(static_cast<std::size_t>(k_max - k_min + 1));
  const auto sm = static_cast<std::int64_t>(m);
  for (std::int64_t k = k_min; k <= k_max; ++k) {
    const std::int64_t index = k >= 0 ? k : sm + k;
    out[static_cast<std::size_t>(k - k_min)] = r[static_cast<std::size_t>(index)] * norm;
  }
  return out;
}

namespace {

// Local maxima of r (a flat top spans [first, last], as findpeaks / scipy)
// and their prominences, into scratch.tops and scratch.prominence.
void find_tops(std::span<const double> r, AwccScratch& scratch) {
  const std::size_t n = r.size();
  auto& tops = scratch.tops;
  tops.clear();
  if (n < 3) return;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (!(r[i - 1] < r[i])) continue;
    std::size_t j = i;
    while (j + 1 < n && r[j + 1] == r[i]) ++j;
    if (j + 1 < n && r[j + 1] < r[i]) tops.push_back({i, j});
    i = j;
  }
}

void top_prominences(std::span<const double> r, AwccScratch& scratch) {
  const std::size_t n = r.size();
  auto& tops = scratch.tops;
  auto& prominence = scratch.prominence;
  prominence.clear();
  find_tops(r, scratch);
  if (tops.empty()) return;
  // Bases in O(n): for each sample, the minimum of r between it and the
  // nearest strictly higher sample on one side (or the end), from a stack of
  // strictly decreasing values whose entries carry the minimum of the samples
  // they covered. On a piecewise-linear function these minima sit at the
  // breakpoints, so its sampled form at the breakpoints gives the same bases.
  auto& left = scratch.left;
  auto& right = scratch.right;
  auto bases = [&](bool from_left, std::vector<double>& base) {
    base.resize(n);
    // (value, minimum over the samples between this entry and the next one up)
    auto& stack = scratch.stack;
    stack.clear();
    double bottom_min = std::numeric_limits<double>::infinity();
    for (std::size_t step = 0; step < n; ++step) {
      const std::size_t i = from_left ? step : n - 1 - step;
      double covered = std::numeric_limits<double>::infinity();
      while (!stack.empty() && stack.back().first <= r[i]) {
        covered = std::min({covered, stack.back().first, stack.back().second});
        stack.pop_back();
      }
      if (stack.empty()) {
        bottom_min = std::min(bottom_min, covered);
        base[i] = std::min(bottom_min, r[i]);
      } else {
        stack.back().second = std::min(stack.back().second, covered);
        base[i] = std::min(stack.back().second, r[i]);
      }
      stack.emplace_back(r[i], std::numeric_limits<double>::infinity());
    }
  };
  bases(true, left);
  bases(false, right);
  prominence.reserve(tops.size());
  // A flat top's bases are those of its outer ends.
  for (const auto& t : tops) prominence.push_back(r[t.first] - std::max(left[t.first], right[t.second]));
}

// The same as (position of the top's middle, prominence) pairs, for samples
// at increasing positions.
template <class Position>
std::vector<std::pair<std::int64_t, double>> prominences(std::span<const double> r, Position position,
                                                        AwccScratch& scratch) {
  top_prominences(r, scratch);
  std::vector<std::pair<std::int64_t, double>> peaks;
  peaks.reserve(scratch.tops.size());
  for (std::size_t i = 0; i < scratch.tops.size(); ++i) {
    const auto& t = scratch.tops[i];
    peaks.emplace_back((position(t.first) + position(t.second)) / 2, scratch.prominence[i]);
  }
  return peaks;
}

// The prominence of one top of r, from its definition: the top's value less
// the higher of its two bases, a base being the minimum of r from the top
// (its outer end for a flat top) to the nearest strictly higher sample on
// that side, or to the end. The same minima over the same samples as
// top_prominences' stacks, so the same number.
double prominence_of(std::span<const double> r, const std::pair<std::size_t, std::size_t>& t) {
  const double h = r[t.first];
  double left = h, right = h;
  for (std::size_t j = t.first; j-- > 0 && !(r[j] > h);) left = std::min(left, r[j]);
  for (std::size_t j = t.second + 1; j < r.size() && !(r[j] > h); ++j) right = std::min(right, r[j]);
  return h - std::max(left, right);
}

// Second-tallest prominent peak over the tallest (0 with one), of the tops
// find_tops found in r. A peak's height is its top's value (a flat top is
// flat: every sample of it, its middle too, holds that value). Only the
// prominences the answer reads are computed: the tallest top's, then the
// others' by decreasing height until one passes the fraction of it (the
// tallest that passes is the second peak; ties of height give the same
// ratio whichever is taken).
double secondary_peak_ratio(std::span<const double> r, AwccScratch& scratch, double prominence_fraction) {
  const auto& tops = scratch.tops;
  if (tops.size() < 2) return 0.0;
  auto& height = scratch.prominence;  // heights of the tops not yet tried
  height.resize(tops.size());
  std::size_t tallest = 0;
  for (std::size_t i = 0; i < tops.size(); ++i) {
    height[i] = r[tops[i].first];
    if (height[i] > height[tallest]) tallest = i;
  }
  const double top = height[tallest];
  const double min_prominence = prominence_fraction * prominence_of(r, tops[tallest]);
  height[tallest] = -std::numeric_limits<double>::infinity();
  for (std::size_t tried = 1; tried < tops.size(); ++tried) {
    const std::size_t next = static_cast<std::size_t>(std::max_element(height.begin(), height.end()) - height.begin());
    if (!(prominence_of(r, tops[next]) < min_prominence)) {
      const double second = height[next];
      return top > 0.0 ? std::max(0.0, second / top) : 0.0;
    }
    height[next] = -std::numeric_limits<double>::infinity();
  }
  return 0.0;
}

// Peaks and prominences depend only on the turning points (where the sign
// of the slope changes, plateau ends included, and the two ends): the minimum
// between a peak and the first higher sample is a turning point, and the scan
// for a higher sample stops at the turning point that follows it. Keeping
// only those makes the prominence scan a few hundred points long. Between two
// consecutive turning points r is monotone, so a flat top among them is flat
// in r too, and its height is the turning points' value.
void turning_points(std::span<const double> r, std::vector<double>& turns) {
  const std::size_t n = r.size();
  turns.resize(n);
  if (n == 0) return;
  // Every sample is written, and kept (the count advanced) where it turns:
  // no branch to mispredict on the turns, about one sample in three.
  double* out = turns.data();
  std::size_t m = 0;
  out[m++] = r[0];
  auto sign = [](double d) { return (d > 0.0) - (d < 0.0); };
  int before = n > 1 ? sign(r[1] - r[0]) : 0;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const int after = sign(r[i + 1] - r[i]);
    out[m] = r[i];
    m += static_cast<std::size_t>(before != after);
    before = after;
  }
  if (n > 1) out[m++] = r[n - 1];
  turns.resize(m);
}

// The SPR of a correlation from its turning points.
double spr_of(std::span<const double> r, double prominence_fraction, AwccScratch& scratch) {
  turning_points(r, scratch.turns);
  find_tops(scratch.turns, scratch);
  return secondary_peak_ratio(scratch.turns, scratch, prominence_fraction);
}

}  // namespace

std::vector<std::pair<std::size_t, double>> peak_prominences(std::span<const double> r) {
  std::vector<std::pair<std::size_t, double>> out;
  AwccScratch scratch;
  for (const auto& [p, prominence] : prominences(r, [](std::size_t i) { return static_cast<std::int64_t>(i); }, scratch))
    out.emplace_back(static_cast<std::size_t>(p), prominence);
  return out;
}

std::vector<std::pair<std::int64_t, double>> peak_prominences(std::span<const double> values,
                                                              std::span<const std::int64_t> positions) {
  AwccScratch scratch;
  return prominences(values, [&](std::size_t i) { return positions[i]; }, scratch);
}

CorrelationPeak analyse_correlation(std::span<const double> r, Subsample subsample, double prominence_fraction,
                                    AwccWorkspace& workspace) {
  CorrelationPeak p;
  if (r.empty()) return p;
  p.index = static_cast<std::size_t>(std::max_element(r.begin(), r.end()) - r.begin());
  p.height = r[p.index];
  p.refined_index = static_cast<double>(p.index);
  p.refined_index += subsample_offset(
      subsample, [&](std::int64_t j) { return r[static_cast<std::size_t>(j)]; }, static_cast<std::int64_t>(p.index),
      0, static_cast<std::int64_t>(r.size()) - 1);
  p.spr = spr_of(r, prominence_fraction, workspace.scratch());
  return p;
}

CorrelationPeak analyse_correlation(const PiecewiseCorrelation& r, Subsample subsample, double prominence_fraction,
                                    AwccWorkspace& workspace) {
  CorrelationPeak p;
  if (r.empty()) return p;
  const auto j = static_cast<std::size_t>(std::max_element(r.values.begin(), r.values.end()) - r.values.begin());
  const std::int64_t k_min = r.lags.front(), k = r.lags[j];
  p.index = static_cast<std::size_t>(k - k_min);
  p.height = r.values[j];
  p.refined_index = static_cast<double>(p.index);
  p.refined_index += subsample_offset(subsample, [&](std::int64_t lag) { return r.at(lag); }, k, k_min, r.lags.back());
  // Peaks, prominences and heights of the piecewise-linear function are
  // those of its breakpoints' values (the bases and the tops sit on breakpoints).
  p.spr = spr_of(r.values, prominence_fraction, workspace.scratch());
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

WeightedMoments weighted_moments(std::span<const double> values, std::span<const double> weights) {
  double total = 0, sum = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    total += weights[i];
    sum += weights[i] * values[i];
  }
  const double m = sum / total;
  double squares = 0;
  for (std::size_t i = 0; i < values.size(); ++i) squares += weights[i] * (values[i] - m) * (values[i] - m);
  return {m, std::sqrt(squares / total)};
}

MomentIntervals moment_intervals95(double mean, double rms, std::int64_t count) {
  return moment_intervals95(mean, rms, count, mean);
}

MomentIntervals moment_intervals95(double mean, double rms, std::int64_t count, double scale) {
  MomentIntervals out;
  const double n = static_cast<double>(count);
  const double tu = rms / scale;
  out.turbulence_intensity = tu;
  out.mean_half = 1.96 * rms / std::sqrt(n);
  out.rms_half = 1.96 * rms / std::sqrt(2.0 * n);
  out.turbulence_intensity_half = 1.96 * std::sqrt(tu * tu * (tu * tu / n + 1.0 / (2.0 * n)));
  out.mean = {mean - out.mean_half, mean + out.mean_half};
  out.rms = {rms - out.rms_half, rms + out.rms_half};
  out.tu = {tu - out.turbulence_intensity_half, tu + out.turbulence_intensity_half};
  return out;
}

std::pair<AwccQuality, std::string> reported_quality(std::int64_t accepted, std::int64_t total, std::int64_t ok_count,
                                                     double yield_ok, const MomentIntervals& intervals,
                                                     const QualityWords& words) {
  if (accepted < ok_count) {
    return {AwccQuality::low,
            fmt::format("{} {} (fewer than {}): Tu's 95 % interval is +/- {:.0f} %", accepted, words.counted, ok_count,
                        100.0 * intervals.turbulence_intensity_half / std::max(intervals.turbulence_intensity, 1e-300))};
  }
  const double yield = static_cast<double>(accepted) / static_cast<double>(total);
  if (yield < yield_ok) {
    return {AwccQuality::low, fmt::format("{} {:.1f} % ({} of {} {}, below {:g} %): {} may not represent the flow",
                                          words.yield, 100.0 * yield, accepted, total, words.ratio, 100.0 * yield_ok,
                                          words.selection)};
  }
  return {AwccQuality::ok, std::string()};
}

std::pair<std::int64_t, std::int64_t> awcc_lag_range(std::int64_t length, double dx, double fs,
                                                      const AwccOptions& options) {
  if (options.velocity_min && options.velocity_max && dx > 0.0) {
    const auto lo = static_cast<std::int64_t>(std::floor(dx * fs / *options.velocity_max));
    const auto hi = static_cast<std::int64_t>(std::ceil(dx * fs / *options.velocity_min));
    const std::int64_t reach = std::min(length - 1, options.max_lag_samples);
    return {std::max<std::int64_t>(lo, -reach), std::min<std::int64_t>(hi, reach)};
  }
  const std::int64_t reach = std::min(length - 1, options.max_lag_samples);
  return {-reach, reach};
}

void analyse_window(AwccWindow& w, const CorrelationPeak& p, bool constant, std::int64_t first_lag, double dx,
                    double fs, const AwccOptions& options) {
  if (constant) {
    w.fate = WindowFate::constant;
    return;
  }
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

void analyse_window(AwccWindow& w, std::span<const double> r, std::int64_t first_lag, double dx, double fs,
                    const AwccOptions& options, AwccWorkspace& workspace) {
  const CorrelationPeak p =
      r.empty() ? CorrelationPeak{} : analyse_correlation(r, options.subsample, options.prominence_fraction, workspace);
  analyse_window(w, p, r.empty(), first_lag, dx, fs, options);
}

void correct_windows(AwccResult& result, double dx, const AwccOptions& options) {
  for (auto& w : result.windows) w.measured_velocity = w.velocity;
  const auto& o = options.probe_correction;
  if (!o.enabled) return;
  result.probe_corrected = true;
  result.windows_not_bubbly = 0;
  for (auto& w : result.windows) {
    if (w.fate != WindowFate::accepted) continue;
    const auto c = correct_window(w.velocity, w.void_fraction, w.count_rate, dx, o);
    if (c.outcome == CorrectionOutcome::failed) w.fate = WindowFate::correction;
    else w.velocity = c.velocity;
    if (c.outcome == CorrectionOutcome::not_bubbly) ++result.windows_not_bubbly;
  }
}

void awcc_summarise(AwccResult& result, const AwccOptions& options) {
  auto& windows = result.windows;
  result.windows_total = static_cast<std::int64_t>(windows.size());
  std::int64_t clear_negative = 0, clear_positive = 0;
  for (const auto& w : windows) {
    const bool clear = w.r12_max / (w.spr * w.spr + 1.0) >= options.filter_a;
    if (w.fate == WindowFate::accepted) ++clear_positive;
    if (w.fate == WindowFate::lag && w.lag_samples < 0 && clear) ++clear_negative;
  }
  if (options.roc) result.roc_iterations = cut_outliers(windows, WindowFate::accepted, WindowFate::roc);
  result.windows_by_fate.fill(0);
  result.lag_zero_windows = result.negative_lag_windows = 0;
  for (const auto& w : windows) {
    ++result.windows_by_fate[static_cast<std::size_t>(w.fate)];
    if (w.fate == WindowFate::lag && w.lag_samples == 0) ++result.lag_zero_windows;
    if (w.fate == WindowFate::lag && w.lag_samples < 0) ++result.negative_lag_windows;
  }
  result.windows_accepted = result.count(WindowFate::accepted);
  result.status = AwccStatus::too_few_windows;
  result.quality = AwccQuality::insufficient;
  result.velocity = result.velocity_rms = result.turbulence_intensity = 0.0;
  result.velocity_ci95 = result.velocity_rms_ci95 = result.turbulence_intensity_ci95 = {};
  result.time_scale_ratio.reset();
  result.weighting_gap.reset();
  result.mean_lag_samples = 0.0;
  result.one_sample_lag = result.chance_yield = false;
  auto insufficient = [&result] { result.quality_reason = result.message; };
  if (result.windows_total == 0) {
    result.status = AwccStatus::too_few_particles;
    result.message = fmt::format("fewer than Np = {} particles on the leading tip: no window can be formed", options.np);
    insufficient();
    return;
  }
  // Swapped tips (or a dx of the wrong sign): the windows whose peak is clear
  // (it passes the correlation filter whatever its sign) peak at negative
  // lags. Unrelated signals peak on either side alike, negative ~ Binomial(n,
  // 1/2), so negative - positive has sd sqrt(n): more than 3 sd of excess
  // (one-sided p = 0.0013; at least 10 clear windows) says the tips are swapped.
  if (static_cast<double>(clear_negative - clear_positive) > 3.0 * std::sqrt(static_cast<double>(clear_negative + clear_positive))) {
    tips_swapped(result, fmt::format("{} of {} windows with a clear correlation peak have it at a negative lag: the "
                                     "trailing tip's signal leads, so the tips are swapped (or dx has the wrong "
                                     "sign); exchange the tips' channels",
                                     clear_negative, clear_negative + clear_positive));
    return;
  }
  if (result.windows_accepted < options.windows_reported) {
    if (result.lag_zero_windows * 2 > result.windows_total) {
      result.status = AwccStatus::delay_below_one_sample;
      result.message = "most windows peak at lag 0: the tip-to-tip delay is shorter than one sample, so the velocity "
                       "cannot be resolved at this sampling rate (sample faster or use a larger dx)";
    } else {
      result.message = fmt::format(
          "{} of {} windows accepted ({} rejected by the correlation filter, {} by a non-positive lag, {} by the "
          "outlier cutoff, {} constant{}): too few for statistics (fewer than {})",
          result.windows_accepted, result.windows_total, result.count(WindowFate::correlation),
          result.count(WindowFate::lag), result.count(WindowFate::roc), result.count(WindowFate::constant),
          result.count(WindowFate::too_short)
              ? fmt::format(", {} too short for the velocity range", result.count(WindowFate::too_short))
              : std::string(),
          options.windows_reported);
    }
    insufficient();
    return;
  }
  const auto moments = [&](double AwccWindow::*velocity) {
    return accepted_moments(windows, options.weighting, velocity);
  };
  const auto [mean, rms] = moments(&AwccWindow::velocity);
  result.status = AwccStatus::ok;
  result.message.clear();
  result.velocity = mean;
  result.velocity_rms = rms;
  result.weighting = options.weighting;
  const auto intervals = moment_intervals95(mean, rms, result.windows_accepted);
  result.turbulence_intensity = intervals.turbulence_intensity;
  if (result.probe_corrected) {
    // The measured moments over the same windows, for comparison.
    const auto [measured_mean, measured_rms] = moments(&AwccWindow::measured_velocity);
    result.velocity_measured = measured_mean;
    result.velocity_rms_measured = measured_rms;
    result.turbulence_intensity_measured = measured_rms / measured_mean;
  }
  result.velocity_ci95 = intervals.mean;
  result.velocity_rms_ci95 = intervals.rms;
  result.turbulence_intensity_ci95 = intervals.tu;
  std::tie(result.quality, result.quality_reason) =
      reported_quality(result.windows_accepted, result.windows_total, options.windows_ok, options.yield_ok, intervals,
                       {"accepted windows", "data yield", "windows accepted", "the accepted windows"});
  result.time_scale_ratio = capped_time_scale_ratio(result, time_scale_ratio_cap);
  {
    std::vector<double> velocities, durations;
    for (const auto& w : windows) {
      if (w.fate != WindowFate::accepted) continue;
      velocities.push_back(w.velocity);
      durations.push_back(w.duration);
    }
    result.weighting_gap = weighting_gap(velocities, durations, result.turbulence_intensity);
  }
  result.mean_lag_samples = mean_lag_samples(windows, options.weighting);
  const double yield = static_cast<double>(result.windows_accepted) / static_cast<double>(result.windows_total);
  if (yield < chance_data_yield) {
    result.chance_yield = true;
    result.quality = AwccQuality::low;
    result.quality_reason = fmt::format(
        "a chance yield: {} of {} windows accepted ({:.3g} %, below {:g} %), about what signals that share no bubble "
        "give by chance, so the accepted windows may be chance peaks rather than the flow's (check that the tips "
        "are aligned with the flow and the lateral separation dy is small against the bubbles)",
        result.windows_accepted, result.windows_total, 100.0 * yield, 100.0 * chance_data_yield);
  }
}

double mean_lag_samples(std::span<const AwccWindow> windows, Weighting weighting) {
  double weights = 0.0, inverse = 0.0;
  for (const auto& w : windows) {
    if (w.fate != WindowFate::accepted || w.lag_samples <= 0) continue;
    const double weight = weighting == Weighting::duration ? w.duration : 1.0;
    weights += weight;
    inverse += weight / static_cast<double>(w.lag_samples);
  }
  return inverse > 0.0 ? weights / inverse : 0.0;
}

void flag_unresolved_lag(AwccResult& result, double dx, double fs) {
  if (!result.ok() || !(result.mean_lag_samples > 0.0) || result.mean_lag_samples >= least_resolved_lag_samples) return;
  const auto [lo, hi] = one_sample_velocity_bounds(dx, fs);
  const std::string why = fmt::format(
      "a lag of one sample: the accepted windows peak at a mean lag of {:.2f} samples (below {:g}), and every "
      "delay of 0.5-1.5 samples reads as one, so the velocity is bounded ({:.4g}-{:.4g} m/s), not measured, and "
      "Tu is not resolved (sample faster or move the tips apart)",
      result.mean_lag_samples, least_resolved_lag_samples, lo, hi);
  result.one_sample_lag = true;
  result.quality = AwccQuality::low;
  // After a chance yield's reason, both; in place of the generic ones.
  result.quality_reason = result.chance_yield ? result.quality_reason + "; " + why : why;
}

namespace {

// A quality reason of `result` lowered to low: after another specific
// reason, both; in place of a generic one (too few windows, a low yield).
void lower_quality(AwccResult& result, const std::string& why, bool specific) {
  result.quality = AwccQuality::low;
  result.quality_reason = specific ? result.quality_reason + "; " + why : why;
}

}  // namespace

void judge_lag_range_and_spread(AwccResult& result, double dx, double fs, const AwccOptions& options) {
  result.windows_at_least_lag = result.windows_at_greatest_lag = 0;
  result.turbulence_measured = true;
  if (!result.ok()) return;
  const bool ranged = options.velocity_min && options.velocity_max && dx > 0.0;
  std::optional<double> shared_lag;
  bool one_lag = true;
  for (const auto& w : result.windows) {
    if (w.fate != WindowFate::accepted) continue;
    if (!shared_lag) shared_lag = w.lag;
    one_lag = one_lag && w.lag == *shared_lag;
    if (!ranged) continue;
    // An end set by the velocity range, not by the window's own length.
    const auto [least, greatest] = awcc_lag_range(w.length, dx, fs, options);
    const std::int64_t reach = std::min(w.length - 1, options.max_lag_samples);
    result.windows_at_least_lag += w.lag_samples == least && least > -reach;
    result.windows_at_greatest_lag += w.lag_samples == greatest && greatest < reach;
  }
  bool specific = result.quality == AwccQuality::low && (result.chance_yield || result.one_sample_lag);
  if (lags_pile_up_at_range_end(result)) {
    lower_quality(result, fmt::format(
        "{} of {} accepted windows peak at an end of the lags the velocity range {}-{} m/s lets AWCC search ({} at "
        "the least lag, the fastest velocity; {} at the greatest): the flow's delays run past it, so those peaks are "
        "the range's and the mean and Tu are truncated; widen the velocity range (velocity-range) or drop it",
        result.windows_at_least_lag + result.windows_at_greatest_lag, result.windows_accepted,
        *options.velocity_min, *options.velocity_max, result.windows_at_least_lag, result.windows_at_greatest_lag),
                  specific);
    specific = true;
  }
  if (one_lag && shared_lag && *shared_lag > 0.0) {
    // The true delays lie within half a sample of the common lag: the
    // velocity is bounded by them, and its spread is not measured.
    const double lag_samples = *shared_lag * fs;
    const double lo = dx * fs / (lag_samples + 0.5), hi = lag_samples > 0.5 ? dx * fs / (lag_samples - 0.5) : 0.0;
    result.turbulence_measured = false;
    result.velocity_ci95 = {std::min(result.velocity_ci95.lower, lo),
                            hi > 0.0 ? std::max(result.velocity_ci95.upper, hi) : result.velocity_ci95.upper};
    lower_quality(result, fmt::format(
        "every one of the {} accepted windows peaks at the same lag, {:.4g} samples{}: their velocities are all "
        "dx / lag, so u_rms is 0 by the lag's resolution, not by the flow, and Tu is not measured; the delays lie "
        "within half a sample of it, so the velocity lies within {:.4g}-{:.4g} m/s (refine the peak, subsample = "
        "triangle, sample faster, or widen the velocity range)",
        result.windows_accepted, lag_samples,
        result.count(WindowFate::roc) > 0
            ? fmt::format(" (the outlier cutoff rejected the other {}: with half the windows or more at one lag, its "
                          "spread estimate, 1.4826 times the median absolute deviation, is 0)",
                          result.count(WindowFate::roc))
            : std::string(),
        lo, hi > 0.0 ? hi : std::numeric_limits<double>::infinity()),
                  specific);
  }
}

}  // namespace detail

bool lags_pile_up_at_range_end(const AwccResult& result) {
  if (!result.ok() || result.windows_accepted <= 0) return false;
  const auto at_ends = static_cast<double>(result.windows_at_least_lag + result.windows_at_greatest_lag);
  return at_ends > lag_range_end_share * static_cast<double>(result.windows_accepted);
}

std::pair<double, double> accepted_moments(std::span<const AwccWindow> windows, Weighting weighting,
                                           double AwccWindow::*velocity) {
  std::vector<double> values, weights;
  for (const auto& w : windows) {
    if (w.fate != WindowFate::accepted) continue;
    values.push_back(w.*velocity);
    weights.push_back(weighting == Weighting::duration ? w.duration : 1.0);
  }
  if (values.empty()) return {0.0, 0.0};
  const auto m = detail::weighted_moments(values, weights);
  return {m.mean, m.rms};
}

AwccResult awcc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const AwccOptions& options) {
  AwccWorkspace workspace;
  return awcc(leading, trailing, dx, options, workspace);
}

AwccResult awcc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const AwccOptions& options,
                AwccWorkspace& workspace) {
  options.validate().throw_if_failed();
  if (options.signal != CorrelationSignal::binary) {
    throw std::invalid_argument("AWCC of air intervals correlates binary signals; raw voltages need the recording");
  }
  if (leading.sample_count != trailing.sample_count || leading.fs != trailing.fs) {
    throw std::invalid_argument("AWCC needs two signals of the same length and sampling rate");
  }
  if (options.path == CorrelationPath::fft) {
    detail::RenderedFftCorrelations rendered(leading, trailing);
    return detail::run_awcc(leading, dx, options, rendered, workspace);
  }
  detail::IntervalCorrelations intervals(leading, trailing);
  return detail::run_awcc(leading, dx, options, intervals, workspace);
}

namespace detail {

WindowPeak fft_window_peak(std::span<const double> x, std::span<const double> y, std::int64_t k_min,
                           std::int64_t k_max, const AwccOptions& options, AwccWorkspace& workspace) {
  const auto r = window_correlation_fft(x, y, k_min, k_max, workspace);
  if (r.empty()) return {.peak = {}, .constant = true};
  return {.peak = analyse_correlation(r, options.subsample, options.prominence_fraction, workspace), .constant = false};
}

WindowPeak IntervalCorrelations::correlate(const AwccWindow& w, std::int64_t k_min, std::int64_t k_max,
                                           const AwccOptions& options, AwccWorkspace& workspace) {
  auto& r = workspace.scratch().piecewise;
  window_correlation_piecewise(leading_, trailing_, w.start, w.length, k_min, k_max, workspace, r);
  if (r.empty()) return {.peak = {}, .constant = true};
  return {.peak = analyse_correlation(r, options.subsample, options.prominence_fraction, workspace), .constant = false};
}

WindowPeak RenderedFftCorrelations::correlate(const AwccWindow& w, std::int64_t k_min, std::int64_t k_max,
                                              const AwccOptions& options, AwccWorkspace& workspace) {
  auto& s = workspace.scratch();
  const auto n = static_cast<std::size_t>(w.length);
  s.rendered_x.resize(n);
  s.rendered_y.resize(n);
  leading_.render(w.start, s.rendered_x);
  trailing_.render(w.start, s.rendered_y);
  s.samples_x.assign(s.rendered_x.begin(), s.rendered_x.end());
  s.samples_y.assign(s.rendered_y.begin(), s.rendered_y.end());
  return fft_window_peak(s.samples_x, s.samples_y, k_min, k_max, options, workspace);
}

AwccResult run_awcc(const AirIntervals& leading, double dx, const AwccOptions& options, WindowCorrelations& source,
                    AwccWorkspace& workspace) {
  AwccResult result;
  result.np = options.np;
  result.options = options;
  result.windows = awcc_windows(leading, options.np);
  const double fs = leading.fs;
  for (auto& w : result.windows) {
    const auto [k_min, k_max] = awcc_lag_range(w.length, dx, fs, options);
    if (k_max < k_min) {
      source.skip(w, workspace);
      w.fate = WindowFate::too_short;
      continue;
    }
    const WindowPeak p = source.correlate(w, k_min, k_max, options, workspace);
    analyse_window(w, p.peak, p.constant, k_min, dx, fs, options);
  }
  correct_windows(result, dx, options);
  awcc_summarise(result, options);
  if (!(dx > 0.0) && result.ok()) no_tip_separation(result);
  flag_unresolved_lag(result, dx, fs);
  judge_lag_range_and_spread(result, dx, fs, options);
  return result;
}

}  // namespace detail

void detail::no_tip_separation(AwccResult& result) {
  result.status = AwccStatus::no_tip_separation;
  result.message = "no tip separation given: the velocity cannot be computed";
  result.quality = AwccQuality::insufficient;
  result.quality_reason = result.message;
  result.velocity = result.velocity_rms = result.turbulence_intensity = 0.0;
  result.velocity_ci95 = result.velocity_rms_ci95 = result.turbulence_intensity_ci95 = {};
  result.time_scale_ratio.reset();
  result.one_sample_lag = result.chance_yield = false;
}

void detail::tips_swapped(AwccResult& result, const std::string& why) {
  result.status = AwccStatus::tips_swapped;
  result.message = why;
  result.quality = AwccQuality::insufficient;
  result.quality_reason = why;
  result.velocity = result.velocity_rms = result.turbulence_intensity = 0.0;
  result.velocity_ci95 = result.velocity_rms_ci95 = result.turbulence_intensity_ci95 = {};
  result.time_scale_ratio.reset();
  result.one_sample_lag = result.chance_yield = false;
}

}  // namespace awcc
