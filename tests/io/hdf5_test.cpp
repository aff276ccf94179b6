// The HDF5 reader (awcc/recording.hpp) on files written here with the HDF5 C
// API: pdp-sim's layout (uint8 0/1 `signal`, `time`, `sensor_id` as integers
// or strings), generic layouts (a 2-D dataset with a rate attribute, 1-D
// datasets per channel with dt, int16 with volts_per_count), chunked and
// deflated data read in odd blocks, transposed, absent and ambiguous
// datasets, time bases that are not uniform, a stated rate that contradicts,
// and hostile files, which must give InputError and never HDF5's own output.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/process.hpp"
#include "awcc/recording.hpp"
#include "test_paths.hpp"
#include "declared_quantity.hpp"

namespace {

namespace fs = std::filesystem;

// ctest runs each test in its own process, in parallel: the name carries the test's own name.
fs::path scratch(const std::string& name) { return pdp_test::test_file(name); }

// A file being written (closed at the end of the scope). Groups on the way
// to a dataset are created.
class Writer {
 public:
  explicit Writer(const fs::path& path, hsize_t user_block = 0) {
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    if (user_block) H5Pset_userblock(fcpl, user_block);
    file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT);
    H5Pclose(fcpl);
    lcpl_ = H5Pcreate(H5P_LINK_CREATE);
    H5Pset_create_intermediate_group(lcpl_, 1);
    EXPECT_GE(file_, 0) << path;
  }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  ~Writer() {
    H5Pclose(lcpl_);
    H5Fclose(file_);
  }
  [[nodiscard]] hid_t file() const { return file_; }

  // A dataset of `dims` from `data` (memory type `memory`), stored as `stored`.
  hid_t dataset(const std::string& name, hid_t stored, hid_t memory, const std::vector<hsize_t>& dims,
                const void* data, hid_t dcpl = H5P_DEFAULT) {
    hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    hid_t d = H5Dcreate2(file_, name.c_str(), stored, space, lcpl_, dcpl, H5P_DEFAULT);
    EXPECT_GE(d, 0) << name;
    if (data) {
      EXPECT_GE(H5Dwrite(d, memory, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0) << name;
    }
    H5Sclose(space);
    datasets_.push_back(d);
    return d;
  }
  void group(const std::string& name) { H5Gclose(H5Gcreate2(file_, name.c_str(), lcpl_, H5P_DEFAULT, H5P_DEFAULT)); }

  static void number(hid_t object, const char* name, double value) {
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(object, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_DOUBLE, &value);
    H5Aclose(a);
    H5Sclose(space);
  }
  void number(const std::string& object, const char* name, double value) {
    hid_t o = H5Oopen(file_, object.c_str(), H5P_DEFAULT);
    number(o, name, value);
    H5Oclose(o);
  }
  static void integers(hid_t object, const char* name, const std::vector<std::int64_t>& values) {
    const hsize_t n = values.size();
    hid_t space = H5Screate_simple(1, &n, nullptr);
    hid_t a = H5Acreate2(object, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT64, values.data());
    H5Aclose(a);
    H5Sclose(space);
  }
  // h5py's form of a list of str: variable-length UTF-8 strings.
  static void strings(hid_t object, const char* name, const std::vector<std::string>& values) {
    const hsize_t n = values.size();
    std::vector<const char*> texts;
    for (const auto& v : values) texts.push_back(v.c_str());
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    hid_t space = H5Screate_simple(1, &n, nullptr);
    hid_t a = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, type, texts.data());
    H5Aclose(a);
    H5Sclose(space);
    H5Tclose(type);
  }

 private:
  hid_t file_ = -1, lcpl_ = -1;
  std::vector<hid_t> datasets_;

 public:
  // Datasets close before the file (weak close degree would keep it open otherwise).
  void close_datasets() {
    for (auto d : datasets_) H5Dclose(d);
    datasets_.clear();
  }
};

std::vector<float> read_all(awcc::Recording& r, std::int64_t block) {
  std::vector<float> all, buffer(static_cast<std::size_t>(block * r.info().channels));
  for (;;) {
    const auto n = r.read(buffer, block);
    if (n == 0) break;
    all.insert(all.end(), buffer.begin(), buffer.begin() + n * r.info().channels);
  }
  return all;
}

// 0/1 runs of a few lengths, different per tip, starting in water.
std::vector<std::uint8_t> air_pattern(std::size_t frames, std::size_t tips) {
  std::vector<std::uint8_t> s(frames * tips, 0);
  for (std::size_t j = 0; j < tips; ++j) {
    std::size_t i = 5 + 3 * j;
    bool air = true;
    int k = 0;
    while (i < frames) {
      const std::size_t run = air ? 4 + (k % 5) : 9 + (k % 11) + j;
      for (std::size_t r = 0; r < run && i < frames; ++r, ++i) s[i * tips + j] = air ? 1 : 0;
      air = !air;
      ++k;
    }
  }
  return s;
}

// pdp-sim's binary_signal.h5: time as numpy's linspace(0, n dt, n + 1), signal 'u1'.
fs::path pdpsim_file(const fs::path& p, std::size_t frames, double fs, bool string_ids, hsize_t user_block = 0) {
  const auto signal = air_pattern(frames, 2);
  std::vector<double> time(frames);
  const double step = (static_cast<double>(frames - 1) / fs) / static_cast<double>(frames - 1);
  for (std::size_t i = 0; i < frames; ++i) time[i] = static_cast<double>(i) * step;
  Writer w(p, user_block);
  w.dataset("time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {frames}, time.data());
  const hid_t s = w.dataset("signal", H5T_STD_U8LE, H5T_NATIVE_UINT8, {frames, 2}, signal.data());
  if (string_ids) Writer::strings(s, "sensor_id", {"lead", "trail"});
  else Writer::integers(s, "sensor_id", {3, 7});
  w.close_datasets();
  return p;
}

// Runs `open` and returns the InputError's message (empty when none was thrown),
// failing the test if anything reached stderr (HDF5's error stack).
template <class F>
std::string refusal(F open, std::string* quantity = nullptr) {
  std::string message;
  ::testing::internal::CaptureStderr();
  try {
    open();
  } catch (const awcc::InputError& e) {
    message = e.what();
    EXPECT_TRUE(declared_reader_quantity(e.quantity())) << e.quantity();
    if (quantity) *quantity = e.quantity();
  }
  std::fflush(stderr);
  const std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "") << "HDF5 printed its error stack";
  return message;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Hdf5Reader, PdpSimLayoutWithIntegerSensorIdsBinarisesToItsIntervals) {
  const std::size_t n = 20'000;
  const auto p = pdpsim_file(scratch("binary_signal.h5"), n, 50e3, false);
  auto r = awcc::open_recording(p, {});
  const auto& info = r->info();
  EXPECT_EQ(info.format, "hdf5");
  EXPECT_EQ(info.channels, 2);
  EXPECT_EQ(info.frames, static_cast<std::int64_t>(n));
  EXPECT_NEAR(info.fs, 50e3, 50e3 * 1e-12);
  EXPECT_EQ(info.channel_names, (std::vector<std::string>{"sensor 3", "sensor 7"}));
  EXPECT_TRUE(has(info.description, "pdp-sim")) << info.description;
  // Counts of unknown scale, normalised as libsndfile does: uint8 full scale 1.
  EXPECT_FALSE(info.volts_known);
  EXPECT_EQ(info.quantum, 1.0 / 256.0);
  EXPECT_TRUE(info.warnings.empty());
  EXPECT_FALSE(r->has_int16());
  const auto pattern = air_pattern(n, 2);
  const auto values = read_all(*r, 4096);
  ASSERT_EQ(values.size(), pattern.size());
  for (std::size_t i = 0; i < values.size(); ++i) ASSERT_EQ(values[i], pattern[i] / 256.0f) << i;

  const auto b = awcc::binarise_recording(p, awcc::ProcessOptions{});
  for (std::size_t j = 0; j < 2; ++j) {
    std::vector<std::uint8_t> tip(n);
    for (std::size_t i = 0; i < n; ++i) tip[i] = pattern[i * 2 + j];
    const auto expected = awcc::from_dense(tip, 50e3);
    const auto& got = j == 0 ? b.leading : b.trailing;
    EXPECT_EQ(got.sample_count, expected.sample_count);
    EXPECT_EQ(got.intervals, expected.intervals) << "tip " << j;
  }
  EXPECT_TRUE(b.leading_threshold.binary_input);
}

TEST(Hdf5Reader, StringSensorIdsAndTheSignatureAfterAUserBlock) {
  // No extension: found by its signature, at byte 512 behind a user block.
  const auto p = pdpsim_file(scratch("signal_without_extension"), 1000, 20e3, true, 512);
  auto r = awcc::open_recording(p, {});
  EXPECT_EQ(r->info().format, "hdf5");
  EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"lead", "trail"}));
  EXPECT_NEAR(r->info().fs, 20e3, 1e-6);
  // Fixed-length strings (numpy 'S') too.
  const auto q = scratch("fixed_ids.h5");
  {
    const auto signal = air_pattern(100, 2);
    Writer w(q);
    const hid_t s = w.dataset("signal", H5T_STD_U8LE, H5T_NATIVE_UINT8, {100, 2}, signal.data());
    Writer::number(s, "fs", 1e4);
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 4);
    const hsize_t two = 2;
    hid_t space = H5Screate_simple(1, &two, nullptr);
    hid_t a = H5Acreate2(s, "sensor_id", type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, type, "s0\0\0s1\0\0");
    H5Aclose(a);
    H5Sclose(space);
    H5Tclose(type);
    w.close_datasets();
  }
  auto f = awcc::open_recording(q, {});
  EXPECT_EQ(f->info().channel_names, (std::vector<std::string>{"s0", "s1"}));
  EXPECT_EQ(f->info().fs, 1e4);
}

TEST(Hdf5Reader, Generic2DFloat32WithAnFsAttributeOnItsGroup) {
  const std::size_t n = 500;
  std::vector<float> v(n * 3);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.25f * static_cast<float>(i % 37) - 1.0f;
  const std::vector<double> temperature(10, 20.0);
  const auto p = scratch("generic.h5");
  {
    Writer w(p);
    w.dataset("/run/volts", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {n, 3}, v.data());
    w.dataset("/meta/temperature", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {10}, temperature.data());
    w.number("/run", "sampling_rate", 20e3);
    w.close_datasets();
  }
  // The only 2-D numeric dataset is found; by its path, or its group, alike.
  const std::vector<std::vector<std::string>> namings{{}, {"/run/volts"}, {"run"}};
  for (const auto& named : namings) {
    awcc::ReaderOptions o;
    o.datasets = named;
    auto r = awcc::open_recording(p, o);
    EXPECT_EQ(r->info().channels, 3);
    EXPECT_EQ(r->info().frames, static_cast<std::int64_t>(n));
    EXPECT_EQ(r->info().fs, 20e3);
    EXPECT_TRUE(r->info().volts_known);
    EXPECT_EQ(r->info().quantum, 0.0);
    EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"/run/volts[0]", "/run/volts[1]", "/run/volts[2]"}));
    EXPECT_EQ(read_all(*r, 77), v);
  }
}

TEST(Hdf5Reader, OneDatasetPerChannelWithDtAndATimeBaseThatAgrees) {
  const std::size_t n = 300;
  std::vector<double> a(n), b(n), t(n);
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = std::sin(0.01 * static_cast<double>(i));
    b[i] = 2.0 + static_cast<double>(i % 7);
    t[i] = static_cast<double>(i) * 1e-5;
  }
  const auto p = scratch("per_channel.h5");
  {
    Writer w(p);
    w.dataset("/probe/b", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, b.data());
    w.dataset("/probe/a", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, a.data());
    w.dataset("/probe/time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, t.data());
    w.number("/", "dt", 1e-5);
    w.close_datasets();
  }
  awcc::ReaderOptions group;
  group.datasets = {"/probe"};
  auto r = awcc::open_recording(p, group);
  // Name order, and the group's time base is not a channel.
  EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"/probe/a", "/probe/b"}));
  EXPECT_NEAR(r->info().fs, 1e5, 1e-6);
  const auto v = read_all(*r, 64);
  ASSERT_EQ(v.size(), 2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(v[2 * i], static_cast<float>(a[i]));
    ASSERT_EQ(v[2 * i + 1], static_cast<float>(b[i]));
  }
  awcc::ReaderOptions listed;
  listed.datasets = {"/probe/b", "probe/a"};  // the order given
  auto s = awcc::open_recording(p, listed);
  EXPECT_EQ(s->info().channel_names, (std::vector<std::string>{"/probe/b", "/probe/a"}));
  EXPECT_EQ(read_all(*s, 1000)[0], static_cast<float>(b[0]));

  // An interval attribute that contradicts the time base: one of them is wrong.
  const auto q = scratch("contradicting.h5");
  {
    Writer w(q);
    w.dataset("/probe/a", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, a.data());
    w.dataset("/probe/time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, t.data());
    w.number("/probe", "dt", 2e-5);
    w.close_datasets();
  }
  awcc::ReaderOptions one;
  one.datasets = {"/probe/a"};
  std::string quantity;
  const auto message = refusal([&] { (void)awcc::open_recording(q, one); }, &quantity);
  EXPECT_TRUE(has(message, "'dt'") && has(message, "/probe/time")) << message;
  EXPECT_EQ(quantity, "override-fs");
}

TEST(Hdf5Reader, Int16WithVoltsPerCountOffersItsCounts) {
  const std::size_t n = 1000;
  std::vector<std::int16_t> counts(n * 2);
  for (std::size_t i = 0; i < counts.size(); ++i) counts[i] = static_cast<std::int16_t>(static_cast<int>(i * 37 % 60000) - 30000);
  const double vpc = 5.0 / 32768.0;
  const auto p = scratch("counts.h5");
  {
    Writer w(p);
    const hid_t d = w.dataset("v", H5T_STD_I16BE, H5T_NATIVE_INT16, {n, 2}, counts.data());  // big-endian on disk
    Writer::number(d, "volts_per_count", vpc);
    Writer::number(d, "Fs", 8e3);
    w.dataset("unscaled", H5T_STD_I16LE, H5T_NATIVE_INT16, {n, 2}, counts.data());
    w.number("/", "fs", 8e3);
    w.close_datasets();
  }
  awcc::ReaderOptions o;
  o.datasets = {"v"};
  auto r = awcc::open_recording(p, o);
  EXPECT_TRUE(r->has_int16());
  EXPECT_TRUE(r->info().volts_known);
  EXPECT_EQ(r->info().quantum, vpc);
  EXPECT_EQ(r->info().fs, 8e3);
  std::vector<std::int16_t> got(n * 2);
  EXPECT_EQ(r->read_int16(got, static_cast<std::int64_t>(n)), static_cast<std::int64_t>(n));
  EXPECT_EQ(got, counts);
  r->rewind();
  const auto volts = read_all(*r, 333);
  for (std::size_t i = 0; i < counts.size(); ++i) ASSERT_EQ(volts[i], static_cast<float>(counts[i] * vpc)) << i;

  o.volts_per_count = 1e-3;  // the stated scale wins
  EXPECT_EQ(awcc::open_recording(p, o)->info().quantum, 1e-3);
  awcc::ReaderOptions bare;
  bare.datasets = {"unscaled"};
  auto u = awcc::open_recording(p, bare);
  EXPECT_FALSE(u->info().volts_known);
  EXPECT_EQ(u->info().quantum, 1.0 / 32768.0);
  EXPECT_FALSE(u->info().warnings.empty());
  EXPECT_EQ(u->info().fs, 8e3);  // from the root
}

// Found by fuzz_read_hdf5: a volts_per_count attribute of 1e298 was accepted,
// so read() handed out infinite volts (count x scale beyond a float) while
// read_int16() offered the counts with that quantum: the two paths of
// processing disagreed, and neither refused. A scale for which the largest
// count is no sample is refused, naming the attribute; the largest that is
// still a float is read.
TEST(Hdf5Reader, AVoltsPerCountBeyondTheSampleRangeIsRefused) {
  const std::size_t n = 64;
  std::vector<std::int16_t> counts(n * 2);
  for (std::size_t i = 0; i < counts.size(); ++i) counts[i] = static_cast<std::int16_t>(i % 2 ? -32768 : 32767);
  const double largest = std::numeric_limits<float>::max() / 32768.0;  // -32768 x this is -FLT_MAX
  const auto p = scratch("huge_scale.h5");
  {
    Writer w(p);
    const hid_t huge = w.dataset("huge", H5T_STD_I16LE, H5T_NATIVE_INT16, {n, 2}, counts.data());
    Writer::number(huge, "volts_per_count", 1e298);
    const hid_t edge = w.dataset("edge", H5T_STD_I16LE, H5T_NATIVE_INT16, {n, 2}, counts.data());
    Writer::number(edge, "volts_per_count", largest);
    w.number("/", "fs", 8e3);
    w.close_datasets();
  }
  awcc::ReaderOptions o;
  o.datasets = {"huge"};
  std::string quantity;
  const auto message = refusal([&] { (void)awcc::open_recording(p, o); }, &quantity);
  EXPECT_TRUE(has(message, "attribute 'volts_per_count' of '/huge' is 1e+298")) << message;
  EXPECT_TRUE(has(message, "beyond a sample's range")) << message;
  EXPECT_EQ(quantity, "volts-per-count");
  o.datasets = {"edge"};
  auto r = awcc::open_recording(p, o);
  for (const float v : read_all(*r, 17)) ASSERT_TRUE(std::isfinite(v)) << v;
}

// Found by fuzz_read_hdf5 (the inputs are committed as found, tests/io/data):
// pdp-sim files whose `sensor_id` attribute has a damaged integer type (bit
// fields outside its bytes). libhdf5 1.10.8 converted it to double trusting the
// fields: a stack smash in H5T__bit_get_d on one, a heap overflow in
// H5T__bit_copy on the other. A damaged number type is refused before any
// conversion, naming the attribute.
TEST(Hdf5Reader, ADamagedNumberTypeIsRefusedBeforeLibhdf5ConvertsIt) {
  for (const char* name : {"hdf5-damaged-type-stack-smash.h5", "hdf5-damaged-type-overflow.h5"}) {
    const auto p = pdp_test::source_dir() / "tests/io/data" / name;
    ASSERT_TRUE(fs::exists(p)) << p;
    const auto message = refusal([&] { (void)awcc::open_recording(p, {}); });
    EXPECT_TRUE(has(message, p.string() + ": attribute 'sensor_id' of '/signal' has a damaged number type")) << message;
  }
}

// Found by fuzz_read_hdf5 (the input as found, tests/io/data): a chunked,
// deflated dataset of 1500 int16 values whose header gives chunks of
// 536871168 values (1 GB) stored in 270 bytes. libhdf5 allocated and inflated
// a whole chunk per read: 21 s and 1 GB to read 3 kB. Chunks the stored bytes
// cannot hold (deflate expands at most 1032-fold) are refused.
TEST(Hdf5Reader, ChunksLargerThanTheirStorageCanHoldAreRefused) {
  const auto p = pdp_test::source_dir() / "tests/io/data/hdf5-lying-chunk-size.h5";
  awcc::ReaderOptions o;
  o.fs = 10000.0;
  o.datasets = {"/run"};
  const auto message = refusal([&] { (void)awcc::open_recording(p, o); });
  EXPECT_TRUE(has(message, "dataset '/run/lead' has 14 chunks of 1073742336 bytes stored in 270 bytes, more than its "
                           "compression allows: the file is damaged"))
      << message;
}

TEST(Hdf5Reader, ChunkedDeflatedDatasetReadInOddBlocksEqualsTheWhole) {
  const std::size_t n = 100'003;
  std::vector<std::int16_t> counts(n * 2);
  std::mt19937 rng(7);
  for (auto& c : counts) c = static_cast<std::int16_t>(static_cast<int>(rng() % 4000) - 2000);
  const auto p = scratch("chunked.h5");
  {
    Writer w(p);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    const hsize_t chunk[2] = {1000, 2};
    H5Pset_chunk(dcpl, 2, chunk);
    H5Pset_shuffle(dcpl);
    H5Pset_deflate(dcpl, 6);
    const hid_t d = w.dataset("signal", H5T_STD_I16LE, H5T_NATIVE_INT16, {n, 2}, counts.data(), dcpl);
    Writer::number(d, "fs", 1e5);
    H5Pclose(dcpl);
    w.close_datasets();
  }
  auto r = awcc::open_recording(p, {});
  const auto whole = read_all(*r, static_cast<std::int64_t>(n));
  ASSERT_EQ(whole.size(), counts.size());
  for (std::size_t i = 0; i < whole.size(); ++i) ASSERT_EQ(whole[i], static_cast<float>(counts[i] / 32768.0)) << i;
  for (std::int64_t block : {1, 7, 999, 4099}) {
    r->rewind();
    EXPECT_EQ(read_all(*r, block), whole) << "blocks of " << block;
  }
  r->rewind();
  std::vector<std::int16_t> got(static_cast<std::size_t>(2 * 1001));
  std::vector<std::int16_t> all;
  for (std::int64_t k; (k = r->read_int16(got, 1001)) > 0;) all.insert(all.end(), got.begin(), got.begin() + 2 * k);
  EXPECT_EQ(all, counts);
}

TEST(Hdf5Reader, ChannelsBySamplesIsReadTransposedAndSaysSo) {
  const std::size_t n = 5000;
  std::vector<float> stored(2 * n);  // row 0: channel 0, row 1: channel 1
  for (std::size_t i = 0; i < n; ++i) {
    stored[i] = static_cast<float>(i);
    stored[n + i] = -static_cast<float>(i);
  }
  const auto p = scratch("transposed.h5");
  {
    Writer w(p);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    const hsize_t chunk[2] = {1, 512};
    H5Pset_chunk(dcpl, 2, chunk);
    H5Pset_deflate(dcpl, 1);
    const hid_t d = w.dataset("x", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {2, n}, stored.data(), dcpl);
    H5Pclose(dcpl);
    Writer::number(d, "fs", 1e4);
    std::vector<float> wide(17 * 100, 1.0f);
    w.dataset("wide", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {17, 100}, wide.data());
    w.close_datasets();
  }
  awcc::ReaderOptions o;
  o.datasets = {"x"};
  auto r = awcc::open_recording(p, o);
  EXPECT_EQ(r->info().channels, 2);
  EXPECT_EQ(r->info().frames, static_cast<std::int64_t>(n));
  EXPECT_TRUE(has(r->info().description, "transposed")) << r->info().description;
  const auto v = read_all(*r, 333);
  ASSERT_EQ(v.size(), 2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(v[2 * i], static_cast<float>(i));
    ASSERT_EQ(v[2 * i + 1], -static_cast<float>(i));
  }
  // 17 rows, 100 columns: too many rows to be a probe's channels, too few to
  // be the samples of 100 channels: refused, as the MATLAB reader refuses it
  // (one rule, awcc/detail/columns.hpp).
  o.datasets = {"wide"};
  o.fs = 1e3;
  std::string quantity;
  const auto message = refusal([&] { (void)awcc::open_recording(p, o); }, &quantity);
  EXPECT_TRUE(has(message, "'/wide' is 17 x 100: more columns than rows, but too many rows (more than 16)")) << message;
  EXPECT_EQ(quantity, "dataset");
}

TEST(Hdf5Reader, AbsentOrAmbiguousDatasetsAreRefusedWithTheList) {
  const std::vector<float> m(40, 1.0f);
  const auto p = scratch("ambiguous.h5");
  {
    Writer w(p);
    w.dataset("/a/first", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {20, 2}, m.data());
    w.dataset("/b/second", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {10, 4}, m.data());
    w.dataset("/c/vector", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {40}, m.data());
    w.dataset("/c/matrix", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {20, 2}, m.data());
    w.dataset("/d/short", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {30}, m.data());
    w.number("/", "fs", 1e3);
    w.close_datasets();
  }
  std::string quantity;
  auto message = refusal([&] { (void)awcc::open_recording(p, {}); }, &quantity);
  EXPECT_TRUE(has(message, p.string())) << message;
  EXPECT_TRUE(has(message, "several") && has(message, "'/a/first' (float32, 20 x 2)") && has(message, "/b/second"))
      << message;
  EXPECT_EQ(quantity, "dataset");
  awcc::ReaderOptions o;
  o.datasets = {"/nothere"};
  message = refusal([&] { (void)awcc::open_recording(p, o); }, &quantity);
  EXPECT_TRUE(has(message, "'/nothere'") && has(message, "/c/vector")) << message;
  o.datasets = {"/c"};
  message = refusal([&] { (void)awcc::open_recording(p, o); });
  EXPECT_TRUE(has(message, "1-D") && has(message, "2-D")) << message;
  o.datasets = {"/c/vector", "/d/short"};
  message = refusal([&] { (void)awcc::open_recording(p, o); }, &quantity);
  EXPECT_TRUE(has(message, "'/c/vector'") && has(message, "'/d/short'") && has(message, "40 and 30")) << message;
  EXPECT_EQ(quantity, "dataset");

  const auto q = scratch("vectors_only.h5");
  {
    Writer w(q);
    w.dataset("/c/vector", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {40}, m.data());
    w.close_datasets();
  }
  message = refusal([&] { (void)awcc::open_recording(q, {}); }, &quantity);
  EXPECT_TRUE(has(message, "no numeric 2-D dataset") && has(message, "/c/vector")) << message;
}

// Found by fuzz_read_hdf5 once a NULL from malloc reached libhdf5 (as in
// production): a named dataset whose object header cannot be read was
// refused as "no dataset or group", sending the user to look for a wrong name
// in a damaged file.
TEST(Hdf5Reader, ANamedDatasetThatCannotBeReadIsADamagedFileNotAWrongName) {
  const std::vector<float> v(40, 1.0f);
  const auto p = scratch("damaged_header.h5");
  haddr_t header = HADDR_UNDEF;
  {
    Writer w(p);
    w.dataset("/g/run", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {40}, v.data());
    w.number("/", "fs", 1e3);
    w.close_datasets();
    H5O_info_t info;
    ASSERT_GE(H5Oget_info_by_name2(w.file(), "/g/run", &info, H5O_INFO_BASIC, H5P_DEFAULT), 0);
    header = info.addr;
  }
  awcc::ReaderOptions o;
  o.datasets = {"/g/run/x"};
  std::string quantity;
  auto message = refusal([&] { (void)awcc::open_recording(p, o); }, &quantity);
  EXPECT_TRUE(has(message, "no dataset or group '/g/run/x'") && has(message, "/g/run")) << message;
  EXPECT_EQ(quantity, "dataset");
  {
    // The dataset's object header overwritten: its link in /g is intact.
    std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(header));
    const std::string garbage(16, '\xff');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  o.datasets = {"/g/run"};
  message = refusal([&] { (void)awcc::open_recording(p, o); });
  EXPECT_TRUE(has(message, p.string()) && has(message, "'/g/run' cannot be opened") && has(message, "damaged"))
      << message;
  EXPECT_FALSE(has(message, "no dataset")) << message;
}

TEST(Hdf5Reader, ATimeBaseThatIsNotUniformOrIncreasingIsRefused) {
  const std::size_t n = 1000;
  const auto signal = air_pattern(n, 2);
  auto file = [&](const std::string& name, const std::vector<double>& time) {
    const auto p = scratch(name);
    Writer w(p);
    w.dataset("time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {time.size()}, time.data());
    w.dataset("signal", H5T_STD_U8LE, H5T_NATIVE_UINT8, {n, 2}, signal.data());
    w.close_datasets();
    return p;
  };
  std::vector<double> gap(n);
  for (std::size_t i = 0; i < n; ++i) gap[i] = static_cast<double>(i + (i >= 500 ? 100 : 0)) * 1e-5;  // samples lost
  std::string quantity;
  auto message = refusal([&] { (void)awcc::open_recording(file("gap.h5", gap), {}); }, &quantity);
  EXPECT_TRUE(has(message, "'/time'") && has(message, "not evenly spaced") &&
              has(message, "the longest step, 0.00101 s, is to value 500"))
      << message;
  EXPECT_EQ(quantity, "override-fs");

  std::vector<double> back(n);
  for (std::size_t i = 0; i < n; ++i) back[i] = static_cast<double>(i) * 1e-5;
  std::swap(back[600], back[601]);  // same first step, same span
  message = refusal([&] { (void)awcc::open_recording(file("back.h5", back), {}); });
  EXPECT_TRUE(has(message, "does not increase at value 601")) << message;

  std::vector<double> shorter(n - 1);
  for (std::size_t i = 0; i < n - 1; ++i) shorter[i] = static_cast<double>(i) * 1e-5;
  message = refusal([&] { (void)awcc::open_recording(file("shorter.h5", shorter), {}); });
  EXPECT_TRUE(has(message, "999 values") && has(message, "1000 samples")) << message;

  // Forcing a rate sets the time base aside.
  awcc::ReaderOptions forced;
  forced.fs = 1e5;
  forced.override_fs = true;
  EXPECT_EQ(awcc::open_recording(file("gap_forced.h5", gap), forced)->info().fs, 1e5);
}

TEST(Hdf5Reader, AStatedRateMustAgreeWithTheFile) {
  const auto p = pdpsim_file(scratch("rate.h5"), 2000, 50e3, false);
  awcc::ReaderOptions o;
  o.fs = 40e3;
  std::string quantity;
  const auto message = refusal([&] { (void)awcc::open_recording(p, o); }, &quantity);
  EXPECT_TRUE(has(message, "'/time'") && has(message, "50kHz")) << message;
  EXPECT_EQ(quantity, "override-fs");
  o.fs = 50e3;
  EXPECT_EQ(awcc::open_recording(p, o)->info().fs, 50e3);
  o.fs = 40e3;
  o.override_fs = true;
  EXPECT_EQ(awcc::open_recording(p, o)->info().fs, 40e3);
  // Without any rate in the file, the stated one is needed.
  const auto q = scratch("no_rate.h5");
  {
    Writer w(q);
    const auto s = air_pattern(100, 2);
    w.dataset("signal", H5T_STD_U8LE, H5T_NATIVE_UINT8, {100, 2}, s.data());
    w.close_datasets();
  }
  const auto none = refusal([&] { (void)awcc::open_recording(q, {}); }, &quantity);
  EXPECT_TRUE(has(none, "no sampling rate")) << none;
  EXPECT_EQ(quantity, "fs");
  awcc::ReaderOptions stated;
  stated.fs = 1e4;
  EXPECT_EQ(awcc::open_recording(q, stated)->info().fs, 1e4);
}

TEST(Hdf5Reader, UnwrittenChunksAndNonFiniteSamplesAreRefused) {
  const auto p = scratch("unfinished.h5");
  {
    Writer w(p);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    const hsize_t chunk[2] = {100, 2};
    H5Pset_chunk(dcpl, 2, chunk);
    const hid_t d = w.dataset("signal", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {1000, 2}, nullptr, dcpl);
    H5Pclose(dcpl);
    Writer::number(d, "fs", 1e3);
    // A writer that stopped after 300 of 1000 frames.
    std::vector<float> part(600, 0.5f);
    const hsize_t start[2] = {0, 0}, count[2] = {300, 2};
    hid_t space = H5Dget_space(d);
    H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    hid_t memory = H5Screate_simple(2, count, nullptr);
    H5Dwrite(d, H5T_NATIVE_FLOAT, memory, space, H5P_DEFAULT, part.data());
    H5Sclose(memory);
    H5Sclose(space);
    w.close_datasets();
  }
  const auto message = refusal([&] { (void)awcc::open_recording(p, {}); });
  EXPECT_TRUE(has(message, "only 3 of the 10 chunks")) << message;

  const auto q = scratch("nan.h5");
  {
    std::vector<double> v(200, 1.0);
    v[2 * 57 + 1] = std::nan("");
    Writer w(q);
    const hid_t d = w.dataset("signal", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {100, 2}, v.data());
    Writer::number(d, "fs", 1e3);
    w.close_datasets();
  }
  auto r = awcc::open_recording(q, {});
  const auto nan = refusal([&] { (void)read_all(*r, 10); });
  EXPECT_TRUE(has(nan, "sample 57") && has(nan, "column 1") && has(nan, "NaN")) << nan;
}

TEST(Hdf5Reader, HostileFilesAreRefusedWithAMessageAndNothingPrinted) {
  const auto good = pdpsim_file(scratch("good.h5"), 3000, 50e3, false);
  std::vector<char> bytes(fs::file_size(good));
  std::ifstream(good, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  auto write = [](const fs::path& p, const char* data, std::size_t size) {
    std::ofstream(p, std::ios::binary).write(data, static_cast<std::streamsize>(size));
  };
  const auto cut = scratch("cut.h5");
  for (std::size_t keep : {std::size_t{8}, std::size_t{100}, bytes.size() / 2, bytes.size() - 1}) {
    write(cut, bytes.data(), keep);
    const auto message = refusal([&] { (void)read_all(*awcc::open_recording(cut, {}), 4096); });
    EXPECT_TRUE(has(message, cut.string())) << "kept " << keep << ": " << message;
  }
  // The signature, then noise; and the valid file with its middle scrambled.
  std::mt19937 rng(11);
  std::vector<char> noise(4096);
  for (auto& c : noise) c = static_cast<char>(rng());
  std::memcpy(noise.data(), "\x89HDF\r\n\x1a\n", 8);
  const auto random = scratch("random.h5");
  write(random, noise.data(), noise.size());
  EXPECT_TRUE(has(refusal([&] { (void)awcc::open_recording(random, {}); }), "HDF5")) << "random bytes";
  for (int trial = 0; trial < 20; ++trial) {
    auto scrambled = bytes;
    for (int k = 0; k < 16; ++k) scrambled[96 + rng() % (scrambled.size() - 96)] = static_cast<char>(rng());
    write(random, scrambled.data(), scrambled.size());
    // Damage the reader may miss (a flipped sample) can be read; what it refuses is an InputError.
    (void)refusal([&] { (void)read_all(*awcc::open_recording(random, {}), 512); });
  }
  // Not HDF5 at all, named .h5.
  const auto text = scratch("text.h5");
  write(text, "time,a,b\n", 9);
  std::string quantity;
  EXPECT_TRUE(has(refusal([&] { (void)awcc::open_recording(text, {}); }, &quantity), "not an HDF5 file"));
  EXPECT_EQ(quantity, "format");

  // Types and shapes that are not samples.
  const auto odd = scratch("odd.h5");
  {
    Writer w(odd);
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 8);
    w.dataset("names", type, type, {2}, "abcdefghijklmnop");
    H5Tclose(type);
    std::vector<float> cube(2 * 3 * 4, 0.0f);
    w.dataset("cube", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {2, 3, 4}, cube.data());
    std::vector<std::int64_t> wide(20, 1);
    w.dataset("int64", H5T_STD_I64LE, H5T_NATIVE_INT64, {10, 2}, wide.data());
    hid_t pair = H5Tcreate(H5T_COMPOUND, 8);
    H5Tinsert(pair, "a", 0, H5T_NATIVE_FLOAT);
    H5Tinsert(pair, "b", 4, H5T_NATIVE_FLOAT);
    w.dataset("table", pair, pair, {3}, cube.data());
    H5Tclose(pair);
    w.close_datasets();
  }
  const std::vector<std::pair<std::string, std::string>> cases{
      {"names", "strings"}, {"cube", "3 dimensions"}, {"int64", "64-bit integers"}, {"table", "compound"}};
  for (const auto& [name, why] : cases) {
    awcc::ReaderOptions o;
    o.datasets = {name};
    o.fs = 1e3;
    const auto message = refusal([&] { (void)awcc::open_recording(odd, o); }, &quantity);
    EXPECT_TRUE(has(message, "'/" + name + "'") && has(message, why)) << message;
    EXPECT_EQ(quantity, "dataset") << name;
  }
}

TEST(Hdf5Reader, RecordingsReadFromSeveralThreadsAtOnce) {
  // libhdf5 is not thread-safe: the reader's lock makes concurrent readers safe.
  const std::size_t n = 50'000;
  const auto p = pdpsim_file(scratch("shared.h5"), n, 50e3, false);
  const auto pattern = air_pattern(n, 2);
  std::vector<int> mismatches(4, -1);
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < mismatches.size(); ++k) {
    threads.emplace_back([&, k] {
      int bad = 0;
      for (int round = 0; round < 3; ++round) {
        auto r = awcc::open_recording(p, {});
        const auto v = read_all(*r, 257 + static_cast<std::int64_t>(k));
        bad += v.size() != pattern.size();
        for (std::size_t i = 0; i < std::min(v.size(), pattern.size()); ++i) bad += v[i] != pattern[i] / 256.0f;
      }
      mismatches[k] = bad;
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(mismatches, std::vector<int>(4, 0));
}

}  // namespace

namespace {

// pdp-sim's run folder of a four-sensor probe: binary_signal.h5 with the ids
// of config.json's sensors in its order, and config.json (PROBE.sensors: id,
// relative_location in m), as pdp-sim's sbg.py writes them. Each test has
// its own folder: config.json's name is fixed.
struct PdpSimRun {
  fs::path folder, signal;
};

PdpSimRun pdpsim_run(const std::string& name, const std::string& config, std::size_t frames = 2000,
                     const std::vector<std::int64_t>& ids = {0, 1, 2, 3}) {
  PdpSimRun run{scratch(name), {}};
  fs::remove_all(run.folder);
  fs::create_directories(run.folder);
  run.signal = run.folder / "binary_signal.h5";
  const auto signal = air_pattern(frames, ids.size());
  std::vector<double> time(frames);
  for (std::size_t i = 0; i < frames; ++i) time[i] = static_cast<double>(i) / 40e3;
  {
    Writer w(run.signal);
    w.dataset("time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {frames}, time.data());
    const hid_t s = w.dataset("signal", H5T_STD_U8LE, H5T_NATIVE_UINT8, {frames, ids.size()}, signal.data());
    Writer::integers(s, "sensor_id", ids);
    w.close_datasets();
  }
  if (!config.empty()) std::ofstream(run.folder / "config.json") << config;
  return run;
}

// pdp-sim's tests/1_SBG_Timeseries/D_Frequency/input/config.json, its PROBE
// block (the sensors listed out of id order here, to show they are matched by id).
const char* const kFourSensorConfig = R"({
  "FLOW_PROPERTIES": {"mean_velocity": [5.0, 0.0, 0.0]},
  "PROBE": {
    "sampling_frequency": 40000,
    "sensors": [
      {"id": 0, "relative_location": [0.0, 0.0, 0.0]},
      {"id": 2, "relative_location": [0.001, -0.0001, -0.0001]},
      {"id": 1, "relative_location": [0.001, 0.0, 0.0002]},
      {"id": 3, "relative_location": [0.001, 0.0001, -0.0001]}
    ]
  },
  "REPRODUCIBLE": "yes"
})";

}  // namespace

TEST(Hdf5Reader, PdpSimMultiTipRunGivesEveryChannelItsSensorIdAndTipPosition) {
  const std::size_t n = 2000;
  const auto run = pdpsim_run("multi_tip_run", kFourSensorConfig, n);
  auto r = awcc::open_recording(run.signal, {});
  const auto& info = r->info();
  EXPECT_EQ(info.channels, 4);
  EXPECT_EQ(info.sensor_ids, (std::vector<std::string>{"0", "1", "2", "3"}));
  EXPECT_EQ(info.channel_names, (std::vector<std::string>{"sensor 0", "sensor 1", "sensor 2", "sensor 3"}));
  // Column k holds sensor id k: its position is config.json's entry of that id, whatever the list's order.
  const std::vector<std::array<double, 3>> expected = {
      {0.0, 0.0, 0.0}, {0.001, 0.0, 0.0002}, {0.001, -0.0001, -0.0001}, {0.001, 0.0001, -0.0001}};
  EXPECT_EQ(info.tip_positions, expected);
  EXPECT_EQ(info.leading_tip, 0);
  // Every channel is delivered: the four columns' samples as written.
  const auto pattern = air_pattern(n, 4);
  const auto values = read_all(*r, 333);
  ASSERT_EQ(values.size(), pattern.size());
  for (std::size_t i = 0; i < values.size(); ++i) ASSERT_EQ(values[i], pattern[i] / 256.0f) << i;

  // The leading tip is sensor id 0 wherever its column is.
  const auto moved = pdpsim_run("multi_tip_leading", kFourSensorConfig, 200, {2, 0, 1, 3});
  const auto opened = awcc::open_recording(moved.signal, {});
  const auto& m = opened->info();
  EXPECT_EQ(m.leading_tip, 1);
  EXPECT_EQ(m.tip_positions[0], expected[2]);
  EXPECT_EQ(m.tip_positions[1], expected[0]);

  // Without config.json (or with another program's), no positions are claimed.
  const auto bare = pdpsim_run("multi_tip_bare", "", 200);
  EXPECT_TRUE(awcc::open_recording(bare.signal, {})->info().tip_positions.empty());
  const auto other = pdpsim_run("multi_tip_other_config", R"({"name": "not pdp-sim's"})", 200);
  EXPECT_TRUE(awcc::open_recording(other.signal, {})->info().tip_positions.empty());
}

TEST(Hdf5Reader, APdpSimRunWhoseConfigDescribesOtherSensorsIsRefusedNamingBoth) {
  // config.json of three sensors beside a recording of four: a recording with more channels than the probe's tips.
  const std::string three = R"({"PROBE": {"sensors": [
      {"id": 0, "relative_location": [0, 0, 0]}, {"id": 1, "relative_location": [0.001, 0, 0]},
      {"id": 2, "relative_location": [0.001, 0.001, 0]}]}})";
  const auto a = pdpsim_run("config_three", three, 200);
  const auto why = refusal([&] { awcc::open_recording(a.signal, {}); });
  EXPECT_TRUE(has(why, "binary_signal.h5")) << why;
  EXPECT_TRUE(has(why, "config.json (PROBE.sensors) describes 3 sensors but the file records 4 channels")) << why;
  // A column whose sensor id config.json does not list.
  const auto b = pdpsim_run("config_other_ids", kFourSensorConfig, 200, {0, 1, 2, 9});
  const auto unknown = refusal([&] { awcc::open_recording(b.signal, {}); });
  EXPECT_TRUE(has(unknown, "column 3 is sensor 9, which")) << unknown;
  // A location that is not three numbers.
  const auto c = pdpsim_run("config_bad_location", R"({"PROBE": {"sensors": [
      {"id": 0, "relative_location": [0, 0]}]}})", 200, {0});
  const auto bad = refusal([&] { awcc::open_recording(c.signal, {}); });
  EXPECT_TRUE(has(bad, "sensor 0 needs an integer 'id' and a 'relative_location' of three numbers")) << bad;
  // Not JSON at all.
  const auto d = pdpsim_run("config_not_json", "{PROBE:", 200);
  const auto broken = refusal([&] { awcc::open_recording(d.signal, {}); });
  EXPECT_TRUE(has(broken, "config.json beside it (pdp-sim's configuration, which states the tips) is not valid JSON"))
      << broken;
}
