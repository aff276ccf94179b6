// The MATLAB MAT-file reader (awcc/recording.hpp) on files written here with
// matio (v5 uncompressed and compressed, v7.3) and byte by byte from
// MathWorks' "MAT-File Format" (the 128-byte header, miMATRIX elements with
// array flags, dimensions, name and real part, small data elements, values
// stored in a smaller type than their class, big-endian files, miCOMPRESSED),
// so that the reader answers to the specification, not only to matio's
// writer. Hostile files must be refused with an InputError and nothing
// printed by matio or HDF5.
#include <gtest/gtest.h>
#include <matio.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "awcc/air_intervals.hpp"
#include "awcc/errors.hpp"
#include "awcc/process.hpp"
#include "awcc/recording.hpp"
#include "test_paths.hpp"
#include "declared_quantity.hpp"

namespace {

namespace fs = std::filesystem;

// ctest runs each test in its own process, in parallel: several tests build the
// same file, so the name carries the test's own name to keep them apart.
fs::path scratch(const std::string& name) { return pdp_test::test_file(name); }

// ---------------------------------------------------------------------------
// Files written with matio.

struct Var {
  std::string name;
  matio_classes cls;
  matio_types type;
  std::vector<std::size_t> dims;
  void* data;
  int flags = 0;
};

void write_mat(const fs::path& p, mat_ft version, matio_compression compression, const std::vector<Var>& vars) {
  fs::remove(p);
  mat_t* m = Mat_CreateVer(p.c_str(), nullptr, version);
  ASSERT_NE(m, nullptr) << p;
  for (const auto& v : vars) {
    auto dims = v.dims;
    matvar_t* mv = Mat_VarCreate(v.name.c_str(), v.cls, v.type, static_cast<int>(dims.size()), dims.data(), v.data,
                                 v.flags | MAT_F_DONT_COPY_DATA);
    ASSERT_NE(mv, nullptr) << v.name;
    ASSERT_EQ(Mat_VarWrite(m, mv, compression), 0) << v.name;
    Mat_VarFree(mv);
  }
  Mat_Close(m);
}

struct Flavour {
  const char* name;
  mat_ft version;
  matio_compression compression;
};
const Flavour kFlavours[] = {{"v5", MAT_FT_MAT5, MAT_COMPRESSION_NONE},
                             {"v5z", MAT_FT_MAT5, MAT_COMPRESSION_ZLIB},
                             {"v73", MAT_FT_MAT73, MAT_COMPRESSION_NONE}};

std::vector<float> read_all(awcc::Recording& r, std::int64_t block) {
  std::vector<float> all, buffer(static_cast<std::size_t>(block * r.info().channels));
  for (;;) {
    const auto n = r.read(buffer, block);
    if (n == 0) break;
    all.insert(all.end(), buffer.begin(), buffer.begin() + n * r.info().channels);
  }
  return all;
}

std::string refusal(const fs::path& p, const awcc::ReaderOptions& o = {}, std::string* quantity = nullptr) {
  try {
    auto r = awcc::open_recording(p, o);
    (void)read_all(*r, 4096);
  } catch (const awcc::InputError& e) {
    EXPECT_TRUE(declared_reader_quantity(e.quantity())) << e.quantity();
    if (quantity) *quantity = e.quantity();
    return e.what();
  }
  return {};
}

// ---------------------------------------------------------------------------
// Files written byte by byte from the format description.

struct Bytes {
  bool big = false;
  std::vector<unsigned char> b;
  template <class T>
  Bytes& put(T v) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if (big) std::reverse(raw, raw + sizeof(T));
    b.insert(b.end(), raw, raw + sizeof(T));
    return *this;
  }
  Bytes& add(const std::vector<unsigned char>& o) {
    b.insert(b.end(), o.begin(), o.end());
    return *this;
  }
  Bytes& pad8() {
    while (b.size() % 8) b.push_back(0);
    return *this;
  }
};

constexpr std::uint32_t miINT8 = 1, miUINT8 = 2, miINT16 = 3, miUINT16 = 4, miINT32 = 5, miUINT32 = 6, miDOUBLE = 9,
                        miMATRIX = 14, miCOMPRESSED = 15;
constexpr std::uint32_t mxDOUBLE = 6;  // the array class of every variable written here

// A data element: the small format (type and size packed into one uint32,
// data in the next four bytes) when it holds 1 to 4 bytes, else a tag and
// the data padded to 8 bytes.
std::vector<unsigned char> element(bool big, std::uint32_t type, const std::vector<unsigned char>& data) {
  Bytes e{big, {}};
  if (!data.empty() && data.size() <= 4) {
    e.put<std::uint32_t>(static_cast<std::uint32_t>(data.size()) << 16 | type).add(data);
    while (e.b.size() < 8) e.b.push_back(0);
    return e.b;
  }
  e.put<std::uint32_t>(type).put<std::uint32_t>(static_cast<std::uint32_t>(data.size())).add(data).pad8();
  return e.b;
}

template <class T>
std::vector<unsigned char> values(bool big, const std::vector<T>& v) {
  Bytes e{big, {}};
  for (auto x : v) e.put(x);
  return e.b;
}

// An miMATRIX element: array flags, dimensions, name, real part.
std::vector<unsigned char> matrix(bool big, const std::string& name, std::uint32_t cls, std::vector<std::int32_t> dims,
                                  std::uint32_t stored, const std::vector<unsigned char>& real,
                                  std::uint32_t flags = 0) {
  Bytes body{big, {}};
  body.add(element(big, miUINT32, values<std::uint32_t>(big, {cls | flags, 0})));
  body.add(element(big, miINT32, values<std::int32_t>(big, dims)));
  body.add(element(big, miINT8, std::vector<unsigned char>(name.begin(), name.end())));
  body.add(element(big, stored, real));
  Bytes m{big, {}};
  m.put<std::uint32_t>(miMATRIX).put<std::uint32_t>(static_cast<std::uint32_t>(body.b.size())).add(body.b);
  return m.b;
}

std::vector<unsigned char> compressed(bool big, const std::vector<unsigned char>& inner) {
  uLongf size = compressBound(static_cast<uLong>(inner.size()));
  std::vector<unsigned char> z(size);
  EXPECT_EQ(compress(z.data(), &size, inner.data(), static_cast<uLong>(inner.size())), Z_OK);
  z.resize(size);
  Bytes e{big, {}};
  e.put<std::uint32_t>(miCOMPRESSED).put<std::uint32_t>(static_cast<std::uint32_t>(z.size())).add(z);
  return e.b;
}

// The 128-byte header: 116 bytes of text, 8 of subsystem offset, the version
// 0x0100 and the byte-order mark 'IM' as written by the machine.
std::vector<unsigned char> header(bool big) {
  const std::string text = "MATLAB 5.0 MAT-file, Platform: pdp-test, Created on: Mon Jan  1 00:00:00 2024";
  std::vector<unsigned char> h(128, 0);
  std::fill(h.begin(), h.begin() + 116, static_cast<unsigned char>(' '));
  std::copy(text.begin(), text.end(), h.begin());
  h[124] = big ? 0x01 : 0x00;  // 0x0100 in the file's byte order
  h[125] = big ? 0x00 : 0x01;
  h[126] = big ? 'M' : 'I';
  h[127] = big ? 'I' : 'M';
  return h;
}

void write(const fs::path& p, const std::vector<unsigned char>& b) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

std::vector<unsigned char> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// ---------------------------------------------------------------------------

TEST(MatFile, ASamplesByTwoDoubleMatrixWithItsRateInEveryVersion) {
  const std::size_t n = 300;
  std::vector<double> x(2 * n);  // column-major: lead then trail
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 0.01 * static_cast<double>(i);
    x[n + i] = -0.5 - 0.001 * static_cast<double>(i);
  }
  double fs = 20000.0;
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + ".mat");
    write_mat(p, f.version, f.compression,
              {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()}, {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    auto r = awcc::open_recording(p, {});
    const auto& info = r->info();
    EXPECT_EQ(info.format, "mat");
    EXPECT_EQ(info.channels, 2);
    EXPECT_EQ(info.frames, static_cast<std::int64_t>(n));
    EXPECT_DOUBLE_EQ(info.fs, 20000.0);
    EXPECT_TRUE(info.volts_known);
    EXPECT_EQ(info.quantum, 0.0);
    EXPECT_FALSE(r->has_int16());
    EXPECT_EQ(info.channel_names, (std::vector<std::string>{"x(:,1)", "x(:,2)"}));
    EXPECT_EQ(info.description.find("compressed") != std::string::npos, f.compression == MAT_COMPRESSION_ZLIB)
        << info.description;
    const auto whole = read_all(*r, static_cast<std::int64_t>(n));
    ASSERT_EQ(whole.size(), 2 * n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(whole[2 * i], static_cast<float>(x[i])) << i;
      ASSERT_EQ(whole[2 * i + 1], static_cast<float>(x[n + i])) << i;
    }
    r->rewind();
    EXPECT_EQ(read_all(*r, 7), whole);  // odd blocks, after a rewind
    r->rewind();
    EXPECT_EQ(read_all(*r, 299), whole);
  }
}

TEST(MatFile, ChannelsInRowsAreReadTransposedAndSaySo) {
  const std::size_t n = 500;
  std::vector<float> x(2 * n);  // 2 x n, column-major: frame after frame
  for (std::size_t i = 0; i < n; ++i) {
    x[2 * i] = static_cast<float>(i);
    x[2 * i + 1] = static_cast<float>(1000 + i);
  }
  double fs = 50000.0;
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + ".mat");
    write_mat(p, f.version, f.compression,
              {{"sig", MAT_C_SINGLE, MAT_T_SINGLE, {2, n}, x.data()}, {"Fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    auto r = awcc::open_recording(p, {});
    EXPECT_EQ(r->info().channels, 2);
    EXPECT_EQ(r->info().frames, static_cast<std::int64_t>(n));
    EXPECT_DOUBLE_EQ(r->info().fs, 50000.0);
    EXPECT_NE(r->info().description.find("transposed"), std::string::npos) << r->info().description;
    EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"sig(1,:)", "sig(2,:)"}));
    EXPECT_EQ(read_all(*r, 13), x);  // interleaved frames are the matrix's own order
  }
}

TEST(MatFile, VectorsNamedWithATimeVector) {
  const std::size_t n = 1000;
  const double fs = 25000.0;
  std::vector<double> lead(n), t(n);
  std::vector<double> trail_d(n);
  for (std::size_t i = 0; i < n; ++i) {
    lead[i] = std::sin(0.01 * static_cast<double>(i));
    trail_d[i] = std::cos(0.01 * static_cast<double>(i));
    t[i] = 0.5 + static_cast<double>(i) / fs;  // a time axis need not start at 0
  }
  std::vector<double> other(6, 1.0);  // a matrix the names leave aside
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + ".mat");
    // lead a column, trail a row: both are vectors.
    write_mat(p, f.version, f.compression,
              {{"lead", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 1}, lead.data()},
               {"trail", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, n}, trail_d.data()},
               {"t", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 1}, t.data()},
               {"other", MAT_C_DOUBLE, MAT_T_DOUBLE, {3, 2}, other.data()}});
    awcc::ReaderOptions o;
    o.variables = {"lead", "trail"};
    auto r = awcc::open_recording(p, o);
    EXPECT_EQ(r->info().channels, 2);
    EXPECT_EQ(r->info().frames, static_cast<std::int64_t>(n));
    EXPECT_NEAR(r->info().fs, fs, 1e-6 * fs);
    EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"lead", "trail"}));
    const auto v = read_all(*r, 33);
    ASSERT_EQ(v.size(), 2 * n);
    for (std::size_t i = 0; i < n; i += 97) {
      EXPECT_EQ(v[2 * i], static_cast<float>(lead[i]));
      EXPECT_EQ(v[2 * i + 1], static_cast<float>(trail_d[i]));
    }
    o.variables = {"trail", "lead"};  // the order named is the channels' order
    auto swapped = awcc::open_recording(p, o);
    const auto w = read_all(*swapped, 1000);
    EXPECT_EQ(w[1], v[0]);
    EXPECT_EQ(w[0], v[1]);
    // A stated rate must agree with the time vector's.
    awcc::ReaderOptions stated = o;
    stated.fs = 20000.0;
    std::string quantity;
    EXPECT_NE(refusal(p, stated, &quantity).find("time variable 't'"), std::string::npos);
    EXPECT_EQ(quantity, "override-fs");
    stated.override_fs = true;
    EXPECT_DOUBLE_EQ(awcc::open_recording(p, stated)->info().fs, 20000.0);
  }
}

TEST(MatFile, AnUnevenOrDecreasingTimeVectorIsRefused) {
  const std::size_t n = 200;
  std::vector<double> x(2 * n, 0.25), t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) * 1e-4;
  t[1] = 0.8e-4;  // the first step 20 % short of the mean
  const auto p = scratch("uneven.mat");
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()}, {"time", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, n}, t.data()}});
  std::string quantity;
  EXPECT_NE(refusal(p, {}, &quantity).find("not evenly spaced"), std::string::npos);
  EXPECT_EQ(quantity, "fs");
  t[1] = 1e-4;
  t[150] = t[149];  // a repeated time
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_ZLIB,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()}, {"time", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, n}, t.data()}});
  EXPECT_NE(refusal(p).find("value 151"), std::string::npos) << refusal(p);
  // A time vector of another length is not the channels' time.
  std::vector<double> short_t(t.begin(), t.begin() + 10);
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()},
             {"t", MAT_C_DOUBLE, MAT_T_DOUBLE, {10, 1}, short_t.data()}});
  EXPECT_NE(refusal(p).find("not a time vector of the channels' 200 samples"), std::string::npos) << refusal(p);
  awcc::ReaderOptions stated;
  stated.fs = 10000.0;
  auto r = awcc::open_recording(p, stated);
  EXPECT_DOUBLE_EQ(r->info().fs, 10000.0);
  EXPECT_EQ(r->info().warnings.size(), 1u);
}

TEST(MatFile, RateVariablesIntervalsAndTheStatedRate) {
  const std::size_t n = 100;
  std::vector<double> x(2 * n, 1.5);
  double dt = 1e-5, fs = 100000.0, wrong = 50000.0;
  const auto p = scratch("rate.mat");
  write_mat(p, MAT_FT_MAT73, MAT_COMPRESSION_NONE,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()}, {"dt", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &dt}});
  EXPECT_DOUBLE_EQ(awcc::open_recording(p, {})->info().fs, 100000.0);
  awcc::ReaderOptions stated;
  stated.fs = 20000.0;
  std::string quantity;
  EXPECT_NE(refusal(p, stated, &quantity).find("'dt'"), std::string::npos);
  EXPECT_EQ(quantity, "override-fs");
  // Two rate variables must agree.
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()},
             {"sampling_rate", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs},
             {"Ts", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &dt}});
  EXPECT_DOUBLE_EQ(awcc::open_recording(p, {})->info().fs, 100000.0);
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()},
             {"sampling_rate", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs},
             {"FS", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &wrong}});
  const auto msg = refusal(p);
  EXPECT_NE(msg.find("'FS'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'sampling_rate'"), std::string::npos) << msg;
  // No rate anywhere: refused until stated.
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_ZLIB, {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()}});
  EXPECT_NE(refusal(p, {}, &quantity).find("records no sampling rate"), std::string::npos);
  EXPECT_EQ(quantity, "fs");
  EXPECT_DOUBLE_EQ(awcc::open_recording(p, stated)->info().fs, 20000.0);
}

TEST(MatFile, Int16CountsWithAndWithoutVoltsPerCount) {
  const std::size_t n = 64;
  std::vector<std::int16_t> x(2 * n);
  for (std::size_t i = 0; i < 2 * n; ++i) x[i] = static_cast<std::int16_t>(static_cast<int>(i) * 500 - 32000);
  double fs = 20000.0;
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + ".mat");
    write_mat(p, f.version, f.compression,
              {{"counts", MAT_C_INT16, MAT_T_INT16, {n, 2}, x.data()}, {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    awcc::ReaderOptions o;
    o.volts_per_count = 5.0 / 32768.0;
    auto r = awcc::open_recording(p, o);
    EXPECT_TRUE(r->has_int16());
    EXPECT_TRUE(r->info().volts_known);
    EXPECT_DOUBLE_EQ(r->info().quantum, 5.0 / 32768.0);
    std::vector<std::int16_t> raw(2 * n);
    ASSERT_EQ(r->read_int16(raw, static_cast<std::int64_t>(n)), static_cast<std::int64_t>(n));
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(raw[2 * i], x[i]);
      ASSERT_EQ(raw[2 * i + 1], x[n + i]);
    }
    r->rewind();
    const auto volts = read_all(*r, 5);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(volts[2 * i + 1], static_cast<float>(x[n + i] * (5.0 / 32768.0)));
    auto counts = awcc::open_recording(p, {});
    EXPECT_FALSE(counts->info().volts_known);
    EXPECT_DOUBLE_EQ(counts->info().quantum, 1.0);
    EXPECT_FALSE(counts->info().warnings.empty());
    EXPECT_EQ(read_all(*counts, 64)[3], static_cast<float>(x[n + 1]));
  }
}

TEST(MatFile, ZeroOneSignalsBinariseToTheAirIntervalsTheyEncode) {
  // Logical, uint8 and int16 0/1 (1 = air), unscaled: the two levels are
  // the phase signal itself, not a voltage to threshold.
  const std::size_t n = 4000;
  std::vector<std::uint8_t> dense(n);
  std::mt19937 rng(7);
  bool air = false;
  for (std::size_t i = 0; i < n;) {
    const auto run = std::uniform_int_distribution<std::size_t>(3, air ? 30 : 120)(rng);
    for (std::size_t k = 0; k < run && i < n; ++k, ++i) dense[i] = air ? 1 : 0;
    air = !air;
  }
  std::vector<std::uint8_t> bytes(2 * n);
  std::vector<std::int16_t> shorts(2 * n);
  // The trailing tip: the same bubbles 5 samples later (one signal twice
  // would be a copied channel, refused).
  std::vector<std::uint8_t> later(n, 0);
  for (std::size_t i = 5; i < n; ++i) later[i] = dense[i - 5];
  for (std::size_t i = 0; i < n; ++i) {
    bytes[i] = dense[i];
    bytes[n + i] = later[i];
    shorts[i] = dense[i];
    shorts[n + i] = later[i];
  }
  double fs = 20000.0;
  struct Case {
    const char* name;
    matio_classes cls;
    matio_types type;
    void* data;
    int flags;
  };
  for (const Case& c : {Case{"logical", MAT_C_UINT8, MAT_T_UINT8, bytes.data(), MAT_F_LOGICAL},
                        Case{"uint8", MAT_C_UINT8, MAT_T_UINT8, bytes.data(), 0},
                        Case{"int16", MAT_C_INT16, MAT_T_INT16, shorts.data(), 0}}) {
    SCOPED_TRACE(c.name);
    const auto p = scratch(std::string(c.name) + ".mat");
    write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_ZLIB,
              {{"phase", c.cls, c.type, {n, 2}, c.data, c.flags}, {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    awcc::ProcessOptions o;
    const auto b = awcc::binarise_recording(p, o);
    EXPECT_TRUE(b.leading_threshold.binary_input);
    EXPECT_EQ(awcc::to_dense(b.leading), dense);
    EXPECT_EQ(awcc::to_dense(b.trailing), later);
  }
}

TEST(MatFile, AFileWrittenFromTheSpecificationIsRead) {
  // What MATLAB writes for whole-number doubles: x = [0 1 2 ...; 250 249
  // ...]' stored as miUINT8, y = [0 100 200 ...; 0 -7 -14 ...]' as miINT16,
  // fs = 20000 as miUINT16 in a small data element, the names in small
  // elements too; little- and big-endian, plain and compressed.
  const int n = 250;
  std::vector<std::uint8_t> x8;
  std::vector<std::int16_t> y16;
  for (int i = 0; i < n; ++i) x8.push_back(static_cast<std::uint8_t>(i));
  for (int i = 0; i < n; ++i) x8.push_back(static_cast<std::uint8_t>(250 - i));
  for (int i = 0; i < n; ++i) y16.push_back(static_cast<std::int16_t>(100 * i));
  for (int i = 0; i < n; ++i) y16.push_back(static_cast<std::int16_t>(-7 * i));
  for (bool big : {false, true}) {
    for (bool zipped : {false, true}) {
      SCOPED_TRACE(fmt::format("{}-endian, {}", big ? "big" : "little", zipped ? "compressed" : "plain"));
      // MATLAB 7 compresses by default: each miMATRIX inside an miCOMPRESSED element.
      auto wrap = [&](std::vector<unsigned char> m) { return zipped ? compressed(big, m) : m; };
      Bytes file{big, header(big)};
      file.add(wrap(matrix(big, "x", mxDOUBLE, {n, 2}, miUINT8, x8)));
      file.add(wrap(matrix(big, "y", mxDOUBLE, {n, 2}, miINT16, values<std::int16_t>(big, y16))));
      file.add(wrap(matrix(big, "fs", mxDOUBLE, {1, 1}, miUINT16, values<std::uint16_t>(big, {20000}))));
      const auto p = scratch(fmt::format("spec-{}{}.mat", big ? "be" : "le", zipped ? "-z" : ""));
      write(p, file.b);
      awcc::ReaderOptions o;
      o.variables = {"x"};
      auto r = awcc::open_recording(p, o);
      EXPECT_DOUBLE_EQ(r->info().fs, 20000.0);
      ASSERT_EQ(r->info().frames, n);
      const auto v = read_all(*r, 17);
      o.variables = {"y"};
      const auto w = read_all(*awcc::open_recording(p, o), 17);
      ASSERT_EQ(w.size(), v.size());
      for (int i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(2 * i);
        ASSERT_EQ(v[k], static_cast<float>(i)) << i;
        ASSERT_EQ(v[k + 1], static_cast<float>(250 - i)) << i;
        ASSERT_EQ(w[k], static_cast<float>(100 * i)) << i;
        ASSERT_EQ(w[k + 1], static_cast<float>(-7 * i)) << i;
      }
    }
  }
}

TEST(MatFile, AmbiguousOrEmptyFilesAreRefusedListingTheVariables) {
  std::vector<double> a(600, 0.5), b(40, 0.5), v(300, 0.1);
  const auto p = scratch("ambiguous.mat");
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE,
            {{"a", MAT_C_DOUBLE, MAT_T_DOUBLE, {300, 2}, a.data()},
             {"b", MAT_C_DOUBLE, MAT_T_DOUBLE, {20, 2}, b.data()}});
  std::string quantity;
  auto msg = refusal(p, {}, &quantity);
  EXPECT_NE(msg.find("more than one"), std::string::npos) << msg;
  EXPECT_NE(msg.find("a (300x2 double)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("b (20x2 double)"), std::string::npos) << msg;
  EXPECT_EQ(quantity, "variable");
  awcc::ReaderOptions o;
  o.variables = {"b"};
  EXPECT_EQ(awcc::open_recording(p, [&] { auto q = o; q.fs = 1e4; return q; }())->info().frames, 20);
  o.variables = {"c"};
  msg = refusal(p, o);
  EXPECT_NE(msg.find("no variable 'c'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("a (300x2 double)"), std::string::npos) << msg;
  // Only vectors: no matrix to take.
  write_mat(p, MAT_FT_MAT73, MAT_COMPRESSION_NONE,
            {{"u", MAT_C_DOUBLE, MAT_T_DOUBLE, {300, 1}, v.data()}, {"w", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 300}, v.data()}});
  msg = refusal(p);
  EXPECT_NE(msg.find("no numeric matrix"), std::string::npos) << msg;
  EXPECT_NE(msg.find("u (300x1 double)"), std::string::npos) << msg;
  // Vectors of different lengths.
  o.variables = {"u", "w"};
  write_mat(p, MAT_FT_MAT5, MAT_COMPRESSION_NONE,
            {{"u", MAT_C_DOUBLE, MAT_T_DOUBLE, {300, 1}, v.data()}, {"w", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 299}, v.data()}});
  msg = refusal(p, o);
  EXPECT_NE(msg.find("'u' and 'w' hold 300 and 299 values"), std::string::npos) << msg;
  // No variables at all, in both versions.
  for (const auto& f : kFlavours) {
    write_mat(p, f.version, f.compression, {});
    msg = refusal(p, {}, &quantity);
    EXPECT_NE(msg.find("holds no variables"), std::string::npos) << f.name << ": " << msg;
  }
}

TEST(MatFile, NonNumericVariablesAreRefusedNamingTheirClass) {
  char text[] = "hello";
  std::vector<double> re(200, 1.0), im(200, 2.0);
  mat_complex_split_t z{re.data(), im.data()};
  double one = 1.0;
  std::size_t d11[2] = {1, 1};
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + ".mat");
    fs::remove(p);
    mat_t* m = Mat_CreateVer(p.c_str(), nullptr, f.version);
    ASSERT_NE(m, nullptr);
    std::size_t dc[2] = {1, 5}, dz[2] = {100, 2};
    matvar_t* c = Mat_VarCreate("label", MAT_C_CHAR, MAT_T_UINT8, 2, dc, text, MAT_F_DONT_COPY_DATA);
    Mat_VarWrite(m, c, f.compression);
    Mat_VarFree(c);
    matvar_t* cx = Mat_VarCreate("zeta", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dz, &z, MAT_F_COMPLEX | MAT_F_DONT_COPY_DATA);
    Mat_VarWrite(m, cx, f.compression);
    Mat_VarFree(cx);
    matvar_t* cells[1] = {Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d11, &one, 0)};
    matvar_t* cell = Mat_VarCreate("box", MAT_C_CELL, MAT_T_CELL, 2, d11, cells, 0);
    Mat_VarWrite(m, cell, f.compression);
    Mat_VarFree(cell);
    Mat_Close(m);
    for (const auto& [name, what] : {std::pair{"label", "char"}, std::pair{"zeta", "complex double"},
                                     std::pair{"box", "cell"}}) {
      awcc::ReaderOptions o;
      o.variables = {name};
      std::string quantity;
      const auto msg = refusal(p, o, &quantity);
      EXPECT_NE(msg.find(std::string("variable '") + name + "' is a"), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
      EXPECT_EQ(quantity, "variable");
    }
    // Without names, nothing numeric to take: the listing says so.
    const auto msg = refusal(p);
    EXPECT_NE(msg.find("no numeric matrix"), std::string::npos) << msg;
    EXPECT_NE(msg.find("zeta (100x2 complex double)"), std::string::npos) << msg;
  }
}

TEST(MatFile, FilesFoundByTheirHeaderAndOldOrForeignFilesRefused) {
  std::vector<double> x(40, 2.0);
  double fs = 10000.0;
  // A v7.3 file is an HDF5 file: its MATLAB header must win, whatever its name.
  const auto p = scratch("rec.bin73");
  write_mat(p, MAT_FT_MAT73, MAT_COMPRESSION_NONE,
            {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {20, 2}, x.data()}, {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
  EXPECT_EQ(awcc::open_recording(p, {})->info().format, "mat");
  // A v4 MAT-file: five int32 (type 0000 = little-endian double, 2 rows, 1
  // column, real, name length 2), the name and the values.
  Bytes v4;
  v4.put<std::int32_t>(0).put<std::int32_t>(2).put<std::int32_t>(1).put<std::int32_t>(0).put<std::int32_t>(2);
  v4.b.push_back('x');
  v4.b.push_back(0);
  v4.put<double>(1.0).put<double>(2.0);
  const auto p4 = scratch("old.mat");
  write(p4, v4.b);
  EXPECT_NE(refusal(p4).find("v4 MAT-file"), std::string::npos) << refusal(p4);
  const auto text = scratch("notes.mat");
  write(text, std::vector<unsigned char>{'h', 'e', 'l', 'l', 'o', '\n'});
  std::string quantity;
  EXPECT_NE(refusal(text, {}, &quantity).find("not a MAT-file"), std::string::npos);
  EXPECT_EQ(quantity, "format");
}

TEST(MatFile, HostileFilesAreRefusedQuietly) {
  std::vector<double> x(2 * 300);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(static_cast<double>(i));
  double fs = 20000.0;
  std::vector<fs::path> hostile;
  for (const auto& f : kFlavours) {
    const auto whole = scratch(std::string(f.name) + ".mat");
    write_mat(whole, f.version, f.compression,
              {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {300, 2}, x.data()}, {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    const auto bytes = slurp(whole);
    ASSERT_GT(bytes.size(), 1000u);
    // Cut short: in the middle of x's values, and just after the header.
    for (std::size_t keep : {bytes.size() / 2, bytes.size() - 3, std::size_t{140}}) {
      auto cut = bytes;
      cut.resize(keep);
      hostile.push_back(scratch(fmt::format("{}-cut{}.mat", f.name, keep)));
      write(hostile.back(), cut);
    }
    // Random bytes after a valid header.
    std::mt19937 rng(11);
    auto noise = bytes;
    for (std::size_t i = 128; i < noise.size(); ++i) noise[i] = static_cast<unsigned char>(rng());
    hostile.push_back(scratch(std::string(f.name) + "-noise.mat"));
    write(hostile.back(), noise);
    // Single bytes inverted, one file each: a stride through the first
    // variable's header (v5), or through the HDF5 part behind the 512-byte
    // MATLAB block (v7.3). Every single-byte inversion of these three files
    // was tried once outside the suite, without a crash or a printed word.
    const bool v73 = f.version == MAT_FT_MAT73;
    for (std::size_t at = v73 ? 512 : 128; at < (v73 ? bytes.size() : 200); at += v73 ? 97 : 9) {
      auto flipped = bytes;
      flipped[at] ^= 0xFF;
      hostile.push_back(scratch(fmt::format("{}-flip{}.mat", f.name, at)));
      write(hostile.back(), flipped);
    }
  }
  // Dimensions far beyond the file: 10^9 x 2 doubles in 16 bytes, plain and
  // compressed; and data that claim more bytes than the element holds.
  const std::vector<unsigned char> four = values<double>(false, {1.0, 2.0});
  Bytes big_dims{false, header(false)};
  big_dims.add(matrix(false, "x", mxDOUBLE, {1000000000, 2}, miDOUBLE, four));
  hostile.push_back(scratch("dims.mat"));
  write(hostile.back(), big_dims.b);
  Bytes big_z{false, header(false)};
  big_z.add(compressed(false, matrix(false, "x", mxDOUBLE, {1000000000, 2}, miDOUBLE, four)));
  hostile.push_back(scratch("dims-z.mat"));
  write(hostile.back(), big_z.b);
  Bytes overlong{false, header(false)};
  auto m = matrix(false, "x", mxDOUBLE, {2, 1}, miDOUBLE, four);
  const std::uint32_t claim = 1u << 30;  // the real part's size
  std::memcpy(m.data() + m.size() - 16 - 4, &claim, 4);
  overlong.add(m);
  hostile.push_back(scratch("overlong.mat"));
  write(hostile.back(), overlong.b);
  // A compressed element whose zlib stream is damaged inside x's values.
  Bytes damaged{false, header(false)};
  std::vector<double> ramp(4000);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = std::sin(0.37 * static_cast<double>(i));
  damaged.add(compressed(false, matrix(false, "x", mxDOUBLE, {2000, 2}, miDOUBLE, values<double>(false, ramp))));
  damaged.b[damaged.b.size() - 600] ^= 0xFF;
  damaged.add(matrix(false, "fs", mxDOUBLE, {1, 1}, miDOUBLE, values<double>(false, {20000.0})));
  hostile.push_back(scratch("zdamaged.mat"));
  write(hostile.back(), damaged.b);
  for (const auto& p : hostile) {
    SCOPED_TRACE(p.filename().string());
    testing::internal::CaptureStderr();
    testing::internal::CaptureStdout();
    bool refused = false;
    try {
      auto r = awcc::open_recording(p, {});
      (void)read_all(*r, 64);
      // A flipped byte may leave a readable file (a changed value or name);
      // it must then still hold what it claims.
      EXPECT_EQ(r->info().channels, 2);
    } catch (const awcc::InputError& e) {
      refused = true;
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
    const auto err = testing::internal::GetCapturedStderr();
    const auto out = testing::internal::GetCapturedStdout();
    EXPECT_EQ(err, "");
    EXPECT_EQ(out, "");
    const auto name = p.filename().string();
    if (name.find("flip") == std::string::npos) {
      EXPECT_TRUE(refused);
    }
  }
}

TEST(MatFile, ReadersOnSeveralThreadsShareTheLibrariesSafely) {
  // Readers on several threads at once, in every version, each read what a
  // lone reader reads. matio keeps global state (its log) and libhdf5 is
  // thread-safe only when built so: the reader serialises its calls on
  // detail::hdf5_library_mutex(), and its deleters must not take the lock
  // twice (a deadlock would hang here).
  const std::size_t n = 20000;
  std::vector<double> x(2 * n);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i % 977);
  double fs = 20000.0;
  std::vector<fs::path> files;
  for (const auto& f : kFlavours) {
    files.push_back(scratch(std::string(f.name) + ".mat"));
    write_mat(files.back(), f.version, f.compression,
              {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, 2}, x.data()}, {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
  }
  double expected = 0.0;
  for (double v : x) expected += v;
  // Mostly v7.3 readers, in small blocks: many HDF5 calls side by side.
  std::vector<double> sums(8, 0.0);
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < sums.size(); ++k) {
    threads.emplace_back([&, k] {
      const auto& file = k < 2 ? files[k] : files[2];
      for (int round = 0; round < 10; ++round) {
        auto r = awcc::open_recording(file, {});
        double s = 0.0;
        for (float v : read_all(*r, 97)) s += v;
        sums[k] = s;
      }
    });
  }
  for (auto& t : threads) t.join();
  for (double s : sums) EXPECT_DOUBLE_EQ(s, expected);
}

TEST(MatFile, ARecordingIsProcessedEndToEnd) {
  // Two single-precision channels at 20 kHz in volts, the trailing one the
  // leading one 5 samples later, saved as MATLAB 7 saves by default
  // (compressed): FSCC finds the planted delay.
  const int n = 20'000, delay = 5;
  std::vector<float> level(static_cast<std::size_t>(n + delay));
  std::uint32_t state = 12345;
  bool air = false;
  int left = 0;
  for (auto& v : level) {
    if (left-- <= 0) {
      state = state * 1664525u + 1013904223u;
      air = !air;
      left = 3 + static_cast<int>((state >> 16) % (air ? 20u : 120u));
    }
    v = air ? 0.3f : 4.1f;
  }
  std::vector<float> x(2 * static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    x[static_cast<std::size_t>(i)] = level[static_cast<std::size_t>(i + delay)];
    x[static_cast<std::size_t>(n + i)] = level[static_cast<std::size_t>(i)];
  }
  double fs = 20000.0;
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + ".mat");
    write_mat(p, f.version, f.compression,
              {{"probe", MAT_C_SINGLE, MAT_T_SINGLE, {static_cast<std::size_t>(n), 2}, x.data()},
               {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    awcc::ProcessOptions o;
    o.dx = 5e-3;
    o.awcc = false;
    const auto r = awcc::process_recording(p, o);
    ASSERT_TRUE(r.fscc && r.fscc->ok()) << r.fscc->message;
    EXPECT_EQ(r.fscc->lag_samples, delay);
    EXPECT_EQ(r.tips[0].name, "probe(:,1)");
  }
}

}  // namespace

// A four-tip probe's recording: every column is a channel, in every version.
TEST(MatFile, AFourColumnMatrixDeliversAllFourChannels) {
  const std::size_t n = 257, channels = 4;
  std::vector<double> x(channels * n);  // column-major: one tip after another
  for (std::size_t c = 0; c < channels; ++c) {
    for (std::size_t i = 0; i < n; ++i) x[c * n + i] = static_cast<double>(c) + 0.001 * static_cast<double>(i);
  }
  double fs = 40000.0;
  for (const auto& f : kFlavours) {
    SCOPED_TRACE(f.name);
    const auto p = scratch(std::string(f.name) + "_four.mat");
    write_mat(p, f.version, f.compression,
              {{"x", MAT_C_DOUBLE, MAT_T_DOUBLE, {n, channels}, x.data()},
               {"fs", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 1}, &fs}});
    auto r = awcc::open_recording(p, {});
    ASSERT_EQ(r->info().channels, 4);
    EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"x(:,1)", "x(:,2)", "x(:,3)", "x(:,4)"}));
    const auto whole = read_all(*r, 50);
    ASSERT_EQ(whole.size(), channels * n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t c = 0; c < channels; ++c) ASSERT_EQ(whole[channels * i + c], static_cast<float>(x[c * n + i]));
    }
  }
}
