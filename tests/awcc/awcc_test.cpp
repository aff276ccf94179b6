#include "awcc/detail/awcc_steps.hpp"
#include "awcc/awcc.hpp"
#include "awcc/velocity_series.hpp"
#include "awcc/detail/awcc_driver.hpp"
#include "awcc/process.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "random_signals.hpp"

namespace {

using awcc::AirInterval;
using awcc::AirIntervals;

using pdp_test::telegraph;

// Naive normalised correlation of a window, in long double.
std::vector<double> naive(const std::vector<std::uint8_t>& dx, const std::vector<std::uint8_t>& dy, std::int64_t start,
                          std::int64_t length, std::int64_t k_min, std::int64_t k_max) {
  long double mx = 0, my = 0;
  for (std::int64_t t = 0; t < length; ++t) {
    mx += dx[static_cast<std::size_t>(start + t)];
    my += dy[static_cast<std::size_t>(start + t)];
  }
  mx /= length;
  my /= length;
  long double qx = 0, qy = 0;
  for (std::int64_t t = 0; t < length; ++t) {
    qx += (dx[static_cast<std::size_t>(start + t)] - mx) * (dx[static_cast<std::size_t>(start + t)] - mx);
    qy += (dy[static_cast<std::size_t>(start + t)] - my) * (dy[static_cast<std::size_t>(start + t)] - my);
  }
  std::vector<double> r;
  for (std::int64_t k = k_min; k <= k_max; ++k) {
    long double s = 0;
    for (std::int64_t t = std::max<std::int64_t>(0, -k); t < std::min(length, length - k); ++t) {
      s += (dx[static_cast<std::size_t>(start + t)] - mx) * (dy[static_cast<std::size_t>(start + t + k)] - my);
    }
    r.push_back(static_cast<double>(s / std::sqrt(qx * qy)));
  }
  return r;
}

TEST(Windows, HoldNpAirAndWaterChordsAndTileTheRecord) {
  const auto x = telegraph(20'000, 3);
  const int np = 10;
  const auto w = awcc::awcc_windows(x, np);
  ASSERT_GT(w.size(), 10u);
  EXPECT_EQ(w.front().start, 0);
  std::int64_t covered = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    covered += w[i].length;
    if (i + 1 < w.size()) {
      EXPECT_EQ(w[i].start + w[i].length, w[i + 1].start);
    }
    if (i > 0 && i + 1 < w.size()) {
      EXPECT_EQ(w[i].particles, np) << i;  // inner windows: Np chords exactly
    }
  }
  EXPECT_EQ(covered, x.sample_count);
  EXPECT_GE(w.back().particles, np);
  // Boundaries are the 2 Np i-th transitions.
  std::vector<std::int64_t> transitions;
  for (const auto& iv : x.intervals) {
    if (iv.start > 0) transitions.push_back(iv.start);
    if (iv.stop < x.sample_count) transitions.push_back(iv.stop);
  }
  for (std::size_t i = 1; i < w.size(); ++i) EXPECT_EQ(w[i].start, transitions[i * 2 * np - 1]);
  EXPECT_TRUE(awcc::awcc_windows(telegraph(50, 1), 100).empty());
}

TEST(WindowCorrelation, IntervalPathEqualsNaiveAndFftPaths) {
  // Thousands of windows of random binary signals, full and restricted lag
  // ranges: interval path against a naive long-double sum, FFT path against
  // the interval path, both to rounding.
  const auto x = telegraph(400'000, 5), y = telegraph(400'000, 6, 1000.0, 15, 30);
  const auto dx = awcc::to_dense(x), dy = awcc::to_dense(y);
  const auto windows = awcc::awcc_windows(x, 5);
  ASSERT_GT(windows.size(), 2000u);
  awcc::AwccWorkspace plans;
  std::size_t compared = 0;
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const auto& w = windows[i];
    const std::int64_t k_min = i % 3 == 0 ? -(w.length - 1) : -3, k_max = i % 3 == 0 ? w.length - 1 : 40;
    if (k_max >= w.length || -k_min >= w.length) continue;
    const auto fast = awcc::detail::window_correlation_intervals(x, y, w.start, w.length, k_min, k_max, plans);
    std::vector<double> xs(dx.begin() + w.start, dx.begin() + w.start + w.length);
    std::vector<double> ys(dy.begin() + w.start, dy.begin() + w.start + w.length);
    const auto fft = awcc::detail::window_correlation_fft(xs, ys, k_min, k_max, plans);
    ASSERT_EQ(fast.size(), fft.size());
    if (i % 10 == 0) {
      const auto ref = naive(dx, dy, w.start, w.length, k_min, k_max);
      for (std::size_t j = 0; j < ref.size(); ++j) ASSERT_NEAR(fast[j], ref[j], 1e-12) << "window " << i << " lag " << j;
    }
    for (std::size_t j = 0; j < fast.size(); ++j) ASSERT_NEAR(fast[j], fft[j], 1e-10) << "window " << i << " lag " << j;
    ++compared;
  }
  EXPECT_GT(compared, 1000u);
}

TEST(WindowCorrelation, ConstantSegmentGivesNothing) {
  AirIntervals x;
  x.fs = 1;
  x.sample_count = 100;
  const auto y = telegraph(100, 1);
  awcc::AwccWorkspace plans;
  EXPECT_TRUE(awcc::detail::window_correlation_intervals(x, y, 0, 100, -99, 99, plans).empty());
  std::vector<double> flat(100, 2.5), other(100, 0.0);
  other[10] = 1;
  EXPECT_TRUE(awcc::detail::window_correlation_fft(flat, other, -5, 5, plans).empty());
}

// Signals whose windows each carry a known delay: the trailing signal is the
// leading one with window i's chords shifted by delay[i] samples.
struct Planted {
  AirIntervals leading, trailing;
  std::vector<std::int64_t> delays;
};

Planted planted(unsigned seed, int np, std::int64_t n = 200'000) {
  Planted p;
  p.leading = telegraph(n, seed, 1000.0, 30, 60);
  const auto windows = awcc::awcc_windows(p.leading, np);
  std::mt19937 rng(seed + 1);
  std::vector<AirInterval> shifted;
  for (const auto& w : windows) {
    const std::int64_t d = 3 + static_cast<std::int64_t>(rng() % 20);
    p.delays.push_back(d);
    for (const auto& iv : p.leading.intervals) {
      if (iv.start >= w.start && iv.start < w.start + w.length) {
        shifted.push_back({std::min(iv.start + d, n), std::min(iv.stop + d, n)});
      }
    }
  }
  awcc::normalise(shifted);
  p.trailing.fs = p.leading.fs;
  p.trailing.sample_count = n;
  p.trailing.intervals = shifted;
  return p;
}

TEST(Awcc, RecoversPlantedDelaysPerWindowExactly) {
  const auto p = planted(9, 10);
  awcc::AwccOptions o;
  o.roc = false;
  o.filter_a = 0.0;
  for (auto path : {awcc::CorrelationPath::intervals, awcc::CorrelationPath::fft}) {
    o.path = path;
    const auto r = awcc::awcc(p.leading, p.trailing, 1.0, o);
    ASSERT_EQ(r.windows.size(), p.delays.size());
    for (std::size_t i = 0; i < r.windows.size(); ++i) {
      EXPECT_EQ(r.windows[i].lag_samples, p.delays[i]) << "window " << i;
      EXPECT_DOUBLE_EQ(r.windows[i].velocity, 1.0 / (static_cast<double>(p.delays[i]) / 1000.0));
    }
  }
}

// --- The one driver and its correlation sources -------------------------------

// Windows of the interval and FFT sources: the same lag in every window (and
// the planted one), the same fate, R12max and SPR to rounding (METHOD 4, item
// 2: both paths give the same R12 to rounding; 1e-10 as in
// WindowCorrelation.IntervalPathEqualsNaiveAndFftPaths), the same velocity to
// rounding of the refined lag.
void expect_same_windows(const awcc::AwccResult& a, const awcc::AwccResult& b) {
  ASSERT_EQ(a.windows.size(), b.windows.size());
  for (std::size_t i = 0; i < a.windows.size(); ++i) {
    const auto &u = a.windows[i], &v = b.windows[i];
    ASSERT_EQ(u.start, v.start);
    EXPECT_EQ(u.fate, v.fate) << "window " << i;
    EXPECT_EQ(u.lag_samples, v.lag_samples) << "window " << i;
    EXPECT_NEAR(u.r12_max, v.r12_max, 1e-10) << "window " << i;
    EXPECT_NEAR(u.spr, v.spr, 1e-9) << "window " << i;
    EXPECT_NEAR(u.velocity, v.velocity, 1e-9 * std::fabs(u.velocity)) << "window " << i;
  }
}

TEST(AwccDriver, FftAndIntervalSourcesGiveThePlantedVelocities) {
  const auto p = planted(21, 10);
  awcc::AwccOptions o;
  o.subsample = awcc::Subsample::parabolic;  // velocities from refined lags: rounding shows, within tolerance
  const double dx = 0.01;
  awcc::AwccWorkspace workspace;
  awcc::detail::IntervalCorrelations intervals(p.leading, p.trailing);
  awcc::detail::RenderedFftCorrelations rendered(p.leading, p.trailing);
  const auto by_intervals = awcc::detail::run_awcc(p.leading, dx, o, intervals, workspace);
  const auto by_fft = awcc::detail::run_awcc(p.leading, dx, o, rendered, workspace);
  ASSERT_EQ(by_intervals.windows.size(), p.delays.size());
  for (std::size_t i = 0; i < p.delays.size(); ++i) {
    EXPECT_EQ(by_intervals.windows[i].lag_samples, p.delays[i]) << "window " << i;
    // A planted shift of d samples peaks at d; the parabola through a binary
    // correlation's rounded triangle stays within half a sample of it.
    EXPECT_NEAR(by_intervals.windows[i].lag * 1000.0, static_cast<double>(p.delays[i]), 0.5) << "window " << i;
  }
  expect_same_windows(by_intervals, by_fft);
  ASSERT_TRUE(by_intervals.ok()) << by_intervals.message;
  EXPECT_EQ(by_intervals.windows_by_fate, by_fft.windows_by_fate);
  EXPECT_NEAR(by_intervals.velocity, by_fft.velocity, 1e-9 * by_intervals.velocity);
  // awcc() is the same driver with the source its options name.
  o.path = awcc::CorrelationPath::fft;
  const auto through_awcc = awcc::awcc(p.leading, p.trailing, dx, o);
  for (std::size_t i = 0; i < by_fft.windows.size(); ++i) {
    EXPECT_EQ(through_awcc.windows[i].lag, by_fft.windows[i].lag) << "window " << i;
  }
}

// Counts of every fate over the windows, by brute force.
void expect_fates_counted(const awcc::AwccResult& r) {
  std::int64_t sum = 0;
  for (std::size_t i = 0; i < awcc::window_fate_count; ++i) {
    const auto fate = static_cast<awcc::WindowFate>(i);
    const auto brute = std::count_if(r.windows.begin(), r.windows.end(),
                                     [fate](const awcc::AwccWindow& w) { return w.fate == fate; });
    EXPECT_EQ(r.count(fate), brute) << awcc::to_string(fate);
    sum += r.count(fate);
  }
  EXPECT_EQ(sum, r.windows_total);
  EXPECT_EQ(r.windows_total, static_cast<std::int64_t>(r.windows.size()));
  EXPECT_EQ(r.windows_accepted, r.count(awcc::WindowFate::accepted));
}

TEST(AwccDriver, FatesAreCountedOncePerWindowAndSumToTheTotal) {
  // Every fate, on windows summarised as they are (no cutoff: fates stay).
  awcc::AwccResult mixed;
  std::mt19937 rng(3);
  for (int i = 0; i < 700; ++i) {
    awcc::AwccWindow w;
    w.fate = static_cast<awcc::WindowFate>(rng() % awcc::window_fate_count);
    w.velocity = 1.0 + 0.01 * (i % 17);
    w.duration = 0.1;
    w.lag_samples = w.fate == awcc::WindowFate::lag ? -1 : 5;
    mixed.windows.push_back(w);
  }
  awcc::AwccOptions o;
  o.roc = false;
  awcc::detail::awcc_summarise(mixed, o);
  for (std::size_t i = 0; i < awcc::window_fate_count; ++i) EXPECT_GT(mixed.windows_by_fate[i], 50) << i;
  expect_fates_counted(mixed);
  // An ok result carries its capped time-scale ratio (the correction's
  // feature), the accepted windows' own; a result that is not ok carries none.
  ASSERT_TRUE(mixed.ok()) << mixed.message;
  ASSERT_TRUE(mixed.time_scale_ratio);
  EXPECT_EQ(*mixed.time_scale_ratio, *awcc::capped_time_scale_ratio(mixed, awcc::time_scale_ratio_cap));
  awcc::AwccResult few = mixed;
  few.windows.resize(3);
  awcc::detail::awcc_summarise(few, o);
  EXPECT_FALSE(few.ok());
  EXPECT_FALSE(few.time_scale_ratio);
  // The driver's own fates: a planted delay in the first half of the windows,
  // an unrelated trailing signal in the second (filter and lag rejections),
  // the outlier cutoff, and windows too short for a stated velocity range.
  const auto p = planted(5, 8);
  const auto noise = telegraph(p.leading.sample_count, 99, 1000.0, 30, 60);
  const auto windows = awcc::awcc_windows(p.leading, 8);
  const std::int64_t half = windows[windows.size() / 2].start;
  awcc::AirIntervals trailing = p.trailing;
  trailing.intervals.clear();
  for (const auto& iv : p.trailing.intervals)
    if (iv.stop <= half) trailing.intervals.push_back(iv);
  for (const auto& iv : noise.intervals)
    if (iv.start >= half) trailing.intervals.push_back(iv);
  awcc::AwccOptions d;
  const auto r = awcc::awcc(p.leading, trailing, 1.0, d);
  EXPECT_GT(r.count(awcc::WindowFate::accepted), 0);
  EXPECT_GT(r.count(awcc::WindowFate::correlation) + r.count(awcc::WindowFate::lag), 0);
  expect_fates_counted(r);
  std::vector<std::int64_t> lengths;
  for (const auto& w : windows) lengths.push_back(w.length);
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2), lengths.end());
  const double least_lag = static_cast<double>(lengths[lengths.size() / 2]);  // half the windows are shorter
  d.velocity_max = 1.0 * 1000.0 / least_lag;
  d.velocity_min = d.velocity_max.value() / 4.0;
  const auto ranged = awcc::awcc(p.leading, trailing, 1.0, d);
  EXPECT_GT(ranged.count(awcc::WindowFate::too_short), 0);
  expect_fates_counted(ranged);
}

TEST(AwccDriver, RawVoltagesThatAreTheBinarySignalGiveTheBinaryResult) {
  // Voltages of exactly 0 and 1 V: the raw-voltage source reads the binary
  // signals back from the recording and must give the rendered FFT source's
  // windows bit for bit (the same samples into the same transforms), and the
  // interval source's to rounding. Blocks of 997 frames split the windows.
  const auto p = planted(13, 10, 120'000);
  const auto lead = awcc::to_dense(p.leading), trail = awcc::to_dense(p.trailing);
  std::vector<float> frames;
  for (std::size_t i = 0; i < lead.size(); ++i) {
    frames.push_back(lead[i]);
    frames.push_back(trail[i]);
  }
  auto recording = awcc::memory_recording(frames, 2, p.leading.fs);
  awcc::ProcessOptions o;
  o.dx = 5e-3;
  o.block_frames = 997;
  o.allow_unusual = true;  // 1 kHz test signals
  o.awcc_options.signal = awcc::CorrelationSignal::raw;
  o.awcc_options.subsample = awcc::Subsample::parabolic;
  const auto binarised = awcc::binarise_recording(*recording, o);
  ASSERT_EQ(binarised.leading.intervals, p.leading.intervals);
  ASSERT_EQ(binarised.trailing.intervals, p.trailing.intervals);
  const auto raw = awcc::awcc_raw(*recording, binarised, o);
  awcc::AwccOptions binary = o.awcc_options;
  binary.signal = awcc::CorrelationSignal::binary;
  binary.path = awcc::CorrelationPath::fft;
  const auto rendered = awcc::awcc(p.leading, p.trailing, o.dx, binary);
  ASSERT_EQ(raw.windows.size(), rendered.windows.size());
  ASSERT_GT(raw.windows.size(), 100u);
  for (std::size_t i = 0; i < raw.windows.size(); ++i) {
    const auto &u = raw.windows[i], &v = rendered.windows[i];
    EXPECT_EQ(u.fate, v.fate) << "window " << i;
    EXPECT_EQ(u.lag, v.lag) << "window " << i;
    EXPECT_EQ(u.r12_max, v.r12_max) << "window " << i;
    EXPECT_EQ(u.spr, v.spr) << "window " << i;
    EXPECT_EQ(u.velocity, v.velocity) << "window " << i;
  }
  EXPECT_EQ(raw.windows_by_fate, rendered.windows_by_fate);
  EXPECT_EQ(raw.velocity, rendered.velocity);
  EXPECT_EQ(raw.turbulence_intensity, rendered.turbulence_intensity);
  binary.path = awcc::CorrelationPath::intervals;
  expect_same_windows(awcc::awcc(p.leading, p.trailing, o.dx, binary), raw);
}

TEST(Awcc, ParabolicRefinementRecoversFractionalDelays) {
  // Delays of k + 0.5 samples: build at 10x the rate, decimate.
  const std::int64_t n = 1'000'000;
  const auto fine = telegraph(n, 17, 10.0, 300, 600);
  std::vector<std::uint8_t> dense = awcc::to_dense(fine), moved(dense.size(), 0);
  for (std::size_t i = 0; i + 125 < dense.size(); ++i) moved[i + 125] = dense[i];  // 12.5 coarse samples
  std::vector<std::uint8_t> a, b;
  for (std::size_t i = 0; i < dense.size(); i += 10) {
    a.push_back(dense[i]);
    b.push_back(moved[i]);
  }
  const auto x = awcc::from_dense(a, 1.0), y = awcc::from_dense(b, 1.0);
  awcc::AwccOptions o;
  o.roc = false;
  o.filter_a = 0.0;
  o.subsample = awcc::Subsample::parabolic;
  const auto r = awcc::awcc(x, y, 1.0, o);
  ASSERT_GT(r.windows.size(), 20u);
  double sum = 0;
  std::size_t close = 0;
  for (const auto& w : r.windows) {
    sum += std::fabs(w.lag - 12.5);
    close += std::fabs(w.lag - 12.5) < 0.25;
  }
  // Integer lags are off by 0.5 in every window. A parabola through the three
  // samples around a binary correlation's peak (a rounded triangle) is not
  // exact, but lands near the true delay in most windows.
  const double mean_error = sum / static_cast<double>(r.windows.size());
  EXPECT_LT(mean_error, 0.2);
  EXPECT_GT(close, r.windows.size() * 8 / 10);
}

TEST(SecondaryPeakRatio, ConstructedShapes) {
  // Two triangles of heights 1 and 0.6 over a zero floor: both prominent.
  std::vector<double> r(61, 0.0);
  for (int i = 0; i < 11; ++i) {
    r[static_cast<std::size_t>(10 + i)] = 0.1 * std::min(i, 10 - i) * 2;       // peak 1.0 at 15
    r[static_cast<std::size_t>(40 + i)] = 0.06 * std::min(i, 10 - i) * 2;      // peak 0.6 at 45
  }
  awcc::AwccWorkspace workspace;
  auto p = awcc::detail::analyse_correlation(r, awcc::Subsample::none, 0.3, workspace);
  EXPECT_EQ(p.index, 15u);
  EXPECT_NEAR(p.spr, 0.6, 1e-12);
  // A bump of prominence 0.1 (< 0.3 x 1.0) on the flank is not kept.
  std::vector<double> q(41, 0.0);
  for (int i = 0; i <= 20; ++i) q[static_cast<std::size_t>(i)] = 0.05 * i;   // rises to 1.0 at 20
  for (int i = 21; i <= 40; ++i) q[static_cast<std::size_t>(i)] = 0.05 * (40 - i);
  q[30] = 0.6;  // neighbours 0.5 and 0.45: prominence 0.1
  p = awcc::detail::analyse_correlation(q, awcc::Subsample::none, 0.3, workspace);
  EXPECT_EQ(p.spr, 0.0);
  // The same bump counts when the rule keeps everything.
  p = awcc::detail::analyse_correlation(q, awcc::Subsample::none, 0.0, workspace);
  EXPECT_NEAR(p.spr, 0.6, 1e-12);
  // A flat-topped secondary peak is found at its middle.
  std::vector<double> f{0, 1, 0, 0.5, 0.5, 0.5, 0};
  const auto peaks = awcc::detail::peak_prominences(f);
  ASSERT_EQ(peaks.size(), 2u);
  EXPECT_EQ(peaks[1].first, 4u);
  EXPECT_NEAR(peaks[1].second, 0.5, 1e-15);
}

// The SPR computes only the prominences it reads (the tallest top's, then
// the others' by decreasing height); it must equal the ratio read from every
// peak's prominence (peak_prominences' stacks over the whole function), on
// functions with ties of height, plateaus and negative tops.
TEST(SecondaryPeakRatio, EqualsTheRatioFromEveryPeaksProminence) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  awcc::AwccWorkspace workspace;
  int positive = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<double> r(20 + trial);
    const double step = trial % 3 == 0 ? 4.0 : 16.0;  // coarse: many equal heights
    for (auto& v : r) v = std::round(u(rng) * step) / step - (trial % 5 == 0 ? 1.5 : 0.0);
    const auto peaks = awcc::detail::peak_prominences(r);
    for (const double fraction : {0.0, 0.3, 0.7, 1.0}) {
      double expected = 0.0;
      if (peaks.size() >= 2) {
        std::size_t tallest = 0;
        for (std::size_t i = 1; i < peaks.size(); ++i)
          if (r[peaks[i].first] > r[peaks[tallest].first]) tallest = i;
        double second = -std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < peaks.size(); ++i)
          if (i != tallest && peaks[i].second >= fraction * peaks[tallest].second) second = std::max(second, r[peaks[i].first]);
        const double top = r[peaks[tallest].first];
        if (std::isfinite(second) && top > 0.0) expected = std::max(0.0, second / top);
      }
      const auto p = awcc::detail::analyse_correlation(r, awcc::Subsample::none, fraction, workspace);
      ASSERT_EQ(p.spr, expected) << "trial " << trial << " fraction " << fraction;
      positive += p.spr > 0.0;
    }
  }
  EXPECT_GT(positive, 300);  // the comparison is not all zeros
}

TEST(PeakProminences, MatchABruteForceScan) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> r(50 + trial);
    for (auto& v : r) v = std::round(u(rng) * 8) / 8;  // ties and plateaus
    const auto fast = awcc::detail::peak_prominences(r);
    for (const auto& [i, prominence] : fast) {
      // scipy: extend each side until a strictly higher sample or the end.
      double left = r[i], right = r[i];
      for (std::size_t j = i; j-- > 0;) {
        if (r[j] > r[i]) break;
        left = std::min(left, r[j]);
      }
      for (std::size_t j = i + 1; j < r.size(); ++j) {
        if (r[j] > r[i]) break;
        right = std::min(right, r[j]);
      }
      ASSERT_NEAR(prominence, r[i] - std::max(left, right), 1e-15) << "trial " << trial << " peak " << i;
    }
  }
}

TEST(RobustOutlierCutoff, RemovesPlantedOutliersOnly) {
  // 200 values spread evenly over [9, 11] and two gross outliers.
  std::vector<double> u;
  for (int i = 0; i < 200; ++i) u.push_back(9.0 + 2.0 * i / 199.0);
  u.push_back(30.0);
  u.push_back(-5.0);
  std::vector<bool> keep(u.size(), true);
  const int iterations = awcc::detail::robust_outlier_cutoff(u, keep);
  EXPECT_FALSE(keep[200]);
  EXPECT_FALSE(keep[201]);
  for (int i = 0; i < 200; ++i) EXPECT_TRUE(keep[static_cast<std::size_t>(i)]) << i;
  EXPECT_EQ(iterations, 2);
  // Hand check of the first iteration: median 10, MAD of the 202 values is
  // 0.5 (half-width of the central half), s = 0.7413; sqrt(2 ln 202) = 3.259,
  // so the cutoff is 2.416: 9-11 stay, 30 and -5 go.
}

TEST(Moments, DurationWeightedAndIntervalsByHand) {
  awcc::AwccResult r;
  for (auto [u, d] : {std::pair{10.0, 1.0}, {12.0, 3.0}, {8.0, 2.0}, {11.0, 2.0}}) {
    awcc::AwccWindow w;
    w.velocity = u;
    w.duration = d;
    w.lag_samples = 5;
    r.windows.push_back(w);
  }
  awcc::AwccOptions o;
  o.roc = false;
  o.windows_reported = 4;  // the moments of 4 windows, by hand
  awcc::detail::awcc_summarise(r, o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.quality, awcc::AwccQuality::low);  // fewer than 100 accepted windows
  // Weighted mean (10 + 36 + 16 + 22) / 8 = 10.5; variance
  // (0.25 + 3 * 2.25 + 2 * 6.25 + 2 * 0.25) / 8 = 20 / 8 = 2.5.
  EXPECT_DOUBLE_EQ(r.velocity, 10.5);
  EXPECT_NEAR(r.velocity_rms, std::sqrt(2.5), 1e-12);
  const double tu = std::sqrt(2.5) / 10.5;
  EXPECT_NEAR(r.turbulence_intensity, tu, 1e-12);
  EXPECT_NEAR(r.velocity_ci95.upper - 10.5, 1.96 * std::sqrt(2.5) / 2.0, 1e-12);
  EXPECT_NEAR(r.velocity_rms_ci95.upper - std::sqrt(2.5), 1.96 * std::sqrt(2.5) / std::sqrt(8.0), 1e-12);
  EXPECT_NEAR(r.turbulence_intensity_ci95.upper - tu, 1.96 * std::sqrt(tu * tu * (tu * tu / 4 + 1.0 / 8)), 1e-12);
  o.weighting = awcc::Weighting::none;
  awcc::detail::awcc_summarise(r, o);
  EXPECT_DOUBLE_EQ(r.velocity, 10.25);
}

TEST(Awcc, UndefinedCasesCarryReasonsAndNoNaN) {
  // Fewer than Np particles.
  const auto few = telegraph(100, 2);
  auto r = awcc::awcc(few, few, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.message.find("fewer than Np"), std::string::npos);
  // Identical signals: every window peaks at lag 0 (delay below one sample).
  const auto x = telegraph(50'000, 8);
  r = awcc::awcc(x, x, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.message.find("shorter than one sample"), std::string::npos) << r.message;
  EXPECT_EQ(r.count(awcc::WindowFate::lag), r.windows_total);
  // Constant trailing tip.
  AirIntervals water;
  water.fs = x.fs;
  water.sample_count = x.sample_count;
  r = awcc::awcc(x, water, 1.0, {});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.count(awcc::WindowFate::constant), r.windows_total);
  for (double v : {r.velocity, r.velocity_rms, r.turbulence_intensity}) EXPECT_TRUE(std::isfinite(v));
}

}  // namespace
