#include "awcc/fscc.hpp"

#include "awcc/detail/fscc_steps.hpp"
#include "awcc/lagged_pearson.hpp"
#include "overlap_impulses.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <future>
#include <iterator>
#include <optional>
#include <stdexcept>

namespace awcc {

Validation FsccOptions::validate() const {
  if (segments < 1) return Validation::invalid("segments", fmt::format("segments = {}: at least 1", segments));
  if (!felder_lags && !(max_lag > 0.0 && std::isfinite(max_lag)))
    return Validation::invalid("max-lag", fmt::format("max lag {} s must be > 0", max_lag));
  return {};
}


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
  const std::size_t ny = yi.size();
  std::int64_t* const counts = impulse.data();
  // Only x's intervals that meet [t0, t1) add pairs, and y's first candidate
  // only moves forward: both are found by binary search rather than walked
  // to from the record's start (FSCC calls this for each of its segments'
  // windows and the gaps between them; the sums are the same integers).
  const auto& xi = x.intervals;
  auto ix = std::partition_point(xi.begin(), xi.end(), [t0](const AirInterval& a) { return a.stop <= t0; });
  std::size_t first = 0;
  if (ix != xi.end()) {
    const std::int64_t reach = std::max(ix->start, t0) + k_min;
    first = static_cast<std::size_t>(
        std::partition_point(yi.begin(), yi.end(), [reach](const AirInterval& b) { return b.stop <= reach; }) -
        yi.begin());
  }
  for (; ix != xi.end() && ix->start < t1; ++ix) {
    const auto& iv = *ix;
    const std::int64_t a0 = std::max(iv.start, t0), a1 = std::min(iv.stop, t1);
    if (a0 >= a1) continue;
    // y intervals that can overlap a shifted by a lag in range: b1 > a0 + k_min, b0 <= a1 + k_max.
    while (first < ny && yi[first].stop <= a0 + k_min) ++first;
    // A pair's impulses lie between b0 - a1 and b1 - a0. y's intervals are
    // sorted and disjoint, so along j the pairs whose lowest impulse falls
    // below k_min come first, then those with all four in range, then those
    // whose highest falls beyond k_max: the middle run, most pairs at a high
    // count rate, adds its impulses without add_pair's range tests (the same
    // integers, so the same sums).
    std::size_t j = first;
    for (; j < ny && yi[j].start <= a1 + k_max && yi[j].start - a1 < k_min; ++j) {
      sum.add_pair(a0, a1, yi[j].start, yi[j].stop);
    }
    for (; j < ny && yi[j].stop - a0 <= k_max; ++j) {
      const std::int64_t b0 = yi[j].start - k_min, b1 = yi[j].stop - k_min;
      ++counts[b0 - a1];
      --counts[b0 - a0];
      --counts[b1 - a1];
      ++counts[b1 - a0];
    }
    for (; j < ny && yi[j].start <= a1 + k_max; ++j) {
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
  const FftPlan& plan = plans.get(m);
  FftBuffers buffers(m);
  std::vector<std::complex<double>> xs(m / 2 + 1);
  std::vector<std::uint8_t> dense(block + lags - 1);
  for (std::int64_t b = t0; b < t1; b += static_cast<std::int64_t>(block)) {
    const auto len = static_cast<std::size_t>(std::min<std::int64_t>(static_cast<std::int64_t>(block), t1 - b));
    x.render(b, std::span<std::uint8_t>(dense.data(), len));
    auto r = buffers.real();
    std::fill(r.begin(), r.end(), 0.0);
    bool any = false;
    for (std::size_t i = 0; i < len; ++i) {
      r[i] = dense[i];
      any = any || dense[i];
    }
    if (!any) continue;
    plan.forward(buffers);
    std::copy(buffers.spectrum().begin(), buffers.spectrum().end(), xs.begin());
    const std::int64_t y0 = b + k_min;
    const std::size_t ylen = len + lags - 1;
    std::fill(r.begin(), r.end(), 0.0);
    const std::int64_t lo = std::max<std::int64_t>(y0, 0);
    const std::int64_t hi = std::min<std::int64_t>(y0 + static_cast<std::int64_t>(ylen), y.sample_count);
    if (hi > lo) {
      y.render(lo, std::span<std::uint8_t>(dense.data(), static_cast<std::size_t>(hi - lo)));
      for (std::int64_t i = lo; i < hi; ++i) r[static_cast<std::size_t>(i - y0)] = dense[static_cast<std::size_t>(i - lo)];
    }
    plan.forward(buffers);
    auto spec = buffers.spectrum();
    for (std::size_t i = 0; i < spec.size(); ++i) spec[i] *= std::conj(xs[i]);
    plan.inverse(buffers);
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
  // x's intervals in [t0, t1), about nx span / n of them, each against the
  // y intervals within the lag range.
  const double pairs = nx * span / static_cast<double>(std::max<std::int64_t>(1, x.sample_count)) * ny *
                       std::min(1.0, (lag_span + 2.0 * span / std::max(1.0, ny)) / static_cast<double>(y.sample_count));
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
    return below_at(t, static_cast<std::size_t>(it - iv.begin()));
  }
  std::int64_t in(std::int64_t a, std::int64_t b) const {
    a = std::clamp<std::int64_t>(a, 0, s_.sample_count);
    b = std::clamp<std::int64_t>(b, 0, s_.sample_count);
    return b > a ? below(b) - below(a) : 0;
  }
  /// Where the last lookups of a sweep ended: the index of the first
  /// interval that stops after each end (none yet: a binary search).
  struct Hint {
    static constexpr std::size_t none = static_cast<std::size_t>(-1);
    std::size_t a = none, b = none;
  };
  /// in(a, b) for a sweep of windows that move a sample or so from one
  /// call to the next (a lag sweep): each end's interval is found by
  /// walking from the last call's instead of a binary search over the whole
  /// record (a 300 s record holds 400,000 intervals, and FSCC's lag range
  /// 20,000 lags per segment). The intervals are sorted and disjoint, so the
  /// walk ends at the index partition_point finds: the same count.
  std::int64_t in(std::int64_t a, std::int64_t b, Hint& hint) const {
    a = std::clamp<std::int64_t>(a, 0, s_.sample_count);
    b = std::clamp<std::int64_t>(b, 0, s_.sample_count);
    return b > a ? below(b, hint.b) - below(a, hint.a) : 0;
  }

 private:
  std::int64_t below_at(std::int64_t t, std::size_t i) const {
    const auto& iv = s_.intervals;
    std::int64_t total = cumulative_[i];
    if (i < iv.size() && iv[i].start < t) total += t - iv[i].start;
    return total;
  }
  std::int64_t below(std::int64_t t, std::size_t& at) const {
    const auto& iv = s_.intervals;
    if (at == Hint::none) {
      at = static_cast<std::size_t>(
          std::partition_point(iv.begin(), iv.end(), [t](const AirInterval& x) { return x.stop <= t; }) - iv.begin());
    } else {
      while (at > 0 && iv[at - 1].stop > t) --at;
      while (at < iv.size() && iv[at].stop <= t) ++at;
    }
    return below_at(t, at);
  }

  const AirIntervals& s_;
  std::vector<std::int64_t> cumulative_;
};

// Full-record normalised correlations (METHOD 3).
// `r12_sums`, when given, are R12's lagged products over the whole record
// (those of window_partition below), else they are computed here.
void full_record(const AirIntervals& x, const AirIntervals& y, const FsccLags& lags, FftPlanCache& plans,
                 CorrelationFunctions& f, const std::vector<double>* r12_sums = nullptr,
                 const std::vector<double>* r11_sums = nullptr) {
  const std::int64_t n = x.sample_count;
  const double sx = static_cast<double>(x.air_samples()), sy = static_cast<double>(y.air_samples());
  const double mx = sx / static_cast<double>(n), my = sy / static_cast<double>(n);
  // Sum of squares of a mean-removed 0/1 signal: n m (1 - m).
  const double qx = static_cast<double>(n) * mx * (1 - mx), qy = static_cast<double>(n) * my * (1 - my);
  if (!(qx > 0.0) || !(qy > 0.0)) {
    f.status = qx > 0.0 ? FsccStatus::constant_trailing : FsccStatus::constant_leading;
    f.message = qx > 0.0 ? "the trailing tip's signal is constant (no bubble)" : "the leading tip's signal is constant (no bubble)";
    return;
  }
  const AirPrefix px(x), py(y);
  auto normalised = [&](const AirIntervals& a, const AirIntervals& b, const AirPrefix& pa, const AirPrefix& pb,
                        double ma, double mb, double qa, double qb, std::int64_t kmin, std::int64_t kmax,
                        const std::vector<double>* given) {
    const auto sums = given ? *given : lagged_products(a, b, 0, n, kmin, kmax, plans);
    std::vector<double> r(sums.size());
    AirPrefix::Hint ha, hb;
    for (std::size_t j = 0; j < sums.size(); ++j) {
      const std::int64_t k = kmin + static_cast<std::int64_t>(j);
      // t in [max(0, -k), min(n, n - k)) and t + k in range.
      const std::int64_t t0 = std::max<std::int64_t>(0, -k), t1 = std::min(n, n - k);
      const double count = static_cast<double>(std::max<std::int64_t>(0, t1 - t0));
      const double sa = static_cast<double>(pa.in(t0, t1, ha));
      const double sb = static_cast<double>(pb.in(t0 + k, t1 + k, hb));
      const double centred = sums[j] - ma * sb - mb * sa + count * ma * mb;
      r[j] = centred / std::sqrt(qa * qb);
    }
    return r;
  };
  f.r11 = normalised(x, x, px, px, mx, mx, qx, qx, 0, lags.r11_last, r11_sums);
  f.r12 = normalised(x, y, px, py, mx, my, qx, qy, lags.r12_first, lags.r12_last, r12_sums);
  f.segments_used = 1;
}

// The window of x in segment [s0, s0 + length) for lags [kmin, kmax]:
// Felder's B = L - (lags) samples, starting where the most negative lag
// still reads y inside the segment.
std::pair<std::int64_t, std::int64_t> segment_window(std::int64_t s0, std::int64_t length, std::int64_t kmin,
                                                     std::int64_t kmax) {
  const std::int64_t t0 = s0 + std::max<std::int64_t>(0, -kmin);
  return {t0, t0 + length - (kmax - kmin + 1)};
}

// The lag of r's maximum (its first occurrence) over lags first.., when positive.
std::optional<std::int64_t> positive_peak_lag(std::span<const double> r, std::int64_t first) {
  if (r.empty()) return std::nullopt;
  const auto it = std::max_element(r.begin(), r.end());
  if (!(*it > 0.0)) return std::nullopt;
  return first + static_cast<std::int64_t>(it - r.begin());
}

// R12's lagged products over the record cut at the segments' R12 windows:
// one per window, and their sum with those of the gaps between the windows
// (and before the first, after the last), which is the whole record's. The
// sums over t of x(t) y(t + k) add over a partition of t, and they are whole
// numbers (exact in doubles below 2^53), so the whole record's are the ones
// lagged_products(x, y, 0, n) gives, at about half its pairs of intervals
// when the segments' R12 is needed anyway (the velocity's interval).
// Empty when the windows do not partition (overlapping windows of a record
// too short for its lags).
struct WindowPartition {
  std::vector<std::vector<double>> windows;
  std::vector<double> whole;
};
std::optional<WindowPartition> window_partition(const AirIntervals& x, const AirIntervals& y, int segments,
                                                const FsccLags& lags, FftPlanCache& plans) {
  const std::int64_t n = x.sample_count;
  const std::int64_t length = n / segments;
  WindowPartition p;
  p.whole.assign(static_cast<std::size_t>(lags.r12_last - lags.r12_first + 1), 0.0);
  auto add = [&p](const std::vector<double>& sums) {
    for (std::size_t j = 0; j < sums.size(); ++j) p.whole[j] += sums[j];
  };
  std::int64_t covered = 0;  // the record before here is summed
  for (int s = 0; s < segments; ++s) {
    const auto [t0, t1] = segment_window(static_cast<std::int64_t>(s) * length, length, lags.r12_first, lags.r12_last);
    if (t0 < covered || t1 < t0 || t1 > n) return std::nullopt;
    if (t0 > covered) add(lagged_products(x, y, covered, t0, lags.r12_first, lags.r12_last, plans));
    p.windows.push_back(lagged_products(x, y, t0, t1, lags.r12_first, lags.r12_last, plans));
    add(p.windows.back());
    covered = t1;
  }
  if (n > covered) add(lagged_products(x, y, covered, n, lags.r12_first, lags.r12_last, plans));
  return p;
}

// Felder's segmented Pearson coefficients of binary signals, averaged over
// the segments; each segment's R12 peak is kept for the velocity's interval.
// Without `auto_correlation` R11 is left at zero and only whether each
// segment has one is found (what the velocity's interval reads: the segments'
// peaks and the status), without its lagged products. `r12_sums`, when
// given, are R12's lagged products per segment's window (window_partition).
void segmented(const AirIntervals& x, const AirIntervals& y, int segments, const FsccLags& lags, FftPlanCache& plans,
               CorrelationFunctions& f, bool auto_correlation = true,
               const std::vector<std::vector<double>>* r12_sums = nullptr) {
  const std::int64_t n = x.sample_count;
  const std::int64_t length = n / segments;
  f.r11.assign(static_cast<std::size_t>(lags.r11_last + 1), 0.0);
  f.r12.assign(static_cast<std::size_t>(lags.r12_last - lags.r12_first + 1), 0.0);
  int used11 = 0, used12 = 0;
  const AirPrefix px(x), py(y);
  // Pearson's coefficient per lag over the segment's window, empty when a signal is constant there.
  auto pearson = [&](const AirIntervals& a, const AirPrefix& pa, const AirPrefix& pb, const AirIntervals& b,
                     std::int64_t s0, std::int64_t kmin, std::int64_t kmax, const std::vector<double>* given) {
    std::vector<double> r;
    const auto [t0, t1] = segment_window(s0, length, kmin, kmax);
    const std::int64_t w = t1 - t0;
    if (w < 2) return r;
    const double wd = static_cast<double>(w);
    const double ma = static_cast<double>(pa.in(t0, t1)) / wd;
    const double va = ma * (1 - ma);
    if (!(va > 0.0)) return r;
    const auto sums = given ? *given : lagged_products(a, b, t0, t1, kmin, kmax, plans);
    r.resize(sums.size());
    AirPrefix::Hint hint;
    for (std::size_t j = 0; j < sums.size(); ++j) {
      const std::int64_t k = kmin + static_cast<std::int64_t>(j);
      const double mb = static_cast<double>(pb.in(t0 + k, t1 + k, hint)) / wd;
      const double vb = mb * (1 - mb);
      if (!(vb > 0.0)) return std::vector<double>();
      r[j] = (sums[j] / wd - ma * mb) / std::sqrt(va * vb);
    }
    return r;
  };
  // Whether pearson() gives a coefficient (its checks, without the products).
  auto has_pearson = [&](const AirPrefix& pa, const AirPrefix& pb, std::int64_t s0, std::int64_t kmin,
                         std::int64_t kmax) {
    const auto [t0, t1] = segment_window(s0, length, kmin, kmax);
    const std::int64_t w = t1 - t0;
    if (w < 2) return false;
    const double wd = static_cast<double>(w);
    const double ma = static_cast<double>(pa.in(t0, t1)) / wd;
    if (!(ma * (1 - ma) > 0.0)) return false;
    // pearson()'s test mb (1 - mb) > 0 with mb = count / w, in integers:
    // for 0 < count < w (w far below 2^52) the quotient lies in (0, 1) and
    // the product of two positive doubles of that size is positive, while
    // count 0 or w gives 0. The same answer without a division per lag.
    AirPrefix::Hint hint;
    for (std::int64_t k = kmin; k <= kmax; ++k) {
      const std::int64_t count = pb.in(t0 + k, t1 + k, hint);
      if (count <= 0 || count >= w) return false;
    }
    return true;
  };
  auto add = [](const std::vector<double>& r, std::vector<double>& acc) {
    for (std::size_t j = 0; j < r.size(); ++j) acc[j] += r[j];
    return !r.empty();
  };
  for (int s = 0; s < segments; ++s) {
    const std::int64_t s0 = static_cast<std::int64_t>(s) * length;
    if (auto_correlation) used11 += add(pearson(x, px, px, x, s0, 0, lags.r11_last, nullptr), f.r11);
    else used11 += has_pearson(px, px, s0, 0, lags.r11_last);
    const auto r12 = pearson(x, px, py, y, s0, lags.r12_first, lags.r12_last,
                             r12_sums ? &(*r12_sums)[static_cast<std::size_t>(s)] : nullptr);
    used12 += add(r12, f.r12);
    if (const auto peak = positive_peak_lag(r12, lags.r12_first)) f.segment_peak_lags.push_back(*peak);
  }
  if (used11 == 0 || used12 == 0) {
    f.status = FsccStatus::no_common_segment;
    f.message = "no segment holds bubbles on both tips";
    return;
  }
  for (auto& v : f.r11) v /= used11;
  for (auto& v : f.r12) v /= used12;
  f.segments_used = std::min(used11, used12);
}

}  // namespace

std::string_view to_string(CorrelationSignal signal) { return signal == CorrelationSignal::raw ? "raw" : "binary"; }

FsccLags fscc_lags(std::int64_t samples, double fs, const FsccOptions& options) {
  FsccLags l;
  if (options.felder_lags) {
    l.r11_last = 999;
    l.r12_first = -199;
    l.r12_last = 800;
  } else {
    l.r11_last = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::llround(options.max_lag * fs)));
    l.r12_first = -l.r11_last;
    l.r12_last = l.r11_last;
  }
  // Every window keeps at least half of its segment.
  const std::int64_t limit = std::max<std::int64_t>(1, samples / std::max(1, options.segments) / 4);
  l.r11_last = std::min(l.r11_last, limit);
  l.r12_last = std::min(l.r12_last, limit);
  l.r12_first = std::max(l.r12_first, -limit);
  return l;
}

namespace {

// The functions of two binary signals before their values: R11 from lag 0, R12 over the lags' range.
CorrelationFunctions binary_functions(double fs, const FsccLags& lags) {
  CorrelationFunctions f;
  f.fs = fs;
  f.signal = CorrelationSignal::binary;
  f.r11_first_lag = 0;
  f.r12_first_lag = lags.r12_first;
  return f;
}

}  // namespace

CorrelationFunctions correlation_functions(const AirIntervals& leading, const AirIntervals& trailing,
                                           const FsccOptions& options) {
  options.validate().throw_if_failed();
  if (leading.sample_count != trailing.sample_count || leading.fs != trailing.fs) {
    throw std::invalid_argument("FSCC needs two signals of the same length and sampling rate");
  }
  const FsccLags lags = fscc_lags(leading.sample_count, leading.fs, options);
  CorrelationFunctions f = binary_functions(leading.fs, lags);
  FftPlanCache plans;
  if (options.segments == 1) full_record(leading, trailing, lags, plans, f);
  else segmented(leading, trailing, options.segments, lags, plans, f);
  return f;
}

// ---- Raw voltages ----

struct RawCorrelation::Segment {
  LaggedPearson r11, r12;
};

bool RawCorrelation::fits(std::int64_t samples, double fs, const FsccOptions& options) {
  const FsccLags lags = fscc_lags(samples, fs, options);
  return samples / std::max(1, options.segments) - (lags.r12_last - lags.r12_first + 1) >= 2;
}

RawCorrelation::RawCorrelation(std::int64_t samples, double fs, const FsccOptions& options, FftPlanCache& plans)
    : samples_(samples), fs_(fs), lags_(fscc_lags(samples, fs, options)), segments_(options.segments), plans_(plans) {
  options.validate().throw_if_failed();
  length_ = samples / segments_;
  if (!fits(samples, fs, options)) {
    throw std::invalid_argument(fmt::format("{} samples in {} segments leave no correlation window", samples, segments_));
  }
  sum11_.assign(static_cast<std::size_t>(lags_.r11_last + 1), 0.0);
  sum12_.assign(static_cast<std::size_t>(lags_.r12_last - lags_.r12_first + 1), 0.0);
}

RawCorrelation::~RawCorrelation() = default;

void RawCorrelation::open_segment() {
  const std::int64_t s0 = static_cast<std::int64_t>(next_) * length_;
  const auto [a0, a1] = segment_window(s0, length_, 0, lags_.r11_last);
  const auto [c0, c1] = segment_window(s0, length_, lags_.r12_first, lags_.r12_last);
  // Every segment has the same windows and lags: the accumulators (and
  // their buffers) of the first serve them all.
  if (!accumulators_) {
    accumulators_ = std::make_unique<Segment>(Segment{LaggedPearson(a0, a1 - a0, 0, lags_.r11_last, plans_, true),
                                                      LaggedPearson(c0, c1 - c0, lags_.r12_first, lags_.r12_last, plans_)});
  } else {
    accumulators_->r11.restart(a0);
    accumulators_->r12.restart(c0);
  }
  current_ = accumulators_.get();
  ++next_;
}

void RawCorrelation::feed(std::int64_t first, std::span<const double> leading, std::span<const double> trailing) {
  const std::int64_t end = first + static_cast<std::int64_t>(leading.size());
  for (;;) {
    if (!current_) {
      if (next_ >= segments_) return;
      // The next segment begins after this block: nothing more in it.
      if (static_cast<std::int64_t>(next_) * length_ >= end) return;
      open_segment();
    }
    current_->r11.feed(first, leading, leading);
    current_->r12.feed(first, leading, trailing);
    if (!(current_->r11.complete() && current_->r12.complete())) return;
    const auto r11 = current_->r11.coefficients();
    const auto r12 = current_->r12.coefficients();
    const bool bad11 = std::any_of(r11.begin(), r11.end(), [](double v) { return std::isnan(v); });
    const bool bad12 = std::any_of(r12.begin(), r12.end(), [](double v) { return std::isnan(v); });
    if (!bad11) constant_leading_ = false;
    if (!bad12) constant_trailing_ = false;
    if (!bad11 && !bad12) {
      for (std::size_t j = 0; j < r11.size(); ++j) sum11_[j] += r11[j];
      for (std::size_t j = 0; j < r12.size(); ++j) sum12_[j] += r12[j];
      ++used_;
      if (const auto peak = positive_peak_lag(r12, lags_.r12_first)) segment_peaks_.push_back(*peak);
    }
    current_ = nullptr;
  }
}

CorrelationFunctions RawCorrelation::finish() {
  if (current_ || next_ < segments_) {
    throw std::logic_error(fmt::format("RawCorrelation: {} of {} segments were fed", next_ - (current_ ? 1 : 0), segments_));
  }
  CorrelationFunctions f;
  f.fs = fs_;
  f.signal = CorrelationSignal::raw;
  f.r11_first_lag = 0;
  f.r12_first_lag = lags_.r12_first;
  f.segments_used = used_;
  if (used_ == 0) {
    f.status = constant_leading_ ? FsccStatus::constant_leading
                                 : (constant_trailing_ ? FsccStatus::constant_trailing : FsccStatus::no_common_segment);
    f.message = constant_leading_ ? "the leading tip's voltage is constant in every segment"
                                  : (constant_trailing_ ? "the trailing tip's voltage is constant in every segment"
                                                        : "no segment holds a varying voltage on both tips");
    return f;
  }
  f.r11 = sum11_;
  f.r12 = sum12_;
  f.segment_peak_lags = segment_peaks_;
  for (auto& v : f.r11) v /= used_;
  for (auto& v : f.r12) v /= used_;
  return f;
}

// ---- Scales ----

namespace {

float fl32(double v) { return static_cast<float>(v); }

// Lag times of the functions' indices: k / fs, or Felder's float32 times.
struct LagTimes {
  double fs;
  std::int64_t first;
  bool felder;
  double operator()(std::size_t j) const {
    if (!felder) return static_cast<double>(first + static_cast<std::int64_t>(j)) / fs;
    const float f = fl32(fs);
    if (first == 0) return fl32(static_cast<float>(j) / f);
    return fl32(fl32(static_cast<float>(first) / f) + fl32(static_cast<float>(j) / f));
  }
};

// The first index i >= from with r[i] <= level, and the lag time there
// (exact when equal, else linear between i - 1 and i).
struct Reached {
  std::size_t index;
  double time;
};
std::optional<Reached> first_at_or_below(const std::vector<double>& r, std::size_t from, double level,
                                         const LagTimes& tau) {
  for (std::size_t i = from; i < r.size(); ++i) {
    if (!(r[i] <= level)) continue;
    if (r[i] == level || i == 0) return Reached{i, tau(i)};
    const double t0 = tau(i - 1), t1 = tau(i);
    return Reached{i, t0 + (t1 - t0) * (level - r[i - 1]) / (r[i] - r[i - 1])};
  }
  return std::nullopt;
}

// The minimum of r over [from, end) (Felder: also bounded by `cap`, the first
// index within 1e-5 of it, and the last lag left out).
std::pair<std::size_t, double> minimum(const std::vector<double>& r, std::size_t from, double cap, bool felder) {
  const std::size_t end = felder ? r.size() - 1 : r.size();
  double m = felder ? cap : r[from];
  for (std::size_t i = from; i < end; ++i) m = std::min(m, r[i]);
  for (std::size_t i = from; i < end; ++i) {
    if (felder ? r[i] - m < 1e-5 : r[i] == m) return {i, m};
  }
  return {from, m};
}

// Trapezoid integral of r, in s, from index `from`: to the interpolated zero
// crossing (`zero`), or to index `to`. Felder: whole trapezoids up to and
// including the one that starts at `to` (one lag past), the thousandth lag
// taken as r / fs.
double integral(const std::vector<double>& r, std::size_t from, std::size_t to, std::optional<double> zero_fraction,
                double fs, bool felder) {
  double sum = 0.0;
  if (felder) {
    for (std::size_t i = from; i <= to && i < r.size(); ++i) {
      sum += (i + 1 == 1000 || i + 1 >= r.size()) ? r[i] / fs : (r[i] + r[i + 1]) / (2.0 * fs);
    }
    return sum;
  }
  for (std::size_t i = from; i < to; ++i) sum += 0.5 * (r[i] + r[i + 1]);
  if (zero_fraction) sum += 0.5 * r[to] * *zero_fraction;  // triangle to the zero after `to`
  return sum / fs;
}

}  // namespace

FsccResult fscc_from_functions(CorrelationFunctions f, double dx, const FsccOptions& options) {
  FsccResult out;
  const double fs = f.fs;
  out.signal = f.signal;
  out.segments_used = f.segments_used;
  out.r11 = std::move(f.r11);
  out.r12 = std::move(f.r12);
  out.r11_first_lag = f.r11_first_lag;
  out.r12_first_lag = f.r12_first_lag;
  if (f.status != FsccStatus::ok) {
    out.status = f.status;
    out.message = f.message;
    return out;
  }
  const bool felder = options.felder_scales;
  const LagTimes tau11{fs, 0, felder}, tau12{fs, out.r12_first_lag, felder};
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
  out.lag_samples = out.r12_first_lag + static_cast<std::int64_t>(peak);
  double lag = static_cast<double>(out.lag_samples) / fs;
  if (felder) lag = tau12(peak);
  const auto r12_at = [&](std::int64_t j) { return out.r12[static_cast<std::size_t>(j)]; };
  lag += subsample_offset(options.subsample, r12_at, static_cast<std::int64_t>(peak), 0,
                          static_cast<std::int64_t>(out.r12.size()) - 1) /
         fs;
  out.lag = lag;
  if (!(out.r12_max > 0.0)) {
    out.status = FsccStatus::no_positive_peak;
    out.message = "the cross-correlation has no positive peak: the tips' signals are unrelated";
  } else if (out.lag_samples <= 0) {
    out.status = out.lag_samples < 0 ? FsccStatus::tips_swapped : FsccStatus::non_positive_lag;
    out.message = fmt::format("the cross-correlation peaks at lag {} samples (not positive): no physical velocity; "
                              "check the tip order",
                              out.lag_samples);
  } else if (out.lag_samples == out.r12_first_lag + static_cast<std::int64_t>(out.r12.size()) - 1) {
    out.status = FsccStatus::peak_at_lag_range_end;
    out.message = "the cross-correlation peaks at the end of the lag range: the delay lies beyond the lags searched, "
                  "or dx's unit or the sampling rate is wrong; check them, or widen the lag range";
  } else if (!(dx > 0.0)) {
    out.status = FsccStatus::no_tip_separation;
    out.message = "no tip separation given: the velocity cannot be computed";
  } else {
    out.status = FsccStatus::ok;
    // Felder: V = fl32(dx in mm / 1000) / T_max.
    out.velocity = felder ? static_cast<double>(fl32(static_cast<double>(fl32(dx * 1e3)) / 1000.0)) / out.lag
                          : dx / out.lag;
    if (out.velocity > 100.0) {
      out.warnings.push_back(fmt::format("FSCC velocity {:.4g} m/s is above 100 m/s, beyond air-water flows: check dx's "
                                         "unit, the sampling rate and the lag range",
                                         out.velocity));
    }
  }
  auto missing = [&](const char* name, std::string why) { out.scale_notes.emplace_back(name, std::move(why)); };
  const std::string lags11 = fmt::format("lags 0 to {}", out.r11.size() - 1);
  const std::string lags12 =
      fmt::format("lags up to {}", out.r12_first_lag + static_cast<std::int64_t>(out.r12.size()) - 1);
  // Auto-correlation scales.
  if (const auto half = first_at_or_below(out.r11, 0, 0.5, tau11)) out.t05 = half->time;
  else missing("t05", "R11 stays above 0.5 within " + lags11);
  // The first zero crossing from `from`, or (without one) the minimum; the
  // integral runs to it. Felder integrates to the minimum instead of leaving
  // it empty; the default leaves it empty rather than report an integral cut
  // short by the lag range.
  struct Descent {
    std::optional<double> t_zero, t_min, min, integral;
  };
  auto descend = [&](const std::vector<double>& r, std::size_t from, double cap, const LagTimes& tau,
                     const char* zero_name, const char* integral_name, const std::string& where) {
    Descent d;
    std::size_t end = from;
    std::optional<double> fraction;
    if (const auto zero = first_at_or_below(r, from, 0.0, tau)) {
      d.t_zero = d.t_min = zero->time;
      d.min = 0.0;
      end = felder ? zero->index : zero->index - 1;
      if (!felder) fraction = r[zero->index - 1] / (r[zero->index - 1] - r[zero->index]);
    } else {
      missing(zero_name, where);
      if (!felder) missing(integral_name, fmt::format("no {} without a zero crossing", integral_name));
      const auto [i, m] = minimum(r, from, cap, felder);
      d.min = m;
      d.t_min = tau(i);
      end = i;
    }
    if (d.t_zero || felder) d.integral = integral(r, from, end, fraction, fs, felder);
    return d;
  };
  const auto r11_descent = descend(out.r11, 0, 1.0, tau11, "t_r11_zero", "txx", "R11 stays above 0 within " + lags11);
  out.t_r11_zero = r11_descent.t_zero;
  out.t_r11_min = r11_descent.t_min;
  out.r11_min = r11_descent.min;
  out.txx = r11_descent.integral;
  // Cross-correlation scales, right of the peak.
  if (out.r12_max > 0.0) {
    if (const auto half = first_at_or_below(out.r12, peak, 0.5 * out.r12_max, tau12)) {
      out.t_half = half->time;
      out.tau05 = half->time - tau12(peak);
    } else {
      missing("tau05", "R12 stays above R12max / 2 right of its peak within " + lags12);
    }
    const auto r12_descent = descend(out.r12, peak, out.r12_max, tau12, "t_r12_zero", "txy",
                                     "R12 stays above 0 right of its peak within " + lags12);
    out.t_r12_zero = r12_descent.t_zero;
    out.t_r12_min = r12_descent.t_min;
    out.r12_min = r12_descent.min;
    out.txy = r12_descent.integral;
  } else {
    missing("tau05", "R12 has no positive peak");
  }
  if (out.t05 && out.tau05 && out.lag > 0.0) {
    const double radicand = *out.tau05 * *out.tau05 - *out.t05 * *out.t05;
    if (radicand >= 0.0) out.turbulence_intensity_chanson = 0.851 * std::sqrt(radicand) / out.lag;
    else missing("turbulence_intensity_chanson", "tau05 < T05: Chanson's turbulence intensity is undefined");
  }
  if (!out.ok()) out.turbulence_intensity_chanson.reset();
  for (const auto& [name, why] : out.scale_notes) out.note += (out.note.empty() ? "" : "; ") + why;
  return out;
}

FsccOptions interval_options(const FsccOptions& options) {
  FsccOptions out = options;
  out.segments = fscc_interval_segments;
  return out;
}

std::optional<Interval95> fscc_velocity_interval(std::span<const std::int64_t> segment_peak_lags, double lag,
                                                 double fs, double dx) {
  const auto n = segment_peak_lags.size();
  if (n < static_cast<std::size_t>(fscc_interval_segments_min) || !(fs > 0.0) || !(lag > 0.0)) return std::nullopt;
  // Student's t(0.975, n - 1) for the n = 5..10 segments that can hold a peak.
  static constexpr double t975[] = {2.776, 2.571, 2.447, 2.365, 2.306, 2.262};
  static_assert(std::size(t975) == fscc_interval_segments - fscc_interval_segments_min + 1);
  const double t = t975[std::min(n, static_cast<std::size_t>(fscc_interval_segments)) - fscc_interval_segments_min];
  double mean = 0.0;
  for (const auto k : segment_peak_lags) mean += static_cast<double>(k);
  mean /= static_cast<double>(n);
  double ss = 0.0;
  for (const auto k : segment_peak_lags) ss += (static_cast<double>(k) - mean) * (static_cast<double>(k) - mean);
  const double standard_error = std::sqrt(ss / static_cast<double>(n - 1) / static_cast<double>(n));
  constexpr double rounding = 0.475;  // 95 % half-width of a uniform error within +/- 1/2 sample
  const double half = std::hypot(t * standard_error, rounding) / fs;
  if (!(lag > half)) return std::nullopt;
  return Interval95{dx / (lag + half), dx / (lag - half)};
}

void add_velocity_interval(FsccResult& result, const CorrelationFunctions& spread, double dx) {
  if (!result.ok() || spread.status != FsccStatus::ok) return;
  result.velocity_ci95 = fscc_velocity_interval(spread.segment_peak_lags, result.lag, spread.fs, dx);
  result.interval_segments = static_cast<int>(spread.segment_peak_lags.size());
}

FsccResult fscc(const AirIntervals& leading, const AirIntervals& trailing, double dx, const FsccOptions& options,
                bool second_thread) {
  // The interval reads the segments' R12 peaks and the status only: the
  // segments' R11 is not computed (correlation_functions would).
  const FsccOptions spread_options = interval_options(options);
  const FsccLags spread_lags = fscc_lags(leading.sample_count, leading.fs, spread_options);
  FftPlanCache plans;
  auto interval = [&](FsccResult& out, const std::vector<std::vector<double>>* r12_sums) {
    CorrelationFunctions spread;
    spread.fs = leading.fs;
    spread.signal = CorrelationSignal::binary;
    spread.r12_first_lag = spread_lags.r12_first;
    segmented(leading, trailing, spread_options.segments, spread_lags, plans, spread, false, r12_sums);
    add_velocity_interval(out, spread, dx);
  };
  // A full-record R12 over the interval's lags is the sum of the segments'
  // windows and the gaps between them (window_partition): computed so, the
  // segments' products serve the interval too.
  std::optional<WindowPartition> partition;
  // R11's lagged products, on a second thread while R12's partition runs
  // here: whole numbers either way, so the thread changes no bit.
  std::future<std::vector<double>> r11_sums;
  std::optional<FsccLags> lags;
  if (options.segments == 1) {
    options.validate().throw_if_failed();
    lags = fscc_lags(leading.sample_count, leading.fs, options);
    if (leading.sample_count == trailing.sample_count && leading.fs == trailing.fs && leading.air_samples() > 0 &&
        trailing.air_samples() > 0 && lags->r12_first == spread_lags.r12_first && lags->r12_last == spread_lags.r12_last) {
      if (second_thread) {
        r11_sums = std::async(std::launch::async, [&leading, last = lags->r11_last] {
          FftPlanCache own;  // a plan cache is one thread's
          return lagged_products(leading, leading, 0, leading.sample_count, 0, last, own);
        });
      }
      partition = window_partition(leading, trailing, spread_options.segments, *lags, plans);
    }
  }
  if (!partition) {
    auto out = fscc_from_functions(correlation_functions(leading, trailing, options), dx, options);
    if (out.ok()) interval(out, nullptr);
    return out;
  }
  CorrelationFunctions f = binary_functions(leading.fs, *lags);
  const bool r11_given = r11_sums.valid();
  const std::vector<double> r11 = r11_given ? r11_sums.get() : std::vector<double>{};
  full_record(leading, trailing, *lags, plans, f, &partition->whole, r11_given ? &r11 : nullptr);
  auto out = fscc_from_functions(std::move(f), dx, options);
  if (out.ok()) interval(out, &partition->windows);
  return out;
}

}  // namespace awcc
