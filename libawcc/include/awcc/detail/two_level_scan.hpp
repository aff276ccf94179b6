#pragma once
// Binary recordings read as 16-bit counts (METHOD.md 2: a channel holding at
// most two distinct values is binary input, its higher value air). For the
// library's own use and its tests; not installed, not a stable interface.
//
// A binary channel needs neither a histogram of every sample nor a threshold
// test per sample: its level changes say everything. The scan compares every
// sample with the one a frame earlier (all channels at once, eight counts per
// vector comparison), keeps the changes of the tips' channels, and stops as
// soon as any tip shows a third value (then the recording is not binary and the
// caller binarises it the general way). The levels' counts follow from the
// run lengths, so the histogram, the threshold and the air intervals equal
// those of the general path on the same counts.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "awcc/air_intervals.hpp"
#include "awcc/binarisation.hpp"

namespace awcc::detail {

class TwoLevelScan {
 public:
  /// Frames of `stride` interleaved channels; tip k is channel `channels[k]`
  /// (distinct, below stride).
  TwoLevelScan(std::size_t stride, std::span<const std::size_t> channels);

  /// Scans the next `frames` frames. False once a tip has shown a third
  /// distinct value: the recording is not binary, and the scan is spent.
  [[nodiscard]] bool feed(const std::int16_t* data, std::size_t frames);

  [[nodiscard]] std::int64_t samples() const { return position_; }

  /// Histogram of tip k (the order of `channels`) at `quantum` volts per count.
  [[nodiscard]] VoltageHistogram histogram(int tip, double quantum) const;
  /// The air intervals of tip k under `threshold` (chosen on histogram(tip)).
  [[nodiscard]] AirIntervals intervals(int tip, const Threshold& threshold, double quantum, double fs) const;

 private:
  struct Tip {
    std::size_t channel = 0;
    std::int16_t level[2] = {0, 0};
    int levels = 0;
    // The first sample of each run, the first at sample 0. A change is to a
    // value other than the run's before it, so with two levels the runs
    // alternate and run i is at level[i % 2]: its value is not kept (8
    // bytes a change instead of 16; a 300 s binary W64 holds about a
    // million a tip).
    std::vector<std::int64_t> changes;
  };
  [[nodiscard]] bool change(Tip& tip, std::int64_t index, std::int16_t value);

  std::size_t stride_;
  std::vector<Tip> tips_;
  std::vector<int> tip_of_channel_;     // -1 for channels that are not a tip
  std::vector<std::int16_t> last_frame_;
  std::vector<std::uint32_t> offsets_;  // scratch: changed counts of one block
  std::int64_t position_ = 0;
};

}  // namespace awcc::detail
