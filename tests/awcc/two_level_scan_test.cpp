// The binary-recording scan (awcc/detail/two_level_scan.hpp) and the
// read-ahead of blocks (awcc/detail/read_ahead.hpp), against brute force.
#include "awcc/detail/read_ahead.hpp"
#include "awcc/detail/two_level_scan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <random>
#include <stdexcept>

namespace {

using awcc::detail::TwoLevelScan;

struct Interleaved {
  std::vector<std::int16_t> data;
  std::size_t stride;
};

// `frames` frames of `stride` channels; the tips hold two levels each with a
// run length drawn around `mean_run`, every other channel is noise.
Interleaved binary_frames(std::size_t frames, std::size_t stride, const std::vector<std::size_t>& tips,
                          double mean_run, unsigned seed) {
  std::mt19937 rng(seed);
  std::exponential_distribution<double> run(1.0 / mean_run);
  Interleaved out{std::vector<std::int16_t>(frames * stride), stride};
  const std::int16_t levels[3][2] = {{0, 1}, {-1200, 31000}, {-32768, 32767}};
  for (std::size_t c = 0; c < stride; ++c) {
    const auto tip = std::find(tips.begin(), tips.end(), c);
    if (tip == tips.end()) {
      for (std::size_t i = 0; i < frames; ++i) out.data[i * stride + c] = static_cast<std::int16_t>(rng() % 65536);
      continue;
    }
    const auto& l = levels[std::min<std::ptrdiff_t>(tip - tips.begin(), 2)];
    int state = static_cast<int>(rng() % 2);
    std::size_t i = 0;
    while (i < frames) {
      const auto len = 1 + static_cast<std::size_t>(run(rng));
      for (std::size_t j = 0; j < len && i < frames; ++j, ++i) out.data[i * stride + c] = l[state];
      state ^= 1;
    }
  }
  return out;
}

// Feeds the frames in blocks of random sizes (1 frame to several thousand), so
// that changes fall on block edges and at every offset within the 64-count steps.
bool feed_in_blocks(TwoLevelScan& scan, const Interleaved& x, unsigned seed) {
  std::mt19937 rng(seed);
  const std::size_t frames = x.data.size() / x.stride;
  std::size_t done = 0;
  while (done < frames) {
    const std::size_t m = std::min<std::size_t>(frames - done, 1 + rng() % (rng() % 2 ? 7 : 5000));
    if (!scan.feed(x.data.data() + done * x.stride, m)) return false;
    done += m;
  }
  return true;
}

// Brute force: the histogram and air intervals of a channel, air above the
// middle of its two levels (binary input, METHOD 2).
struct Expected {
  std::vector<std::pair<double, std::int64_t>> values;
  awcc::AirIntervals intervals;
};
Expected brute_force(const Interleaved& x, std::size_t channel, double quantum) {
  const std::size_t frames = x.data.size() / x.stride;
  std::map<std::int16_t, std::int64_t> counts;
  for (std::size_t i = 0; i < frames; ++i) ++counts[x.data[i * x.stride + channel]];
  Expected e;
  for (auto [v, n] : counts) e.values.emplace_back(static_cast<float>(v * quantum), n);
  const double middle = counts.size() == 2 ? 0.5 * (counts.begin()->first + counts.rbegin()->first) : 1e9;
  std::vector<std::uint8_t> dense(frames);
  for (std::size_t i = 0; i < frames; ++i) dense[i] = x.data[i * x.stride + channel] > middle;
  e.intervals = awcc::from_dense(dense, 1000.0);
  return e;
}

TEST(TwoLevelScan, EqualsBruteForceForAnyStrideAndBlockSplit) {
  struct Case {
    std::size_t stride;
    std::vector<std::size_t> tips;
    double mean_run;
  };
  // Two tips in any order among noise channels, and probes of 4 and 5 tips.
  for (const Case& c : {Case{2, {0, 1}, 150.0}, Case{2, {1, 0}, 3.0}, Case{3, {2, 0}, 20.0}, Case{5, {1, 3}, 70.0},
                        Case{2, {0, 1}, 1.0}, Case{4, {0, 1, 2, 3}, 40.0}, Case{6, {5, 0, 2, 3, 1}, 9.0}}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const auto x = binary_frames(30011, c.stride, c.tips, c.mean_run, seed);
      TwoLevelScan scan(c.stride, c.tips);
      ASSERT_TRUE(feed_in_blocks(scan, x, seed + 100)) << "stride " << c.stride;
      EXPECT_EQ(scan.samples(), 30011);
      const double quantum = 1.0 / 32768.0;
      for (std::size_t tip = 0; tip < c.tips.size(); ++tip) {
        const auto e = brute_force(x, c.tips[tip], quantum);
        const auto h = scan.histogram(static_cast<int>(tip), quantum);
        EXPECT_EQ(h.values(), e.values) << "stride " << c.stride << " tip " << tip;
        const auto t = awcc::choose_threshold(h, {});
        ASSERT_TRUE(t.binary_input);
        const auto got = scan.intervals(static_cast<int>(tip), t, quantum, 1000.0);
        EXPECT_EQ(got.intervals, e.intervals.intervals) << "stride " << c.stride << " tip " << tip << " seed " << seed;
        EXPECT_EQ(got.sample_count, 30011);
        EXPECT_EQ(got.check(), "");
      }
    }
  }
}

TEST(TwoLevelScan, AThirdValueOnATipEndsTheScanButNotOnAnotherChannel) {
  const std::vector<std::size_t> tips{0, 2};
  auto x = binary_frames(20000, 3, tips, 50.0, 7);  // channel 1 is noise: ignored
  {
    TwoLevelScan scan(3, tips);
    EXPECT_TRUE(feed_in_blocks(scan, x, 1));
  }
  // One sample of a third value, deep inside a block and at a block's first frame.
  for (std::size_t frame : {std::size_t{12345}, std::size_t{0}, std::size_t{19999}}) {
    auto y = x;
    y.data[frame * 3 + 2] = 555;
    TwoLevelScan scan(3, tips);
    EXPECT_FALSE(feed_in_blocks(scan, y, 1)) << frame;
  }
}

TEST(TwoLevelScan, AConstantTipIsOneLevel) {
  Interleaved x{std::vector<std::int16_t>(2 * 5000, 7), 2};
  for (std::size_t i = 0; i < 5000; i += 2) x.data[2 * i] = 9;  // lead alternates, trail constant at 7
  const std::vector<std::size_t> tips{0, 1};
  TwoLevelScan scan(2, tips);
  ASSERT_TRUE(scan.feed(x.data.data(), 5000));
  const auto h = scan.histogram(1, 1.0);
  EXPECT_EQ(h.values(), (std::vector<std::pair<double, std::int64_t>>{{7.0, 5000}}));
  const auto t = awcc::choose_threshold(h, {});
  EXPECT_TRUE(t.constant);
  EXPECT_TRUE(scan.intervals(1, t, 1.0, 1.0).intervals.empty());  // constant, not 1: taken as water
  EXPECT_EQ(scan.histogram(0, 1.0).total(), 5000);
}

// --- read-ahead ---------------------------------------------------------------

// A source of numbered frames that fails after `fail_after` frames (or never).
struct Source {
  std::int64_t frames, fail_after, position = 0;
  std::int64_t operator()(std::span<int> out, std::int64_t max) {
    if (position >= fail_after) throw std::runtime_error("damaged at frame " + std::to_string(position));
    const std::int64_t n = std::min({max, frames - position, fail_after - position});
    for (std::int64_t i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = static_cast<int>(position + i);
    position += n;
    return n;
  }
};

TEST(ReadAhead, BlocksComeInOrderWithOrWithoutTheThread) {
  for (bool threaded : {false, true}) {
    Source src{100003, 1 << 30};
    awcc::detail::ReadAhead<int> reader(std::ref(src), 1000, 1, threaded);
    std::int64_t expected = 0, blocks = 0;
    for (auto b = reader.next(); !b.empty(); b = reader.next(), ++blocks) {
      for (int v : b) ASSERT_EQ(v, expected++);
    }
    EXPECT_EQ(expected, 100003);
    EXPECT_EQ(blocks, 101);
    EXPECT_TRUE(reader.next().empty());  // stays at the end
  }
}

TEST(ReadAhead, AReadersErrorComesAfterTheBlocksBeforeIt) {
  for (bool threaded : {false, true}) {
    Source src{100000, 4500};
    awcc::detail::ReadAhead<int> reader(std::ref(src), 1000, 1, threaded);
    std::int64_t seen = 0;
    try {
      for (auto b = reader.next(); !b.empty(); b = reader.next()) seen += static_cast<std::int64_t>(b.size());
      FAIL() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "damaged at frame 4500");
    }
    EXPECT_EQ(seen, 4500);
  }
}

TEST(ReadAhead, StoppingEarlyJoinsTheThread) {
  Source src{1 << 30, 1 << 30};
  {
    awcc::detail::ReadAhead<int> reader(std::ref(src), 1000, 1, true);
    EXPECT_EQ(reader.next().size(), 1000u);
  }  // destroyed with the reader blocked on full slots: must not hang
  EXPECT_LE(src.position, 4000);  // at most the held block and the slots ahead
}

}  // namespace
