// HDF5 reader (awcc/recording.hpp), through libhdf5's C API.
//
// Which datasets hold the channels:
//  - the datasets named (`datasets`): one dataset (2-D: samples x channels,
//    1-D: one channel), several (their channels side by side, equal lengths),
//    or a group: its 1-D numeric datasets in name order (a `time` or `t`
//    among them is the time base, not a channel), else its only 2-D one;
//  - else pdp-sim's layout (awcc/pdpsim_layout.hpp): the root dataset `signal`;
//  - else the file's only numeric 2-D dataset.
// A 2-D dataset is samples x channels, or channels x samples read transposed
// (which the description says), by the rule of awcc/detail/columns.hpp.
//
// The rate: an attribute of the dataset, its group or the root (fs, Fs,
// sampling_rate, sample_rate, sampling_frequency in Hz; dt, wf_increment,
// sampling_interval in s), else a `time` (or `t`) dataset beside it (by the
// time-base rule of awcc/detail/time_base.hpp), else the stated fs. An
// attribute and a time dataset that disagree (beyond the rule's tolerance)
// are refused: one of them is wrong.
//
// Integer samples are counts: volts = count x quantum, the quantum stated
// (volts_per_count) or an attribute `volts_per_count` of the dataset; without
// either the samples are normalised to a full scale of 1 as libsndfile does
// for an audio file of unknown scale (1/32768 per int16 count, 1/256 per
// uint8 count), which is how pdp reads a binary 0/1 recording: two levels,
// the higher one air. Floating samples are volts.
//
// Reading streams: each read() selects a hyperslab of the requested frames
// only; chunked (and deflate-compressed) datasets keep a chunk cache of a few
// chunks, so memory does not grow with the recording's length.
//
// Debian's libhdf5 is not thread-safe: every call into it holds
// hdf5_library_mutex() (handles are released under it too), and HDF5's own printing
// of its error stack is off: a damaged file gives our message, with HDF5's
// innermost complaint quoted.
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <type_traits>
#include <utility>

#include "awcc/detail/columns.hpp"
#include "awcc/detail/time_base.hpp"
#include "awcc/pdpsim_layout.hpp"
#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc::detail {

namespace {

namespace fs = std::filesystem;
using pdpsim::hdf5_says;

// A probe has a handful of tips; a wider dataset is a table stored the other
// way round (or damage), and a frame of it would not fit a block.
constexpr hsize_t kMaxChannels = 4096;
// Objects listed when looking for the datasets (a hostile file may hold millions).
constexpr std::size_t kMaxListed = 4096;
// Values of the time dataset read at a time while checking it.
constexpr hsize_t kTimeBlock = 1 << 16;

// The library lock. Not reentrant, and no handle takes it: every Handle is
// released where it is held (a local Handle inside a LibraryLock's scope; the
// recording's own in Held, whose deleter takes it). So no thread needs to know
// whether it holds the lock already, and nothing per thread is kept.
class LibraryLock {
 public:
  LibraryLock() : lock_(hdf5_library_mutex()) {
    // Set at every entry: another user of the library (matio) may have turned
    // the printing back on.
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }

 private:
  std::lock_guard<std::mutex> lock_;
};

// Any identifier libhdf5 hands out (file, group, dataset, dataspace,
// datatype, attribute, property list), released when the handle goes, which
// must be under the LibraryLock.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  void reset() noexcept {
    if (id_ >= 0) H5Idec_ref(id_);
    id_ = H5I_INVALID_HID;
  }
  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

enum class Kind { i8, u8, i16, u16, i32, u32, f32, f64 };

struct KindInfo {
  const char* name;
  std::size_t size;
  bool integer;
  int bits;         // integer kinds: value bits including the sign
  bool is_signed;
};

constexpr KindInfo info_of(Kind k) {
  switch (k) {
    case Kind::i8: return {"int8", 1, true, 8, true};
    case Kind::u8: return {"uint8", 1, true, 8, false};
    case Kind::i16: return {"int16", 2, true, 16, true};
    case Kind::u16: return {"uint16", 2, true, 16, false};
    case Kind::i32: return {"int32", 4, true, 32, true};
    case Kind::u32: return {"uint32", 4, true, 32, false};
    case Kind::f32: return {"float32", 4, false, 0, true};
    case Kind::f64: return {"float64", 8, false, 0, true};
  }
  return {"?", 1, true, 8, true};
}

hid_t memory_type(Kind k) {
  switch (k) {
    case Kind::i8: return H5T_NATIVE_INT8;
    case Kind::u8: return H5T_NATIVE_UINT8;
    case Kind::i16: return H5T_NATIVE_INT16;
    case Kind::u16: return H5T_NATIVE_UINT16;
    case Kind::i32: return H5T_NATIVE_INT32;
    case Kind::u32: return H5T_NATIVE_UINT32;
    case Kind::f32: return H5T_NATIVE_FLOAT;
    case Kind::f64: return H5T_NATIVE_DOUBLE;
  }
  return H5T_NATIVE_INT16;
}

// A number type whose bit fields lie outside its bytes (a damaged file):
// libhdf5 1.10's conversions trust the fields and write past their buffers
// (found by fuzz_read_hdf5: stack smashing in H5T__bit_get_d, overflows in
// H5T__bit_copy reading a sensor_id attribute), so such a type is never read.
bool damaged_number_type(hid_t type) {
  const H5T_class_t cls = H5Tget_class(type);
  if (cls != H5T_INTEGER && cls != H5T_FLOAT) return false;
  const std::size_t bits = 8 * H5Tget_size(type);
  const int offset = H5Tget_offset(type);
  const std::size_t precision = H5Tget_precision(type);
  if (bits == 0 || offset < 0 || precision == 0 || static_cast<std::size_t>(offset) + precision > bits) return true;
  if (cls == H5T_INTEGER) return false;
  std::size_t sign = 0, exponent = 0, exponent_bits = 0, mantissa = 0, mantissa_bits = 0;
  if (H5Tget_fields(type, &sign, &exponent, &exponent_bits, &mantissa, &mantissa_bits) < 0) {
    H5Eclear2(H5E_DEFAULT);
    return true;
  }
  return sign >= bits || exponent_bits == 0 || exponent + exponent_bits > bits || mantissa + mantissa_bits > bits ||
         exponent_bits > 64 || mantissa_bits > 64;
}

// "strings", "int64", ... for a type that is not read; empty with `kind` set when it is.
std::string classify(hid_t file_type, std::optional<Kind>& kind) {
  kind.reset();
  if (damaged_number_type(file_type)) return "numbers of a damaged type (its bit fields lie outside its bytes)";
  Handle native(H5Tget_native_type(file_type, H5T_DIR_ASCEND));
  const hid_t t = native.valid() ? native.get() : file_type;
  const H5T_class_t cls = H5Tget_class(t);
  const std::size_t size = H5Tget_size(t);
  if (cls == H5T_INTEGER) {
    const bool is_signed = H5Tget_sign(t) == H5T_SGN_2;
    switch (size) {
      case 1: kind = is_signed ? Kind::i8 : Kind::u8; return {};
      case 2: kind = is_signed ? Kind::i16 : Kind::u16; return {};
      case 4: kind = is_signed ? Kind::i32 : Kind::u32; return {};
      default: return fmt::format("{}{}-bit integers", is_signed ? "" : "unsigned ", 8 * size);
    }
  }
  if (cls == H5T_FLOAT) {
    if (size == 4) kind = Kind::f32;
    else if (size == 8) kind = Kind::f64;
    else return fmt::format("{}-bit floating point", 8 * size);
    return {};
  }
  switch (cls) {
    case H5T_STRING: return "strings";
    case H5T_COMPOUND: return "compound records (a table of fields)";
    case H5T_ENUM: return "an enumeration (h5py stores booleans so)";
    case H5T_ARRAY: return "arrays per element";
    case H5T_VLEN: return "variable-length sequences";
    case H5T_REFERENCE: return "object references";
    case H5T_OPAQUE: return "opaque bytes";
    case H5T_BITFIELD: return "bit fields";
    case H5T_TIME: return "time stamps";
    default: return "values of an unknown type";
  }
}

bool numeric_class(hid_t type) {
  const H5T_class_t c = H5Tget_class(type);
  return c == H5T_INTEGER || c == H5T_FLOAT;
}

// "/a/b" for a path given as "a/b", "/a/b/" or "//a//b": the form messages and channel names show.
std::string absolute(const std::string& name) {
  std::string out = "/";
  for (char c : name) {
    if (c != '/' || out.back() != '/') out += c;
  }
  if (out.size() > 1 && out.back() == '/') out.pop_back();
  return out;
}

std::string parent_of(const std::string& name) {
  const auto slash = name.find_last_of('/');
  return slash == std::string::npos || slash == 0 ? std::string("/") : name.substr(0, slash);
}

std::string shape_text(const std::vector<hsize_t>& dims) {
  std::string s;
  for (auto d : dims) s += (s.empty() ? "" : " x ") + std::to_string(d);
  return s.empty() ? std::string("scalar") : s;
}

// The k-th value of a block read as stored (values of type T).
template <class T>
auto stored(const std::vector<unsigned char>& block) {
  return [bytes = block.data()](std::size_t k) {
    T v;
    std::memcpy(&v, bytes + k * sizeof(T), sizeof(T));
    return v;
  };
}

// One dataset contributing channels.
struct Source {
  std::string name;       // absolute path in the file
  Handle dataset;
  Handle space;           // its file dataspace (hyperslabs are selected on it)
  Kind kind = Kind::f64;
  std::vector<hsize_t> dims;
  bool transposed = false;  // stored channels x samples
  std::int64_t frames = 0;
  int channels = 0;
};

// A dataset found in the file, for choosing and for messages.
struct Found {
  std::string name;
  std::vector<hsize_t> dims;
  std::string type;  // "int16", or what it holds when not read
};

class Hdf5Recording final : public Recording {
 public:
  Hdf5Recording(const fs::path& path, const ReaderOptions& options) {
    info_.path = path;
    std::error_code ec;
    file_size_ = fs::file_size(path, ec);
    if (ec) reader_fail(path, fmt::format("cannot read its size ({})", ec.message()));
    LibraryLock lock;
    open_file();
    choose(options);
    check_sources();
    tune_chunk_cache();
    scale(options);
    name_channels();
    locate_tips();
    info_.fs = rate(options);
    describe();
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const std::int64_t n = std::min<std::int64_t>(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    fetch(n);
    const auto channels = static_cast<std::size_t>(info_.channels);
    std::size_t first = 0;
    for (std::size_t s = 0; s < sources_.size(); ++s) {
      switch (kind_) {
        case Kind::i8: convert<std::int8_t>(s, n, first, channels, out); break;
        case Kind::u8: convert<std::uint8_t>(s, n, first, channels, out); break;
        case Kind::i16: convert<std::int16_t>(s, n, first, channels, out); break;
        case Kind::u16: convert<std::uint16_t>(s, n, first, channels, out); break;
        case Kind::i32: convert<std::int32_t>(s, n, first, channels, out); break;
        case Kind::u32: convert<std::uint32_t>(s, n, first, channels, out); break;
        case Kind::f32: convert<float>(s, n, first, channels, out); break;
        case Kind::f64: convert<double>(s, n, first, channels, out); break;
      }
      first += static_cast<std::size_t>(sources_[s].channels);
    }
    position_ += n;
    return n;
  }

  void rewind() override { position_ = 0; }

  [[nodiscard]] bool has_int16() const override { return kind_ == Kind::i16; }

  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    if (kind_ != Kind::i16) return Recording::read_int16(out, max_frames);
    const std::int64_t n = std::min<std::int64_t>(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    fetch(n);
    const auto channels = static_cast<std::size_t>(info_.channels);
    const auto frames = static_cast<std::size_t>(n);
    std::size_t first = 0;
    for (std::size_t s = 0; s < sources_.size(); ++s) {
      const auto width = static_cast<std::size_t>(sources_[s].channels);
      interleave(frames, width, sources_[s].transposed, stored<std::int16_t>(buffers_[s]), out, channels, first,
                 [](std::int16_t v, std::size_t, std::size_t) { return v; });
      first += width;
    }
    position_ += n;
    return n;
  }

 private:
  [[noreturn]] void fail(std::string_view what, std::string quantity = {}) const {
    reader_fail(info_.path, what, std::move(quantity));
  }

  void open_file() {
    Handle fapl(H5Pcreate(H5P_FILE_ACCESS));
    // The plain POSIX driver: a file whose superblock names another driver
    // (family, multi) is refused by the open instead of reaching other files.
    if (fapl.valid()) H5Pset_fapl_sec2(fapl.get());
    file_ = Handle(H5Fopen(info_.path.c_str(), H5F_ACC_RDONLY, fapl.valid() ? fapl.get() : H5P_DEFAULT));
    if (!file_.valid()) {
      const std::string says = hdf5_says();
      if (!hdf5_magic(info_.path)) {
        fail("not an HDF5 file (no HDF5 signature at its start or at 512, 1024, 2048, ... bytes); check the file, "
             "or state its format",
             "format");
      }
      fail(fmt::format("cannot be opened as HDF5{}: the file is damaged or truncated (a copy cut short, or a "
                       "recording still being written); recover the whole file",
                       says));
    }
  }

  // Every numeric dataset in the file, in name order (the first kMaxListed
  // hard links), with its shape and type.
  std::vector<Found> list_datasets() {
    struct Visit {
      std::vector<std::string> names;
      std::size_t links = 0;
    } visit;
    const herr_t status = H5Lvisit(
        file_.get(), H5_INDEX_NAME, H5_ITER_INC,
        [](hid_t, const char* name, const H5L_info_t* link, void* data) -> herr_t {
          auto* v = static_cast<Visit*>(data);
          if (++v->links > 16 * kMaxListed) return 1;
          // Soft and external links are not followed: an external link would
          // open another file, a soft one repeats a hard link's object.
          if (link && link->type == H5L_TYPE_HARD && name) v->names.emplace_back(name);
          return v->names.size() >= kMaxListed ? 1 : 0;
        },
        &visit);
    if (status < 0) fail(fmt::format("its groups cannot be listed{}: the file is damaged", hdf5_says()));
    std::vector<Found> found;
    for (const auto& name : visit.names) {
      Handle object(H5Oopen(file_.get(), name.c_str(), H5P_DEFAULT));
      if (!object.valid() || H5Iget_type(object.get()) != H5I_DATASET) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      Handle type(H5Dget_type(object.get()));
      Handle space(H5Dget_space(object.get()));
      if (!type.valid() || !space.valid()) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      Found f;
      f.name = absolute(name);
      f.dims = dimensions(space.get(), f.name);
      std::optional<Kind> kind;
      const std::string unread = classify(type.get(), kind);
      f.type = kind ? info_of(*kind).name : (numeric_class(type.get()) ? unread : std::string());
      if (!f.type.empty()) found.push_back(std::move(f));
    }
    return found;
  }

  static std::string listing(const std::vector<Found>& found) {
    if (found.empty()) return "none";
    std::string s;
    for (const auto& f : found) {
      s += fmt::format("{}'{}' ({}, {})", s.empty() ? "" : ", ", f.name, f.type, shape_text(f.dims));
      if (s.size() > 600) return s + ", ...";
    }
    return s;
  }

  std::vector<hsize_t> dimensions(hid_t space, const std::string& name) {
    const int rank = H5Sget_simple_extent_ndims(space);
    if (rank < 0) {
      fail(fmt::format("the shape of dataset '{}' cannot be read{}: the file is damaged", name, hdf5_says()));
    }
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    if (rank > 0 && H5Sget_simple_extent_dims(space, dims.data(), nullptr) < 0) {
      fail(fmt::format("the shape of dataset '{}' cannot be read{}: the file is damaged", name, hdf5_says()));
    }
    return dims;
  }

  // The dataset `name` as a source of channels, or a refusal saying why not.
  Source source(const std::string& name, Handle dataset) {
    Source s;
    s.name = absolute(name);
    s.dataset = std::move(dataset);
    s.space = Handle(H5Dget_space(s.dataset.get()));
    Handle type(H5Dget_type(s.dataset.get()));
    if (!s.space.valid() || !type.valid()) {
      fail(fmt::format("dataset '{}' cannot be read{}: the file is damaged", s.name, hdf5_says()));
    }
    if (H5Sget_simple_extent_type(s.space.get()) != H5S_SIMPLE) {
      fail(fmt::format("dataset '{}' holds a single value or none, not samples; name the dataset that holds the "
                       "samples",
                       s.name),
           "dataset");
    }
    s.dims = dimensions(s.space.get(), s.name);
    std::optional<Kind> kind;
    if (const auto unread = classify(type.get(), kind); !kind) {
      fail(fmt::format("dataset '{}' holds {}: only int8, uint8, int16, uint16, int32, uint32, float32 and float64 "
                       "samples are read; store the samples as one of them (numpy: .astype('int16') or 'float64'), "
                       "or name another dataset",
                       s.name, unread),
           "dataset");
    }
    s.kind = *kind;
    if (s.dims.size() == 1) {
      shape(s, s.dims[0], 1);
    } else if (s.dims.size() == 2) {
      const auto layout = column_layout(s.dims[0], s.dims[1]);
      if (!layout) {
        fail(fmt::format("dataset '{}' is {}: more columns than rows, but too many rows (more than {}) to be "
                         "channels; store it samples x channels, or name the dataset(s) holding the channels",
                         s.name, shape_text(s.dims), kMaxStackedChannels),
             "dataset");
      }
      s.transposed = layout->transposed;
      shape(s, layout->frames, layout->channels);
    } else {
      fail(fmt::format("dataset '{}' has {} dimensions ({}): samples x channels (2-D) or one channel (1-D) is "
                       "expected; name a 1-D or 2-D dataset",
                       s.name, s.dims.size(), shape_text(s.dims)),
           "dataset");
    }
    return s;
  }

  void shape(Source& s, hsize_t frames, hsize_t channels) const {
    if (channels == 0) {
      fail(fmt::format("dataset '{}' ({}) holds no channel; name the dataset that holds the samples", s.name,
                       shape_text(s.dims)),
           "dataset");
    }
    if (channels > kMaxChannels) {
      fail(fmt::format("dataset '{}' ({}) would hold {} channels, more than {}: a recording is samples x channels; "
                       "name the dataset(s) holding the channels",
                       s.name, shape_text(s.dims), channels, kMaxChannels),
           "dataset");
    }
    if (frames > static_cast<hsize_t>(std::numeric_limits<std::int64_t>::max())) {
      fail(fmt::format("dataset '{}' claims {} samples, more than any file holds: the file is damaged", s.name,
                       frames));
    }
    s.frames = static_cast<std::int64_t>(frames);
    s.channels = static_cast<int>(channels);
  }

  // The options' datasets, pdp-sim's `signal`, or the only numeric 2-D dataset.
  void choose(const ReaderOptions& options) {
    if (options.datasets.size() == 1) {
      const std::string& name = options.datasets.front();
      Handle object = open_named(name);
      if (H5Iget_type(object.get()) == H5I_GROUP) {
        from_group(absolute(name), object.get());
      } else {
        sources_.push_back(source(name, std::move(object)));
      }
    } else if (!options.datasets.empty()) {
      for (const auto& name : options.datasets) {
        Handle object = open_named(name);
        if (H5Iget_type(object.get()) == H5I_GROUP) {
          fail(fmt::format("'{}' is a group: name one group alone (its 1-D datasets are the channels) or several "
                           "datasets",
                           absolute(name)),
               "dataset");
        }
        sources_.push_back(source(name, std::move(object)));
      }
    } else if (H5Lexists(file_.get(), pdpsim::signal_dataset, H5P_DEFAULT) > 0 && is_dataset(pdpsim::signal_dataset)) {
      sources_.push_back(source(pdpsim::signal_dataset, open_named(pdpsim::signal_dataset)));
    } else {
      H5Eclear2(H5E_DEFAULT);
      const auto found = list_datasets();
      std::vector<const Found*> matrices;
      for (const auto& f : found)
        if (f.dims.size() == 2) matrices.push_back(&f);
      if (matrices.size() != 1) {
        fail(fmt::format("{}: name the dataset(s) holding the channels (a 2-D dataset samples x channels, one 1-D "
                         "dataset per channel, or a group of them); its numeric datasets: {}",
                         matrices.empty() ? "no pdp-sim 'signal' dataset and no numeric 2-D dataset"
                                          : "no pdp-sim 'signal' dataset and several numeric 2-D datasets",
                         listing(found)),
             "dataset");
      }
      sources_.push_back(source(matrices.front()->name, open_named(matrices.front()->name)));
    }
    pdpsim_ = sources_.size() == 1 && sources_.front().name == absolute(pdpsim::signal_dataset);
  }

  bool is_dataset(const char* name) {
    Handle object(H5Oopen(file_.get(), name, H5P_DEFAULT));
    const bool yes = object.valid() && H5Iget_type(object.get()) == H5I_DATASET;
    H5Eclear2(H5E_DEFAULT);
    return yes;
  }

  // Whether the file links every component of an absolute path: 1 yes, 0
  // no (or a dataset on the way), negative when a look-up fails (damaged).
  htri_t holds(const std::string& path) {
    htri_t held = 1;
    for (std::size_t end = 0; held > 0 && end != std::string::npos;) {
      end = path.find('/', end + 1);
      const std::string part = path.substr(0, end);
      held = H5Lexists(file_.get(), part.c_str(), H5P_DEFAULT);
      H5O_info_t info;
      if (held > 0 && end != std::string::npos) {
        if (H5Oget_info_by_name2(file_.get(), part.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
          held = -1;
        } else if (info.type != H5O_TYPE_GROUP) {
          held = 0;
        }
      }
    }
    H5Eclear2(H5E_DEFAULT);
    return held;
  }

  Handle open_named(const std::string& name) {
    Handle object(H5Oopen(file_.get(), name.c_str(), H5P_DEFAULT));
    if (!object.valid()) {
      const std::string says = hdf5_says();
      // A name the file holds whose object cannot be read, or a look-up that
      // fails on the way, is a damaged file, not a wrong name.
      if (holds(absolute(name)) != 0) {
        fail(fmt::format("'{}' cannot be opened{}: the file is damaged", absolute(name), says));
      }
      fail(fmt::format("no dataset or group '{}'; its numeric datasets: {}", absolute(name), listing(list_datasets())),
           "dataset");
    }
    const H5I_type_t type = H5Iget_type(object.get());
    if (type != H5I_DATASET && type != H5I_GROUP) {
      fail(fmt::format("'{}' is a stored datatype, not a dataset; name a dataset or a group", absolute(name)),
           "dataset");
    }
    return object;
  }

  // A group's 1-D numeric datasets (name order, its time base left out), or its only 2-D one.
  void from_group(const std::string& group_name, hid_t group) {
    std::vector<std::string> names;
    hsize_t index = 0;
    const herr_t status = H5Literate(
        group, H5_INDEX_NAME, H5_ITER_INC, &index,
        [](hid_t, const char* name, const H5L_info_t* link, void* data) -> herr_t {
          auto* v = static_cast<std::vector<std::string>*>(data);
          if (link && link->type == H5L_TYPE_HARD && name) v->emplace_back(name);
          return v->size() >= kMaxListed ? 1 : 0;
        },
        &names);
    if (status < 0) fail(fmt::format("group '{}' cannot be listed{}: the file is damaged", group_name, hdf5_says()));
    std::vector<std::string> vectors, matrices;
    const std::string prefix = group_name == "/" ? "/" : group_name + "/";
    for (const auto& leaf : names) {
      Handle object(H5Oopen(group, leaf.c_str(), H5P_DEFAULT));
      if (!object.valid() || H5Iget_type(object.get()) != H5I_DATASET) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      Handle type(H5Dget_type(object.get()));
      Handle space(H5Dget_space(object.get()));
      if (!type.valid() || !space.valid() || !numeric_class(type.get())) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      const auto rank = H5Sget_simple_extent_ndims(space.get());
      if (rank == 1 && leaf != pdpsim::time_dataset && leaf != "t") vectors.push_back(prefix + leaf);
      if (rank == 2) matrices.push_back(prefix + leaf);
    }
    auto quoted = [](const std::vector<std::string>& v) {
      std::string s;
      for (const auto& n : v) s += (s.empty() ? "'" : ", '") + n + "'";
      return s;
    };
    if (!vectors.empty() && !matrices.empty()) {
      fail(fmt::format("group '{}' holds 1-D datasets ({}) and 2-D datasets ({}): name the dataset(s) holding the "
                       "channels",
                       group_name, quoted(vectors), quoted(matrices)),
           "dataset");
    }
    if (vectors.empty() && matrices.size() != 1) {
      fail(fmt::format("group '{}' holds {}: name the dataset(s) holding the channels",
                       group_name, matrices.empty() ? "no numeric 1-D or 2-D dataset"
                                                    : "several 2-D datasets (" + quoted(matrices) + ")"),
           "dataset");
    }
    for (const auto& name : vectors.empty() ? matrices : vectors) sources_.push_back(source(name, open_named(name)));
  }

  // Shapes the recording can take, types alike, storage the file holds.
  void check_sources() {
    const Source& first = sources_.front();
    std::int64_t channels = 0;
    for (auto& s : sources_) {
      if (s.frames != first.frames) {
        fail(fmt::format("datasets '{}' and '{}' hold {} and {} samples: the channels of one recording have equal "
                         "lengths; name datasets recorded together",
                         first.name, s.name, first.frames, s.frames),
             "dataset");
      }
      if (s.kind != first.kind) {
        fail(fmt::format("datasets '{}' and '{}' hold {} and {}: the channels of one recording are stored alike; "
                         "convert one, or name datasets recorded together",
                         first.name, s.name, info_of(first.kind).name, info_of(s.kind).name),
             "dataset");
      }
      channels += s.channels;
      const std::size_t across = s.dims.size() == 2 ? (s.transposed ? 0 : 1) : 1;
      cache_bytes_ = std::max(cache_bytes_, check_storage(s.name, s.dataset.get(), s.dims, info_of(s.kind).size, across));
    }
    if (channels > static_cast<std::int64_t>(kMaxChannels)) {
      fail(fmt::format("the datasets named hold {} channels, more than {}: name fewer", channels, kMaxChannels),
           "dataset");
    }
    kind_ = first.kind;
    info_.channels = static_cast<int>(channels);
    info_.frames = first.frames;
    const auto bytes_per_frame = static_cast<std::int64_t>(info_of(kind_).size) * channels;
    if (info_.frames > std::numeric_limits<std::int64_t>::max() / bytes_per_frame) {
      fail(fmt::format("dataset '{}' claims {} samples, more than any file holds: the file is damaged", first.name,
                       first.frames));
    }
  }

  // Storage the file cannot hold (a damaged or incomplete file) is refused
  // here, not met halfway through reading it.
  // Returns the chunk cache a sequential read needs: a row of chunks across
  // the channels (dimension `across`, when 2-D), and one more (0: not chunked).
  std::uint64_t check_storage(const std::string& name, hid_t dataset, const std::vector<hsize_t>& dims,
                              std::size_t element, std::size_t across) {
    Handle dcpl(H5Dget_create_plist(dataset));
    if (!dcpl.valid()) fail(fmt::format("dataset '{}' cannot be read{}: the file is damaged", name, hdf5_says()));
    // Saturating: a hostile shape must not wrap around to a small size.
    constexpr std::uint64_t huge = std::uint64_t{1} << 62;
    auto times = [](std::uint64_t a, std::uint64_t b) { return b != 0 && a > huge / b ? huge : a * b; };
    std::uint64_t bytes = element;
    for (auto d : dims) bytes = times(bytes, d);
    std::uint64_t cache = 0;
    switch (H5Pget_layout(dcpl.get())) {
      case H5D_COMPACT: break;
      case H5D_CONTIGUOUS: {
        if (H5Pget_external_count(dcpl.get()) > 0) {
          fail(fmt::format("dataset '{}' keeps its samples in external files, which are not read: copy them into "
                           "the file (h5repack)",
                           name));
        }
        const haddr_t offset = H5Dget_offset(dataset);
        H5Eclear2(H5E_DEFAULT);
        if (offset == HADDR_UNDEF) {
          if (bytes > 0) {
            fail(fmt::format("dataset '{}' was never written (no storage for its {} values): the file is "
                             "incomplete; recover the whole file",
                             name, bytes / element));
          }
        } else if (offset > file_size_ || bytes > file_size_ - offset) {
          fail(fmt::format("dataset '{}' claims {} bytes from byte {} but the file holds {} bytes: it is truncated "
                           "or damaged; recover the whole file",
                           name, bytes, offset, file_size_));
        }
        break;
      }
      case H5D_CHUNKED: {
        const int filters = H5Pget_nfilters(dcpl.get());
        // Deflate expands at most 1032-fold; shuffle and checksums not at all.
        std::uint64_t expansion = 1;
        for (int k = 0; k < filters; ++k) {
          unsigned flags = 0;
          std::size_t n_values = 0;
          char filter[64] = {};
          const H5Z_filter_t id = H5Pget_filter2(dcpl.get(), static_cast<unsigned>(k), &flags, &n_values, nullptr,
                                                 sizeof(filter), filter, nullptr);
          if (id < 0 || H5Zfilter_avail(id) <= 0) {
            H5Eclear2(H5E_DEFAULT);
            fail(fmt::format("dataset '{}' is compressed with filter {} ('{}'), which this libhdf5 lacks: rewrite it "
                             "with gzip (deflate) or without compression (h5repack -f GZIP=4)",
                             name, id, filter));
          }
          if (id == H5Z_FILTER_DEFLATE) expansion = std::max<std::uint64_t>(expansion, 1032);
          else if (id != H5Z_FILTER_SHUFFLE && id != H5Z_FILTER_FLETCHER32) expansion = 0;  // no bound known
        }
        const int rank = H5Pget_chunk(dcpl.get(), 0, nullptr);
        std::vector<hsize_t> chunk(dims.size(), 0);
        if (rank != static_cast<int>(dims.size()) ||
            H5Pget_chunk(dcpl.get(), rank, chunk.data()) < 0 ||
            std::any_of(chunk.begin(), chunk.end(), [](hsize_t c) { return c == 0; })) {
          fail(fmt::format("dataset '{}' has a chunk shape that does not fit its {} dimensions{}: the file is "
                           "damaged",
                           name, dims.size(), hdf5_says()));
        }
        long double expected = 1;
        for (std::size_t d = 0; d < chunk.size(); ++d)
          expected *= static_cast<long double>((dims[d] + chunk[d] - 1) / chunk[d]);
        hsize_t stored = 0;
        Handle space(H5Dget_space(dataset));
        if (!space.valid() || H5Dget_num_chunks(dataset, space.get(), &stored) < 0) {
          fail(fmt::format("the chunks of dataset '{}' cannot be counted{}: the file is damaged", name, hdf5_says()));
        }
        // Unwritten chunks would read as zeros: a recording cut short, not silence.
        if (static_cast<long double>(stored) < expected) {
          fail(fmt::format("only {} of the {:.0f} chunks of dataset '{}' are stored: the file is incomplete (a "
                           "recording cut short, or a damaged copy); recover the whole file",
                           stored, static_cast<double>(expected), name));
        }
        std::uint64_t chunk_bytes = element;
        for (auto c : chunk) chunk_bytes = times(chunk_bytes, c);
        // libhdf5 allocates a whole chunk to read any of it: chunks the stored
        // bytes cannot hold are a lying header, not a recording (found by
        // fuzz_read_hdf5: 1 GB chunks in a 10 kB file, 21 s and 1 GB per read).
        const hsize_t held = H5Dget_storage_size(dataset);
        H5Eclear2(H5E_DEFAULT);
        constexpr std::uint64_t slack = 1024;  // a chunk's own headers, per chunk
        if (expansion > 0 && times(chunk_bytes, stored) > times(expansion, held) + times(slack, stored)) {
          fail(fmt::format("dataset '{}' has {} chunks of {} bytes stored in {} bytes, more than its compression "
                           "allows: the file is damaged",
                           name, stored, chunk_bytes, held));
        }
        const std::uint64_t row = across < dims.size() ? (dims[across] + chunk[across] - 1) / chunk[across] : 1;
        cache = times(chunk_bytes, row + 1);
        break;
      }
      case H5D_VIRTUAL:
        fail(fmt::format("dataset '{}' is virtual (it maps other datasets, possibly in other files): copy its data "
                         "into a plain dataset (h5repack)",
                         name));
      default:
        fail(fmt::format("dataset '{}' has a storage layout this reader does not know{}: the file is damaged",
                         name, hdf5_says()));
    }
    return cache;
  }

  // Chunked datasets read in blocks smaller than a chunk would decompress
  // each chunk once per block without a cache holding it: room for the
  // chunks a block spans, within 64 MB for all datasets.
  void tune_chunk_cache() {
    if (cache_bytes_ == 0) return;
    const std::uint64_t budget = std::max<std::uint64_t>(1 << 20, (std::uint64_t{64} << 20) / sources_.size());
    const auto bytes = static_cast<std::size_t>(std::clamp<std::uint64_t>(cache_bytes_, 1 << 20, budget));
    Handle dapl(H5Pcreate(H5P_DATASET_ACCESS));
    if (!dapl.valid() || H5Pset_chunk_cache(dapl.get(), 521, bytes, H5D_CHUNK_CACHE_W0_DEFAULT) < 0) {
      H5Eclear2(H5E_DEFAULT);
      return;
    }
    for (auto& s : sources_) {
      Handle reopened(H5Dopen2(file_.get(), s.name.c_str(), dapl.get()));
      if (reopened.valid()) s.dataset = std::move(reopened);
      H5Eclear2(H5E_DEFAULT);
    }
  }

  // A number stored as an attribute of `object`, if present.
  std::optional<double> number_attribute(hid_t object, const char* name, const std::string& where) {
    const htri_t exists = H5Aexists(object, name);
    if (exists <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return std::nullopt;
    }
    Handle attribute(H5Aopen(object, name, H5P_DEFAULT));
    Handle type(attribute.valid() ? H5Aget_type(attribute.get()) : H5I_INVALID_HID);
    Handle space(attribute.valid() ? H5Aget_space(attribute.get()) : H5I_INVALID_HID);
    if (!type.valid() || !space.valid()) {
      fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, where, hdf5_says()));
    }
    if (!numeric_class(type.get())) {
      fail(fmt::format("attribute '{}' of '{}' is not a number: store it as one (a float or an integer)", name,
                       where));
    }
    if (damaged_number_type(type.get())) {
      fail(fmt::format("attribute '{}' of '{}' has a damaged number type: the file is damaged", name, where));
    }
    const hssize_t values = H5Sget_simple_extent_npoints(space.get());
    if (values != 1) {
      fail(fmt::format("attribute '{}' of '{}' holds {} values, one was expected: store a single number", name,
                       where, values));
    }
    double v = 0.0;
    if (H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &v) < 0) {
      fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, where, hdf5_says()));
    }
    return v;
  }

  // volts_per_count: the stated one, else every dataset's attribute (alike).
  void scale(const ReaderOptions& options) {
    const KindInfo k = info_of(kind_);
    if (!k.integer) {
      info_.quantum = 0.0;
      info_.volts_known = true;
      return;
    }
    if (options.volts_per_count > 0.0) {
      info_.quantum = options.volts_per_count;
      info_.volts_known = true;
      return;
    }
    std::vector<std::optional<double>> stated;
    // The largest count's magnitude: times the scale it must still be a sample (a float).
    const double full_scale = std::ldexp(1.0, k.is_signed ? k.bits - 1 : k.bits);
    for (const auto& src : sources_) {
      const auto v = number_attribute(src.dataset.get(), pdpsim::volts_per_count_attribute, src.name);
      if (v && !(std::isfinite(*v) && *v > 0.0)) {
        fail(fmt::format("attribute 'volts_per_count' of '{}' is {}: a scale must be a positive number; correct it, "
                         "or state the volts per count",
                         src.name, *v),
             "volts-per-count");
      }
      if (v && *v * full_scale > std::numeric_limits<float>::max()) {
        fail(fmt::format("attribute 'volts_per_count' of '{}' is {:g}: a {} count of {:g} would be {:g} V, beyond a "
                         "sample's range (+/- 3.4e38 V); correct it, or state the volts per count",
                         src.name, *v, k.name, full_scale, *v * full_scale),
             "volts-per-count");
      }
      stated.push_back(v);
    }
    const auto& vpc = stated.front();
    for (std::size_t i = 1; i < stated.size(); ++i) {
      if (stated[i].has_value() != vpc.has_value()) {
        fail(fmt::format("'{}' has a volts_per_count attribute and '{}' has none: state the volts per count",
                         vpc ? sources_.front().name : sources_[i].name, vpc ? sources_[i].name : sources_.front().name),
             "volts-per-count");
      }
      if (vpc && std::fabs(*stated[i] - *vpc) > 1e-9 * *vpc) {
        fail(fmt::format("datasets '{}' and '{}' have volts_per_count {} and {}: one recording has one scale; state "
                         "the volts per count",
                         sources_.front().name, sources_[i].name, *vpc, *stated[i]),
             "volts-per-count");
      }
    }
    if (vpc) {
      info_.quantum = *vpc;
      info_.volts_known = true;
      return;
    }
    // Unknown scale: full scale 1, as libsndfile reads integer audio.
    info_.quantum = std::ldexp(1.0, -(k.is_signed ? k.bits - 1 : k.bits));
    info_.volts_known = false;
    if (!pdpsim_) {
      info_.warnings.push_back(fmt::format("{} samples without a volts_per_count attribute: values are normalised "
                                           "(full scale 1), not volts; state the volts per count for volts",
                                           k.name));
    }
  }

  // Column names from a `sensor_id` attribute (numbers: "sensor 3"; strings
  // as they are), else the datasets' paths. The ids themselves are the
  // recording's sensor_ids when one dataset holds every channel.
  void name_channels() {
    for (const auto& s : sources_) {
      bool numeric = false;
      std::vector<std::string> ids;
      if (s.dims.size() == 2) ids = sensor_ids(s, numeric);
      if (sources_.size() == 1) info_.sensor_ids = ids;
      for (int c = 0; c < s.channels; ++c) {
        const auto column = static_cast<std::size_t>(c);
        if (!ids.empty()) info_.channel_names.push_back(numeric ? "sensor " + ids[column] : ids[column]);
        else if (s.dims.size() == 1 || s.channels == 1) info_.channel_names.push_back(s.name);
        else info_.channel_names.push_back(fmt::format("{}[{}]", s.name, c));
      }
    }
  }

  // Where the tips are: the `relative_location` attribute pdp synth writes on
  // pdp-sim's `signal`, and pdp-sim's config.json beside the file (sensors
  // matched by id); both when both, which must agree.
  void locate_tips() {
    if (!pdpsim_) return;
    const auto& s = sources_.front();
    const auto written = location_attribute(s);
    const auto configured = configured_locations();
    if (written && configured) {
      for (std::size_t c = 0; c < written->size(); ++c) {
        const auto& a = (*written)[c];
        const auto& b = (*configured)[c];
        if (std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]) > 1e-9) {
          fail(fmt::format("attribute '{}' of '{}' places the tip of column {} at ({}, {}, {}) m, but {} places "
                           "sensor {} at ({}, {}, {}) m: one of them describes another probe; correct or remove one",
                           pdpsim::tip_position_attribute, s.name, c, a[0], a[1], a[2], config_path().string(),
                           info_.sensor_ids.empty() ? std::to_string(c) : info_.sensor_ids[c], b[0], b[1], b[2]));
        }
      }
    }
    if (written) info_.tip_positions = *written;
    else if (configured) info_.tip_positions = *configured;
    else return;
    // pdp-sim's leading tip is sensor id 0 (mssp.py: S_0k from sensor 0).
    const auto zero = std::find(info_.sensor_ids.begin(), info_.sensor_ids.end(), "0");
    info_.leading_tip = zero == info_.sensor_ids.end() ? 0 : static_cast<int>(zero - info_.sensor_ids.begin());
  }

  fs::path config_path() const { return info_.path.parent_path() / pdpsim::config_file; }

  std::optional<std::vector<std::array<double, 3>>> location_attribute(const Source& s) {
    const char* name = pdpsim::tip_position_attribute;
    if (H5Aexists(s.dataset.get(), name) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return std::nullopt;
    }
    Handle attribute(H5Aopen(s.dataset.get(), name, H5P_DEFAULT));
    Handle type(attribute.valid() ? H5Aget_type(attribute.get()) : H5I_INVALID_HID);
    Handle space(attribute.valid() ? H5Aget_space(attribute.get()) : H5I_INVALID_HID);
    if (!type.valid() || !space.valid()) {
      fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, s.name, hdf5_says()));
    }
    if (!numeric_class(type.get()) || damaged_number_type(type.get())) {
      fail(fmt::format("attribute '{}' of '{}' does not hold numbers: the file is damaged", name, s.name));
    }
    hsize_t dims[2] = {0, 0};
    if (H5Sget_simple_extent_ndims(space.get()) != 2 || H5Sget_simple_extent_dims(space.get(), dims, nullptr) != 2 ||
        dims[0] != static_cast<hsize_t>(s.channels) || dims[1] != 3) {
      fail(fmt::format("attribute '{}' of '{}' must hold one position x, y, z per column ({} x 3 values): the file "
                       "is damaged",
                       name, s.name, s.channels));
    }
    std::vector<double> values(static_cast<std::size_t>(s.channels) * 3);
    if (H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, values.data()) < 0) {
      fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, s.name, hdf5_says()));
    }
    std::vector<std::array<double, 3>> out;
    for (std::size_t c = 0; c < values.size(); c += 3) {
      if (!std::isfinite(values[c]) || !std::isfinite(values[c + 1]) || !std::isfinite(values[c + 2])) {
        fail(fmt::format("attribute '{}' of '{}': the position of column {} is not finite: the file is damaged",
                         name, s.name, c / 3));
      }
      out.push_back({values[c], values[c + 1], values[c + 2]});
    }
    return out;
  }

  // pdp-sim's config.json beside the file, by sensor id; none when there is
  // no such file or it describes no probe (another program's config.json).
  std::optional<std::vector<std::array<double, 3>>> configured_locations() const {
    const fs::path path = config_path();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return std::nullopt;
    std::ifstream in(path);
    nlohmann::json config;
    try {
      config = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      fail(fmt::format("{} beside it (pdp-sim's configuration, which states the tips) is not valid JSON ({}): "
                       "correct it, or move it away and declare the tips",
                       path.string(), e.what()));
    }
    if (!config.is_object() || !config.contains(pdpsim::config_probe)) return std::nullopt;
    const std::string where = fmt::format("{} ({}.{})", path.string(), pdpsim::config_probe, pdpsim::config_sensors);
    const auto& probe = config[pdpsim::config_probe];
    if (!probe.is_object() || !probe.contains(pdpsim::config_sensors) || !probe[pdpsim::config_sensors].is_array()) {
      fail(fmt::format("{} lists no sensors: correct it, or move it away and declare the tips", where));
    }
    std::vector<std::pair<std::string, std::array<double, 3>>> sensors;
    for (const auto& sensor : probe[pdpsim::config_sensors]) {
      const auto index = sensors.size();
      if (!sensor.is_object() || !sensor.contains(pdpsim::config_sensor_id) ||
          !sensor[pdpsim::config_sensor_id].is_number_integer() || !sensor.contains(pdpsim::config_location) ||
          !sensor[pdpsim::config_location].is_array() || sensor[pdpsim::config_location].size() != 3) {
        fail(fmt::format("{}: sensor {} needs an integer '{}' and a '{}' of three numbers (m)", where, index,
                         pdpsim::config_sensor_id, pdpsim::config_location));
      }
      std::array<double, 3> at{};
      for (std::size_t k = 0; k < 3; ++k) {
        const auto& v = sensor[pdpsim::config_location][k];
        if (!v.is_number() || !std::isfinite(v.get<double>())) {
          fail(fmt::format("{}: the '{}' of sensor {} holds a value that is not a finite number", where,
                           pdpsim::config_location, index));
        }
        at[k] = v.get<double>();
      }
      sensors.emplace_back(std::to_string(sensor[pdpsim::config_sensor_id].get<long long>()), at);
    }
    const auto columns = static_cast<std::size_t>(info_.channels);
    if (sensors.size() != columns) {
      fail(fmt::format("{} describes {} sensors but the file records {} channel{}: they belong to different runs; "
                       "correct config.json, or move it away and declare the tips recorded",
                       where, sensors.size(), columns, columns == 1 ? "" : "s"));
    }
    std::vector<std::array<double, 3>> out;
    for (std::size_t c = 0; c < columns; ++c) {
      // pdp-sim writes the ids in config.json's order; without ids, that order is the columns'.
      const std::string id = info_.sensor_ids.empty() ? sensors[c].first : info_.sensor_ids[c];
      const auto it = std::find_if(sensors.begin(), sensors.end(), [&id](const auto& x) { return x.first == id; });
      if (it == sensors.end()) {
        fail(fmt::format("column {} is sensor {}, which {} does not describe: they belong to different runs; "
                         "correct config.json, or move it away and declare the tips",
                         c, id, where));
      }
      out.push_back(it->second);
    }
    return out;
  }

  std::vector<std::string> sensor_ids(const Source& s, bool& numeric) {
    const char* name = pdpsim::sensor_id_attribute;
    if (H5Aexists(s.dataset.get(), name) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return {};
    }
    Handle attribute(H5Aopen(s.dataset.get(), name, H5P_DEFAULT));
    Handle type(attribute.valid() ? H5Aget_type(attribute.get()) : H5I_INVALID_HID);
    Handle space(attribute.valid() ? H5Aget_space(attribute.get()) : H5I_INVALID_HID);
    if (!type.valid() || !space.valid()) {
      fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, s.name, hdf5_says()));
    }
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (n != s.channels) {
      info_.warnings.push_back(fmt::format("attribute '{}' of '{}' lists {} ids for {} columns: the ids are not used",
                                           name, s.name, n, s.channels));
      return {};
    }
    const auto count = static_cast<std::size_t>(n);
    std::vector<std::string> ids;
    if (numeric_class(type.get())) {
      if (damaged_number_type(type.get())) {
        fail(fmt::format("attribute '{}' of '{}' has a damaged number type: the file is damaged", name, s.name));
      }
      std::vector<double> values(count);
      if (H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, values.data()) < 0) {
        fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, s.name, hdf5_says()));
      }
      numeric = true;
      for (double v : values) {
        ids.push_back(std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15 ? fmt::format("{:.0f}", v)
                                                                                     : fmt::format("{}", v));
      }
    } else if (H5Tget_class(type.get()) == H5T_STRING) {
      ids = strings(attribute.get(), type.get(), space.get(), count, name, s.name);
    } else {
      info_.warnings.push_back(
          fmt::format("attribute '{}' of '{}' holds neither numbers nor strings: the ids are not used", name, s.name));
    }
    return ids;
  }

  std::vector<std::string> strings(hid_t attribute, hid_t file_type, hid_t space, std::size_t count,
                                   const char* name, const std::string& where) {
    Handle memory(H5Tcopy(H5T_C_S1));
    std::vector<std::string> out;
    const htri_t variable = H5Tis_variable_str(file_type);
    if (!memory.valid() || variable < 0) {
      fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, where, hdf5_says()));
    }
    H5Tset_cset(memory.get(), H5Tget_cset(file_type));
    if (variable > 0) {
      H5Tset_size(memory.get(), H5T_VARIABLE);
      std::vector<char*> texts(count, nullptr);
      if (H5Aread(attribute, memory.get(), texts.data()) < 0) {
        fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, where, hdf5_says()));
      }
      for (auto* t : texts) out.emplace_back(t ? t : "");
      H5Dvlen_reclaim(memory.get(), space, H5P_DEFAULT, texts.data());
    } else {
      const std::size_t width = H5Tget_size(file_type);
      if (width == 0 || width > 4096) {
        fail(fmt::format("attribute '{}' of '{}' holds strings of {} bytes: the file is damaged", name, where, width));
      }
      H5Tset_size(memory.get(), width);
      std::vector<char> bytes(count * width, '\0');
      if (H5Aread(attribute, memory.get(), bytes.data()) < 0) {
        fail(fmt::format("attribute '{}' of '{}' cannot be read{}: the file is damaged", name, where, hdf5_says()));
      }
      for (std::size_t i = 0; i < count; ++i) {
        std::string t(bytes.data() + i * width, width);
        t.erase(std::find(t.begin(), t.end(), '\0'), t.end());
        while (!t.empty() && t.back() == ' ') t.pop_back();
        out.push_back(std::move(t));
      }
    }
    return out;
  }

  struct Rate {
    double fs;
    std::string where;
    double tolerance = 1e-6;  // relative, of a stated rate: a time base's is wider (time_base.hpp)
  };

  double rate(const ReaderOptions& options) {
    // Forced: the file's own rate (and its time base) is not consulted.
    if (options.override_fs && options.fs > 0.0) return options.fs;
    const auto attribute = rate_attribute();
    const auto timed = rate_from_time();
    if (attribute && timed && std::fabs(attribute->fs - timed->fs) > timed->tolerance * timed->fs) {
      fail(fmt::format("{} states a sampling rate of {} but {} steps at {}: one of them is wrong; correct the file, "
                       "or force the rate",
                       attribute->where, format_quantity(attribute->fs, Dimension::frequency), timed->where,
                       format_quantity(timed->fs, Dimension::frequency)),
           "override-fs");
    }
    if (attribute) return stated_rate(info_.path, options, attribute->fs, attribute->where);
    if (timed) return stated_rate(info_.path, options, timed->fs, timed->where, timed->tolerance);
    if (options.fs > 0.0) return options.fs;
    fail(fmt::format("dataset '{}' records no sampling rate (no attribute fs, Fs, sampling_rate, sample_rate, "
                     "sampling_frequency, dt, wf_increment or sampling_interval on it, its group or the root, and no "
                     "'time' dataset beside it): state the sampling rate",
                     sources_.front().name),
         "fs");
  }

  // The first object (dataset, its group, the root) carrying a rate attribute;
  // several rate attributes there must agree.
  std::optional<Rate> rate_attribute() {
    static constexpr std::array<std::pair<const char*, bool>, 8> names{{{"fs", true},
                                                                         {"Fs", true},
                                                                         {"sampling_rate", true},
                                                                         {"sample_rate", true},
                                                                         {"sampling_frequency", true},
                                                                         {"dt", false},
                                                                         {"wf_increment", false},
                                                                         {"sampling_interval", false}}};
    const std::string dataset = sources_.front().name;
    std::vector<std::string> objects{dataset};
    if (parent_of(dataset) != "/") objects.push_back(parent_of(dataset));
    objects.emplace_back("/");
    for (const auto& where : objects) {
      Handle object(H5Oopen(file_.get(), where.c_str(), H5P_DEFAULT));
      if (!object.valid()) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      const std::string shown = where == "/" ? std::string("the root group") : "'" + where + "'";
      std::optional<Rate> found;
      for (const auto& [name, hertz] : names) {
        const auto v = number_attribute(object.get(), name, where);
        if (!v) continue;
        if (!(std::isfinite(*v) && *v > 0.0)) {
          fail(fmt::format("attribute '{}' of {} is {}: a {} must be positive; correct it, or force the rate", name,
                           shown, *v, hertz ? "sampling rate" : "sampling interval"),
               "override-fs");
        }
        const Rate r{hertz ? *v : 1.0 / *v, fmt::format("attribute '{}' of {}", name, shown)};
        if (found && std::fabs(found->fs - r.fs) > 1e-6 * found->fs) {
          fail(fmt::format("{} and {} give sampling rates of {} and {}: correct the wrong one, or force the rate",
                           found->where, r.where, format_quantity(found->fs, Dimension::frequency),
                           format_quantity(r.fs, Dimension::frequency)),
               "override-fs");
        }
        if (!found) found = r;
      }
      if (found) return found;
    }
    return std::nullopt;
  }

  // The mean step of a `time` (or `t`) dataset beside the first dataset.
  std::optional<Rate> rate_from_time() {
    const std::string group_name = parent_of(sources_.front().name);
    Handle group(H5Oopen(file_.get(), group_name.c_str(), H5P_DEFAULT));
    if (!group.valid()) {
      H5Eclear2(H5E_DEFAULT);
      return std::nullopt;
    }
    for (const char* leaf : {pdpsim::time_dataset, "t"}) {
      if (H5Lexists(group.get(), leaf, H5P_DEFAULT) <= 0) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      const std::string name = (group_name == "/" ? "/" : group_name + "/") + leaf;
      Handle dataset(H5Oopen(group.get(), leaf, H5P_DEFAULT));
      if (!dataset.valid() || H5Iget_type(dataset.get()) != H5I_DATASET) {
        H5Eclear2(H5E_DEFAULT);
        continue;
      }
      return time_rate(name, dataset.get());
    }
    return std::nullopt;
  }

  std::optional<Rate> time_rate(const std::string& name, hid_t dataset) {
    Handle type(H5Dget_type(dataset));
    Handle space(H5Dget_space(dataset));
    if (!type.valid() || !space.valid()) {
      fail(fmt::format("dataset '{}' cannot be read{}: the file is damaged", name, hdf5_says()));
    }
    if (!numeric_class(type.get())) {
      fail(fmt::format("dataset '{}' is not numeric: a time base holds seconds; rename it, or force the rate", name),
           "override-fs");
    }
    const auto dims = dimensions(space.get(), name);
    const bool vector = dims.size() == 1 || (dims.size() == 2 && (dims[0] == 1 || dims[1] == 1));
    if (!vector) {
      fail(fmt::format("dataset '{}' has shape {}: a time base is one value per sample; correct it, or force the "
                       "rate",
                       name, shape_text(dims)),
           "override-fs");
    }
    hsize_t n = 1;
    for (auto d : dims) n *= d;
    if (n != static_cast<hsize_t>(info_.frames)) {
      fail(fmt::format("dataset '{}' holds {} values but '{}' holds {} samples: a time base has one value per "
                       "sample; correct the file, or force the rate",
                       name, n, sources_.front().name, info_.frames),
           "override-fs");
    }
    if (n < 2) return std::nullopt;
    // A time base cut short is refused, not read as zeros.
    check_storage(name, dataset, dims, H5Tget_size(type.get()), 1);
    std::optional<Kind> kind;
    if (const auto unread = classify(type.get(), kind); !kind) {
      fail(fmt::format("dataset '{}' holds {}: a time base is numbers; correct it, or force the rate", name, unread),
           "override-fs");
    }
    const bool floating = kind == Kind::f32 || kind == Kind::f64;
    TimeBase base;
    base.path = info_.path;
    base.name = fmt::format("dataset '{}'", name);
    base.where = [](std::uint64_t index) { return fmt::format("value {}", index); };
    base.float_bits = kind == Kind::f32 ? 24 : (floating ? 53 : 0);
    base.fix = "correct it, or force the rate";
    base.quantity = "override-fs";
    base.scan = [&](const TimeBase::Sink& sink) {
      Handle file_space(H5Dget_space(dataset));
      std::vector<double> values;
      for (hsize_t at = 0; at < n; at += kTimeBlock) {
        const hsize_t count = std::min(kTimeBlock, n - at);
        values.resize(static_cast<std::size_t>(count));
        Handle memory(H5Screate_simple(1, &count, nullptr));
        // A 2-D time base (MATLAB's 1 x n or n x 1) is selected as its flat run of elements.
        hsize_t start2[2] = {0, 0}, count2[2] = {0, 0};
        if (dims.size() == 2) {
          start2[0] = dims[0] == 1 ? 0 : at;
          start2[1] = dims[0] == 1 ? at : 0;
          count2[0] = dims[0] == 1 ? 1 : count;
          count2[1] = dims[0] == 1 ? count : 1;
        }
        const herr_t selected =
            dims.size() == 1 ? H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &at, nullptr, &count, nullptr)
                             : H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start2, nullptr, count2, nullptr);
        if (selected < 0 ||
            H5Dread(dataset, H5T_NATIVE_DOUBLE, memory.get(), file_space.get(), H5P_DEFAULT, values.data()) < 0) {
          fail(fmt::format("dataset '{}' cannot be read at values {} to {}{}: the file is damaged", name, at,
                           at + count, hdf5_says()));
        }
        sink(at, values);
      }
      // Integers count whole units of the time base.
      return TimeBaseScan{n, floating ? 0.0 : 1.0};
    };
    const auto rate = time_base_rate(base);
    return Rate{rate.fs, base.name, rate.tolerance};
  }

  // "HDF5 '/signal' (pdp-sim layout, uint8, normalised units)": the channel
  // count and rate are reported beside it.
  void describe() {
    const KindInfo k = info_of(kind_);
    std::string names;
    for (const auto& s : sources_) names += (names.empty() ? "'" : ", '") + s.name + "'";
    std::string layout;
    for (const auto& s : sources_) {
      if (s.transposed) {
        layout += fmt::format(", {}stored channels x samples ({}) and read transposed",
                              sources_.size() > 1 ? "'" + s.name + "' " : std::string(), shape_text(s.dims));
      }
    }
    const char* units = k.integer ? (info_.volts_known ? ", volts" : ", normalised units") : ", volts";
    info_.description =
        fmt::format("HDF5 {} ({}{}{}{})", names, pdpsim_ ? "pdp-sim layout, " : "", k.name, units, layout);
  }

  // The next n frames of every source, as stored, into buffers_.
  void fetch(std::int64_t n) {
    const auto count = static_cast<hsize_t>(n);
    const auto at = static_cast<hsize_t>(position_);
    buffers_.resize(sources_.size());
    LibraryLock lock;
    for (std::size_t s = 0; s < sources_.size(); ++s) {
      auto& src = sources_[s];
      const auto width = static_cast<hsize_t>(src.channels);
      buffers_[s].resize(static_cast<std::size_t>(count * width) * info_of(kind_).size);
      herr_t selected = -1;
      Handle memory;
      if (src.dims.size() == 1) {
        selected = H5Sselect_hyperslab(src.space.get(), H5S_SELECT_SET, &at, nullptr, &count, nullptr);
        memory = Handle(H5Screate_simple(1, &count, nullptr));
      } else {
        const hsize_t start[2] = {src.transposed ? 0 : at, src.transposed ? at : 0};
        const hsize_t extent[2] = {src.transposed ? width : count, src.transposed ? count : width};
        selected = H5Sselect_hyperslab(src.space.get(), H5S_SELECT_SET, start, nullptr, extent, nullptr);
        memory = Handle(H5Screate_simple(2, extent, nullptr));
      }
      if (selected < 0 || !memory.valid() ||
          H5Dread(src.dataset.get(), memory_type(kind_), memory.get(), src.space.get(), H5P_DEFAULT,
                  buffers_[s].data()) < 0) {
        fail(fmt::format("dataset '{}' cannot be read at frames {} to {}{}: the file is damaged", src.name, at,
                         at + count, hdf5_says()));
      }
    }
  }

  template <class T>
  void convert(std::size_t s, std::int64_t n, std::size_t first, std::size_t channels, std::span<float> out) {
    const auto& src = sources_[s];
    const auto width = static_cast<std::size_t>(src.channels);
    const double quantum = info_.quantum;
    interleave(static_cast<std::size_t>(n), width, src.transposed, stored<T>(buffers_[s]), out, channels, first,
               [&](T v, std::size_t i, std::size_t c) {
                 if constexpr (std::is_integral_v<T>) {
                   return static_cast<float>(static_cast<double>(v) * quantum);
                 } else {
                   const auto o = static_cast<float>(v);
                   if (!std::isfinite(o)) [[unlikely]] {
                     fail(fmt::format("sample {} of '{}'{} is {}: the recording is damaged (or beyond single "
                                      "precision); repair or cut it before processing",
                                      position_ + static_cast<std::int64_t>(i), src.name,
                                      width > 1 ? fmt::format(" column {}", c) : std::string(),
                                      std::isnan(v) ? "NaN" : (std::isinf(v) ? "infinite" : "too large for a float")));
                   }
                   return o;
                 }
               });
  }

  // What the recording holds of libhdf5, released under the lock whether the
  // recording ends or its constructor throws (after its own lock is gone).
  struct Held {
    Handle file;
    std::vector<Source> sources;
  };
  struct ReleaseUnderLock {
    void operator()(Held* held) const {
      LibraryLock lock;
      delete held;
    }
  };
  std::unique_ptr<Held, ReleaseUnderLock> held_{new Held};
  Handle& file_ = held_->file;
  std::vector<Source>& sources_ = held_->sources;
  std::vector<std::vector<unsigned char>> buffers_;
  Kind kind_ = Kind::f64;
  bool pdpsim_ = false;
  std::uint64_t file_size_ = 0;
  std::uint64_t cache_bytes_ = 0;  // chunk cache each chunked dataset needs
  std::int64_t position_ = 0;
};

}  // namespace

bool hdf5_magic(const fs::path& path) {
  static constexpr char signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(path, std::ios::binary);
  // At 0, or after a user block of 512, 1024, 2048, ... bytes.
  for (std::uint64_t at = 0; in; at = at == 0 ? 512 : 2 * at) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    char m[8] = {};
    in.read(m, 8);
    if (in.gcount() < 8) return false;
    if (std::memcmp(m, signature, 8) == 0) return true;
    if (at > (std::uint64_t{1} << 50)) return false;
  }
  return false;
}

std::unique_ptr<Recording> open_hdf5(const fs::path& path, const ReaderOptions& options) {
  return std::make_unique<Hdf5Recording>(path, options);
}

}  // namespace awcc::detail
