#include "awcc/air_intervals.hpp"

#include <algorithm>
#include <string_view>

namespace awcc {

std::int64_t AirIntervals::air_samples() const {
  std::int64_t total = 0;
  for (const auto& iv : intervals) total += iv.stop - iv.start;
  return total;
}

std::int64_t shared_air_samples(const AirIntervals& a, const AirIntervals& b) {
  std::int64_t shared = 0;
  auto i = a.intervals.begin(), j = b.intervals.begin();
  while (i != a.intervals.end() && j != b.intervals.end()) {
    shared += std::max<std::int64_t>(0, std::min(i->stop, j->stop) - std::max(i->start, j->start));
    if (i->stop < j->stop) ++i;
    else ++j;
  }
  return shared;
}

double AirIntervals::void_fraction() const {
  if (sample_count <= 0) return 0.0;
  return static_cast<double>(air_samples()) / static_cast<double>(sample_count);
}

void AirIntervals::render(std::int64_t first, std::span<std::uint8_t> out) const {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  const std::int64_t last = first + static_cast<std::int64_t>(out.size());
  // First interval that may reach into the block.
  auto it = std::partition_point(intervals.begin(), intervals.end(),
                                 [first](const AirInterval& iv) { return iv.stop <= first; });
  for (; it != intervals.end() && it->start < last; ++it) {
    const std::int64_t a = std::max(it->start, first);
    const std::int64_t b = std::min(it->stop, last);
    std::fill(out.begin() + (a - first), out.begin() + (b - first), std::uint8_t{1});
  }
}

std::string_view AirIntervals::check() const {
  std::int64_t previous_stop = -1;
  for (const auto& iv : intervals) {
    if (iv.start >= iv.stop) return "an interval is empty or reversed";
    if (iv.start < 0 || iv.stop > sample_count) return "an interval lies outside the record";
    if (iv.start <= previous_stop) return "intervals overlap, touch or are out of order";
    previous_stop = iv.stop;
  }
  return {};
}

void normalise(std::vector<AirInterval>& intervals) {
  std::sort(intervals.begin(), intervals.end(),
            [](const AirInterval& a, const AirInterval& b) { return a.start < b.start; });
  std::size_t out = 0;
  for (const auto& iv : intervals) {
    if (iv.start >= iv.stop) continue;
    if (out > 0 && iv.start <= intervals[out - 1].stop) {
      intervals[out - 1].stop = std::max(intervals[out - 1].stop, iv.stop);
    } else {
      intervals[out++] = iv;
    }
  }
  intervals.resize(out);
}

std::vector<std::uint8_t> to_dense(const AirIntervals& signal) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(signal.sample_count));
  signal.render(0, out);
  return out;
}

AirIntervals from_dense(std::span<const std::uint8_t> samples, double fs) {
  AirIntervals signal;
  signal.fs = fs;
  signal.sample_count = static_cast<std::int64_t>(samples.size());
  std::int64_t start = -1;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const bool air = samples[i] != 0;
    if (air && start < 0) start = static_cast<std::int64_t>(i);
    if (!air && start >= 0) {
      signal.intervals.push_back({start, static_cast<std::int64_t>(i)});
      start = -1;
    }
  }
  if (start >= 0) signal.intervals.push_back({start, signal.sample_count});
  return signal;
}

}  // namespace awcc
