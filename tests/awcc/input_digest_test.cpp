// The inputs' SHA-256 of the provenance, hashed as the readers read
// (Recording::hash_while_reading, ProcessOptions::hash_input): always the
// digest of every byte of the file, whatever the reader's order of reading.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "awcc/sha256.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;

synth::Scene short_scene() {
  synth::Scene s;
  s.duration = 1.0;
  return s;
}

fs::path write_scene(const synth::Scene& s, synth::SignalKind signal, const std::string& name) {
  const auto path = pdp_test::temp_dir() / name;
  synth::RecordingOptions o;
  o.signal = signal;
  o.format = *synth::format_from_extension(path);
  synth::write_recording(path, s, synth::synthesise(s).signals, o);
  return path;
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

awcc::ProcessOptions hashing_options(double dx) {
  awcc::ProcessOptions o;
  o.dx = dx;
  o.hash_input = true;
  return o;
}

// Every container the riding path reads, binary and voltage signals (the
// two-level scan stopping after its first block on a voltage signal, then
// the one-pass path; FLAC decoded through libFLAC's own reads; a WAV, whose
// header libsndfile parses by seeking past the data and back): the digest
// of the processing is sha256_of_file's, in the provenance too.
TEST(InputDigest, ProcessingGivesTheWholeFilesDigest) {
  const auto s = short_scene();
  for (const auto signal : {synth::SignalKind::binary, synth::SignalKind::voltage}) {
    for (const std::string ext : {"w64", "wav", "flac", "rf64"}) {
      const std::string name =
          std::string("digest_") + (signal == synth::SignalKind::binary ? "binary." : "voltage.") + ext;
      const auto path = write_scene(s, signal, name);
      const auto r = awcc::process_recording(path, hashing_options(s.dx));
      const auto whole = awcc::sha256_of_file(path);
      EXPECT_EQ(r.input_sha256, whole) << name;
      const auto provenance = awcc::provenance_json({}, {{path.string(), r.input_sha256}}, "pdp process");
      EXPECT_EQ(provenance["inputs"][0]["sha256"], whole) << name;
    }
  }
}

// Without hash_input nothing is hashed (the option costs a core's time).
TEST(InputDigest, OffUnlessAsked) {
  const auto s = short_scene();
  const auto path = write_scene(s, synth::SignalKind::binary, "digest_off.w64");
  awcc::ProcessOptions o;
  o.dx = s.dx;
  EXPECT_TRUE(awcc::process_recording(path, o).input_sha256.empty());
  // The provenance of an input without a digest hashes the file itself.
  EXPECT_EQ(awcc::provenance_json(o, {{path.string(), ""}}, "")["inputs"][0]["sha256"], awcc::sha256_of_file(path));
}

// A WAV with a chunk after its data (a LIST chunk, as many recorders write):
// libsndfile reads that chunk while parsing the header, before the data, so
// those bytes are seen ahead of the cursor and must be read again at the end.
// And a UQ .dat, whose 8-byte header the reader skips before its data.
TEST(InputDigest, BytesReadOutOfOrderOrSkipped) {
  const auto s = short_scene();
  const auto plain = write_scene(s, synth::SignalKind::voltage, "digest_list.wav");
  std::string wav = bytes_of(plain);
  ASSERT_EQ(wav.substr(0, 4), "RIFF");
  std::string list = "LIST";
  const std::string info = "INFOISFT\x0e\x00\x00\x00pdp test file\x00";  // a 14-byte software tag
  const auto size = static_cast<std::uint32_t>(info.size());
  for (int k = 0; k < 4; ++k) list.push_back(static_cast<char>((size >> (8 * k)) & 0xFF));
  list += info;
  wav += list;
  const auto riff = static_cast<std::uint32_t>(wav.size() - 8);
  for (int k = 0; k < 4; ++k) wav[static_cast<std::size_t>(4 + k)] = static_cast<char>((riff >> (8 * k)) & 0xFF);
  write_bytes(plain, wav);
  auto plain_options = hashing_options(s.dx);
  plain_options.hash_input = false;
  const auto reference = awcc::process_recording(plain, plain_options);  // the file still reads as before
  const auto r = awcc::process_recording(plain, hashing_options(s.dx));
  EXPECT_EQ(r.input_sha256, awcc::sha256_of_file(plain));
  EXPECT_EQ(r.tips[0].phase.void_fraction, reference.tips[0].phase.void_fraction);

  // A .dat: two int32 (rows, channels), then int16 frames; a square wave per tip.
  const std::int32_t rows = 200000, channels = 2;
  std::string dat(8 + static_cast<std::size_t>(rows) * channels * 2, '\0');
  std::memcpy(dat.data(), &rows, 4);
  std::memcpy(dat.data() + 4, &channels, 4);
  for (std::int32_t i = 0; i < rows; ++i) {
    for (std::int32_t c = 0; c < channels; ++c) {
      const std::int16_t v = ((i + 7 * c) / 300) % 3 == 0 ? 20000 : -3000;
      std::memcpy(dat.data() + 8 + (static_cast<std::size_t>(i) * channels + static_cast<std::size_t>(c)) * 2, &v, 2);
    }
  }
  const auto dat_path = pdp_test::temp_dir() / "digest.dat";
  write_bytes(dat_path, dat);
  auto o = hashing_options(5e-3);
  o.reader.fs = 20e3;
  EXPECT_EQ(awcc::process_recording(dat_path, o).input_sha256, awcc::sha256_of_file(dat_path));
}

// The digest rides on the read: a file read front to back is hashed from the
// reader's bytes (a 2 MB file: within FileSha256's bytes in flight, so none
// is left for the hashing thread to read itself). Proof: bytes changed in place
// after the reading do not change the digest (it is of the bytes the
// processing read), where hashing the file again would see them.
TEST(InputDigest, RidesOnTheRead) {
  const auto s = short_scene();
  for (const std::string name : {"digest_ride.w64", "digest_ride.flac"}) {
    const auto path = write_scene(s, synth::SignalKind::voltage, name);
    const std::string before = bytes_of(path);
    const auto digest_before = awcc::sha256_of_file(path);
    auto recording = awcc::open_recording(path);
    recording->hash_while_reading();
    const auto c = static_cast<std::size_t>(recording->info().channels);
    std::vector<float> block(4096 * c);
    while (recording->read(block, 4096) > 0) {
    }
    std::string after = before;
    after[after.size() / 2] = static_cast<char>(after[after.size() / 2] ^ 0x5A);
    {
      std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
      f.seekp(static_cast<std::streamoff>(after.size() / 2));
      f.put(after[after.size() / 2]);
    }
    ASSERT_NE(awcc::sha256_of_file(path), digest_before);
    EXPECT_EQ(recording->sha256(), digest_before) << name;
  }
}

}  // namespace
