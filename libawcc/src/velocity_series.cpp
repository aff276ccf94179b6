#include "awcc/velocity_series.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <numbers>

#include "awcc/fft.hpp"

namespace awcc {

Validation SpectrumOptions::validate() const {
  if (segment_length < 8 || segment_length > (1 << 24)) {
    return Validation::invalid("spectrum-segment",
                               fmt::format("spectrum segment length {} must lie in 8 to 16777216 points", segment_length));
  }
  return {};
}

std::string_view to_string(SpectrumStatus status) {
  switch (status) {
    case SpectrumStatus::ok: return "ok";
    case SpectrumStatus::no_awcc_velocity: return "no_awcc_velocity";
    case SpectrumStatus::too_few_points: return "too_few_points";
  }
  return "?";
}

RegularSeries sample_and_hold(std::span<const double> times, std::span<const double> values, double rate, double start,
                              double end) {
  RegularSeries out;
  out.rate = rate;
  out.start = start;
  if (times.empty() || !(rate > 0.0) || !(end >= start)) return out;
  const auto n = static_cast<std::size_t>(std::floor((end - start) * rate)) + 1;
  out.values.resize(n);
  std::size_t j = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = start + static_cast<double>(k) / rate;
    while (j + 1 < times.size() && times[j + 1] <= t) ++j;
    out.values[k] = values[j];
  }
  return out;
}

PowerSpectrum welch_psd(std::span<const double> x, double rate, int segment_length) {
  PowerSpectrum p;
  const auto l = static_cast<std::size_t>(segment_length);
  if (x.size() < l || l < 2) return p;
  const std::size_t step = l / 2;
  std::vector<double> window(l);
  double power = 0.0;
  for (std::size_t n = 0; n < l; ++n) {
    // Periodic Hann (spectral analysis), as scipy.signal.welch.
    window[n] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(n) / static_cast<double>(l));
    power += window[n] * window[n];
  }
  const FftPlan plan(l);
  FftBuffers buffers(l);
  const std::size_t bins = l / 2 + 1;
  p.density.assign(bins, 0.0);
  for (std::size_t first = 0; first + l <= x.size(); first += step) {
    double mean = 0.0;
    for (std::size_t n = 0; n < l; ++n) mean += x[first + n];
    mean /= static_cast<double>(l);
    auto r = buffers.real();
    for (std::size_t n = 0; n < l; ++n) r[n] = (x[first + n] - mean) * window[n];
    plan.forward(buffers);
    const auto s = buffers.spectrum();
    for (std::size_t k = 0; k < bins; ++k) p.density[k] += std::norm(s[k]);
    ++p.segments;
  }
  const double scale = 1.0 / (rate * power * p.segments);
  for (std::size_t k = 0; k < bins; ++k) {
    const bool doubled = k > 0 && !(l % 2 == 0 && k == l / 2);  // one-sided: all but 0 and Nyquist
    p.density[k] *= scale * (doubled ? 2.0 : 1.0);
    p.frequency.push_back(static_cast<double>(k) * rate / static_cast<double>(l));
  }
  return p;
}

std::vector<double> autocorrelation(std::span<const double> x, std::size_t max_lag) {
  const std::size_t n = x.size();
  if (n == 0) return {};
  max_lag = std::min(max_lag, n - 1);
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  // Through the FFT: |X|^2 of the zero-padded series is the circular
  // autocorrelation, linear for lags below the padding.
  const FftPlan plan(fast_fft_size(n + max_lag + 1));
  FftBuffers buffers(plan.size());
  auto r = buffers.real();
  std::fill(r.begin(), r.end(), 0.0);
  for (std::size_t i = 0; i < n; ++i) r[i] = x[i] - mean;
  plan.forward(buffers);
  for (auto& c : buffers.spectrum()) c = std::norm(c);
  plan.inverse(buffers);
  std::vector<double> out(max_lag + 1);
  const double zero = r[0];
  for (std::size_t k = 0; k <= max_lag; ++k) out[k] = zero > 0.0 ? r[k] / zero : 0.0;
  return out;
}

namespace {
// The mean and the (biased) variance of the values, as the slotted
// correlations normalise by them.
std::pair<double, double> mean_and_variance(std::span<const double> values) {
  const auto n = static_cast<double>(values.size());
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= n;
  double variance = 0.0;
  for (double v : values) variance += (v - mean) * (v - mean);
  return {mean, variance / n};
}
}  // namespace

std::vector<double> slotted_autocorrelation(std::span<const double> times, std::span<const double> values, double slot,
                                            std::size_t slots) {
  const std::size_t n = values.size();
  std::vector<double> r(slots + 1, 0.0);
  if (n < 2 || !(slot > 0.0)) return r;
  const auto [mean, variance] = mean_and_variance(values);
  std::vector<double> sum(slots + 1, 0.0);
  std::vector<std::int64_t> count(slots + 1, 0);
  const double reach = (static_cast<double>(slots) + 0.5) * slot;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n && times[j] - times[i] <= reach; ++j) {
      const auto k = static_cast<std::size_t>(std::ceil((times[j] - times[i]) / slot - 0.5));
      if (k == 0 || k > slots) continue;
      sum[k] += (values[i] - mean) * (values[j] - mean);
      ++count[k];
    }
  }
  r[0] = 1.0;
  for (std::size_t k = 1; k <= slots; ++k) {
    r[k] = count[k] > 0 && variance > 0.0 ? sum[k] / static_cast<double>(count[k]) / variance : r[k - 1];
  }
  return r;
}

std::optional<double> integral_to_first_zero(std::span<const double> r, double dt) {
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < r.size(); ++i) {
    if (r[i + 1] <= 0.0) return (sum + 0.5 * r[i] * r[i] / (r[i] - r[i + 1])) * dt;
    sum += 0.5 * (r[i] + r[i + 1]);
  }
  return std::nullopt;
}

SlottedIntegral slotted_integral_to_first_zero(std::span<const double> times, std::span<const double> values,
                                               double slot, std::size_t slots, double stop_at) {
  SlottedIntegral out;
  const std::size_t n = values.size();
  if (n < 2 || !(slot > 0.0) || slots == 0) return out;
  const auto [mean, variance] = mean_and_variance(values);
  std::vector<double> sum(slots + 1, 0.0), r(slots + 1, 0.0);
  std::vector<std::int64_t> count(slots + 1, 0);
  const double reach = (static_cast<double>(slots) + 0.5) * slot;
  r[0] = 1.0;
  double area = 0.0;  // trapezoids so far, in slots (integral_to_first_zero's sum)
  std::size_t done = 0;
  for (std::size_t band_end = std::min<std::size_t>(slots, 16);; band_end = std::min(slots, 2 * band_end)) {
    // The pairs of slots (done, band_end]: for each i from the first j past
    // slot `done` (nondecreasing in i, as the times ascend) while in the band.
    const bool last_band = band_end == slots;
    std::size_t from = 1;
    for (std::size_t i = 0; i < n; ++i) {
      from = std::max(from, i + 1);
      while (from < n && std::ceil((times[from] - times[i]) / slot - 0.5) <= static_cast<double>(done)) ++from;
      for (std::size_t j = from; j < n; ++j) {
        const double separation = times[j] - times[i];
        const double k = std::ceil(separation / slot - 0.5);
        if (k > static_cast<double>(band_end) || (last_band && separation > reach)) break;
        const auto slot_index = static_cast<std::size_t>(k);
        sum[slot_index] += (values[i] - mean) * (values[j] - mean);
        ++count[slot_index];
      }
    }
    for (std::size_t k = done + 1; k <= band_end; ++k) {
      r[k] = count[k] > 0 && variance > 0.0 ? sum[k] / static_cast<double>(count[k]) / variance : r[k - 1];
    }
    for (std::size_t i = done; i < band_end; ++i) {
      if (r[i + 1] <= 0.0) {
        out.integral = (area + 0.5 * r[i] * r[i] / (r[i] - r[i + 1])) * slot;
        out.zero_reached = true;
        return out;
      }
      area += 0.5 * (r[i] + r[i + 1]);
      if (area * slot >= stop_at) {
        out.integral = area * slot;
        out.stopped = true;
        return out;
      }
    }
    done = band_end;
    if (last_band) break;
  }
  out.integral = area * slot;
  return out;
}

namespace {

// The accepted windows' centres and velocities, and their mean duration T_W.
struct AcceptedSeries {
  std::vector<double> times, values;
  double mean_window_duration = 0.0;
};
AcceptedSeries accepted_series(const AwccResult& awcc) {
  AcceptedSeries s;
  double total = 0.0;
  for (const auto& w : awcc.windows) {
    if (w.fate != WindowFate::accepted) continue;
    s.times.push_back(w.start_time + 0.5 * w.duration);
    s.values.push_back(w.velocity);
    total += w.duration;
  }
  if (!s.times.empty()) s.mean_window_duration = total / static_cast<double>(s.times.size());
  return s;
}

// velocity_spectrum's slots: half a window, out to a quarter of the record
// (at most 4096 slots).
std::pair<double, std::size_t> slots_of(const AcceptedSeries& s) {
  const double slot = 0.5 * s.mean_window_duration;
  const auto slots =
      static_cast<std::size_t>(std::clamp((s.times.back() - s.times.front()) / 4.0 / slot, 1.0, 4096.0));
  return {slot, slots};
}

}  // namespace

namespace detail {

std::string windows_too_long(const AwccResult& awcc, double ratio) {
  std::string out = fmt::format("the velocity's integral time scale is {:.2f} mean window durations (below {:g}): the "
                                "windows are too long to follow its fluctuations, and AWCC's turbulence intensity is "
                                "underestimated (Kramer et al.'s error E4).",
                                ratio, time_scale_ratio_min);
  if (ratio <= time_scale_ratio_unresolved) {
    out += " Adjacent windows' velocities are uncorrelated: the time scale is not resolved and may be shorter still.";
  }
  // T_W is proportional to Np (METHOD 6): windows of Np' particles give the ratio ratio Np / Np'.
  const int np = awcc.np;
  const double np_enough = np * ratio / time_scale_ratio_min;
  const int np_advised = static_cast<int>(std::floor(np_enough));
  if (np_advised >= np_least) {
    out += fmt::format(" Windows of np = {} particles or fewer (now {}) would be short enough, though shorter windows "
                       "correlate worse and fewer may pass the filter.",
                       np_advised, np);
  } else {
    out += fmt::format(" Windows short enough would need np = {:.1f} or fewer (now {}), under the {} particles per window "
                       "the method is used with: at this void fraction and bubble size AWCC's windows cannot follow "
                       "the flow.",
                       np_enough, np, np_least);
  }
  const auto windows_ok = awcc.options.windows_ok;
  if (awcc.windows_accepted < windows_ok) {
    out += fmt::format(" The time scale itself rests on {} accepted windows (quality ok needs {}) and is uncertain too.",
                       awcc.windows_accepted, windows_ok);
  }
  return out;
}

}  // namespace detail

VelocitySpectrum velocity_spectrum(const AwccResult& awcc, double duration, const SpectrumOptions& options) {
  VelocitySpectrum out;
  if (!awcc.ok()) {
    out.status = SpectrumStatus::no_awcc_velocity;
    out.message = "AWCC gave no velocity series";
    return out;
  }
  const auto accepted = accepted_series(awcc);
  const auto& times = accepted.times;
  const auto& values = accepted.values;
  out.mean_window_duration = accepted.mean_window_duration;
  out.resample_rate = 1.0 / out.mean_window_duration;
  out.resolvable_frequency = 0.5 * out.resample_rate;
  const auto series = sample_and_hold(times, values, out.resample_rate, times.front(), std::min(times.back(), duration));
  if (series.values.size() < static_cast<std::size_t>(options.segment_length)) {
    out.status = SpectrumStatus::too_few_points;
    out.message = fmt::format("{} resampled points, fewer than one spectrum segment of {}: record longer, or give a "
                              "shorter segment",
                              series.values.size(), options.segment_length);
    return out;
  }
  out.status = SpectrumStatus::ok;
  out.psd = welch_psd(series.values, series.rate, options.segment_length);
  out.autocorrelation = autocorrelation(series.values, series.values.size() / 2);
  out.integral_time_scale_held = integral_to_first_zero(out.autocorrelation, 1.0 / series.rate);
  const auto [slot, slots] = slots_of(accepted);
  const auto slotted = slotted_integral_to_first_zero(times, values, slot, slots,
                                                      std::numeric_limits<double>::infinity());
  if (slotted.zero_reached) out.integral_time_scale = slotted.integral;
  if (out.integral_time_scale) {
    out.time_scale_ratio = *out.integral_time_scale / out.mean_window_duration;
    if (*out.time_scale_ratio < time_scale_ratio_min) out.warning = detail::windows_too_long(awcc, *out.time_scale_ratio);
  } else {
    out.warning = "the velocity's autocorrelation does not reach zero within half the record: no integral time scale";
  }
  return out;
}

std::optional<double> capped_time_scale_ratio(const AwccResult& awcc, double cap) {
  if (!awcc.ok() || !(cap > 0.0)) return std::nullopt;
  const auto accepted = accepted_series(awcc);
  if (accepted.times.size() < 2 || !(accepted.mean_window_duration > 0.0)) return std::nullopt;
  const auto [slot, slots] = slots_of(accepted);
  const double t_w = accepted.mean_window_duration;
  const auto slotted = slotted_integral_to_first_zero(accepted.times, accepted.values, slot, slots, cap * t_w);
  return std::min(slotted.integral / t_w, cap);
}

}  // namespace awcc
