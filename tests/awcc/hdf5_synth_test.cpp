// pdp-sim's HDF5 layout written by the simulator (synth::write_recording to
// .h5) and read back by the HDF5 reader: the same samples as the FLAC file of
// the same scene, so processing both gives identical results, for the binary
// and the voltage signal; and the file has pdp-sim's layout, checked with the
// HDF5 C API as pdp-sim's tools would read it.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <string>
#include <vector>

#include "awcc/pdpsim_layout.hpp"
#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;

// ctest runs each test in its own process, in parallel: the name carries the test's own name.
fs::path scratch(const std::string& name) { return pdp_test::test_file(name); }

synth::Scene scene() {
  synth::Scene s;
  s.duration = 2.0;
  s.fs = 100e3;
  s.dy = 0.0;
  s.tu = 0.1;
  s.tu_y = s.tu_z = 0.02;
  return s;
}

void write(const fs::path& path, const synth::Scene& s, const synth::Synthesis& synthesis, synth::SignalKind signal,
           std::int64_t block = 1 << 16) {
  synth::RecordingOptions o;
  o.format = *synth::format_from_extension(path);
  o.signal = signal;
  o.block_frames = block;
  synth::write_recording(path, s, synthesis.signals, o);
}

// The process JSON without what names the file, its format and its channels
// (and, when asked, the thresholds, which are in each file's own units).
nlohmann::json comparable(const awcc::ProcessResult& r, bool thresholds) {
  auto j = awcc::to_json(r);
  j.erase("file");
  j.erase("format");
  const nlohmann::json threshold_keys = awcc::to_json(awcc::Threshold{});
  for (auto& tip : j["tips"]) {
    tip.erase("name");
    if (!thresholds) {
      for (auto key = threshold_keys.begin(); key != threshold_keys.end(); ++key) tip.erase(key.key());
      tip.erase("threshold_note");
      // The levels of binary input are the file's values (0 and 1, or a count's volts).
      tip["signal"].erase("low_level");
      tip["signal"].erase("high_level");
    }
  }
  return j;
}

// A whole dataset read with the C API as `memory` values.
template <class T>
std::vector<T> dataset(hid_t file, const char* name, hid_t memory, std::vector<hsize_t>& dims) {
  hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
  EXPECT_GE(d, 0) << name;
  hid_t space = H5Dget_space(d);
  dims.assign(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)), 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  hsize_t count = 1;
  for (auto n : dims) count *= n;
  std::vector<T> values(static_cast<std::size_t>(count));
  EXPECT_GE(H5Dread(d, memory, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0) << name;
  H5Sclose(space);
  H5Dclose(d);
  return values;
}

TEST(Hdf5Synth, BinaryH5ProcessesExactlyLikeFlac) {
  const auto s = scene();
  const auto synthesis = synth::synthesise(s);
  const auto flac = scratch("binary.flac"), h5 = scratch("binary.h5");
  write(flac, s, synthesis, synth::SignalKind::binary);
  write(h5, s, synthesis, synth::SignalKind::binary, 777);  // blocks that end inside chunks
  awcc::ProcessOptions o;
  o.dx = s.dx;
  const auto a = awcc::process_recording(flac, o);
  const auto b = awcc::process_recording(h5, o);
  EXPECT_EQ(b.info.format, "hdf5");
  EXPECT_EQ(b.info.fs, s.fs);
  ASSERT_EQ(a.tips.size(), 2u);
  ASSERT_EQ(b.tips.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_TRUE(b.tips[j].threshold.binary_input);
    EXPECT_EQ(b.tips[j].phase.void_fraction, a.tips[j].phase.void_fraction);
    EXPECT_EQ(b.tips[j].phase.void_fraction, synthesis.truth.tips[j].void_fraction);
    EXPECT_EQ(b.tips[j].phase.bubble_count_rate, a.tips[j].phase.bubble_count_rate);
  }
  EXPECT_EQ(b.tips[0].name, "sensor 0");
  ASSERT_TRUE(a.fscc && b.fscc && a.fscc->ok()) << a.fscc->message;
  EXPECT_EQ(b.fscc->velocity, a.fscc->velocity);
  EXPECT_EQ(b.fscc->r12_max, a.fscc->r12_max);
  ASSERT_TRUE(a.awcc && b.awcc && a.awcc->ok()) << a.awcc->message;
  EXPECT_EQ(b.awcc->velocity, a.awcc->velocity);
  EXPECT_EQ(b.awcc->windows_accepted, a.awcc->windows_accepted);
  // Everything else too: chords, structure, spectrum.
  EXPECT_EQ(comparable(b, false), comparable(a, false));
}

TEST(Hdf5Synth, VoltageH5ProcessesExactlyLikeFlacWithItsScale) {
  const auto s = scene();
  const auto synthesis = synth::synthesise(s);
  const auto flac = scratch("voltage.flac"), h5 = scratch("voltage.h5");
  write(flac, s, synthesis, synth::SignalKind::voltage);
  write(h5, s, synthesis, synth::SignalKind::voltage, 1000);
  awcc::ProcessOptions o;
  o.dx = s.dx;
  o.reader.volts_per_count = s.voltage_full_scale / 32768.0;  // the FLAC has no scale of its own
  const auto a = awcc::process_recording(flac, o);
  o.reader.volts_per_count = 0.0;  // the .h5 carries it
  const auto b = awcc::process_recording(h5, o);
  EXPECT_TRUE(b.info.volts_known);
  EXPECT_EQ(b.info.quantum, s.voltage_full_scale / 32768.0);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_FALSE(b.tips[j].threshold.binary_input);
    EXPECT_EQ(b.tips[j].threshold.threshold, a.tips[j].threshold.threshold);
    EXPECT_EQ(b.tips[j].phase.void_fraction, a.tips[j].phase.void_fraction);
    EXPECT_EQ(b.tips[j].phase.bubble_count_rate, a.tips[j].phase.bubble_count_rate);
  }
  ASSERT_TRUE(a.fscc && b.fscc && a.fscc->ok()) << a.fscc->message;
  EXPECT_EQ(b.fscc->velocity, a.fscc->velocity);
  ASSERT_TRUE(a.awcc && b.awcc && a.awcc->ok()) << a.awcc->message;
  EXPECT_EQ(b.awcc->velocity, a.awcc->velocity);
  EXPECT_EQ(comparable(b, true), comparable(a, true));
  // The raw-voltage correlations read the samples again: the same there too.
  o.awcc_options.signal = awcc::CorrelationSignal::raw;
  const auto raw_b = awcc::process_recording(h5, o);
  o.reader.volts_per_count = s.voltage_full_scale / 32768.0;
  const auto raw_a = awcc::process_recording(flac, o);
  ASSERT_TRUE(raw_a.awcc && raw_b.awcc && raw_a.fscc && raw_b.fscc);
  EXPECT_EQ(raw_b.awcc->velocity, raw_a.awcc->velocity);
  EXPECT_EQ(raw_b.fscc->velocity, raw_a.fscc->velocity);
}

TEST(Hdf5Synth, FileHasPdpSimsLayoutWhateverTheBlockSize) {
  synth::Scene s = scene();
  s.duration = 0.5;
  const auto synthesis = synth::synthesise(s);
  const auto n = static_cast<hsize_t>(s.sample_count());
  for (const auto signal : {synth::SignalKind::binary, synth::SignalKind::voltage}) {
    const bool binary = signal == synth::SignalKind::binary;
    const auto small = scratch(binary ? "layout_777.h5" : "layout_777_v.h5");
    const auto large = scratch(binary ? "layout_whole.h5" : "layout_whole_v.h5");
    write(small, s, synthesis, signal, 777);
    write(large, s, synthesis, signal, 1 << 20);
    std::vector<std::vector<std::int16_t>> samples;
    for (const auto& path : {small, large}) {
      hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
      ASSERT_GE(file, 0) << path;
      hid_t d = H5Dopen2(file, awcc::pdpsim::signal_dataset, H5P_DEFAULT);
      ASSERT_GE(d, 0);
      hid_t type = H5Dget_type(d);
      EXPECT_EQ(H5Tget_class(type), H5T_INTEGER);
      EXPECT_EQ(H5Tget_size(type), binary ? 1u : 2u);
      EXPECT_EQ(H5Tget_sign(type), binary ? H5T_SGN_NONE : H5T_SGN_2);
      H5Tclose(type);
      // sensor_id as pdp-sim's h5py writes a list of ints: int64, one per column.
      hid_t ids = H5Aopen(d, awcc::pdpsim::sensor_id_attribute, H5P_DEFAULT);
      ASSERT_GE(ids, 0);
      hid_t ids_type = H5Aget_type(ids);
      EXPECT_EQ(H5Tget_class(ids_type), H5T_INTEGER);
      EXPECT_EQ(H5Tget_size(ids_type), 8u);
      H5Tclose(ids_type);
      std::vector<std::int64_t> id(2, -1);
      hid_t ids_space = H5Aget_space(ids);
      EXPECT_EQ(H5Sget_simple_extent_npoints(ids_space), 2);
      H5Sclose(ids_space);
      H5Aread(ids, H5T_NATIVE_INT64, id.data());
      EXPECT_EQ(id, (std::vector<std::int64_t>{0, 1}));
      H5Aclose(ids);
      double fs = 0.0;
      hid_t fs_attribute = H5Aopen(d, awcc::pdpsim::fs_attribute, H5P_DEFAULT);
      H5Aread(fs_attribute, H5T_NATIVE_DOUBLE, &fs);
      H5Aclose(fs_attribute);
      EXPECT_EQ(fs, s.fs);
      EXPECT_EQ(H5Aexists(d, awcc::pdpsim::volts_per_count_attribute), binary ? 0 : 1);
      H5Dclose(d);

      std::vector<hsize_t> dims;
      // pdp-sim's tools read the signal as int8; int16 holds both forms.
      samples.push_back(dataset<std::int16_t>(file, awcc::pdpsim::signal_dataset, H5T_NATIVE_INT16, dims));
      EXPECT_EQ(dims, (std::vector<hsize_t>{n, 2}));
      const auto time = dataset<double>(file, awcc::pdpsim::time_dataset, H5T_NATIVE_DOUBLE, dims);
      EXPECT_EQ(dims, (std::vector<hsize_t>{n}));
      ASSERT_EQ(time.size(), n);
      EXPECT_EQ(time[0], 0.0);
      EXPECT_DOUBLE_EQ(time[1] - time[0], 1.0 / s.fs);
      EXPECT_DOUBLE_EQ(time[n - 1], static_cast<double>(n - 1) / s.fs);
      H5Fclose(file);
    }
    EXPECT_EQ(samples[0], samples[1]) << "the block size changed the samples";
    if (binary) {
      for (std::size_t j = 0; j < 2; ++j) {
        const auto dense = awcc::to_dense(synthesis.signals[j]);
        std::size_t mismatches = 0;
        for (std::size_t i = 0; i < dense.size(); ++i) mismatches += samples[0][2 * i + j] != dense[i];
        EXPECT_EQ(mismatches, 0u) << "tip " << j;
      }
    }
  }
  // Deflated (time with shuffle): the whole file weighs less than the signal would bare.
  EXPECT_LT(fs::file_size(scratch("layout_whole.h5")), n * 2);  // less than the bare uint8 signal
}

}  // namespace
