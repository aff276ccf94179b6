#include "awcc/binarisation.hpp"

#include "awcc/errors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>

namespace awcc {

std::string_view to_string(ThresholdRule rule) {
  switch (rule) {
    case ThresholdRule::histogram: return "histogram";
    case ThresholdRule::felder: return "felder";
    case ThresholdRule::kramer: return "kramer";
    case ThresholdRule::fixed: return "fixed";
    case ThresholdRule::hysteresis: return "hysteresis";
  }
  return "?";
}

std::string_view to_string(ProbeType probe) { return probe == ProbeType::conductivity ? "conductivity" : "optical"; }

Validation BinarisationOptions::validate() const {
  if (!(theta > 0.0 && theta < 1.0))
    return Validation::invalid("threshold", fmt::format("threshold fraction {} must lie in (0, 1)", theta));
  if (!(hysteresis_low > 0.0 && hysteresis_low < hysteresis_high && hysteresis_high < 1.0)) {
    return Validation::invalid("threshold", fmt::format("hysteresis fractions {}, {} must satisfy 0 < low < high < 1",
                                                        hysteresis_low, hysteresis_high));
  }
  if (!(bin_width >= 0.0 && std::isfinite(bin_width)))
    return Validation::invalid("bin-width", fmt::format("histogram bin width {} V must be >= 0", bin_width));
  if (rule == ThresholdRule::fixed && !fixed_threshold)
    return Validation::invalid("threshold", "the fixed threshold rule needs a threshold voltage (e.g. 2.5V)");
  if (fixed_threshold && !std::isfinite(*fixed_threshold))
    return Validation::invalid("threshold", "the fixed threshold must be finite");
  if (fixed_threshold_trailing && rule != ThresholdRule::fixed) {
    return Validation::invalid("threshold-rule",
                               "a trailing tip's own threshold is a voltage of the fixed rule: set threshold-rule to fixed");
  }
  if (fixed_threshold_trailing && !std::isfinite(*fixed_threshold_trailing))
    return Validation::invalid("threshold-trailing", "the trailing threshold must be finite");
  return {};
}

BinarisationOptions BinarisationOptions::for_trailing_tip() const {
  BinarisationOptions o = *this;
  if (fixed_threshold_trailing) o.fixed_threshold = fixed_threshold_trailing;
  return o;
}

VoltageHistogram::VoltageHistogram(double quantum) : width_(quantum > 0.0 ? quantum : 1e-4) {}

void VoltageHistogram::grow(std::int64_t index) {
  if (counts_.empty()) {
    offset_ = index - 64;
    counts_.assign(129, 0);
    return;
  }
  const std::int64_t lo = std::min(offset_, index);
  const std::int64_t hi = std::max(offset_ + static_cast<std::int64_t>(counts_.size()) - 1, index);
  // Grow by at least half again, so that a stream of new extremes costs amortised O(1).
  const std::int64_t span = hi - lo + 1;
  const std::int64_t extra = std::max<std::int64_t>(span / 2, 64);
  const std::int64_t new_lo = index < offset_ ? lo - extra : lo;
  const std::int64_t new_size = span + extra;
  if (new_size > (std::int64_t{1} << 26)) {
    throw InputError(fmt::format(
        "the signal spans more than {} V at a resolution of {} V: the values are not a probe voltage (wrong scale "
        "or damaged data)",
        static_cast<double>(new_size) * width_, width_));
  }
  std::vector<std::int64_t> grown(static_cast<std::size_t>(new_size), 0);
  std::copy(counts_.begin(), counts_.end(), grown.begin() + (offset_ - new_lo));
  counts_ = std::move(grown);
  offset_ = new_lo;
}

void VoltageHistogram::add(std::span<const float> values, std::size_t first, std::size_t stride) {
  const double inv = 1.0 / width_;
  for (std::size_t i = first; i < values.size(); i += stride) {
    const float v = values[i];
    // Readers refuse non-finite samples; one that slips through is named, not cast (undefined behaviour).
    if (!std::isfinite(v)) [[unlikely]] {
      throw InputError(fmt::format("sample {} of a channel is {}: the recording is damaged", (i - first) / stride,
                                   std::isnan(v) ? "NaN" : "infinite"));
    }
    const auto index = static_cast<std::int64_t>(std::floor(static_cast<double>(v) * inv + 0.5));
    std::int64_t k = index - offset_;
    if (k < 0 || k >= static_cast<std::int64_t>(counts_.size())) [[unlikely]] {
      grow(index);
      k = index - offset_;
    }
    ++counts_[static_cast<std::size_t>(k)];
    if (distinct_.size() < 3 && std::find(distinct_.begin(), distinct_.end(), v) == distinct_.end()) [[unlikely]] {
      distinct_.push_back(v);
    }
  }
  total_ += static_cast<std::int64_t>((values.size() + stride - 1 - first) / stride);
}

void VoltageHistogram::add_counts(std::span<const std::int64_t> counts, std::int64_t first_index) {
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (!counts[i]) continue;
    const std::int64_t index = first_index + static_cast<std::int64_t>(i);
    std::int64_t k = index - offset_;
    if (k < 0 || k >= static_cast<std::int64_t>(counts_.size())) {
      grow(index);
      k = index - offset_;
    }
    counts_[static_cast<std::size_t>(k)] += counts[i];
    total_ += counts[i];
    const auto v = static_cast<float>(static_cast<double>(index) * width_);
    if (distinct_.size() < 3 && std::find(distinct_.begin(), distinct_.end(), v) == distinct_.end()) {
      distinct_.push_back(v);
    }
  }
}

std::optional<std::vector<double>> VoltageHistogram::binary_levels() const {
  if (distinct_.size() > 2 || distinct_.empty()) return std::nullopt;
  std::vector<double> levels(distinct_.begin(), distinct_.end());
  std::sort(levels.begin(), levels.end());
  return levels;
}

double VoltageHistogram::min_value() const {
  for (std::size_t k = 0; k < counts_.size(); ++k)
    if (counts_[k]) return static_cast<double>(offset_ + static_cast<std::int64_t>(k)) * width_;
  return 0.0;
}

double VoltageHistogram::max_value() const {
  for (std::size_t k = counts_.size(); k-- > 0;)
    if (counts_[k]) return static_cast<double>(offset_ + static_cast<std::int64_t>(k)) * width_;
  return 0.0;
}

std::vector<std::pair<std::int64_t, std::int64_t>> VoltageHistogram::regroup(double width) const {
  std::vector<std::pair<std::int64_t, std::int64_t>> out;
  for (std::size_t k = 0; k < counts_.size(); ++k) {
    if (!counts_[k]) continue;
    const double v = static_cast<double>(offset_ + static_cast<std::int64_t>(k)) * width_;
    const auto bin = static_cast<std::int64_t>(std::floor(v / width));
    if (!out.empty() && out.back().first == bin) out.back().second += counts_[k];
    else out.emplace_back(bin, counts_[k]);
  }
  return out;
}

std::vector<std::pair<double, std::int64_t>> VoltageHistogram::values() const {
  std::vector<std::pair<double, std::int64_t>> out;
  for (std::size_t k = 0; k < counts_.size(); ++k) {
    if (counts_[k]) out.emplace_back(static_cast<double>(offset_ + static_cast<std::int64_t>(k)) * width_, counts_[k]);
  }
  return out;
}

namespace {

// MATLAB's eps(x): the distance from |x| to the next larger double.
double matlab_eps(double x) {
  const double a = std::fabs(x);
  return a == 0.0 ? std::numeric_limits<double>::denorm_min() : std::nextafter(a, HUGE_VAL) - a;
}

// Kramer's thres.m on a histogram of the channel's values (see the header).
Threshold kramer_threshold(const VoltageHistogram& h, const BinarisationOptions& o, Threshold t) {
  constexpr int bins = 100;
  const auto values = h.values();
  const double lo = values.front().first, hi = values.back().first;
  if (lo == hi) {
    t.constant = true;
    t.air_level = t.water_level = lo;
    t.threshold = t.lower = t.upper = o.probe == ProbeType::conductivity ? lo - 1.0 : hi + 1.0;
    t.note = "every sample has one value: no interface, taken as water";
    return t;
  }
  // hist(Signal, 100): edges miny + w k (the last exactly maxy), each
  // shifted up by eps so that a value on an edge belongs to the bin below.
  const double width = (hi - lo) / bins;
  std::array<double, bins + 1> edge{};
  std::array<double, bins> centre{};
  for (int k = 0; k <= bins; ++k) edge[static_cast<std::size_t>(k)] = lo + width * k;
  edge[bins] = hi;
  for (int k = 0; k < bins; ++k) centre[static_cast<std::size_t>(k)] = edge[static_cast<std::size_t>(k)] + width / 2;
  for (auto& e : edge) e += matlab_eps(e);
  std::array<std::int64_t, bins> count{};
  for (const auto& [v, c] : values) {
    const auto above = std::upper_bound(edge.begin(), edge.end(), v) - edge.begin();  // edges <= v
    count[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(above - 1, 0, bins - 1))] += c;
  }
  const double split = centre[bins - 1] / 2;  // max(centers) / 2
  // The mode of one side: the mean of the centres of every bin holding the
  // side's largest count, on either side.
  auto mode = [&](bool below, bool& quirk) {
    std::int64_t top = -1;
    for (int k = 0; k < bins; ++k) {
      const double x = centre[static_cast<std::size_t>(k)];
      if (below ? x < split : x > split) top = std::max(top, count[static_cast<std::size_t>(k)]);
    }
    if (top < 0) throw InputError(fmt::format("kramer threshold: no histogram bin {} half the largest centre ({:.4g} V)",
                                              below ? "below" : "above", split),
                                  "threshold-rule,threshold");
    double sum = 0.0;
    int n = 0;
    for (int k = 0; k < bins; ++k) {
      if (count[static_cast<std::size_t>(k)] != top) continue;
      const double x = centre[static_cast<std::size_t>(k)];
      quirk = quirk || (below ? !(x < split) : !(x > split));
      sum += x;
      ++n;
    }
    return sum / n;
  };
  bool quirk = false;
  const double low_mode = mode(true, quirk), high_mode = mode(false, quirk);
  const bool air_low = o.probe == ProbeType::conductivity;
  t.air_level = air_low ? low_mode : high_mode;
  t.water_level = air_low ? high_mode : low_mode;
  t.threshold = t.lower = t.upper = t.air_level + o.theta * (t.water_level - t.air_level);
  if (quirk) {
    t.note = "thres.m's quirk: a bin on the other side of the first split holds a mode's count and was averaged into "
             "that mode (as Kramer's toolbox does)";
  }
  return t;
}

}  // namespace

Threshold choose_threshold(const VoltageHistogram& h, const BinarisationOptions& o) {
  Threshold t;
  t.rule = o.rule;
  t.probe = o.probe;
  if (auto levels = h.binary_levels()) {
    t.binary_input = true;
    if (levels->size() == 1) {
      // One value: in a 0/1 file, 1 is air; otherwise no interface is seen and
      // the channel is taken as water.
      t.constant = true;
      const bool air = (*levels)[0] == 1.0;
      t.air_level = t.water_level = (*levels)[0];
      t.threshold = air ? (*levels)[0] - 0.5 : (*levels)[0] + 0.5;
      t.note = air ? "constant channel at 1: binary input, all air" : "constant channel: no interface, taken as water";
    } else {
      t.water_level = (*levels)[0];
      t.air_level = (*levels)[1];
      t.threshold = 0.5 * (t.water_level + t.air_level);
      t.note = "binary input (two levels): higher level is air, not thresholded again";
    }
    t.lower = t.upper = t.threshold;
    return t;
  }
  const bool air_low = o.probe == ProbeType::conductivity;
  if (o.rule == ThresholdRule::fixed) {
    t.threshold = t.lower = t.upper = o.fixed_threshold.value_or(0.0);
    return t;
  }
  if (o.rule == ThresholdRule::kramer) return kramer_threshold(h, o, t);
  double width = o.bin_width;
  const double lo = h.min_value(), hi = h.max_value();
  if (width == 0.0 || o.rule == ThresholdRule::felder) {
    if (o.rule == ThresholdRule::felder) width = 0.1;
    else width = (hi - lo) / 100.0;
  }
  if (!(width > 0.0)) {
    throw InputError("the signal has no spread: no threshold can be found", "threshold-rule,threshold");
  }
  const auto bins = h.regroup(width);
  if (bins.size() == 1) {
    // Every sample in one bin: a channel without interfaces (a tip in water,
    // or a dead channel). Not an error: all water, and said so.
    t.constant = true;
    t.air_level = t.water_level = (static_cast<double>(bins[0].first) + 0.5) * width;
    t.threshold = t.lower = t.upper = air_low ? lo - 1.0 : hi + 1.0;
    t.note = "every sample in one histogram bin: no interface, taken as water";
    return t;
  }
  // Search each side for its most populated bin; ties go to the first bin.
  struct Mode {
    std::int64_t bin = 0, count = -1;
  } low_mode, high_mode;
  const double split = o.rule == ThresholdRule::felder ? o.felder_split : 0.5 * (lo + hi);
  for (const auto& [bin, count] : bins) {
    if (o.rule == ThresholdRule::felder) {
      const double label = static_cast<double>(bin + 1) * width;  // upper edge
      if (label <= split + 1e-9 && count > low_mode.count) low_mode = {bin, count};
      if (label >= split - 1e-9 && count > high_mode.count) high_mode = {bin, count};
    } else {
      const double centre = (static_cast<double>(bin) + 0.5) * width;
      if (centre < split && count > low_mode.count) low_mode = {bin, count};
      if (centre >= split && count > high_mode.count) high_mode = {bin, count};
    }
  }
  if (low_mode.count < 0 || high_mode.count < 0) {
    throw InputError(fmt::format("no {} mode found: the voltage histogram has no populated bin {} {:.3f} V; use a "
                                 "fixed threshold voltage",
                                 low_mode.count < 0 ? "low" : "high", low_mode.count < 0 ? "below" : "above", split),
                     "threshold-rule,threshold");
  }
  auto level = [&](std::int64_t bin) {
    return o.rule == ThresholdRule::felder ? static_cast<double>(bin + 1) * width
                                           : (static_cast<double>(bin) + 0.5) * width;
  };
  const double low_level = level(low_mode.bin), high_level = level(high_mode.bin);
  t.air_level = air_low ? low_level : high_level;
  t.water_level = air_low ? high_level : low_level;
  const double span = t.water_level - t.air_level;
  t.threshold = t.air_level + o.theta * span;
  if (o.rule == ThresholdRule::hysteresis) {
    const double a = t.air_level + o.hysteresis_low * span;
    const double b = t.air_level + o.hysteresis_high * span;
    t.lower = std::min(a, b);
    t.upper = std::max(a, b);
  } else {
    t.lower = t.upper = t.threshold;
  }
  if (o.rule == ThresholdRule::felder) t.tolerance = 1e-5;
  if (low_mode.bin == high_mode.bin) {
    t.note = "air and water modes fall in one bin: the channel may hold no bubble";
  }
  return t;
}

Binariser::Binariser(const Threshold& threshold, double fs) : t_(threshold) { out_.fs = fs; }

void Binariser::feed(std::span<const float> values, std::size_t first, std::size_t stride) {
  const bool binary = t_.binary_input;
  const bool air_low = !binary && t_.probe == ProbeType::conductivity;
  // Air test per sample: conductivity air below, optical and binary air above.
  // Compared in double: a threshold between two floats must not move to one of them.
  const double lower = t_.lower + (air_low ? t_.tolerance : -t_.tolerance);
  const double upper = t_.upper + (air_low ? t_.tolerance : -t_.tolerance);
  const bool hysteresis = t_.rule == ThresholdRule::hysteresis && !binary;
  std::int64_t n = position_;
  for (std::size_t i = first; i < values.size(); i += stride, ++n) {
    const double v = values[i];
    bool air;
    if (!hysteresis) {
      air = air_low ? v < upper : v > lower;
    } else if (!started_) {
      air = air_low ? v < 0.5 * (lower + upper) : v > 0.5 * (lower + upper);
    } else if (in_air_) {
      air = air_low ? !(v > upper) : !(v < lower);
    } else {
      air = air_low ? v < lower : v > upper;
    }
    if (!started_) {
      started_ = true;
      in_air_ = air;
      air_start_ = n;
      continue;
    }
    if (air != in_air_) {
      if (in_air_) out_.intervals.push_back({air_start_, n});
      else air_start_ = n;
      in_air_ = air;
    }
  }
  position_ = n;
}

void Binariser::feed_run(float value, std::int64_t length) {
  if (length <= 0) return;
  // The first sample may switch the state; the rest repeat its decision.
  const float one[1] = {value};
  feed(one, 0, 1);
  position_ += length - 1;
}

AirIntervals Binariser::finish() {
  if (started_ && in_air_) out_.intervals.push_back({air_start_, position_});
  out_.sample_count = position_;
  started_ = false;
  return std::move(out_);
}

}  // namespace awcc
