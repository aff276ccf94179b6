// NI TDMS reader (awcc/recording.hpp), written from NI's published
// description of the format ("TDMS File Format Internal Structure"): a file
// is a sequence of segments; each has a 28-byte lead-in ("TDSm", the table
// of contents flags, the version, the offsets of the next segment and of the
// raw data from the end of the lead-in), optional metadata (objects by path
// with their raw data index and properties) and raw data in chunks, each
// chunk holding every active channel's values, one channel after another or
// interleaved. The metadata is read once at opening (a list of pieces per
// channel: memory grows with the segments, not the samples); the samples are
// read piece by piece as asked.
#include <algorithm>
#include <bit>
#include <cmath>
#include <charconv>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc::detail {

namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kTocMetaData = 1u << 1, kTocNewObjList = 1u << 2, kTocRawData = 1u << 3,
                        kTocInterleaved = 1u << 5, kTocBigEndian = 1u << 6, kTocDaqmx = 1u << 7;
constexpr std::uint32_t kNoData = 0xFFFFFFFFu, kSameIndex = 0u;

std::size_t type_size(std::uint32_t type) {
  switch (type) {
    case 1: case 5: case 0x21: return 1;        // int8, uint8, bool
    case 2: case 6: return 2;                   // int16, uint16
    case 3: case 7: case 9: return 4;           // int32, uint32, float32
    case 4: case 8: case 10: return 8;          // int64, uint64, float64
    case 0x44: return 16;                       // timestamp
    default: return 0;
  }
}

std::string_view type_name(std::uint32_t type) {
  switch (type) {
    case 2: return "int16";
    case 3: return "int32";
    case 9: return "float32";
    case 10: return "float64";
    default: return "unsupported";
  }
}

// A little-endian cursor over a byte block, refusing reads past its end.
class Cursor {
 public:
  Cursor(const std::vector<char>& bytes, const fs::path& path, std::uint64_t origin)
      : bytes_(bytes), path_(path), origin_(origin) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::string string() {
    const auto n = get<std::uint32_t>();
    need(n);
    std::string s(bytes_.data() + at_, n);
    at_ += n;
    return s;
  }
  void skip(std::size_t n) {
    need(n);
    at_ += n;
  }

 private:
  void need(std::size_t n) {
    if (n > bytes_.size() - at_) {
      reader_fail(path_, fmt::format("the TDMS metadata at byte {} runs past its segment: the file is damaged",
                                     origin_ + at_));
    }
  }
  const std::vector<char>& bytes_;
  const fs::path& path_;
  std::uint64_t origin_;
  std::size_t at_ = 0;
};

struct Piece {
  std::uint64_t offset;  // first value's byte
  std::uint64_t count;   // values
  std::uint64_t stride;  // bytes from one value to the next
};

struct Channel {
  std::string group, name;
  std::uint32_t type = 0;
  std::optional<double> increment;  // wf_increment, s
  std::string scaling_status;
  std::map<std::string, double> numbers;        // numeric properties
  std::map<std::string, std::string> strings;   // string properties
  std::vector<Piece> pieces;
  std::uint64_t total = 0;
};

// "/'group'/'channel'" -> group, channel ('' inside a name is a quote).
std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t i = 0;
  while (i < path.size()) {
    if (path[i] != '/') return {};
    ++i;
    if (i >= path.size() || path[i] != '\'') return {};
    ++i;
    std::string part;
    while (i < path.size()) {
      if (path[i] == '\'') {
        if (i + 1 < path.size() && path[i + 1] == '\'') {
          part += '\'';
          i += 2;
          continue;
        }
        break;
      }
      part += path[i++];
    }
    if (i >= path.size()) return {};
    ++i;  // closing quote
    parts.push_back(part);
  }
  return parts;
}

class TdmsRecording final : public Recording {
 public:
  TdmsRecording(const fs::path& path, const ReaderOptions& options) : in_(path, std::ios::binary) {
    info_.path = path;
    if (!in_) reader_fail(path, "cannot open for reading");
    const auto size = fs::file_size(path);
    parse(path, options, size);
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const std::int64_t n = std::min<std::int64_t>(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    const auto channels = selected_.size();
    for (std::size_t c = 0; c < channels; ++c) {
      read_channel(c, static_cast<std::size_t>(n));
      for (std::int64_t i = 0; i < n; ++i)
        out[static_cast<std::size_t>(i) * channels + c] = values_[static_cast<std::size_t>(i)];
    }
    position_ += n;
    return n;
  }

  void rewind() override {
    position_ = 0;
    cursor_.assign(selected_.size(), {0, 0});
  }

 private:
  struct Cursor2 {
    std::size_t piece;
    std::uint64_t within;
  };

  void parse(const fs::path& path, const ReaderOptions& options, std::uintmax_t size) {
    std::vector<std::size_t> active;  // channel indices with data in the current object list, in order
    std::map<std::string, std::size_t> by_path;
    std::map<std::size_t, std::pair<std::uint32_t, std::uint64_t>> index;  // channel -> (type, values per chunk)
    std::uint64_t at = 0;
    int segment = 0;
    while (at < size) {
      ++segment;
      if (size - at < 28) {
        truncated(path, options, fmt::format("segment {} holds {} bytes, less than its lead-in", segment, size - at));
        break;
      }
      char lead[28];
      in_.seekg(static_cast<std::streamoff>(at));
      in_.read(lead, 28);
      if (std::memcmp(lead, "TDSm", 4) != 0) {
        reader_fail(path, fmt::format("segment {} at byte {} does not start with 'TDSm': not a TDMS file, or damaged",
                                      segment, at));
      }
      std::uint32_t toc;
      std::uint64_t next, raw;
      std::memcpy(&toc, lead + 4, 4);
      std::memcpy(&next, lead + 12, 8);
      std::memcpy(&raw, lead + 20, 8);
      if (toc & kTocBigEndian) reader_fail(path, "big-endian TDMS segments are not supported; save the file little-endian");
      if (toc & kTocDaqmx) reader_fail(path, "DAQmx raw data in a TDMS file is not supported; log scaled data instead");
      const std::uint64_t body = at + 28;
      bool cut = next == ~std::uint64_t{0} || next > size - body || raw > next;
      const std::uint64_t end = cut ? size : body + next;
      if (raw > end - body) reader_fail(path, fmt::format("segment {}: its raw data would start past the file's end", segment));
      if (toc & kTocMetaData) {
        std::vector<char> meta(static_cast<std::size_t>(raw));
        in_.seekg(static_cast<std::streamoff>(body));
        in_.read(meta.data(), static_cast<std::streamsize>(meta.size()));
        if (in_.gcount() != static_cast<std::streamsize>(meta.size())) reader_fail(path, "the TDMS metadata is cut short");
        Cursor c(meta, path, body);
        if (toc & kTocNewObjList) active.clear();
        const auto objects = c.get<std::uint32_t>();
        for (std::uint32_t o = 0; o < objects; ++o) {
          const std::string object = c.string();
          const auto parts = split_path(object);
          const auto raw_index = c.get<std::uint32_t>();
          std::optional<std::size_t> ch;
          if (parts.size() == 2) {
            auto [it, fresh] = by_path.emplace(object, channels_.size());
            if (fresh) {
              channels_.emplace_back();
              channels_.back().group = parts[0];
              channels_.back().name = parts[1];
            }
            ch = it->second;
          }
          if (raw_index == 0x69120000u || raw_index == 0x69130000u) {
            reader_fail(path, "DAQmx raw data in a TDMS file is not supported; log scaled data instead");
          }
          if (raw_index != kNoData && raw_index != kSameIndex) {
            const auto type = c.get<std::uint32_t>();
            const auto dimension = c.get<std::uint32_t>();
            const auto count = c.get<std::uint64_t>();
            if (type == 0x20) c.skip(8);  // strings: total size
            if (dimension != 1) reader_fail(path, fmt::format("object {}: array dimension {}, expected 1", object, dimension));
            if (count > size) {
              reader_fail(path, fmt::format("object {} claims {} values per chunk, more than the file's {} bytes: the "
                                            "file is damaged",
                                            object, count, size));
            }
            if (!ch) reader_fail(path, fmt::format("object {} holds raw data but is not a channel", object));
            index[*ch] = {type, count};
          }
          if (ch && raw_index != kNoData) {
            if (!index.count(*ch)) reader_fail(path, fmt::format("object {} reuses a raw data index it never had", object));
            if (std::find(active.begin(), active.end(), *ch) == active.end()) active.push_back(*ch);
          } else if (ch && raw_index == kNoData) {
            active.erase(std::remove(active.begin(), active.end(), *ch), active.end());
          }
          const auto properties = c.get<std::uint32_t>();
          for (std::uint32_t p = 0; p < properties; ++p) {
            const std::string name = c.string();
            const auto type = c.get<std::uint32_t>();
            if (type == 0x20) {
              const std::string value = c.string();
              if (ch) channels_[*ch].strings[name] = value;
              continue;
            }
            double value = 0.0;
            switch (type) {
              case 1: value = c.get<std::int8_t>(); break;
              case 2: value = c.get<std::int16_t>(); break;
              case 3: value = c.get<std::int32_t>(); break;
              case 4: value = static_cast<double>(c.get<std::int64_t>()); break;
              case 5: value = c.get<std::uint8_t>(); break;
              case 6: value = c.get<std::uint16_t>(); break;
              case 7: value = c.get<std::uint32_t>(); break;
              case 8: value = static_cast<double>(c.get<std::uint64_t>()); break;
              case 9: value = c.get<float>(); break;
              case 10: value = c.get<double>(); break;
              case 0x21: value = c.get<std::uint8_t>(); break;
              case 0x44: c.skip(16); continue;
              default: reader_fail(path, fmt::format("property '{}' of {} has data type {:#x}, which TDMS does not define", name, object, type));
            }
            if (ch) channels_[*ch].numbers[name] = value;
          }
        }
      }
      if ((toc & kTocRawData) && !active.empty()) {
        std::uint64_t chunk = 0;
        for (auto ch : active) {
          const auto [type, count] = index[ch];
          const auto width = type_size(type);
          if (width == 0 || type == 0x20) {
            reader_fail(path, fmt::format("channel '{}/{}' holds values of type {:#x}: only numbers can be read",
                                          channels_[ch].group, channels_[ch].name, type));
          }
          chunk += count * width;
        }
        const std::uint64_t data = end - (body + raw);
        if (chunk == 0) reader_fail(path, fmt::format("segment {}: raw data without values", segment));
        const std::uint64_t chunks = data / chunk;
        if (data % chunk != 0 && !cut) {
          reader_fail(path, fmt::format("segment {}: {} bytes of raw data are not a whole number of {}-byte chunks",
                                        segment, data, chunk));
        }
        const bool interleaved = (toc & kTocInterleaved) != 0;
        std::uint64_t frame = 0;  // interleaved: bytes of one value of each channel
        if (interleaved) {
          for (auto ch : active) {
            if (index[ch].second != index[active.front()].second) reader_fail(path, "interleaved channels of different lengths");
            frame += type_size(index[ch].first);
          }
        }
        for (std::uint64_t k = 0; k < chunks; ++k) {
          std::uint64_t offset = body + raw + k * chunk;
          for (auto ch : active) {
            auto& channel = channels_[ch];
            const auto [type, count] = index[ch];
            if (channel.type != 0 && channel.type != type) {
              reader_fail(path, fmt::format("channel '{}/{}' changes its data type between segments", channel.group, channel.name));
            }
            channel.type = type;
            const auto width = type_size(type);
            channel.pieces.push_back({offset, count, interleaved ? frame : width});
            channel.total += count;
            offset += interleaved ? width : count * width;
          }
        }
      }
      if (cut) {
        // The next segment's offset is unset (LabVIEW still writing) or past the file's end.
        truncated(path, options, fmt::format("its segment {} is cut short", segment));
        break;
      }
      at = body + next;
    }
    select(path, options);
  }

  void truncated(const fs::path& path, const ReaderOptions& options, const std::string& what) {
    if (!options.allow_truncated) {
      reader_fail(path, fmt::format("{}: the file is truncated (a recording still being written, or a copy cut short); "
                                    "recover the whole file, or process what is there",
                                    what),
                  "allow-truncated");
    }
    info_.warnings.push_back(fmt::format("{}: only its whole chunks are read", what));
  }

  void select(const fs::path& path, const ReaderOptions& options) {
    std::vector<std::size_t> numeric;
    for (std::size_t i = 0; i < channels_.size(); ++i) {
      const auto t = channels_[i].type;
      if (t == 2 || t == 3 || t == 9 || t == 10) numeric.push_back(i);
    }
    if (options.tdms_channels.empty()) {
      selected_ = numeric;
    } else {
      for (const auto& want : options.tdms_channels) {
        std::optional<std::size_t> found;
        for (auto i : numeric) {
          const auto& c = channels_[i];
          if (want == c.name || want == c.group + "/" + c.name) {
            if (found) reader_fail(path, fmt::format("channel name '{}' is in more than one group; write group/channel", want), "tdms-channels");
            found = i;
          }
        }
        if (!found) {
          std::string names;
          for (auto i : numeric) names += (names.empty() ? "" : ", ") + channels_[i].group + "/" + channels_[i].name;
          reader_fail(path, fmt::format("no numeric channel '{}'; the file has: {}", want, names.empty() ? "none" : names),
                      "tdms-channels");
        }
        selected_.push_back(*found);
      }
    }
    if (selected_.empty()) reader_fail(path, "the TDMS file holds no int16, int32, float32 or float64 channel", "tdms-channels");
    const auto& first = channels_[selected_.front()];
    for (auto i : selected_) {
      const auto& c = channels_[i];
      if (c.total != first.total) {
        reader_fail(path,
                    fmt::format("channels '{}/{}' and '{}/{}' hold {} and {} samples: choose channels recorded together",
                                first.group, first.name, c.group, c.name, first.total, c.total),
                    "tdms-channels");
      }
      const auto inc = c.numbers.find("wf_increment");
      const auto inc0 = first.numbers.find("wf_increment");
      if ((inc == c.numbers.end()) != (inc0 == first.numbers.end()) ||
          (inc != c.numbers.end() && std::fabs(inc->second - inc0->second) > 1e-9 * inc0->second)) {
        reader_fail(path, fmt::format("channels '{}/{}' and '{}/{}' have different sampling intervals", first.group,
                                      first.name, c.group, c.name), "tdms-channels");
      }
    }
    // Linear scaling: NI_Scale[n]_..., applied in order from scale 1.
    scales_.clear();
    bool all_volts = true;
    for (auto i : selected_) {
      auto& c = channels_[i];
      double slope = 1.0, intercept = 0.0;
      bool scaled = false;
      const auto status = c.strings.find("NI_Scaling_Status");
      const auto count = c.numbers.find("NI_Number_Of_Scales");
      if (status != c.strings.end() && status->second == "unscaled" && count != c.numbers.end()) {
        // The scales the file describes, up to the count it states, in order:
        // the count is the file's word, not a loop bound (a count of 2^31
        // would loop for minutes, one of 1e300 would not fit an int).
        std::vector<std::pair<int, const std::string*>> present;  // k, its type
        constexpr std::string_view head = "NI_Scale[", tail = "]_Scale_Type";
        for (const auto& entry : c.strings) {
          const std::string_view key = entry.first;
          if (key.size() <= head.size() + tail.size() || !key.starts_with(head) || !key.ends_with(tail)) continue;
          const std::string_view number = key.substr(head.size(), key.size() - head.size() - tail.size());
          int k = 0;
          const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), k);
          if (error == std::errc{} && end == number.data() + number.size() && number.front() != '0' && k >= 1 &&
              k <= count->second) {
            present.emplace_back(k, &entry.second);
          }
        }
        std::sort(present.begin(), present.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
        for (const auto& [k, type] : present) {
          if (*type != "Linear") {
            reader_fail(path, fmt::format("channel '{}/{}' has a '{}' scale: only linear scales are supported", c.group,
                                          c.name, *type));
          }
          const double m = c.numbers.count(fmt::format("NI_Scale[{}]_Linear_Slope", k))
                               ? c.numbers.at(fmt::format("NI_Scale[{}]_Linear_Slope", k)) : 1.0;
          const double b = c.numbers.count(fmt::format("NI_Scale[{}]_Linear_Y_Intercept", k))
                               ? c.numbers.at(fmt::format("NI_Scale[{}]_Linear_Y_Intercept", k)) : 0.0;
          intercept = m * intercept + b;
          slope *= m;
          scaled = true;
        }
      }
      if (!scaled && (c.type == 2 || c.type == 3)) all_volts = false;
      if (options.volts_per_count > 0.0 && (c.type == 2 || c.type == 3)) {
        slope = options.volts_per_count;
        intercept = 0.0;
        scaled = true;
      }
      scales_.push_back({slope, intercept});
    }
    info_.channels = static_cast<int>(selected_.size());
    info_.frames = static_cast<std::int64_t>(first.total);
    info_.volts_known = all_volts || options.volts_per_count > 0.0;
    info_.quantum = 0.0;
    for (auto i : selected_) info_.channel_names.push_back(channels_[i].group + "/" + channels_[i].name);
    const auto inc = first.numbers.find("wf_increment");
    if (inc != first.numbers.end() && inc->second > 0.0) {
      info_.fs = stated_rate(path, options, 1.0 / inc->second, "its wf_increment");
    } else if (options.fs > 0.0) {
      info_.fs = options.fs;
    } else {
      reader_fail(path, "the TDMS channels record no wf_increment: state the sampling rate", "fs");
    }
    info_.description = fmt::format("NI TDMS ({} channels of {}{})", selected_.size(), type_name(first.type),
                                    info_.volts_known ? "" : ", unscaled counts");
    if (!info_.volts_known) info_.warnings.push_back("integer TDMS channels without a linear scale: values are counts");
    rewind();
  }

  // The next n values of selected channel c into values_.
  void read_channel(std::size_t c, std::size_t n) {
    const auto& channel = channels_[selected_[c]];
    const auto width = type_size(channel.type);
    const auto [slope, intercept] = scales_[c];
    values_.resize(n);
    auto& cur = cursor_[c];
    std::size_t done = 0;
    while (done < n) {
      const auto& piece = channel.pieces[cur.piece];
      const std::uint64_t take = std::min<std::uint64_t>(piece.count - cur.within, n - done);
      bytes_.resize(static_cast<std::size_t>((take - 1) * piece.stride + width));
      in_.clear();
      in_.seekg(static_cast<std::streamoff>(piece.offset + cur.within * piece.stride));
      in_.read(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
      if (in_.gcount() != static_cast<std::streamsize>(bytes_.size())) {
        reader_fail(info_.path, "the TDMS raw data ends early: the file changed or is damaged");
      }
      for (std::uint64_t k = 0; k < take; ++k) {
        const char* p = bytes_.data() + k * piece.stride;
        double v = 0.0;
        switch (channel.type) {
          case 2: { std::int16_t x; std::memcpy(&x, p, 2); v = x; break; }
          case 3: { std::int32_t x; std::memcpy(&x, p, 4); v = x; break; }
          case 9: { float x; std::memcpy(&x, p, 4); v = x; break; }
          default: { double x; std::memcpy(&x, p, 8); v = x; break; }
        }
        const double volts = slope * v + intercept;
        // A finite double beyond a float (a count times a huge scale) would be an infinite sample.
        if (!(std::fabs(volts) <= std::numeric_limits<float>::max())) {
          reader_fail(info_.path,
                      fmt::format("sample {} of channel '{}/{}' is {}", position_ + static_cast<std::int64_t>(done + k),
                                  channel.group, channel.name,
                                  std::isfinite(volts) ? fmt::format("{:g} V, beyond a sample's range (+/- 3.4e38 V): "
                                                                     "check the channel's scale", volts)
                                                       : std::string("not finite (NaN or infinite)")));
        }
        values_[done + k] = static_cast<float>(volts);
      }
      done += take;
      cur.within += take;
      if (cur.within == piece.count) {
        ++cur.piece;
        cur.within = 0;
      }
    }
  }

  std::ifstream in_;
  std::vector<Channel> channels_;
  std::vector<std::size_t> selected_;
  std::vector<std::pair<double, double>> scales_;
  std::vector<Cursor2> cursor_;
  std::vector<char> bytes_;
  std::vector<float> values_;
  std::int64_t position_ = 0;
};

}  // namespace

bool tdms_magic(const fs::path& path) { return leading_bytes(path, 4) == "TDSm"; }

std::unique_ptr<Recording> open_tdms(const fs::path& path, const ReaderOptions& options) {
  return std::make_unique<TdmsRecording>(path, options);
}

}  // namespace awcc::detail
