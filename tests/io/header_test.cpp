// Headers that contradict their data (issue 29, case 7): a channel count
// that does not fit the interleaved samples (UQ .dat, raw layouts, audio
// headers) and a LabVIEW Channels line that does not fit the columns are
// refused before any physics, naming the file, the field and the fix; true
// counts, doubled and dead channels and noise are read. And LabVIEW .lvm as
// LabVIEW writes it (Windows line ends, the full header, a Comment cell
// filled on some rows, left out on others) reads as the same samples.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sndfile.h>

#include <cstring>
#include <fstream>
#include <random>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/recording.hpp"
#include "declared_quantity.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using awcc::ReaderOptions;

// Two tips of a probe as int16 counts, interleaved: a telegraph signal
// (water ~ 26000 counts, air ~ 2000, noise sd 40) with exponential chord
// lengths, the trailing tip the leading one 30 samples later. What a real
// .dat holds, small enough to write in a test.
std::vector<std::int16_t> two_tips(std::size_t frames, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 40.0);
  std::exponential_distribution<double> water(1.0 / 400.0), air(1.0 / 60.0);
  std::vector<bool> in_air(frames + 30);
  bool state = false;
  for (std::size_t i = 0; i < in_air.size();) {
    const auto run = static_cast<std::size_t>((state ? air : water)(rng)) + 1;
    for (std::size_t k = 0; k < run && i < in_air.size(); ++k) in_air[i++] = state;
    state = !state;
  }
  std::vector<std::int16_t> out(2 * frames);
  for (std::size_t t = 0; t < frames; ++t) {
    out[2 * t] = static_cast<std::int16_t>((in_air[t + 30] ? 2000.0 : 26000.0) + noise(rng));
    out[2 * t + 1] = static_cast<std::int16_t>((in_air[t] ? 2500.0 : 25000.0) + noise(rng));
  }
  return out;
}

// The two tips plus a third channel (a dead one at `level` counts, or a copy of the leading tip).
std::vector<std::int16_t> three_channels(const std::vector<std::int16_t>& two, bool copy, std::int16_t level = 100) {
  std::vector<std::int16_t> out;
  for (std::size_t t = 0; 2 * t < two.size(); ++t) {
    out.push_back(two[2 * t]);
    out.push_back(two[2 * t + 1]);
    out.push_back(copy ? two[2 * t] : level);
  }
  return out;
}

void write_dat(const fs::path& p, std::int32_t rows, std::int32_t channels, const std::vector<std::int16_t>& counts) {
  std::ofstream f(p, std::ios::binary);
  f.write(reinterpret_cast<const char*>(&rows), 4);
  f.write(reinterpret_cast<const char*>(&channels), 4);
  f.write(reinterpret_cast<const char*>(counts.data()), static_cast<std::streamsize>(counts.size() * 2));
}

struct Refusal {
  std::string message, quantity;
};

// Opens and reads the whole file; the refusal, or an empty one.
Refusal refusal_of(const fs::path& p, const ReaderOptions& o = {}) {
  try {
    auto r = awcc::open_recording(p, o);
    std::vector<float> block(static_cast<std::size_t>(4096 * r->info().channels));
    while (r->read(block, 4096) > 0) {
    }
  } catch (const awcc::InputError& e) {
    EXPECT_TRUE(declared_reader_quantity(e.quantity())) << e.quantity();
    return {e.what(), e.quantity()};
  }
  return {};
}

ReaderOptions at_20khz() {
  ReaderOptions o;
  o.fs = 20e3;
  return o;
}

TEST(ChannelCount, DatHeaderSayingThreeChannelsOverTwoIsRefusedNamingTheFieldAndTheFix) {
  const auto counts = two_tips(30000);
  const auto good = pdp_test::test_file("two.dat");
  write_dat(good, 30000, 2, counts);
  EXPECT_EQ(refusal_of(good, at_20khz()).message, "");
  // The same bytes under a header of 20000 rows x 3 channels: sizes agree, the channels do not.
  const auto lying = pdp_test::test_file("three.dat");
  write_dat(lying, 20000, 3, counts);
  const auto r = refusal_of(lying, at_20khz());
  EXPECT_NE(r.message.find(lying.string() + ": the .dat header's channel count (bytes 4-7) says 3 channels, but the "
                                            "samples repeat as 2 channels"),
            std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("correct the header to 2 channels and 30000 rows, or read the file as raw (format raw, "
                           "raw-channels 2, raw-header 8 bytes)"),
            std::string::npos)
      << r.message;
  EXPECT_EQ(r.quantity, "format");
}

TEST(ChannelCount, DatHeaderSayingTwoChannelsOverThreeIsRefused) {
  const auto three = three_channels(two_tips(20000), false);
  const auto lying = pdp_test::test_file("two_of_three.dat");
  write_dat(lying, 30000, 2, three);
  const auto r = refusal_of(lying, at_20khz());
  EXPECT_NE(r.message.find("says 2 channels, but the samples repeat as 3 channels"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("correct the header to 3 channels and 20000 rows"), std::string::npos) << r.message;
  const auto good = pdp_test::test_file("three_of_three.dat");
  write_dat(good, 20000, 3, three);
  EXPECT_EQ(refusal_of(good, at_20khz()).message, "");
}

// What the check must not refuse: a doubled tip (a stride of 1 beats the
// count: it divides it), a dead channel, noise alone, and files too short to judge.
TEST(ChannelCount, CopiedDeadAndNoisyChannelsAndShortFilesAreRead) {
  const auto copied = pdp_test::test_file("copied.dat");
  write_dat(copied, 20000, 3, three_channels(two_tips(20000), true));
  EXPECT_EQ(refusal_of(copied, at_20khz()).message, "");
  const auto tips = two_tips(20000);
  std::vector<std::int16_t> doubled;
  for (std::size_t t = 0; t < 20000; ++t) doubled.insert(doubled.end(), 2, tips[2 * t]);
  const auto twice = pdp_test::test_file("doubled.dat");
  write_dat(twice, 20000, 2, doubled);
  EXPECT_EQ(refusal_of(twice, at_20khz()).message, "");
  const auto dead = pdp_test::test_file("dead.dat");
  write_dat(dead, 20000, 3, three_channels(two_tips(20000), false, 0));
  EXPECT_EQ(refusal_of(dead, at_20khz()).message, "");
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 3000.0);
  std::vector<std::int16_t> noise(60000);
  for (auto& v : noise) v = static_cast<std::int16_t>(n(rng));
  const auto noisy = pdp_test::test_file("noise.dat");
  write_dat(noisy, 20000, 3, noise);
  EXPECT_EQ(refusal_of(noisy, at_20khz()).message, "");
  // 100 samples cannot be judged: read as stated.
  const auto counts = two_tips(60);
  const auto short_file = pdp_test::test_file("short.dat");
  write_dat(short_file, 40, 3, std::vector<std::int16_t>(counts.begin(), counts.begin() + 120));
  EXPECT_EQ(refusal_of(short_file, at_20khz()).message, "");
}

TEST(ChannelCount, RawLayoutWithTheWrongChannelCountIsRefusedNamingTheSetting) {
  const auto counts = two_tips(30000);
  const auto p = pdp_test::test_file("two.raw");
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(counts.data()), static_cast<std::streamsize>(counts.size() * 2));
  auto o = at_20khz();
  o.raw.channels = 3;
  const auto r = refusal_of(p, o);
  EXPECT_NE(r.message.find("the stated raw layout (raw-channels) says 3 channels, but the samples repeat as 2 "
                           "channels"),
            std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("state raw-channels 2"), std::string::npos) << r.message;
  EXPECT_EQ(r.quantity, "raw-channels");
  o.raw.channels = 2;
  EXPECT_EQ(refusal_of(p, o).message, "");
}

TEST(ChannelCount, AudioHeaderWithTheWrongChannelCountIsRefused) {
  const auto counts = two_tips(30000);
  auto write_wav = [&](const fs::path& p, int channels) {
    SF_INFO sf{};
    sf.samplerate = 20000;
    sf.channels = channels;
    sf.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
    SNDFILE* f = sf_open(p.c_str(), SFM_WRITE, &sf);
    ASSERT_NE(f, nullptr);
    sf_write_short(f, counts.data(), static_cast<sf_count_t>(counts.size()));
    sf_close(f);
  };
  const auto lying = pdp_test::test_file("three.wav");
  write_wav(lying, 3);
  const auto r = refusal_of(lying);
  EXPECT_NE(r.message.find("the audio header's channel count says 3 channels, but the samples repeat as 2 channels"),
            std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("write the file again with 2 channels"), std::string::npos) << r.message;
  const auto good = pdp_test::test_file("two.wav");
  write_wav(good, 2);
  EXPECT_EQ(refusal_of(good).message, "");
}

// LabVIEW's header as "Write To Measurement File" writes it (Writer_Version 2,
// one X column, a segment header with Channels, Samples, Delta_X), Windows
// line ends, a Comment cell filled on the first row as LabVIEW writes a
// comment, empty on others, or left out.
std::string labview_file(int channels_line, bool comment_cells, const std::vector<std::int16_t>& counts, int rows) {
  const char* eol = "\r\n";
  std::string t;
  for (const char* line :
       {"LabVIEW Measurement\t", "Writer_Version\t2", "Reader_Version\t2", "Separator\tTab", "Decimal_Separator\t.",
        "Multi_Headings\tNo", "X_Columns\tOne", "Time_Pref\tRelative", "Operator\tlab", "Date\t2024/03/05",
        "Time\t10:15:02.4973711967468261719", "***End_of_Header***\t", "\t"}) {
    t += std::string(line) + eol;
  }
  t += fmt::format("Channels\t{}\t\t{}", channels_line, eol);
  t += fmt::format("Samples\t{}\t{}\t{}", rows, rows, eol);
  t += fmt::format(
      "Date\t2024/03/05\t2024/03/05\t{}Time\t10:15:02.4973711967468261719\t10:15:02.4973711967468261719\t{}", eol, eol);
  t += fmt::format("Y_Unit_Label\tVolts\tVolts\t{}X_Dimension\tTime\tTime\t{}", eol, eol);
  t += fmt::format("X0\t0.0000000000000000E+0\t0.0000000000000000E+0\t{}Delta_X\t0.000050\t0.000050\t{}", eol, eol);
  t += fmt::format("***End_of_Header***\t\t\t{}X_Value\tVoltage\tVoltage_0\tComment{}", eol, eol);
  for (int i = 0; i < rows; ++i) {
    const double a = counts[2 * static_cast<std::size_t>(i)] * 5.0 / 32768.0;
    const double b = counts[2 * static_cast<std::size_t>(i) + 1] * 5.0 / 32768.0;
    const std::string comment = !comment_cells ? "" : (i == 0 ? "\tprobe at 8 mm" : "\t");
    t += fmt::format("{:.6f}\t{:.6f}\t{:.6f}{}{}", i * 5e-5, a, b, comment, eol);
  }
  return t;
}

std::pair<awcc::RecordingInfo, std::vector<float>> read_text(const std::string& name, const std::string& text) {
  const auto p = pdp_test::test_file(name);
  std::ofstream(p, std::ios::binary) << text;
  auto r = awcc::open_recording(p);
  std::vector<float> all, block(2 * 1000);
  for (std::int64_t n; (n = r->read(block, 1000)) > 0;) all.insert(all.end(), block.begin(), block.begin() + 2 * n);
  return {r->info(), all};
}

TEST(LabviewLvm, AsLabviewWritesItWithAndWithoutCommentCells) {
  const auto counts = two_tips(2000);
  const auto [with_info, with] = read_text("with_comment.lvm", labview_file(2, true, counts, 2000));
  const auto [without_info, without] = read_text("without_comment.lvm", labview_file(2, false, counts, 2000));
  ASSERT_EQ(with.size(), 4000u);
  EXPECT_EQ(with, without);
  EXPECT_DOUBLE_EQ(with_info.fs, 20e3);
  EXPECT_DOUBLE_EQ(without_info.fs, 20e3);
  EXPECT_EQ(with_info.channel_names, (std::vector<std::string>{"Voltage", "Voltage_0"}));
  EXPECT_EQ(without_info.channel_names, with_info.channel_names);
  // The samples as printed (6 decimals): within half a printed digit of the counts' volts.
  for (std::size_t i = 0; i < with.size(); ++i) EXPECT_NEAR(with[i], counts[i] * 5.0 / 32768.0, 5.1e-7) << i;
}

// LabVIEW starts a segment at every write unless told to write one header
// only: the segments read as one recording, as the same rows in one segment do.
TEST(LabviewLvm, SegmentsReadAsOneRecording) {
  const auto counts = two_tips(2000);
  const std::string whole = labview_file(2, true, counts, 2000);
  // The second segment: the segment header of the first (from Channels to
  // the column names) before row 1000.
  const auto segment_at = whole.find("Channels\t");
  const auto data_at = whole.find("Comment\r\n") + 9;
  const std::string segment_header = whole.substr(segment_at, data_at - segment_at);
  std::size_t row_1000 = data_at;
  for (int i = 0; i < 1000; ++i) row_1000 = whole.find("\r\n", row_1000) + 2;
  const std::string split = whole.substr(0, row_1000) + segment_header + whole.substr(row_1000);
  const auto [one_info, one] = read_text("one_segment.lvm", whole);
  const auto [two_info, two] = read_text("two_segments.lvm", split);
  EXPECT_EQ(two, one);
  EXPECT_EQ(two_info.fs, one_info.fs);
  // A segment of other channels is no continuation: refused, naming its line (23 lines of
  // headers and names, 1000 rows).
  std::string three = segment_header;
  three.replace(three.find("Channels\t2"), 10, "Channels\t3");
  const auto p = pdp_test::test_file("segment_of_three.lvm");
  std::ofstream(p, std::ios::binary) << whole.substr(0, row_1000) + three + whole.substr(row_1000);
  EXPECT_NE(refusal_of(p).message.find("the LabVIEW segment at line 1024 has 3 channels, the first segment 2"),
            std::string::npos)
      << refusal_of(p).message;
}

TEST(LabviewLvm, AChannelsLineThatContradictsTheColumnsIsRefused) {
  const auto counts = two_tips(2000);
  const auto p = pdp_test::test_file("channels3.lvm");
  std::ofstream(p, std::ios::binary) << labview_file(3, false, counts, 2000);
  const auto r = refusal_of(p);
  EXPECT_NE(r.message.find(p.string() + ": its header's Channels line says 3 channels, but its rows hold 2 data "
                                        "columns ('Voltage', 'Voltage_0')"),
            std::string::npos)
      << r.message;
}

}  // namespace
