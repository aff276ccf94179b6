// Stiff, extreme and hostile inputs: each has a stated expected behaviour, a
// finite result or a clear refusal, never NaN or Inf and never an allocation
// of what a header merely claims.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sndfile.h>

#include "awcc/awcc.hpp"
#include "awcc/process.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;

// A two-channel int16 recording generated on the fly: a square wave of air
// (2,000 samples at 1,000 counts) every 100,000 samples of water (27,000),
// the trailing channel 50 samples later; length chosen by the test.
class SquareWave final : public awcc::Recording {
 public:
  explicit SquareWave(std::int64_t frames) : period_(2 * kPeriod) {
    info_.path = "square-wave";
    info_.channels = 2;
    info_.fs = 1e6;
    info_.frames = frames;
    info_.quantum = 5.0 / 32768.0;
    info_.volts_known = true;
    info_.description = "generated";
    // One period, interleaved; blocks are copied out of it.
    for (std::int64_t t = 0; t < kPeriod; ++t) {
      period_[static_cast<std::size_t>(2 * t)] = level(t);
      period_[static_cast<std::size_t>(2 * t + 1)] = level(t - 50);
    }
  }
  bool has_int16() const override { return true; }
  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    const std::int64_t n = std::max<std::int64_t>(0, std::min(max_frames, info_.frames - position_));
    for (std::int64_t done = 0; done < n;) {
      const std::int64_t phase = (position_ + done) % kPeriod;
      const std::int64_t take = std::min(n - done, kPeriod - phase);
      std::memcpy(out.data() + 2 * done, period_.data() + 2 * phase, static_cast<std::size_t>(take) * 4);
      done += take;
    }
    position_ += n;
    return n;
  }
  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    std::vector<std::int16_t> counts(static_cast<std::size_t>(2 * max_frames));
    const auto n = read_int16(counts, max_frames);
    for (std::int64_t i = 0; i < 2 * n; ++i) out[static_cast<std::size_t>(i)] = static_cast<float>(counts[static_cast<std::size_t>(i)] * info_.quantum);
    return n;
  }
  void rewind() override { position_ = 0; }
  static constexpr std::int64_t kPeriod = 100'000;
  // Water 27,000 +/- 1 counts (three values: not binary input), air 1,000
  // for 2,000 samples from sample 50,000 of each period (the trailing
  // channel wraps its delayed copy of the first 50 samples from the period's end).
  static std::int16_t level(std::int64_t t) {
    const std::int64_t p = ((t % kPeriod) + kPeriod) % kPeriod;
    return static_cast<std::int16_t>(p >= 50'000 && p < 52'000 ? 1000 : 27000 + p % 3 - 1);
  }

 private:
  std::vector<std::int16_t> period_;
  std::int64_t position_ = 0;
};

TEST(Limits, MoreThan2To31SamplesAreBinarisedInBlocks) {
  // 2^31 + 10^6 frames a channel: 64-bit indices all the way; memory is the
  // block plus what the interfaces need.
  const std::int64_t frames = (std::int64_t{1} << 31) + 1'000'000;
  SquareWave wave(frames);
  awcc::ProcessOptions o;
  o.block_frames = 1 << 18;
  const auto b = awcc::binarise_recording(wave, o);
  ASSERT_EQ(b.leading.sample_count, frames);
  // 21,484 whole periods and a last part of 83,648 frames that holds air too.
  const std::int64_t periods = frames / 100'000 + 1;
  EXPECT_EQ(static_cast<std::int64_t>(b.leading.intervals.size()), periods);
  EXPECT_EQ(b.leading.air_samples(), periods * 2000);
  EXPECT_EQ(b.leading.intervals.back().start, (periods - 1) * 100'000 + 50'000);
  EXPECT_EQ(b.trailing.intervals.back().start, (periods - 1) * 100'000 + 50'050);
  // FSCC over the whole record finds the 50-sample delay.
  awcc::FsccOptions f;
  f.max_lag = 1e-4;
  const auto r = awcc::fscc(b.leading, b.trailing, 50e-6 * 10.0, f);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.lag_samples, 50);
  // AWCC: windows of 10 chords, each 10^6 samples long; the lag search is
  // bounded, the delay found in every window.
  const auto a = awcc::awcc(b.leading, b.trailing, 5e-4, {});
  ASSERT_TRUE(a.ok()) << a.message;
  EXPECT_EQ(a.windows_total, periods / 10);  // leftover chords join the last window
  for (const auto& w : a.windows) ASSERT_EQ(w.lag_samples, 50);
}

TEST(Limits, OneEnormousBubble) {
  // A record that is one bubble from sample 1,000 to the end of 2^31 + 1
  // samples: no window can be formed, FSCC says why, nothing is NaN.
  awcc::AirIntervals x, y;
  x.fs = y.fs = 1e6;
  x.sample_count = y.sample_count = (std::int64_t{1} << 31) + 1;
  x.intervals = {{1000, x.sample_count}};
  y.intervals = {{1050, y.sample_count}};
  const auto p = awcc::phase_statistics(x);
  EXPECT_NEAR(p.void_fraction, 1.0, 1e-6);
  EXPECT_EQ(p.bubble_count_rate, 0.0);
  const auto a = awcc::awcc(x, y, 5e-3, {});
  EXPECT_FALSE(a.ok());
  EXPECT_NE(a.message.find("fewer than Np"), std::string::npos);
  awcc::FsccOptions f;
  f.max_lag = 1e-4;
  const auto r = awcc::fscc(x, y, 5e-3, f);
  for (double v : {r.r12_max, r.lag, r.velocity}) EXPECT_TRUE(std::isfinite(v));
}

TEST(Limits, AHeaderClaimingATrillionSamplesIsRefusedWithoutAllocating) {
  // A real RF64 of 1,000 frames whose ds64 chunk is patched to claim 10^12
  // samples (2 x 10^12 bytes): reading stops at the real end with an error.
  const auto path = pdp_test::temp_dir() / "liar.rf64";
  {
    SF_INFO info{};
    info.samplerate = 10000;
    info.channels = 2;
    info.format = SF_FORMAT_RF64 | SF_FORMAT_PCM_16;
    SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
    ASSERT_NE(f, nullptr);
    std::vector<short> data(2000);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<short>(i % 7 ? 27000 : 1000);
    sf_writef_short(f, data.data(), 1000);
    sf_close(f);
  }
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    std::vector<char> bytes(64);
    f.read(bytes.data(), 64);
    const auto ds64 = std::string(bytes.data(), 64).find("ds64");
    ASSERT_NE(ds64, std::string::npos);
    const std::uint64_t claim = 2'000'000'000'000ull, frames = 1'000'000'000'000ull / 2;
    f.seekp(static_cast<std::streamoff>(ds64 + 8 + 8));  // riff size, then data size
    f.write(reinterpret_cast<const char*>(&claim), 8);
    f.write(reinterpret_cast<const char*>(&frames), 8);  // sample count
  }
  // Either refused as truncated, or read for what it holds: never an
  // allocation of the claim (10^12 samples would be 2 TB).
  awcc::ProcessOptions o;
  o.dx = 5e-3;
  try {
    const auto r = awcc::process_recording(path, o);
    EXPECT_EQ(r.info.frames, 1000);
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_TRUE(m.find("truncated") != std::string::npos || m.find("not a readable") != std::string::npos) << m;
  }
}

TEST(Limits, ACsvLineOf100MegabytesIsRefused) {
  const auto path = pdp_test::temp_dir() / "long_line.csv";
  {
    std::ofstream f(path);
    f << "lead,trail\n1,2\n";
    const std::string chunk(1 << 20, '7');
    for (int i = 0; i < 100; ++i) f << chunk;
    f << ",1\n";
  }
  awcc::ProcessOptions o;
  o.reader.fs = 1000;
  try {
    awcc::process_recording(path, o);
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 3 is longer than"), std::string::npos) << e.what();
  }
}

TEST(Limits, ValuesAtTheInt16LimitsAndDenormalFloats) {
  // A clipped conductivity signal at -32768 / 32767 counts.
  std::vector<std::int16_t> data;
  for (int i = 0; i < 20000; ++i) {
    const bool air = (i / 50) % 4 == 0;
    data.push_back(air ? -32768 : 32767);
    data.push_back(air ? -32768 : 32767);
    data.push_back(static_cast<std::int16_t>(i % 3));  // a third channel keeps it from being binary input
  }
  // ... made non-binary by a sprinkle of intermediate values.
  data[3 * 100] = 0;
  const auto dat = pdp_test::temp_dir() / "clipped.dat";
  {
    std::ofstream f(dat, std::ios::binary);
    const std::int32_t rows = 20000, channels = 3;
    f.write(reinterpret_cast<const char*>(&rows), 4);
    f.write(reinterpret_cast<const char*>(&channels), 4);
    f.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size() * 2));
  }
  awcc::ProcessOptions o;
  o.reader.fs = 20e3;
  o.dx = 5e-3;
  // Clipped levels fail the signal check; the trailing tip, two values, is
  // binary input whose higher value, air by that convention, holds 75 %:
  // flagged. The arithmetic at the limits is what this tests.
  o.signal_check.allow_bad_signal = true;
  const auto r = awcc::process_recording(dat, o);
  EXPECT_EQ(r.tips[0].signal.status, awcc::SignalStatus::saturated);
  EXPECT_EQ(r.tips[1].signal.status, awcc::SignalStatus::air_continuous);
  EXPECT_NEAR(r.tips[0].phase.void_fraction, 0.25, 1e-3);
  EXPECT_TRUE(std::isfinite(r.tips[0].threshold.threshold));
  // Float32 raw data full of denormals around clean levels.
  std::vector<float> values;
  for (int i = 0; i < 20000; ++i) {
    const bool air = (i / 40) % 5 == 0;
    const float tiny = std::numeric_limits<float>::denorm_min() * static_cast<float>(i % 100);
    const float wobble = 0.01f * static_cast<float>(i % 3);  // three levels a phase: not binary input
    values.push_back((air ? 0.3f : 4.0f) + wobble + tiny);
    values.push_back(i % 7 ? tiny : -tiny);
  }
  const auto raw = pdp_test::temp_dir() / "denormal.raw";
  {
    std::ofstream f(raw, std::ios::binary);
    f.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * 4));
  }
  awcc::ProcessOptions p;
  p.reader.fs = 20e3;
  p.reader.format = "raw";
  p.reader.raw.sample_type = awcc::SampleType::float32;
  p.dx = 5e-3;
  p.signal_check.allow_bad_signal = true;  // the trailing tip: denormals around 0 V, one level
  const auto q = awcc::process_recording(raw, p);
  EXPECT_EQ(q.tips[0].signal.status, awcc::SignalStatus::two_level);
  EXPECT_EQ(q.tips[1].signal.status, awcc::SignalStatus::one_level);
  EXPECT_NEAR(q.tips[0].phase.void_fraction, 0.2, 1e-3);
  // The second channel is all denormals: a constant channel, processed as allowed.
  EXPECT_TRUE(std::isfinite(q.tips[1].phase.void_fraction));
  EXPECT_FALSE(q.fscc->ok());
}

TEST(Limits, ExtremeVoidFractionsRunToFiniteResults) {
  // 0.5: the densest bubbles; 0.99: the sparsest droplets (the spray
  // region, synth::DispersedPhase), as sparse as bubbles at 0.01.
  for (double c : {0.001, 0.5, 0.99}) {
    synth::Scene s;
    s.void_fraction = c;
    s.duration = c < 0.01 || c > 0.98 ? 30.0 : 1.0;
    const auto syn = synth::synthesise(s);
    EXPECT_EQ(syn.truth.reentries_missed, 0);
    const auto a = awcc::awcc(syn.signals[0], syn.signals[1], s.dx, {});
    EXPECT_TRUE(a.ok() || !a.message.empty()) << c;
    EXPECT_TRUE(std::isfinite(a.velocity) && std::isfinite(a.turbulence_intensity)) << c;
    // Above the jamming limit of sequential placement particles are placed
    // overlapping, and the truth says so (under equal-time arrivals, as
    // here, their shared volume is lost; the space rules give it back).
    if (c == 0.5) {
      EXPECT_GT(syn.truth.overlaps_unresolved, 0);
    }
  }
}

}  // namespace
