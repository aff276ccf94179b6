#pragma once
// Channels as the columns of a stored array (an HDF5 dataset, a MATLAB
// matrix): which way round the array holds them, and how a block of it is
// interleaved into frames. Not installed; the readers' own.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace awcc::detail {

/// A probe has a handful of tips: an array with more columns than rows is
/// taken as channels x samples when it has at most this many rows.
inline constexpr std::uint64_t kMaxStackedChannels = 16;

/// A 2-D array read as a recording.
struct ColumnLayout {
  std::uint64_t frames = 0;
  std::uint64_t channels = 0;
  bool transposed = false;  ///< stored channels x samples: one channel per row
};

/// The array of `rows` x `columns` as samples x channels when it has at
/// least as many rows as columns; as channels x samples (transposed) when it
/// has more columns than rows and at most kMaxStackedChannels rows (MATLAB and
/// NumPy users store signals as stacked rows as often as not, and no probe
/// recording has fewer samples than channels); neither otherwise (nullopt:
/// more columns than rows, and too many rows to be channels).
[[nodiscard]] constexpr std::optional<ColumnLayout> column_layout(std::uint64_t rows, std::uint64_t columns) {
  if (rows >= columns) return ColumnLayout{rows, columns, false};
  if (rows <= kMaxStackedChannels) return ColumnLayout{columns, rows, true};
  return std::nullopt;
}

/// Where value (frame i, channel c) lies in a block of `frames` frames of
/// `channels` channels as stored: each channel's run whole (`channels_first`:
/// a row-major channels x samples block, a column-major samples x channels
/// one) or frame after frame.
[[nodiscard]] constexpr std::size_t stored_index(bool channels_first, std::size_t frames, std::size_t channels,
                                                 std::size_t i, std::size_t c) {
  return channels_first ? c * frames + i : i * channels + c;
}

/// Interleaves a block of one array's `channels` channels into frames of
/// `out_channels` channels, from channel `first` on:
/// out[i * out_channels + first + c] = convert(value(stored_index(...)), i, c).
/// `value(k)` gives the block's k-th stored value; `convert` turns it into a
/// sample (scaling, refusing what is not finite: it knows frame and channel).
template <class Value, class Out, class Convert>
void interleave(std::size_t frames, std::size_t channels, bool channels_first, Value value, std::span<Out> out,
                std::size_t out_channels, std::size_t first, Convert convert) {
  for (std::size_t i = 0; i < frames; ++i) {
    for (std::size_t c = 0; c < channels; ++c) {
      out[i * out_channels + first + c] = convert(value(stored_index(channels_first, frames, channels, i, c)), i, c);
    }
  }
}

}  // namespace awcc::detail
