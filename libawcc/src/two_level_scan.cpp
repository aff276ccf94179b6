#include "awcc/detail/two_level_scan.hpp"

#include <algorithm>
#include <bit>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace awcc::detail {

TwoLevelScan::TwoLevelScan(std::size_t stride, std::span<const std::size_t> channels)
    : stride_(stride), tips_(channels.size()), tip_of_channel_(stride, -1), last_frame_(stride, 0) {
  for (std::size_t k = 0; k < channels.size(); ++k) {
    tips_[k].channel = channels[k];
    tip_of_channel_[channels[k]] = static_cast<int>(k);
  }
}

bool TwoLevelScan::change(Tip& tip, std::int64_t index, std::int16_t value) {
  // The caller reports a change only where the value differs from the
  // sample before, so the third run on is at level[run % 2] or at a third value.
  const std::size_t run = tip.changes.size();
  if (run < 2) {
    tip.level[run] = value;
    tip.levels = static_cast<int>(run) + 1;
  } else if (value != tip.level[run % 2]) {
    return false;
  }
  tip.changes.push_back(index);
  return true;
}

namespace {

// Appends to `out` every offset k in [begin, n) with data[k] != data[k - s]
// (a count that differs from the one a frame earlier); returns the new end.
// 64 counts give one bit each; a step without a change (about 70 % of them at
// one interface per 200 counts) costs the loads, the comparisons and one test.
std::uint32_t* find_changes_scalar(const std::int16_t* data, std::size_t k, std::size_t n, std::size_t s,
                                   std::uint32_t* out) {
  for (; k < n; ++k)
    if (data[k] != data[k - s]) *out++ = static_cast<std::uint32_t>(k);
  return out;
}

inline std::uint32_t* append_bits(std::uint64_t differ, std::size_t k, std::uint32_t* out) {
  while (differ) {
    *out++ = static_cast<std::uint32_t>(k + static_cast<std::size_t>(std::countr_zero(differ)));
    differ &= differ - 1;
  }
  return out;
}

#if defined(__SSE2__)
std::uint32_t* find_changes_sse2(const std::int16_t* data, std::size_t k, std::size_t n, std::size_t s,
                                 std::uint32_t* out) {
  for (; k + 64 <= n; k += 64) {
    std::uint64_t same = 0;
    for (std::size_t j = 0; j < 4; ++j) {
      const std::int16_t* p = data + k + 16 * j;
      const __m128i e0 = _mm_cmpeq_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)),
                                         _mm_loadu_si128(reinterpret_cast<const __m128i*>(p - s)));
      const __m128i e1 = _mm_cmpeq_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 8)),
                                         _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 8 - s)));
      // Lanes are 0 or -1: packing with saturation keeps one byte per count.
      same |= static_cast<std::uint64_t>(static_cast<unsigned>(_mm_movemask_epi8(_mm_packs_epi16(e0, e1))))
              << (16 * j);
    }
    if (~same) [[unlikely]] out = append_bits(~same, k, out);
  }
  return find_changes_scalar(data, k, n, s, out);
}
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PDP_HAVE_AVX2_SCAN 1
__attribute__((target("avx2"))) std::uint32_t* find_changes_avx2(const std::int16_t* data, std::size_t k,
                                                                 std::size_t n, std::size_t s, std::uint32_t* out) {
  for (; k + 64 <= n; k += 64) {
    std::uint64_t same = 0;
    for (std::size_t j = 0; j < 2; ++j) {
      const std::int16_t* p = data + k + 32 * j;
      const __m256i e0 = _mm256_cmpeq_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)),
                                            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p - s)));
      const __m256i e1 = _mm256_cmpeq_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 16)),
                                            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 16 - s)));
      // Packing works within 128-bit lanes; the permutation restores count order.
      const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packs_epi16(e0, e1), 0xD8);
      same |= static_cast<std::uint64_t>(static_cast<unsigned>(_mm256_movemask_epi8(bytes))) << (32 * j);
    }
    if (~same) [[unlikely]] out = append_bits(~same, k, out);
  }
  return find_changes_scalar(data, k, n, s, out);
}
#endif

using FindChanges = std::uint32_t* (*)(const std::int16_t*, std::size_t, std::size_t, std::size_t, std::uint32_t*);

FindChanges pick_find_changes() {
#if defined(PDP_HAVE_AVX2_SCAN)
  if (__builtin_cpu_supports("avx2")) return find_changes_avx2;
#endif
#if defined(__SSE2__)
  return find_changes_sse2;
#else
  return find_changes_scalar;
#endif
}

}  // namespace

bool TwoLevelScan::feed(const std::int16_t* data, std::size_t frames) {
  static const FindChanges find_changes = pick_find_changes();
  if (frames == 0) return true;
  const std::size_t s = stride_;
  const std::size_t n = frames * s;
  if (n > std::numeric_limits<std::uint32_t>::max()) {
    // Offsets are 32-bit: scan a huge block in parts .
    const std::size_t part = (std::size_t{1} << 30) / s;
    std::size_t done = 0;
    while (done < frames) {
      const std::size_t m = std::min(part, frames - done);
      if (!feed(data + done * s, m)) return false;
      done += m;
    }
    return true;
  }
  // The first frame against the previous block's last (or opening the runs).
  for (auto& tip : tips_) {
    const std::int16_t v = data[tip.channel];
    if (position_ == 0 || v != last_frame_[tip.channel]) {
      if (!change(tip, position_, v)) return false;
    }
  }
  // In chunks of 64 Ki counts: the offsets' scratch stays small (a noisy
  // channel changes at every count) and a third value is seen early.
  constexpr std::size_t chunk = std::size_t{1} << 16;
  offsets_.resize(std::min(n, chunk));
  for (std::size_t begin = s; begin < n; begin += chunk) {
    const std::size_t stop = std::min(n, begin + chunk);
    const std::uint32_t* end = find_changes(data, begin, stop, s, offsets_.data());
    for (const std::uint32_t* o = offsets_.data(); o != end; ++o) {
      const std::size_t k = *o;
      const std::size_t channel = s == 2 ? (k & 1u) : k % s;
      const int t = tip_of_channel_[channel];
      if (t >= 0 && !change(tips_[static_cast<std::size_t>(t)], position_ + static_cast<std::int64_t>(k / s), data[k])) return false;
    }
  }
  std::copy(data + n - s, data + n, last_frame_.begin());
  position_ += static_cast<std::int64_t>(frames);
  return true;
}

VoltageHistogram TwoLevelScan::histogram(int tip, double quantum) const {
  const Tip& t = tips_[static_cast<std::size_t>(tip)];
  std::int64_t count[2] = {0, 0};
  for (std::size_t c = 0; c < t.changes.size(); ++c) {
    const std::int64_t end = c + 1 < t.changes.size() ? t.changes[c + 1] : position_;
    count[c % 2] += end - t.changes[c];
  }
  VoltageHistogram h(quantum);
  for (int l = 0; l < t.levels; ++l) {
    const std::int64_t one[1] = {count[l]};
    h.add_counts(one, t.level[l]);
  }
  return h;
}

AirIntervals TwoLevelScan::intervals(int tip, const Threshold& threshold, double quantum, double fs) const {
  const Tip& t = tips_[static_cast<std::size_t>(tip)];
  // Each level's decision is the binariser's own, asked once per level; the
  // runs then become intervals without a decision per change.
  bool air[2] = {false, false};
  for (int l = 0; l < t.levels; ++l) {
    Binariser probe(threshold, fs);
    // The value as the histogram holds it (VoltageHistogram::add_counts).
    probe.feed_run(static_cast<float>(static_cast<double>(t.level[l]) * quantum), 1);
    air[l] = !probe.finish().intervals.empty();
  }
  AirIntervals out;
  out.fs = fs;
  out.sample_count = position_;
  bool in_air = false;
  std::int64_t start = 0;
  // At most one interval for every two runs: reserved, so that the array
  // does not grow by doubling beside the scan's changes (the binary path's
  // peak memory).
  out.intervals.reserve(t.changes.size() / 2 + 1);
  for (std::size_t c = 0; c < t.changes.size(); ++c) {
    const bool now = air[c % 2];
    if (now == in_air) continue;
    if (now) start = t.changes[c];
    else out.intervals.push_back({start, t.changes[c]});
    in_air = now;
  }
  if (in_air) out.intervals.push_back({start, position_});
  return out;
}

}  // namespace awcc::detail
