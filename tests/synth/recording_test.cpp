#include "synth/recording.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "awcc/errors.hpp"
#include "awcc/random.hpp"
#include "synth/sidecar.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using synth::FileFormat;
using synth::RecordingOptions;
using synth::Scene;
using synth::SignalKind;

Scene small_scene() {
  Scene s;
  s.duration = 0.3;
  s.fs = 100e3;
  return s;
}

class BinaryRoundTrip : public ::testing::TestWithParam<FileFormat> {};

TEST_P(BinaryRoundTrip, FileHoldsExactlyTheGeneratedSamples) {
  const Scene s = small_scene();
  const auto synthesis = synth::synthesise(s);
  RecordingOptions o;
  o.format = GetParam();
  o.block_frames = 777;  // blocks that do not divide the record
  const fs::path path = pdp_test::temp_dir() / ("roundtrip." + std::string(synth::to_string(o.format)));
  synth::write_recording(path, s, synthesis.signals, o);
  int channels = 0;
  double rate = 0;
  const auto data = synth::read_recording_int16(path, channels, rate);
  ASSERT_EQ(channels, 2);
  EXPECT_EQ(rate, s.fs);
  ASSERT_EQ(data.size(), static_cast<std::size_t>(2 * s.sample_count()));
  for (std::size_t j = 0; j < 2; ++j) {
    const auto dense = awcc::to_dense(synthesis.signals[j]);
    std::size_t mismatches = 0;
    for (std::size_t n = 0; n < dense.size(); ++n) mismatches += data[2 * n + j] != dense[n];
    EXPECT_EQ(mismatches, 0u) << "tip " << j;
  }
  // No temporary file of this output is left beside it (other tests may be
  // writing their own in the same folder).
  const std::string prefix = "." + path.filename().string() + ".";
  for (const auto& entry : fs::directory_iterator(path.parent_path())) {
    EXPECT_NE(entry.path().filename().string().rfind(prefix, 0), 0u) << entry.path();
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, BinaryRoundTrip,
                         ::testing::Values(FileFormat::flac, FileFormat::wav, FileFormat::w64, FileFormat::rf64),
                         [](const auto& param_info) { return std::string(synth::to_string(param_info.param)); });

TEST(VoltageRendering, LevelsWithoutNoiseOrLagAreTheQuantisedLevels) {
  Scene s = small_scene();
  s.voltage_noise = 0.0;
  s.voltage_time_constant = 0.0;
  const auto synthesis = synth::synthesise(s);
  RecordingOptions o;
  o.signal = SignalKind::voltage;
  o.format = FileFormat::wav;
  const fs::path path = pdp_test::temp_dir() / "levels.wav";
  synth::write_recording(path, s, synthesis.signals, o);
  int channels = 0;
  double rate = 0;
  const auto data = synth::read_recording_int16(path, channels, rate);
  // 4.0 V and 0.3 V at 5 V full scale: 26214.4 -> 26214, 1966.08 -> 1966 counts.
  const auto dense = awcc::to_dense(synthesis.signals[0]);
  for (std::size_t n = 0; n < dense.size(); ++n) {
    ASSERT_EQ(data[2 * n], dense[n] ? 1966 : 26214) << n;
  }
}

TEST(VoltageRendering, BlockSizeDoesNotChangeTheCounts) {
  Scene s = small_scene();
  const auto synthesis = synth::synthesise(s);
  std::vector<std::vector<std::int16_t>> results;
  for (std::int64_t block : {1 << 16, 1000, 3}) {
    RecordingOptions o;
    o.signal = SignalKind::voltage;
    o.format = FileFormat::w64;
    o.block_frames = block;
    const fs::path path = pdp_test::temp_dir() / "blocks.w64";
    synth::write_recording(path, s, synthesis.signals, o);
    int channels = 0;
    double rate = 0;
    results.push_back(synth::read_recording_int16(path, channels, rate));
  }
  EXPECT_EQ(results[0], results[1]);
  EXPECT_EQ(results[0], results[2]);
}

TEST(VoltageRendering, FirstOrderResponseAndNoiseHaveTheRequestedSizes) {
  // One long air chord: after a step the level approaches its target as
  // exp(-t / tau); the residual noise around the settled level has the
  // requested standard deviation (within 5 standard errors, sd/sqrt(2n)).
  Scene s;
  s.fs = 1e6;
  s.voltage_time_constant = 5e-6;
  s.voltage_noise = 0.05;
  synth::VoltageRenderer renderer(s, 1);
  const std::size_t n = 20000;
  std::vector<std::uint8_t> air(n, 0);
  std::fill(air.begin() + 1000, air.end(), 1);
  std::vector<std::int16_t> out(n);
  renderer.render({std::span<const std::uint8_t>(air)}, out);
  const double vpc = renderer.volts_per_count();
  double sum = 0, sum2 = 0;
  const std::size_t settled = 2000;
  for (std::size_t i = settled; i < n; ++i) {
    const double v = out[i] * vpc - s.voltage_air;
    sum += v;
    sum2 += v * v;
  }
  const double m = static_cast<double>(n - settled);
  const double sd = std::sqrt(sum2 / m - (sum / m) * (sum / m));
  EXPECT_NEAR(sd, 0.05, 5 * 0.05 / std::sqrt(2 * m));
  EXPECT_NEAR(sum / m, 0.0, 5 * 0.05 / std::sqrt(m));
  // Noise-free response 5 samples (one tau) after the switch: the mean over
  // many realisations is water + (air - water)(1 - e^-1); one realisation
  // sits within 5 noise sd of it.
  const double expected = s.voltage_water + (s.voltage_air - s.voltage_water) * (1 - std::exp(-1.0));
  EXPECT_NEAR(out[1004] * vpc, expected, 5 * 0.05 + vpc);
}

TEST(Recordability, RefusesWhatAContainerCannotHold) {
  Scene s;
  s.fs = 2e6;
  EXPECT_NE(synth::check_recordable(s, 2, FileFormat::flac).find("655350"), std::string::npos);
  EXPECT_TRUE(synth::check_recordable(s, 2, FileFormat::rf64).empty());
  s.fs = 500e3;
  EXPECT_NE(synth::check_recordable(s, 9, FileFormat::flac).find("8 channels"), std::string::npos);
  s.duration = 3000.0;  // 6 GB of int16 in two channels
  EXPECT_NE(synth::check_recordable(s, 2, FileFormat::wav).find("4 GB"), std::string::npos);
  s.fs = 20000.5;
  EXPECT_NE(synth::check_recordable(s, 2, FileFormat::w64).find("whole number"), std::string::npos);
}

TEST(Recordability, AFailedWriteLeavesNoFile) {
  Scene s = small_scene();
  s.fs = 700e3;  // too fast for FLAC
  s.duration = 0.01;
  const auto synthesis = synth::synthesise(s);
  const fs::path path = pdp_test::temp_dir() / "refused.flac";
  fs::remove(path);
  EXPECT_THROW(synth::write_recording(path, s, synthesis.signals, {}), awcc::OptionError);
  EXPECT_FALSE(fs::exists(path));
  // A recordable scene (WAV takes 700 kHz) into a missing folder: the output fails.
  synth::RecordingOptions wav;
  wav.format = synth::FileFormat::wav;
  EXPECT_THROW(synth::write_recording(pdp_test::temp_dir() / "no-such-dir" / "x.wav", s, synthesis.signals, wav),
               awcc::OutputError);
}

TEST(Sidecar, HoldsTheDocumentedKeys) {
  const Scene s = small_scene();
  const auto synthesis = synth::synthesise(s);
  const auto j = synth::sidecar_json(synthesis.truth, {}, "rec.flac");
  for (const char* key : {"imposed", "realised", "scene", "probe", "fs", "seed", "toolkit", "recording"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  const auto& r = j["realised"];
  EXPECT_EQ(r["mean_velocity"].size(), 3u);
  EXPECT_EQ(r["turbulence_intensity"].size(), 3u);
  EXPECT_EQ(r["integral_time_scale"].size(), 3u);
  EXPECT_EQ(r["void_fraction"].size(), 2u);
  EXPECT_EQ(r["bubbles_pierced"].size(), 2u);
  EXPECT_DOUBLE_EQ(r["void_fraction"][1].get<double>(), synthesis.signals[1].void_fraction());
  EXPECT_EQ(synth::sidecar_path("dir/rec.flac"), fs::path("dir/rec.truth.json"));
  // The stored sample type follows the writer: uint8 only for a binary .h5.
  EXPECT_EQ(j["recording"]["sample_type"], "int16");
  synth::RecordingOptions h5;
  h5.format = synth::FileFormat::hdf5;
  h5.signal = synth::SignalKind::binary;
  EXPECT_EQ(synth::sidecar_json(synthesis.truth, h5, "rec.h5")["recording"]["sample_type"], "uint8");
  h5.signal = synth::SignalKind::voltage;
  EXPECT_EQ(synth::sidecar_json(synthesis.truth, h5, "rec.h5")["recording"]["sample_type"], "int16");
}

}  // namespace

namespace {

TEST(ShippedSample, IsReproducedExactlyFromItsScene) {
  // samples/base-voltage.flac was made by scripts/make-samples; the same scene
  // and seed must give the same decoded samples. A deliberate change to the
  // generator shows up here: rerun scripts/make-samples and commit.
  const fs::path recording = pdp_test::source_dir() / "samples" / "base-voltage.flac";
  std::ifstream sidecar_file(synth::sidecar_path(recording));
  ASSERT_TRUE(sidecar_file.good());
  const auto sidecar = nlohmann::json::parse(sidecar_file);
  Scene s;
  synth::load_scene_toml(pdp_test::source_dir() / "samples" / "base.toml", s);
  s.duration = sidecar["scene"]["duration"].get<double>();
  s.fs = sidecar["fs"].get<double>();
  EXPECT_EQ(sidecar["seed"].get<std::uint64_t>(), s.seed);
  EXPECT_EQ(sidecar["generator_version"].get<int>(), awcc::generator_version);
  const auto synthesis = synth::synthesise(s);
  RecordingOptions o;
  o.signal = SignalKind::voltage;
  o.format = FileFormat::w64;
  const fs::path again = pdp_test::temp_dir() / "sample_again.w64";
  synth::write_recording(again, s, synthesis.signals, o);
  int c1 = 0, c2 = 0;
  double f1 = 0, f2 = 0;
  const auto shipped = synth::read_recording_int16(recording, c1, f1);
  const auto regenerated = synth::read_recording_int16(again, c2, f2);
  EXPECT_EQ(c1, 2);
  EXPECT_EQ(f1, 100e3);
  EXPECT_EQ(shipped.size(), 2u * 500'000u);
  EXPECT_TRUE(shipped == regenerated);
}

}  // namespace
