#include "awcc/recording.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "awcc/errors.hpp"
#include "awcc/options.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sndfile.h>
#include <vector>

#include "test_paths.hpp"
#include "declared_quantity.hpp"

namespace {

namespace fs = std::filesystem;
using awcc::open_recording;
using awcc::ReaderOptions;

fs::path scratch(const std::string& name) { return pdp_test::temp_dir() / ("reader_" + name); }

template <class T>
void write_binary(const fs::path& p, const std::vector<T>& values, const std::vector<char>& header = {}) {
  std::ofstream f(p, std::ios::binary);
  f.write(header.data(), static_cast<std::streamsize>(header.size()));
  f.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(T)));
}

std::vector<char> dat_header(std::int32_t rows, std::int32_t channels) {
  std::vector<char> h(8);
  std::memcpy(h.data(), &rows, 4);
  std::memcpy(h.data() + 4, &channels, 4);
  return h;
}

std::vector<float> read_all(awcc::Recording& r, std::int64_t block = 7) {
  std::vector<float> all, buf(static_cast<std::size_t>(block * r.info().channels));
  for (;;) {
    const auto n = r.read(buf, block);
    if (n == 0) break;
    all.insert(all.end(), buf.begin(), buf.begin() + n * r.info().channels);
  }
  return all;
}

// The message, and "[quantity]" when the error names the setting that fixes
// it (the command line turns that into its flag).
std::string error_of(const fs::path& p, const ReaderOptions& o = {}) {
  try {
    auto r = open_recording(p, o);
    read_all(*r);
  } catch (const awcc::InputError& e) {
    // not_a_recording marks a file a folder run skips, not an option.
    if (e.quantity() != "not_a_recording") {
      EXPECT_TRUE(declared_reader_quantity(e.quantity())) << e.quantity();
    }
    return e.quantity().empty() ? std::string(e.what()) : std::string(e.what()) + " [" + e.quantity() + "]";
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return {};
}

TEST(UqDat, ReadsCountsAsVolts) {
  const std::vector<std::int16_t> counts{0, 100, -32768, 32767, 26214, 1966};
  const auto p = scratch("ok.dat");
  write_binary(p, counts, dat_header(3, 2));
  ReaderOptions o;
  o.fs = 20e3;
  auto r = open_recording(p, o);
  EXPECT_EQ(r->info().format, "dat");
  EXPECT_EQ(r->info().channels, 2);
  EXPECT_EQ(r->info().frames, 3);
  const auto v = read_all(*r, 2);
  ASSERT_EQ(v.size(), counts.size());
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_FLOAT_EQ(v[i], static_cast<float>(counts[i] * 5.0 / 32768.0));
  r->rewind();
  EXPECT_EQ(read_all(*r, 100), v);
}

TEST(UqDat, RefusesHeadersThatDoNotMatchTheData) {
  ReaderOptions o;
  o.fs = 20e3;
  const auto truncated = scratch("truncated.dat");
  write_binary(truncated, std::vector<std::int16_t>(10), dat_header(900000, 2));
  EXPECT_NE(error_of(truncated, o).find("truncated"), std::string::npos) << error_of(truncated, o);
  const auto lying = scratch("lying.dat");
  write_binary(lying, std::vector<std::int16_t>(100), dat_header(10, 2));
  EXPECT_NE(error_of(lying, o).find("does not describe the data"), std::string::npos) << error_of(lying, o);
  const auto garbage = scratch("garbage.dat");
  write_binary(garbage, std::vector<std::int16_t>(100), dat_header(-5, 2));
  EXPECT_NE(error_of(garbage, o).find("not a UQ .dat header"), std::string::npos);
  // No fs: a .dat file does not store it.
  const auto fine = scratch("no_fs.dat");
  write_binary(fine, std::vector<std::int16_t>(20), dat_header(10, 2));
  EXPECT_NE(error_of(fine, {}).find("sampling rate; state it (e.g. 20 kHz) [fs]"), std::string::npos) << error_of(fine, {});
}

TEST(Raw, ReadsEveryLayout) {
  ReaderOptions o;
  o.fs = 1000;
  o.format = "raw";
  o.raw.channels = 3;
  o.raw.header_bytes = 4;
  o.raw.volts_per_count = 0.5;
  {
    const auto p = scratch("i32be.raw");
    std::vector<char> bytes{'H', 'D', 'R', '!'};
    for (std::int32_t v : {1, -2, 3, 40000, 5, 6}) {
      for (int b = 3; b >= 0; --b) bytes.push_back(static_cast<char>((static_cast<std::uint32_t>(v) >> (8 * b)) & 0xff));
    }
    write_binary(p, bytes);
    o.raw.sample_type = awcc::SampleType::int32;
    o.raw.byte_order = awcc::ByteOrder::big;
    auto r = open_recording(p, o);
    const auto v = read_all(*r);
    const std::vector<float> expected{0.5f, -1.0f, 1.5f, 20000.0f, 2.5f, 3.0f};
    EXPECT_EQ(v, expected);
  }
  {
    const auto p = scratch("f64.raw");
    write_binary(p, std::vector<double>{0.25, 1.0, -3.5, 2.0, 4.0, 8.0}, {'x', 'x', 'x', 'x'});
    o.raw.sample_type = awcc::SampleType::float64;
    o.raw.byte_order = awcc::ByteOrder::little;
    auto r = open_recording(p, o);
    EXPECT_EQ(read_all(*r), (std::vector<float>{0.125f, 0.5f, -1.75f, 1.0f, 2.0f, 4.0f}));
  }
  {
    // A size that is not a whole number of frames is refused.
    const auto p = scratch("odd.raw");
    write_binary(p, std::vector<std::int16_t>(7), {'x', 'x', 'x', 'x'});
    o.raw.sample_type = awcc::SampleType::int16;
    EXPECT_NE(error_of(p, o).find("whole number"), std::string::npos);
  }
}

TEST(Raw, NaNAndInfinityAreRefusedWithTheirPosition) {
  ReaderOptions o;
  o.fs = 1000;
  o.format = "raw";
  o.raw.channels = 2;
  o.raw.sample_type = awcc::SampleType::float32;
  const auto p = scratch("nan.raw");
  write_binary(p, std::vector<float>{1, 2, 3, std::numeric_limits<float>::quiet_NaN(), 5, 6});
  const auto e = error_of(p, o);
  EXPECT_NE(e.find("NaN"), std::string::npos) << e;
  EXPECT_NE(e.find("frame 1"), std::string::npos) << e;
  write_binary(p, std::vector<float>{1, std::numeric_limits<float>::infinity()});
  EXPECT_NE(error_of(p, o).find("infinite"), std::string::npos);
}

TEST(Csv, HeaderTimeColumnAndSamplingRate) {
  const auto p = scratch("with_time.csv");
  {
    std::ofstream f(p);
    f << "time,lead,trail\n";
    for (int i = 0; i < 50; ++i) f << i * 1e-4 << "," << (i % 5 == 0 ? 0.2 : 4.0) << "," << 4.1 << "\n";
  }
  auto r = open_recording(p);
  EXPECT_EQ(r->info().format, "csv");
  EXPECT_EQ(r->info().channels, 2);
  EXPECT_NEAR(r->info().fs, 1e4, 1e-6);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 100u);
  EXPECT_FLOAT_EQ(v[0], 0.2f);
  EXPECT_FLOAT_EQ(v[2], 4.0f);
  EXPECT_FLOAT_EQ(v[3], 4.1f);
}

TEST(Csv, TabsWithoutHeaderNeedFs) {
  const auto p = scratch("plain.tsv");
  {
    std::ofstream f(p);
    f << "1.5\t2.5\n3\t4\n";
  }
  EXPECT_NE(error_of(p).find("[fs]"), std::string::npos) << error_of(p);
  ReaderOptions o;
  o.fs = 100;
  auto r = open_recording(p, o);
  EXPECT_EQ(read_all(*r), (std::vector<float>{1.5f, 2.5f, 3.f, 4.f}));
}

TEST(Csv, TextCellInADataRowIsRefusedWithItsLine) {
  const auto p = scratch("text.csv");
  {
    std::ofstream f(p);
    f << "a,b\n1,2\n3,oops\n";
  }
  ReaderOptions o;
  o.fs = 100;
  const auto e = error_of(p, o);
  EXPECT_NE(e.find("line 3, column 2"), std::string::npos) << e;
  EXPECT_NE(e.find("'oops'"), std::string::npos) << e;
}

TEST(Csv, AValueBeyondTheSampleRangeIsRefusedWithItsLine) {
  // Found by fuzz_recording: 1e113 parses, but as a 32-bit sample it is infinite.
  const auto p = scratch("huge.csv");
  {
    std::ofstream f(p);
    f << "time,lead,trail\n0,4.1,4.2\n0.0001,1e113,4.1\n0.0002,-3.5e38,0.2\n";
  }
  const auto e = error_of(p, {});
  EXPECT_NE(e.find("line 3, column 2"), std::string::npos) << e;
  EXPECT_NE(e.find("beyond the range of a sample"), std::string::npos) << e;
}

TEST(Sndfile, ReadsIntegerAudioAsCountsTimesScale) {
  const auto p = scratch("pcm.wav");
  SF_INFO info{};
  info.samplerate = 48000;
  info.channels = 2;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* f = sf_open(p.c_str(), SFM_WRITE, &info);
  ASSERT_NE(f, nullptr);
  const std::vector<short> counts{0, 1, -2, 32767, 26214, 1966};
  sf_writef_short(f, counts.data(), 3);
  sf_close(f);
  ReaderOptions o;
  o.volts_per_count = 5.0 / 32768.0;
  auto r = open_recording(p, o);
  EXPECT_EQ(r->info().fs, 48000);
  EXPECT_TRUE(r->info().volts_known);
  const auto v = read_all(*r);
  for (std::size_t i = 0; i < counts.size(); ++i) EXPECT_FLOAT_EQ(v[i], static_cast<float>(counts[i] * 5.0 / 32768.0));
  // Without a scale: counts / 32768, normalised units.
  auto n = open_recording(p);
  EXPECT_FALSE(n->info().volts_known);
  EXPECT_FLOAT_EQ(read_all(*n)[1], 1.0f / 32768.0f);
}

TEST(Sndfile, FloatAudioWithNaNIsRefused) {
  const auto p = scratch("nan.wav");
  SF_INFO info{};
  info.samplerate = 1000;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  SNDFILE* f = sf_open(p.c_str(), SFM_WRITE, &info);
  ASSERT_NE(f, nullptr);
  const std::vector<float> values{0.1f, std::numeric_limits<float>::quiet_NaN()};
  sf_writef_float(f, values.data(), 2);
  sf_close(f);
  EXPECT_NE(error_of(p).find("NaN"), std::string::npos) << error_of(p);
}

TEST(Detection, BadFilesGetClearMessages) {
  const auto empty = scratch("empty.wav");
  { std::ofstream f(empty); }
  EXPECT_NE(error_of(empty).find("empty"), std::string::npos);
  const auto text = scratch("notaudio.wav");
  {
    std::ofstream f(text);
    f << "this is not audio at all\n";
  }
  EXPECT_NE(error_of(text).find("not a readable audio file"), std::string::npos) << error_of(text);
  EXPECT_NE(error_of(scratch("missing.flac")).find("no such file"), std::string::npos);
  const auto unknown = scratch("blob.xyz");
  write_binary(unknown, std::vector<std::uint8_t>{0, 1, 2, 3, 200});
  EXPECT_NE(error_of(unknown).find("[format]"), std::string::npos) << error_of(unknown);
  // Library messages speak of quantities, never of command-line flags.
  const auto no_fs = scratch("detection_no_fs.dat");
  write_binary(no_fs, std::vector<std::int16_t>(20), dat_header(10, 2));
  for (const auto& f : {no_fs, unknown}) EXPECT_EQ(error_of(f).find("--"), std::string::npos) << error_of(f);
}

// The format registry: the names `format` takes, the option's choices and
// the message for an undetectable file come from one list.
TEST(Registry, TheFormatOptionTakesExactlyTheRegisteredNames) {
  const auto names = awcc::input_formats();
  ASSERT_EQ(names.size(), 7u);
  std::string listed = "auto";
  for (auto n : names) listed += " | " + std::string(n);
  const auto fields = awcc::reader_option_fields();
  const auto field = std::find_if(fields.begin(), fields.end(), [](const auto& f) { return f.name == "format"; });
  ASSERT_NE(field, fields.end());
  EXPECT_NE(field->help.find(listed), std::string_view::npos) << field->help;
  for (auto n : names) {
    ReaderOptions o;
    field->parse(o, n);
    EXPECT_EQ(o.format, n);
    EXPECT_EQ(field->format(o), n);
  }
  ReaderOptions o;
  try {
    field->parse(o, "wav");
    ADD_FAILURE() << "'wav' accepted as a format";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(listed), std::string::npos) << e.what();
  }
  // Through the library without the option parser: refused with the names.
  const auto p = scratch("registry_unknown.csv");
  std::ofstream(p) << "1,2\n3,4\n";
  o.format = "wav";
  const auto message = error_of(p, o);
  EXPECT_NE(message.find("'wav' is not a recording format; state one of auto, sndfile, dat, raw, csv, tdms, hdf5, mat"),
            std::string::npos) << message;
  EXPECT_NE(message.find("[format]"), std::string::npos) << message;
}

// Detection tries the formats by rank, each by extension or magic; a stated
// format wins over both, and RecordingInfo::format is the registry's name.
TEST(Registry, DetectionFollowsTheRanksAndAStatedFormatWins) {
  const std::string text = "0.1,4.0\n4.1,0.2\n0.3,4.2\n";
  ReaderOptions o;
  o.fs = 1000;
  for (const char* name : {"rows.txt", "rows.tsv", "rows.lvmx"}) {  // .lvmx: by its content (text)
    const auto p = scratch(name);
    std::ofstream(p, std::ios::binary) << text;
    EXPECT_EQ(open_recording(p, o)->info().format, "csv") << name;
  }
  // The same bytes named .bin are raw (rank 5 before text): two int16 channels of counts.
  const auto bin = scratch("rows.bin");
  std::ofstream(bin, std::ios::binary) << text;
  EXPECT_EQ(open_recording(bin, o)->info().format, "raw");
  // Named .dat they are UQ's (rank 0, by extension alone), and refused as its header.
  const auto dat = scratch("rows.dat");
  std::ofstream(dat, std::ios::binary) << text;
  EXPECT_NE(error_of(dat, o).find("not a UQ .dat header"), std::string::npos) << error_of(dat, o);
  // Stated, the format wins over the extension.
  ReaderOptions stated = o;
  stated.format = "csv";
  const auto r = open_recording(dat, stated);
  EXPECT_EQ(r->info().format, "csv");
  EXPECT_EQ(r->info().channels, 2);
  // A TDMS lead-in behind a .wav name: the TDMS reader (rank 1) takes it before libsndfile (rank 4).
  const auto tdms = scratch("lead_in.wav");
  std::ofstream(tdms, std::ios::binary) << "TDSm and then nothing a TDMS file needs";
  EXPECT_NE(error_of(tdms).find("segment 1"), std::string::npos) << error_of(tdms);
  // Files a glob catches beside recordings are refused by name before any reader guesses.
  const auto md = scratch("rows.md");
  std::ofstream(md, std::ios::binary) << text;
  EXPECT_NE(error_of(md).find("a .md file is not a recording [not_a_recording]"), std::string::npos) << error_of(md);
}

}  // namespace

namespace {

// Reads every frame of a column file written by `write`.
std::pair<awcc::RecordingInfo, std::vector<float>> read_columns(const std::string& name, const std::string& text,
                                                                const ReaderOptions& o = {}) {
  const auto p = scratch(name);
  std::ofstream(p, std::ios::binary) << text;
  auto r = open_recording(p, o);
  auto all = read_all(*r);
  return {r->info(), all};
}

}  // namespace

// Time stamps printed to 1 us at 300 kHz step 3 or 4 us: the rate from the
// mean step is 300 kHz to the stamps' rounding (1 us over 2000 steps: 2e-6
// relative at worst... here 5e-5 with the first and last stamps rounded),
// where the median step (3 us) gave 333 kHz.
TEST(Csv, SamplingRateFromRoundedTimeStamps) {
  std::string text = "time,a,b\n";
  for (int i = 0; i < 3000; ++i) text += fmt::format("{:.6f},{},{}\n", i / 300e3, i % 7 < 3 ? 0 : 4, i % 5 < 2 ? 0 : 4);
  const auto [info, samples] = read_columns("rounded_time.csv", text);
  EXPECT_NEAR(info.fs, 300e3, 300e3 * 1e-4);
  // A stated rate that agrees to 0.1 % is taken; one that does not is refused.
  ReaderOptions o;
  o.fs = 300e3;
  EXPECT_EQ(read_columns("rounded_time_stated.csv", text, o).first.fs, 300e3);
  o.fs = 30e3;
  EXPECT_NE(error_of(scratch("rounded_time.csv"), o).find("[override-fs]"), std::string::npos);
}

// A unit in the time column's name is honoured: "Time [ms]" at 20 kHz.
TEST(Csv, TimeColumnUnitInBrackets) {
  std::string text = "Time [ms];Spitze 1 [V];Spitze 2 [V]\n";
  for (int i = 0; i < 200; ++i) {
    std::string t = fmt::format("{:.2f}", i * 0.05);
    std::replace(t.begin(), t.end(), '.', ',');
    text += fmt::format("{};{};{}\n", t, i % 7 < 3 ? "0,3" : "4,1", "4,0");
  }
  const auto [info, samples] = read_columns("time_ms.csv", text);
  EXPECT_NEAR(info.fs, 20e3, 1e-6 * 20e3);
  ASSERT_EQ(info.channel_names.size(), 2u);
  EXPECT_EQ(info.channel_names[0], "Spitze 1 [V]");
  EXPECT_FLOAT_EQ(samples[0], 0.3f);  // decimal comma
}

// A trailing separator on header-less rows: the first row is data, and the
// empty last column is no channel.
TEST(Csv, TrailingSeparatorIsNeitherAHeaderNorAChannel) {
  ReaderOptions o;
  o.fs = 1000;
  const auto [info, samples] = read_columns("trailing_tab.tsv", "1.5\t2.5\t\n3\t4\t\n5\t6\t\n", o);
  EXPECT_EQ(info.channels, 2);
  ASSERT_EQ(samples.size(), 6u);
  EXPECT_FLOAT_EQ(samples[0], 1.5f);
}

// Quoted cells with decimal commas ("0,3";"4,1") split at the separators only.
TEST(Csv, QuotedCellsWithDecimalCommas) {
  ReaderOptions o;
  o.fs = 1000;
  const auto [info, samples] = read_columns("quoted.csv", "\"0,3\";\"4,1\"\n\"0,4\";\"4,2\"\n\"0,5\";\"4,3\"\n", o);
  EXPECT_EQ(info.channels, 2);
  ASSERT_EQ(samples.size(), 6u);
  EXPECT_FLOAT_EQ(samples[5], 4.3f);
}

// LabVIEW .lvm with one X column per channel: the second X_Value is no tip;
// Delta_X gives the rate; only the first segment is read.
TEST(Lvm, MultipleXColumnsAndDeltaX) {
  std::string text = "LabVIEW Measurement\t\nSeparator\tTab\nDecimal_Separator\t.\n***End_of_Header***\t\n\n"
                     "Channels\t2\t\nDelta_X\t0.00005\t0.00005\t\n***End_of_Header***\t\n"
                     "X_Value\tVoltage\tX_Value\tVoltage_0\tComment\n";
  for (int i = 0; i < 100; ++i) text += fmt::format("{:.6f}\t{}\t{:.6f}\t{}\t\n", i * 5e-5, i % 3 ? 4.1 : 0.3, i * 5e-5, 4.0);
  const auto [info, samples] = read_columns("multi_x.lvm", text);
  EXPECT_DOUBLE_EQ(info.fs, 20e3);
  EXPECT_EQ(info.channels, 2);
  EXPECT_EQ(info.channel_names, (std::vector<std::string>{"Voltage", "Voltage_0"}));
  EXPECT_EQ(samples.size(), 200u);
}

// LabVIEW writes rows with and without the empty trailing Comment cell (and
// files that mix them): every form reads as the same samples, rate and names.
TEST(Lvm, RowsWithoutTheEmptyCommentCellReadLikeRowsWithIt) {
  const std::string head = "LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
                           "***End_of_Header***\t\n\nChannels\t2\t\nDelta_X\t0.0001\t0.0001\t\n"
                           "***End_of_Header***\t\nX_Value\tVoltage\tVoltage_0\tComment\n";
  auto file = [&](const std::string& name, auto with_comment) {
    std::string text = head;
    for (int i = 0; i < 300; ++i) {
      text += fmt::format("{:.6f}\t{}\t{}{}\n", i * 1e-4, i % 3 ? 4.125 : 0.25, i % 4 ? 3.5 : 0.5,
                          with_comment(i) ? "\t" : "");
    }
    return read_columns(name, text);
  };
  const auto [kept_info, kept] = file("comment_kept.lvm", [](int) { return true; });
  const auto [left_info, left] = file("comment_left_out.lvm", [](int) { return false; });
  const auto [mixed_info, mixed] = file("comment_mixed.lvm", [](int i) { return i % 2 == 0; });
  ASSERT_EQ(kept.size(), 600u);
  EXPECT_EQ(kept[0], 0.25f);
  EXPECT_EQ(kept[1], 0.5f);
  EXPECT_EQ(kept[2 * 299], 4.125f);
  EXPECT_EQ(kept[2 * 299 + 1], 3.5f);
  for (const auto& [info, samples] : {std::pair{left_info, left}, std::pair{mixed_info, mixed}}) {
    EXPECT_EQ(samples, kept);
    EXPECT_EQ(info.fs, kept_info.fs);
    EXPECT_EQ(info.channel_names, kept_info.channel_names);
  }
  EXPECT_DOUBLE_EQ(kept_info.fs, 10e3);
  EXPECT_EQ(kept_info.channel_names, (std::vector<std::string>{"Voltage", "Voltage_0"}));
  // A missing sample cell is no Comment left out: still refused.
  const std::string broken = head + "0.000000\t4.1\t3.5\t\n0.000100\t4.1\t3.5\n0.000200\t4.1\n";
  const auto p = scratch("comment_broken.lvm");
  std::ofstream(p, std::ios::binary) << broken;
  EXPECT_NE(error_of(p).find("line 13 has 2 cells where the first row has 4"), std::string::npos) << error_of(p);
}


// A four-tip probe's recording in each column format: every channel is
// delivered, in order, each sample as written (channel c, frame i holds a
// value of its own, so a channel read from another column shows).
TEST(FourChannels, EveryColumnFormatDeliversAllFourChannels) {
  constexpr int channels = 4, frames = 50;
  auto count = [](int i, int c) { return static_cast<std::int16_t>(1000 * c + i - 20); };
  std::vector<std::int16_t> counts;
  for (int i = 0; i < frames; ++i)
    for (int c = 0; c < channels; ++c) counts.push_back(count(i, c));
  auto check = [&](const fs::path& p, const ReaderOptions& o, double volts_per_count) {
    SCOPED_TRACE(p.filename().string());
    auto r = open_recording(p, o);
    ASSERT_EQ(r->info().channels, channels);
    const auto v = read_all(*r, 3);
    ASSERT_EQ(v.size(), counts.size());
    for (std::size_t k = 0; k < v.size(); ++k) {
      ASSERT_FLOAT_EQ(v[k], static_cast<float>(counts[k] * volts_per_count)) << "frame " << k / 4 << ", channel " << k % 4;
    }
  };
  ReaderOptions o;
  o.fs = 20e3;
  const auto dat = scratch("four.dat");
  write_binary(dat, counts, dat_header(frames, channels));
  check(dat, o, 5.0 / 32768.0);

  const auto raw = scratch("four.raw");
  write_binary(raw, counts);
  ReaderOptions r = o;
  r.format = "raw";
  r.raw.channels = channels;
  check(raw, r, 1.0);

  const auto csv = scratch("four.csv");
  {
    std::ofstream f(csv);
    f << "time,tip0,tip1,tip2,tip3\n";
    for (int i = 0; i < frames; ++i) {
      f << fmt::format("{:.6f}", i / 20e3);
      for (int c = 0; c < channels; ++c) f << "," << count(i, c);
      f << "\n";
    }
  }
  check(csv, {}, 1.0);
  EXPECT_EQ(open_recording(csv)->info().channel_names, (std::vector<std::string>{"tip0", "tip1", "tip2", "tip3"}));

  const auto wav = scratch("four.wav");
  SF_INFO info{};
  info.samplerate = 20000;
  info.channels = channels;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* f = sf_open(wav.c_str(), SFM_WRITE, &info);
  ASSERT_NE(f, nullptr);
  sf_writef_short(f, counts.data(), frames);
  sf_close(f);
  ReaderOptions w;
  w.volts_per_count = 1.0;
  check(wav, w, 1.0);
}
