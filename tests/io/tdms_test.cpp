// The NI TDMS reader (awcc/recording.hpp) on files written here to NI's
// published format: several segments (a new object list, then raw data
// reusing the previous index, then a segment appending data only),
// interleaved float32 data, int16 with a linear scale, wf_increment as the
// rate, channels chosen by name, a truncated last segment, hostile bytes.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/process.hpp"
#include "awcc/recording.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;

// ctest runs each test in its own process, in parallel: several tests build the
// same file, so the name carries the test's own name to keep them apart.
fs::path scratch(const std::string& name) { return pdp_test::test_file(name); }

// A little-endian byte builder.
struct Bytes {
  std::vector<char> b;
  template <class T>
  Bytes& put(T v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
    return *this;
  }
  Bytes& str(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    b.insert(b.end(), s.begin(), s.end());
    return *this;
  }
  Bytes& add(const Bytes& o) {
    b.insert(b.end(), o.b.begin(), o.b.end());
    return *this;
  }
};

struct Property {
  std::string name;
  std::uint32_t type;  // 10 double, 0x20 string, 7 uint32
  double number = 0;
  std::string text;
};

struct Object {
  std::string path;
  std::uint32_t raw_index;  // 0xFFFFFFFF none, 0 same as before, 20 new
  std::uint32_t type = 0;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

Bytes metadata(const std::vector<Object>& objects) {
  Bytes m;
  m.put<std::uint32_t>(static_cast<std::uint32_t>(objects.size()));
  for (const auto& o : objects) {
    m.str(o.path).put<std::uint32_t>(o.raw_index);
    if (o.raw_index == 20) m.put<std::uint32_t>(o.type).put<std::uint32_t>(1).put<std::uint64_t>(o.count);
    m.put<std::uint32_t>(static_cast<std::uint32_t>(o.properties.size()));
    for (const auto& p : o.properties) {
      m.str(p.name).put<std::uint32_t>(p.type);
      if (p.type == 0x20) m.str(p.text);
      else if (p.type == 7) m.put<std::uint32_t>(static_cast<std::uint32_t>(p.number));
      else m.put<double>(p.number);
    }
  }
  return m;
}

// One segment: lead-in, metadata (when given) and raw data.
Bytes segment(std::uint32_t toc, const Bytes* meta, const Bytes& raw, bool unfinished = false) {
  Bytes s;
  const std::uint64_t meta_size = meta ? meta->b.size() : 0;
  s.b.insert(s.b.end(), {'T', 'D', 'S', 'm'});
  s.put<std::uint32_t>(toc).put<std::uint32_t>(4713);
  s.put<std::uint64_t>(unfinished ? ~std::uint64_t{0} : meta_size + raw.b.size()).put<std::uint64_t>(meta_size);
  if (meta) s.add(*meta);
  return s.add(raw);
}

constexpr std::uint32_t kMeta = 1u << 1, kNewList = 1u << 2, kRaw = 1u << 3, kInterleaved = 1u << 5;

void write(const fs::path& p, const Bytes& b) {
  std::ofstream out(p, std::ios::binary);
  out.write(b.b.data(), static_cast<std::streamsize>(b.b.size()));
}

std::vector<float> read_all(awcc::Recording& r) {
  std::vector<float> all, block(static_cast<std::size_t>(7 * r.info().channels));
  for (;;) {
    const auto n = r.read(block, 7);  // odd blocks across pieces
    if (n == 0) break;
    all.insert(all.end(), block.begin(), block.begin() + n * r.info().channels);
  }
  return all;
}

// Two int16 channels at 20 kHz with a linear scale 5/32768 V per count
// (+0.1 V on the second), in three segments: 4 values each with a new
// object list; raw data only, reusing that index, in two chunks; then the
// lead with a new index of 2 values and the trail reusing its 4.
fs::path three_segments(bool cut_last = false) {
  auto props = [](double intercept) {
    return std::vector<Property>{{"wf_increment", 10, 5e-5, ""},
                                 {"NI_Scaling_Status", 0x20, 0, "unscaled"},
                                 {"NI_Number_Of_Scales", 7, 1, ""},
                                 {"NI_Scale[1]_Scale_Type", 0x20, 0, "Linear"},
                                 {"NI_Scale[1]_Linear_Slope", 10, 5.0 / 32768.0, ""},
                                 {"NI_Scale[1]_Linear_Y_Intercept", 10, intercept, ""}};
  };
  Bytes file;
  const Bytes m1 = metadata({{"/", 0xFFFFFFFF, 0, 0, {}},
                             {"/'probe'", 0xFFFFFFFF, 0, 0, {}},
                             {"/'probe'/'lead'", 20, 2, 4, props(0.0)},
                             {"/'probe'/'trail'", 20, 2, 4, props(0.1)}});
  Bytes r1;
  for (int v : {100, 200, 300, 400}) r1.put(static_cast<std::int16_t>(v));
  for (int v : {-1, -2, -3, -4}) r1.put(static_cast<std::int16_t>(v));
  file.add(segment(kMeta | kNewList | kRaw, &m1, r1));
  Bytes r2;  // two chunks of 4 values per channel, the index of segment 1
  for (int chunk = 0; chunk < 2; ++chunk) {
    for (int i = 0; i < 4; ++i) r2.put(static_cast<std::int16_t>(500 + 10 * chunk + i));
    for (int i = 0; i < 4; ++i) r2.put(static_cast<std::int16_t>(-5 - 10 * chunk - i));
  }
  file.add(segment(kRaw, nullptr, r2));
  const Bytes m3 = metadata({{"/'probe'/'lead'", 20, 2, 2, {}}, {"/'probe'/'trail'", 0, 0, 0, {}}});
  Bytes r3;
  for (int v : {7, 8}) r3.put(static_cast<std::int16_t>(v));
  for (int v : {9, 10, 11, 12}) r3.put(static_cast<std::int16_t>(v));
  if (cut_last) {
    Bytes cut;
    cut.add(segment(kMeta | kRaw, &m3, r3, true));
    cut.b.resize(cut.b.size() - 3);
    file.add(cut);
  } else {
    file.add(segment(kMeta | kRaw, &m3, r3));
  }
  const auto p = scratch(cut_last ? "cut.tdms" : "three.tdms");
  write(p, file);
  return p;
}

TEST(TdmsReader, SegmentsIndexReuseAndLinearScales) {
  // lead: 4 + 8 + 2 = 14 values; trail: 4 + 8 + 4 = 16: read one at a time.
  const auto p = three_segments();
  awcc::ReaderOptions lead;
  lead.tdms_channels = {"lead"};
  auto r = awcc::open_recording(p, lead);
  EXPECT_EQ(r->info().format, "tdms");
  EXPECT_EQ(r->info().channels, 1);
  EXPECT_DOUBLE_EQ(r->info().fs, 20000.0);
  EXPECT_TRUE(r->info().volts_known);
  EXPECT_EQ(r->info().channel_names, (std::vector<std::string>{"probe/lead"}));
  EXPECT_EQ(r->info().frames, 14);
}

TEST(TdmsReader, ChannelsOfDifferentLengthsAreRefusedAndNamedChannelsRead) {
  const auto p = three_segments();
  EXPECT_THROW(
      {
        auto r = awcc::open_recording(p, {});
        (void)r;
      },
      awcc::InputError);
  awcc::ReaderOptions o;
  o.tdms_channels = {"lead"};
  auto r = awcc::open_recording(p, o);
  ASSERT_EQ(r->info().frames, 14);
  const auto v = read_all(*r);
  const std::vector<double> counts{100, 200, 300, 400, 500, 501, 502, 503, 510, 511, 512, 513, 7, 8};
  ASSERT_EQ(v.size(), counts.size());
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_FLOAT_EQ(v[i], static_cast<float>(counts[i] * 5.0 / 32768.0)) << i;
  o.tdms_channels = {"probe/trail"};
  auto t = awcc::open_recording(p, o);
  const auto w = read_all(*t);
  ASSERT_EQ(w.size(), 16u);
  EXPECT_FLOAT_EQ(w[0], static_cast<float>(-1 * 5.0 / 32768.0 + 0.1));
  EXPECT_FLOAT_EQ(w[15], static_cast<float>(12 * 5.0 / 32768.0 + 0.1));
  o.tdms_channels = {"nothere"};
  try {
    (void)awcc::open_recording(p, o);
    FAIL() << "an unknown channel was accepted";
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("probe/lead"), std::string::npos) << e.what();  // names what there is
  }
}

TEST(TdmsReader, InterleavedFloatChannelsAndTheStatedRate) {
  Bytes file;
  const Bytes m = metadata({{"/'g'/'a'", 20, 9, 5, {{"wf_increment", 10, 1e-4, ""}}},
                            {"/'g'/'b'", 20, 9, 5, {{"wf_increment", 10, 1e-4, ""}}}});
  Bytes raw;
  for (int i = 0; i < 5; ++i) raw.put(static_cast<float>(i)).put(static_cast<float>(10 + i));
  file.add(segment(kMeta | kNewList | kRaw | kInterleaved, &m, raw));
  const auto p = scratch("interleaved.tdms");
  write(p, file);
  auto r = awcc::open_recording(p, {});
  EXPECT_DOUBLE_EQ(r->info().fs, 10000.0);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 10u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(v[static_cast<std::size_t>(2 * i)], static_cast<float>(i));
    EXPECT_EQ(v[static_cast<std::size_t>(2 * i + 1)], static_cast<float>(10 + i));
  }
  r->rewind();
  EXPECT_EQ(read_all(*r), v);
  awcc::ReaderOptions stated;
  stated.fs = 20e3;
  EXPECT_THROW((void)awcc::open_recording(p, stated), awcc::InputError);  // contradicts wf_increment
}

// Found by fuzz_read_tdms: a denormal wf_increment gave an infinite rate,
// which the reader handed on as the recording's.
TEST(TdmsReader, AnIncrementGivingNoFiniteRateIsRefusedNamingIt) {
  Bytes file;
  const Bytes m = metadata({{"/'g'/'a'", 20, 9, 5, {{"wf_increment", 10, 1e-320, ""}}},
                            {"/'g'/'b'", 20, 9, 5, {{"wf_increment", 10, 1e-320, ""}}}});
  Bytes raw;
  for (int i = 0; i < 5; ++i) raw.put(static_cast<float>(i)).put(static_cast<float>(10 + i));
  file.add(segment(kMeta | kNewList | kRaw | kInterleaved, &m, raw));
  const auto p = scratch("denormal-increment.tdms");
  write(p, file);
  try {
    (void)awcc::open_recording(p, {});
    ADD_FAILURE() << "an infinite sampling rate was accepted";
  } catch (const awcc::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(p.string() + ": its wf_increment gives a sampling rate of inf Hz", 0), 0u) << what;
  }
  awcc::ReaderOptions forced;
  forced.fs = 20e3;
  forced.override_fs = true;
  EXPECT_DOUBLE_EQ(awcc::open_recording(p, forced)->info().fs, 20e3);
}

TEST(TdmsReader, ATruncatedLastSegmentIsNamedAndReadOnlyWhenAllowed) {
  const auto p = three_segments(true);
  awcc::ReaderOptions o;
  o.tdms_channels = {"lead"};
  try {
    (void)awcc::open_recording(p, o);
    FAIL() << "a truncated file was accepted";
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    EXPECT_EQ(e.quantity(), "allow-truncated");
  }
  o.allow_truncated = true;
  auto r = awcc::open_recording(p, o);
  EXPECT_EQ(r->info().frames, 12);  // the cut segment has no whole chunk
  EXPECT_FALSE(r->info().warnings.empty());
}

TEST(TdmsReader, ARecordingIsProcessedEndToEnd) {
  // Two float32 channels at 20 kHz in volts, the trailing one the leading
  // one 5 samples later: FSCC finds the planted delay.
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
  Bytes raw;
  for (int i = 0; i < n; ++i) raw.put(level[static_cast<std::size_t>(i + delay)]).put(level[static_cast<std::size_t>(i)]);
  const Bytes m = metadata({{"/'probe'/'lead'", 20, 9, static_cast<std::uint64_t>(n), {{"wf_increment", 10, 5e-5, ""}}},
                            {"/'probe'/'trail'", 20, 9, static_cast<std::uint64_t>(n), {{"wf_increment", 10, 5e-5, ""}}}});
  Bytes file;
  file.add(segment(kMeta | kNewList | kRaw | kInterleaved, &m, raw));
  const auto p = scratch("probe.tdms");
  write(p, file);
  awcc::ProcessOptions o;
  o.dx = 5e-3;
  o.awcc = false;
  const auto r = awcc::process_recording(p, o);
  ASSERT_TRUE(r.fscc && r.fscc->ok()) << r.fscc->message;
  EXPECT_EQ(r.fscc->lag_samples, delay);
  EXPECT_EQ(r.tips[0].name, "probe/lead");
}

// Found by fuzz_read_tdms: NI_Number_Of_Scales is the file's word, and was the
// loop bound. A count of 2^32 - 1 did not fit the int it was cast to (the
// scale was silently dropped: counts read as volts); one of 2^31 - 1 looped
// two billion times (minutes per file). Only the scales the file describes are
// applied, whatever count it states.
TEST(TdmsReader, AScaleCountBeyondTheScalesDescribedAppliesTheScalesThereAre) {
  for (const double count : {4294967295.0, 2147483647.0}) {
    const Bytes m = metadata({{"/'probe'/'lead'", 20, 2, 3,
                               {{"wf_increment", 10, 1e-4, ""},
                                {"NI_Scaling_Status", 0x20, 0, "unscaled"},
                                {"NI_Number_Of_Scales", 7, count, ""},
                                {"NI_Scale[1]_Scale_Type", 0x20, 0, "Linear"},
                                {"NI_Scale[1]_Linear_Slope", 10, 0.5, ""},
                                {"NI_Scale[1]_Linear_Y_Intercept", 10, 1.0, ""}}}});
    Bytes raw;
    for (int v : {10, 20, -30}) raw.put(static_cast<std::int16_t>(v));
    const auto p = scratch("many-scales.tdms");
    write(p, segment(kMeta | kNewList | kRaw, &m, raw));
    const auto start = std::chrono::steady_clock::now();
    auto r = awcc::open_recording(p, {});
    // A few milliseconds; two billion scale look-ups took minutes.
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0) << count;
    EXPECT_TRUE(r->info().volts_known) << count;
    EXPECT_EQ(read_all(*r), (std::vector<float>{6.0f, 11.0f, -14.0f})) << count;
  }
}

// A linear scale that takes a count beyond a float (slope 1e300): read()
// handed out infinite volts without a word (the finite check was on the
// double). Found by the reader fuzz target's check that every sample read is
// finite (fuzz_read_tdms); the sample is named, with its value.
TEST(TdmsReader, AScaleThatTakesASampleBeyondAFloatIsRefusedNamingIt) {
  const Bytes m = metadata({{"/'probe'/'lead'", 20, 2, 3,
                             {{"wf_increment", 10, 1e-4, ""},
                              {"NI_Scaling_Status", 0x20, 0, "unscaled"},
                              {"NI_Number_Of_Scales", 7, 1, ""},
                              {"NI_Scale[1]_Scale_Type", 0x20, 0, "Linear"},
                              {"NI_Scale[1]_Linear_Slope", 10, 1e300, ""}}}});
  Bytes raw;
  for (int v : {0, 1000, 2}) raw.put(static_cast<std::int16_t>(v));
  const auto p = scratch("huge-slope.tdms");
  write(p, segment(kMeta | kNewList | kRaw, &m, raw));
  auto r = awcc::open_recording(p, {});
  try {
    (void)read_all(*r);
    ADD_FAILURE() << "a sample of 1e303 V was read";
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sample 1 of channel 'probe/lead' is 1e+303 V, beyond a sample's range"),
              std::string::npos)
        << e.what();
  }
}

TEST(TdmsReader, HostileBytesAreRefusedWithAMessage) {
  Bytes bad;
  bad.b.insert(bad.b.end(), {'T', 'D', 'S', 'm'});
  bad.put<std::uint32_t>(kMeta | kRaw).put<std::uint32_t>(4713).put<std::uint64_t>(40).put<std::uint64_t>(30);
  bad.put<std::uint32_t>(1000000);  // a million objects in 26 bytes
  bad.b.resize(bad.b.size() + 22, 0);
  const auto p = scratch("hostile.tdms");
  write(p, bad);
  EXPECT_THROW((void)awcc::open_recording(p, {}), awcc::InputError);
  Bytes empty_lead;
  empty_lead.b = {'T', 'D', 'S', 'm', 0, 0};
  write(p, empty_lead);
  EXPECT_THROW((void)awcc::open_recording(p, {}), awcc::InputError);
}

}  // namespace

// A four-tip probe's recording: four channels of one group, all delivered in order.
TEST(TdmsReader, FourChannelsOfAGroupAreAllDelivered) {
  Bytes file;
  const Bytes m = metadata({{"/'probe'/'tip0'", 20, 10, 6, {{"wf_increment", 10, 2.5e-5, ""}}},
                            {"/'probe'/'tip1'", 20, 10, 6, {{"wf_increment", 10, 2.5e-5, ""}}},
                            {"/'probe'/'tip2'", 20, 10, 6, {{"wf_increment", 10, 2.5e-5, ""}}},
                            {"/'probe'/'tip3'", 20, 10, 6, {{"wf_increment", 10, 2.5e-5, ""}}}});
  Bytes raw;
  for (int c = 0; c < 4; ++c) {
    for (int i = 0; i < 6; ++i) raw.put(static_cast<double>(c) + 0.125 * i);
  }
  file.add(segment(kMeta | kNewList | kRaw, &m, raw));
  const auto p = scratch("four_tips.tdms");
  write(p, file);
  auto r = awcc::open_recording(p, {});
  ASSERT_EQ(r->info().channels, 4);
  EXPECT_DOUBLE_EQ(r->info().fs, 40000.0);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 24u);
  for (int i = 0; i < 6; ++i) {
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(v[static_cast<std::size_t>(4 * i + c)], static_cast<float>(c + 0.125 * i)) << i << "," << c;
    }
  }
}
