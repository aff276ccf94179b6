#pragma once
// A binary phase signal (1 = air, 0 = water) held as its sorted list of air
// intervals [start, stop) in samples. This is the currency between the
// synthetic probe, the readers and the processors: it is small (two integers
// per bubble instead of one value per sample) and void fraction, chord times
// and interval-based correlation follow from it directly.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace awcc {

struct AirInterval {
  std::int64_t start = 0;  ///< first air sample
  std::int64_t stop = 0;   ///< one past the last air sample
  friend bool operator==(const AirInterval&, const AirInterval&) = default;
};

struct AirIntervals {
  std::vector<AirInterval> intervals;  ///< sorted, disjoint, non-touching, inside [0, sample_count)
  std::int64_t sample_count = 0;       ///< length of the record in samples
  double fs = 0.0;                     ///< sampling rate, Hz

  /// Air samples over all samples (0 for an empty record).
  [[nodiscard]] double void_fraction() const;
  /// Total air samples.
  [[nodiscard]] std::int64_t air_samples() const;
  /// Writes samples [first, first + out.size()) as 0/1 into out.
  void render(std::int64_t first, std::span<std::uint8_t> out) const;
  /// Checks the invariants above; returns an empty string or what is wrong.
  [[nodiscard]] std::string_view check() const;
};

/// Sorts intervals by start and merges overlapping or touching ones, so that
/// a union of per-bubble intervals becomes a valid AirIntervals list.
void normalise(std::vector<AirInterval>& intervals);

/// The samples where both signals are air (their intervals' intersection),
/// in one merge of the two lists.
[[nodiscard]] std::int64_t shared_air_samples(const AirIntervals& a, const AirIntervals& b);

/// Renders one record as a dense 0/1 vector (tests and small records only).
std::vector<std::uint8_t> to_dense(const AirIntervals& signal);

/// Builds intervals from a dense 0/1 (nonzero = air) vector.
AirIntervals from_dense(std::span<const std::uint8_t> samples, double fs);

}  // namespace awcc
