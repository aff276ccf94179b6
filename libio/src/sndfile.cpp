// Audio containers through libsndfile (awcc/recording.hpp): WAV, W64, RF64,
// FLAC, AIFF, ... A data chunk shorter than its header promises is checked
// here, as libsndfile reads it as if it were whole.
#include <fcntl.h>
#include <sndfile.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <bit>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <optional>

#include "awcc/sha256.hpp"
#include "reader_support.hpp"

namespace awcc::detail {

namespace {

namespace fs = std::filesystem;

// The data bytes a WAV (RIFF), RF64 or W64 header promises, and where the
// data start; empty for other files or headers that do not say (streaming
// writers leave 0 or 0xFFFFFFFF). libsndfile reads a truncated data chunk
// as if it were whole, so the promise is checked here.
struct DataChunk {
  std::uint64_t offset = 0, declared = 0;
};
std::optional<DataChunk> declared_data(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  // n bytes from byte `at`, or false at the file's end.
  const auto read_at = [&in](std::uint64_t at, char* out, std::streamsize n) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    in.read(out, n);
    return in.gcount() == n;
  };
  char head[40] = {};
  if (!read_at(0, head, 40)) return std::nullopt;
  auto u32 = [](const char* p) { return load<std::uint32_t>(p, std::endian::native == std::endian::big); };
  auto u64 = [](const char* p) { return load<std::uint64_t>(p, std::endian::native == std::endian::big); };
  const std::string_view magic(head, 4);
  if ((magic == "RIFF" || magic == "RF64") && std::string_view(head + 8, 4) == "WAVE") {
    std::optional<std::uint64_t> ds64_data;
    std::uint64_t pos = 12;
    for (int chunks = 0; chunks < 64; ++chunks) {
      char c[8];
      if (!read_at(pos, c, 8)) return std::nullopt;
      const std::string_view id(c, 4);
      const std::uint64_t size = u32(c + 4);
      if (id == "ds64") {
        char d[16];
        if (!read_at(pos + 8, d, 16)) return std::nullopt;
        ds64_data = u64(d + 8);
      }
      if (id == "data") {
        const std::uint64_t declared = (size == 0xFFFFFFFFu && ds64_data) ? *ds64_data : size;
        if (declared == 0 || declared == 0xFFFFFFFFu) return std::nullopt;
        return DataChunk{pos + 8, declared};
      }
      pos += 8 + size + (size & 1);
    }
    return std::nullopt;
  }
  static const unsigned char riff_guid[16] = {'r', 'i', 'f', 'f', 0x2E, 0x91, 0xCF, 0x11,
                                              0xA5, 0xD6, 0x28, 0xDB, 0x04, 0xC1, 0x00, 0x00};
  static const unsigned char data_guid[16] = {'d', 'a', 't', 'a', 0xF3, 0xAC, 0xD3, 0x11,
                                              0x8C, 0xD1, 0x00, 0xC0, 0x4F, 0x8E, 0xDB, 0x8A};
  if (std::memcmp(head, riff_guid, 16) == 0) {
    std::uint64_t pos = 40;  // riff GUID, size, wave GUID
    for (int chunks = 0; chunks < 64; ++chunks) {
      char c[24];
      if (!read_at(pos, c, 24)) return std::nullopt;
      const std::uint64_t size = u64(c + 16);  // includes the 24-byte chunk header
      if (size < 24) return std::nullopt;
      if (std::memcmp(c, data_guid, 16) == 0) return DataChunk{pos + 24, size - 24};
      pos += (size + 7) / 8 * 8;
    }
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------
// The file as libsndfile reads it (sf_open_virtual): every byte it reads
// passes through read(), so the file's digest rides on the read (in the
// read-ahead thread when there is one) instead of costing a second one.

class VirtualFile {
 public:
  explicit VirtualFile(const fs::path& path) : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {}
  VirtualFile(const VirtualFile&) = delete;
  VirtualFile& operator=(const VirtualFile&) = delete;
  ~VirtualFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] bool is_open() const { return fd_ >= 0; }
  void hash_into(FileSha256* digest) { digest_ = digest; }

  static SF_VIRTUAL_IO* io() {
    static SF_VIRTUAL_IO v{&length, &seek, &read, &write, &tell};
    return &v;
  }

 private:
  static VirtualFile& of(void* self) { return *static_cast<VirtualFile*>(self); }
  static sf_count_t length(void* self) {
    struct stat st {};
    return ::fstat(of(self).fd_, &st) == 0 ? static_cast<sf_count_t>(st.st_size) : -1;
  }
  static sf_count_t seek(sf_count_t offset, int whence, void* self) {
    VirtualFile& f = of(self);
    sf_count_t to = offset;
    if (whence == SEEK_CUR) to = f.offset_ + offset;
    if (whence == SEEK_END) to = length(self) + offset;
    if (to < 0) return -1;
    f.offset_ = to;
    return to;
  }
  static sf_count_t read(void* out, sf_count_t count, void* self) {
    VirtualFile& f = of(self);
    auto* bytes = static_cast<std::uint8_t*>(out);
    sf_count_t got = 0;
    while (got < count) {
      const ssize_t n = ::pread(f.fd_, bytes + got, static_cast<std::size_t>(count - got), f.offset_ + got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;  // the end, or an error libsndfile reports as a short read
      got += n;
    }
    if (f.digest_ && got > 0) f.digest_->saw(static_cast<std::uint64_t>(f.offset_), {bytes, static_cast<std::size_t>(got)});
    f.offset_ += got;
    return got;
  }
  static sf_count_t write(const void*, sf_count_t, void*) { return 0; }
  static sf_count_t tell(void* self) { return of(self).offset_; }

  int fd_;
  sf_count_t offset_ = 0;
  FileSha256* digest_ = nullptr;
};

// ---------------------------------------------------------------------------
// libsndfile containers.

class SndfileRecording final : public Recording {
 public:
  SndfileRecording(const fs::path& path, const ReaderOptions& options) {
    SF_INFO sf{};
    // Owned from here: a refusal below (thrown from the constructor) closes it.
    open(path, sf);
    if (!virtual_->is_open()) reader_fail(path, fmt::format("cannot be opened for reading: {}", std::strerror(errno)));
    if (!file_) {
      reader_fail(path, fmt::format("not a readable audio file (libsndfile: {}); check the file or state its format", 
                             sf_strerror(nullptr)));
    }
    if (sf.channels <= 0 || sf.samplerate <= 0) reader_fail(path, "the audio header has no channels or no sampling rate");
    info_.path = path;
    info_.channels = sf.channels;
    info_.fs = stated_rate(path, options, sf.samplerate, "the file header");
    info_.frames = sf.frames;
    SF_FORMAT_INFO major{};
    major.format = sf.format & SF_FORMAT_TYPEMASK;
    sf_command(file_.get(), SFC_GET_FORMAT_INFO, &major, sizeof(major));
    int bits = 0;
    switch (sf.format & SF_FORMAT_SUBMASK) {
      case SF_FORMAT_PCM_S8: case SF_FORMAT_PCM_U8: bits = 8; break;
      case SF_FORMAT_PCM_16: bits = 16; break;
      case SF_FORMAT_PCM_24: bits = 24; break;
      case SF_FORMAT_PCM_32: bits = 32; break;
      default: bits = 0;
    }
    const int sub = sf.format & SF_FORMAT_SUBMASK;
    floating_ = sub == SF_FORMAT_FLOAT || sub == SF_FORMAT_DOUBLE;
    floating_double_ = sub == SF_FORMAT_DOUBLE;
    int16_ = bits == 16;
    // Companded or compressed samples (u-law, A-law, ADPCM, Vorbis, ...) have
    // no volts: read normalised to full scale 1.
    const bool coded = bits == 0 && !floating_;
    coded_ = coded;
    // Values as counts for integer data, as stored for floating data.
    sf_command(file_.get(), SFC_SET_NORM_FLOAT, nullptr, coded ? SF_TRUE : SF_FALSE);
    const double vpc = options.volts_per_count;
    info_.volts_known = !coded && (vpc > 0.0 || floating_);
    if (coded) {
      scale_ = 1.0;
      info_.quantum = 0.0;
    } else if (floating_) {
      scale_ = vpc > 0.0 ? vpc : 1.0;
      info_.quantum = 0.0;
    } else {
      // Unknown scale: full scale is 1 (normalised units).
      scale_ = vpc > 0.0 ? vpc : 1.0 / std::ldexp(1.0, bits - 1);
      info_.quantum = scale_;
    }
    check_complete(path, options, sf, bits);
    info_.description = fmt::format("{} ({}, {})", major.name ? major.name : "audio",
                                    floating_ ? "floating point"
                                              : (coded ? "compressed" : fmt::format("{}-bit integer", bits)),
                                    info_.volts_known ? "volts" : "normalised units");
  }
  // A data chunk shorter than the header promises is refused (or, when
  // allowed, read with a warning naming the promised and present durations).
  void check_complete(const fs::path& path, const ReaderOptions& options, const SF_INFO& sf, int bits) {
    const auto chunk = declared_data(path);
    if (!chunk) return;
    std::error_code ec;
    const std::uint64_t size = fs::file_size(path, ec);
    const std::uint64_t present = size > chunk->offset ? size - chunk->offset : 0;
    if (ec || present >= chunk->declared) return;
    const double frame_bytes = static_cast<double>(sf.channels) * (bits > 0 ? bits / 8 : (floating_double_ ? 8 : 4));
    const double rate = static_cast<double>(sf.samplerate);
    const std::string what = fmt::format(
        "the header promises {:.3f} s of data but the file holds {:.3f} s: it is truncated (a recording still being "
        "written, or a copy cut short)",
        static_cast<double>(chunk->declared) / frame_bytes / rate, static_cast<double>(present) / frame_bytes / rate);
    if (!options.allow_truncated) reader_fail(path, what + "; recover the whole file, or process what is there", "allow-truncated");
    info_.warnings.push_back(what + "; only what is there was processed");
  }


  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const sf_count_t got = sf_readf_float(file_.get(), out.data(), max_frames);
    if (got < 0) reader_fail(info_.path, "read error");
    const auto n = static_cast<std::size_t>(got) * static_cast<std::size_t>(info_.channels);
    if (scale_ != 1.0) {
      const auto s = static_cast<float>(scale_);
      for (std::size_t i = 0; i < n; ++i) out[i] *= s;
    }
    if (floating_) check_finite(info_.path, out.first(n), position_, info_.channels);
    position_ += got;
    if (got == 0 && info_.frames >= 0 && position_ < info_.frames) {
      reader_fail(info_.path, fmt::format("the header announces {} frames but the data ends after {}: the file is truncated",
                                   info_.frames, position_));
    }
    return got;
  }

  // Opened afresh, not sf_seek(0): libsndfile does not always seek back to
  // where its first pass began (an AU header giving its data offset as 0: the
  // first pass starts after the header, the seek at byte 0, so the second
  // pass read the header as samples; found by fuzz_read_sndfile).
  void rewind() override {
    SF_INFO sf{};
    open(info_.path, sf);
    if (!file_ || sf.channels != info_.channels) {
      reader_fail(info_.path, "cannot be opened again for a second pass: the file changed or went away");
    }
    sf_command(file_.get(), SFC_SET_NORM_FLOAT, nullptr, coded_ ? SF_TRUE : SF_FALSE);
    position_ = 0;
  }

  [[nodiscard]] bool has_int16() const override { return int16_; }

  void hash_while_reading() override {
    digest_ = std::make_unique<FileSha256>(info_.path);
    virtual_->hash_into(digest_.get());
  }

  std::string sha256() override {
    if (!digest_) return Recording::sha256();
    virtual_->hash_into(nullptr);
    const auto digest = std::move(digest_);
    return digest->hex();
  }

  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    const sf_count_t got = sf_readf_short(file_.get(), out.data(), max_frames);
    if (got < 0) reader_fail(info_.path, "read error");
    position_ += got;
    if (got == 0 && info_.frames >= 0 && position_ < info_.frames) {
      reader_fail(info_.path, fmt::format("the header announces {} frames but the data ends after {}: the file is truncated",
                                   info_.frames, position_));
    }
    return got;
  }

 private:
  // The file through its own descriptor and virtual I/O; a failure leaves file_ empty.
  void open(const fs::path& path, SF_INFO& sf) {
    file_.reset();  // closed before the file it reads
    virtual_ = std::make_unique<VirtualFile>(path);
    virtual_->hash_into(digest_.get());
    if (virtual_->is_open()) file_.reset(sf_open_virtual(VirtualFile::io(), SFM_READ, &sf, virtual_.get()));
  }

  std::unique_ptr<FileSha256> digest_;  // while hashing as read
  std::unique_ptr<VirtualFile> virtual_;
  std::unique_ptr<SNDFILE, int (*)(SNDFILE*)> file_{nullptr, &sf_close};
  bool floating_ = false;
  bool floating_double_ = false;
  bool int16_ = false;
  bool coded_ = false;
  double scale_ = 1.0;
  std::int64_t position_ = 0;
};
}  // namespace

bool audio_magic(const fs::path& path) {
  const std::string s = leading_bytes(path, 4);
  return s == "RIFF" || s == "RIFX" || s == "RF64" || s == "fLaC" || s == "FORM" || s == "riff" || s == "OggS" ||
         s == "caff" || s == ".snd";
}

std::unique_ptr<Recording> open_sndfile(const fs::path& path, const ReaderOptions& options) {
  auto recording = std::make_unique<SndfileRecording>(path, options);
  check_interleaving(*recording, "the audio header's channel count", [](int n) {
    return fmt::format("the header is wrong: write the file again with {} channels", n);
  });
  return recording;
}

}  // namespace awcc::detail
