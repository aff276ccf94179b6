// MATLAB MAT-file reader (awcc/recording.hpp): level 5 files (MathWorks'
// "MAT-File Format": a 128-byte text header, then one data element per
// variable, miMATRIX or, from MATLAB 7 on, miCOMPRESSED holding a zlib
// stream of one) and v7.3 files (HDF5 behind a 512-byte MATLAB user block),
// through matio.
//
// matio lists the variables (names, classes, sizes, without their data) and
// reads slabs of v7.3 and uncompressed v5 variables. Three things are done
// here instead:
//  - matio reads past the end of a truncated v5 file without a word (zeros
//    or whatever memory held come back), so the top-level elements are walked
//    here first: each variable must lie inside the file and hold the values
//    its dimensions claim;
//  - a slab of a compressed v5 variable costs matio an inflation from the
//    variable's start (0.45 s per 65536-frame block of a 10^7 x 2 double
//    matrix, over a minute for one pass that inflates whole in 0.5 s), so
//    compressed variables are inflated here with zlib, forward only, one
//    stream per channel: memory stays flat and a pass costs one inflation
//    (and the skip over the channels before each one);
//  - matio opens a truncated v7.3 file without an error and then shows no
//    variables, so HDF5 is asked first.
// Every matio call holds detail::hdf5_library_mutex(): matio keeps global
// state (its log), and its v7.3 half is libhdf5, thread-safe only when built
// so (Debian bookworm's 1.10.8 is; other builds need not be). HDF5's error
// printing is off meanwhile and matio's log kept for the refusal's text: the
// caller's message is the only one a bad file produces.
#include <hdf5.h>
#include <matio.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <optional>
#include <type_traits>

#include "awcc/detail/columns.hpp"
#include "awcc/detail/time_base.hpp"
#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc::detail {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// matio under the library lock.

std::string& matio_said() {
  static std::string said;  // guarded by hdf5_library_mutex()
  return said;
}

void keep_matio_message(int level, char* message) {
  if (message && (level & (MATIO_LOG_LEVEL_ERROR | MATIO_LOG_LEVEL_CRITICAL | MATIO_LOG_LEVEL_WARNING))) {
    matio_said() = message;
  }
}

// HDF5 1.10 leaks a little on the error paths of some damaged files, and its
// library shutdown at exit then prints "HDF5: infinite loop closing library"
// to stderr while its error printing is on. Run before that shutdown (exit
// handlers run in reverse order, and HDF5 registered its own when it
// started, before the first lock), this turns the printing off.
void quiet_hdf5_at_exit() {
  // A thread still inside HDF5 at exit keeps the lock: better the message
  // than a process that never ends.
  std::unique_lock<std::mutex> lock(hdf5_library_mutex(), std::try_to_lock);
  if (lock.owns_lock()) H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

class MatioLock {
 public:
  MatioLock() : lock_(hdf5_library_mutex()) {
    H5Eget_auto2(H5E_DEFAULT, &handler_, &handler_data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    static bool started = false;
    if (!started) {
      // matio's default log prints to stderr when a program set it up; this
      // one keeps the last message. Mat_LogInitFunc also points HDF5's error
      // printing at matio's log: the destructor puts back what was there.
      Mat_LogInitFunc("awcc", &keep_matio_message);
      std::atexit(&quiet_hdf5_at_exit);
      started = true;
    }
    matio_said().clear();
  }
  ~MatioLock() { H5Eset_auto2(H5E_DEFAULT, handler_, handler_data_); }
  MatioLock(const MatioLock&) = delete;
  MatioLock& operator=(const MatioLock&) = delete;

  // What matio logged since the lock was taken, as a clause for a refusal.
  [[nodiscard]] static std::string said() {
    const auto& s = matio_said();
    return s.empty() ? std::string() : fmt::format(" (matio: {})", s);
  }

 private:
  std::lock_guard<std::mutex> lock_;
  H5E_auto2_t handler_ = nullptr;
  void* handler_data_ = nullptr;
};

// The deleters take the lock: never let one run while it is held.
struct MatCloser {
  void operator()(mat_t* m) const noexcept {
    MatioLock lock;
    Mat_Close(m);
  }
};
struct VarFreer {
  void operator()(matvar_t* v) const noexcept {
    MatioLock lock;
    Mat_VarFree(v);
  }
};
using MatFile = std::unique_ptr<mat_t, MatCloser>;
using MatVar = std::unique_ptr<matvar_t, VarFreer>;

// ---------------------------------------------------------------------------
// Values: the numeric types of a class or of a v5 data element.

enum class Kind { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };

std::size_t size_of(Kind k) {
  switch (k) {
    case Kind::i8: case Kind::u8: return 1;
    case Kind::i16: case Kind::u16: return 2;
    case Kind::i32: case Kind::u32: case Kind::f32: return 4;
    case Kind::i64: case Kind::u64: case Kind::f64: return 8;
  }
  return 8;
}

std::optional<Kind> kind_of_class(int c) {
  switch (c) {
    case MAT_C_DOUBLE: return Kind::f64;
    case MAT_C_SINGLE: return Kind::f32;
    case MAT_C_INT8: return Kind::i8;
    case MAT_C_UINT8: return Kind::u8;
    case MAT_C_INT16: return Kind::i16;
    case MAT_C_UINT16: return Kind::u16;
    case MAT_C_INT32: return Kind::i32;
    case MAT_C_UINT32: return Kind::u32;
    case MAT_C_INT64: return Kind::i64;
    case MAT_C_UINT64: return Kind::u64;
    default: return std::nullopt;
  }
}

// v5 data types (miINT8 ...), as the real part of a numeric array may be
// stored in a smaller type than its class (MATLAB saves whole-number doubles
// as miUINT8 and the like).
constexpr std::uint32_t miINT8 = 1, miUINT8 = 2, miINT32 = 5, miUINT32 = 6, miMATRIX = 14, miCOMPRESSED = 15;

std::optional<Kind> kind_of_stored(std::uint32_t t) {
  switch (t) {
    case 1: return Kind::i8;
    case 2: return Kind::u8;
    case 3: return Kind::i16;
    case 4: return Kind::u16;
    case 5: return Kind::i32;
    case 6: return Kind::u32;
    case 7: return Kind::f32;
    case 9: return Kind::f64;
    case 12: return Kind::i64;
    case 13: return Kind::u64;
    default: return std::nullopt;
  }
}

std::string class_name(int c, bool logical, bool complex) {
  if (logical) return "logical";
  std::string name;
  switch (c) {
    case MAT_C_EMPTY: return "empty";
    case MAT_C_CELL: return "cell";
    case MAT_C_STRUCT: return "struct";
    case MAT_C_OBJECT: return "object";
    case MAT_C_CHAR: return "char";
    case MAT_C_SPARSE: return complex ? "complex sparse" : "sparse";
    case MAT_C_DOUBLE: name = "double"; break;
    case MAT_C_SINGLE: name = "single"; break;
    case MAT_C_INT8: name = "int8"; break;
    case MAT_C_UINT8: name = "uint8"; break;
    case MAT_C_INT16: name = "int16"; break;
    case MAT_C_UINT16: name = "uint16"; break;
    case MAT_C_INT32: name = "int32"; break;
    case MAT_C_UINT32: name = "uint32"; break;
    case MAT_C_INT64: name = "int64"; break;
    case MAT_C_UINT64: name = "uint64"; break;
    case MAT_C_FUNCTION: return "function handle";
    case MAT_C_OPAQUE: return "opaque object";
    default: return fmt::format("class {}", c);
  }
  return complex ? "complex " + name : name;
}

template <class Out>
void convert(const unsigned char* p, Kind kind, std::size_t n, bool swap, Out* out) {
  switch (kind) {
    case Kind::i8: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::int8_t>(p + i, swap)); break;
    case Kind::u8: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::uint8_t>(p + i, swap)); break;
    case Kind::i16: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::int16_t>(p + 2 * i, swap)); break;
    case Kind::u16: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::uint16_t>(p + 2 * i, swap)); break;
    case Kind::i32: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::int32_t>(p + 4 * i, swap)); break;
    case Kind::u32: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::uint32_t>(p + 4 * i, swap)); break;
    case Kind::i64: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::int64_t>(p + 8 * i, swap)); break;
    case Kind::u64: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<std::uint64_t>(p + 8 * i, swap)); break;
    case Kind::f32: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<float>(p + 4 * i, swap)); break;
    case Kind::f64: for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Out>(load<double>(p + 8 * i, swap)); break;
  }
}

// Dimensions multiplied, or nullopt past 2^53 values (no file holds them).
std::optional<std::uint64_t> product(const std::vector<std::uint64_t>& dims) {
  std::uint64_t n = 1;
  for (auto d : dims) {
    if (d != 0 && n > (std::uint64_t{1} << 53) / d) return std::nullopt;
    n *= d;
  }
  return n;
}

std::string size_text(const std::vector<std::uint64_t>& dims) {
  std::string s;
  for (auto d : dims) s += (s.empty() ? "" : "x") + std::to_string(d);
  return s;
}

// ---------------------------------------------------------------------------
// A zlib stream inside the file (a compressed v5 variable), read forward.

class Inflater {
 public:
  Inflater(const fs::path& path, std::uint64_t offset, std::uint64_t bytes, std::string what)
      : path_(path), in_(path, std::ios::binary), offset_(offset), bytes_(bytes), what_(std::move(what)) {
    if (!in_) reader_fail(path_, "cannot open for reading");
    z_ = {};
    if (inflateInit(&z_) != Z_OK) reader_fail(path_, "zlib cannot start inflating (out of memory?)");
    restart();
  }
  ~Inflater() { inflateEnd(&z_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  void restart() {
    inflateReset(&z_);
    z_.avail_in = 0;
    fed_ = 0;
    position_ = 0;
    ended_ = false;
  }

  // Bytes of the inflated stream handed out so far.
  [[nodiscard]] std::uint64_t position() const { return position_; }

  // Up to n inflated bytes into `out`; fewer only at the stream's end.
  std::size_t read_some(unsigned char* out, std::size_t n) {
    std::size_t done = 0;
    while (done < n && !ended_) {
      if (z_.avail_in == 0 && fed_ < bytes_) {
        const std::uint64_t left = bytes_ - fed_;
        input_.resize(std::min<std::uint64_t>(left, 1 << 16));
        in_.clear();
        in_.seekg(static_cast<std::streamoff>(offset_ + fed_));
        in_.read(reinterpret_cast<char*>(input_.data()), static_cast<std::streamsize>(input_.size()));
        if (in_.gcount() != static_cast<std::streamsize>(input_.size())) {
          reader_fail(path_, fmt::format("the compressed data of {} cannot be read: the file changed or is damaged", what_));
        }
        fed_ += input_.size();
        z_.next_in = input_.data();
        z_.avail_in = static_cast<uInt>(input_.size());
      }
      const std::size_t want = std::min<std::size_t>(n - done, std::size_t{1} << 30);
      z_.next_out = out + done;
      z_.avail_out = static_cast<uInt>(want);
      const int rc = inflate(&z_, Z_NO_FLUSH);
      done += want - z_.avail_out;
      if (rc == Z_STREAM_END) {
        ended_ = true;
      } else if (rc == Z_BUF_ERROR || (rc == Z_OK && z_.avail_in == 0 && want == z_.avail_out)) {
        // No progress: inflate wants input, and the element has no more.
        if (z_.avail_in == 0 && fed_ == bytes_) {
          reader_fail(path_, fmt::format("the compressed data of {} end after {} inflated bytes, inside the zlib "
                                         "stream: the file is truncated or damaged",
                                         what_, position_ + done));
        }
      } else if (rc != Z_OK) {
        reader_fail(path_, fmt::format("the compressed data of {} are damaged (zlib: {}, after {} inflated bytes)", what_,
                                       z_.msg ? z_.msg : zError(rc), position_ + done));
      }
    }
    position_ += done;
    return done;
  }

  // Exactly n bytes, or a refusal naming what they were for.
  void read(unsigned char* out, std::size_t n) {
    const auto got = read_some(out, n);
    if (got < n) {
      reader_fail(path_, fmt::format("the compressed data of {} end after {} bytes, before the values its dimensions "
                                     "claim: the file is damaged",
                                     what_, position_));
    }
  }

  // Reads on to the stream's end, where zlib checks the Adler-32 sum of all
  // it inflated: a damaged stream that still inflated is caught here. At most
  // `slack` bytes (the padding after the values) may remain.
  void finish(std::size_t slack) {
    std::array<unsigned char, 64> rest{};
    (void)read_some(rest.data(), std::min(slack + 1, rest.size()));
  }

  void skip(std::uint64_t n) {
    std::array<unsigned char, 1 << 15> scratch{};
    while (n > 0) {
      const auto step = static_cast<std::size_t>(std::min<std::uint64_t>(n, scratch.size()));
      read(scratch.data(), step);
      n -= step;
    }
  }

 private:
  fs::path path_;
  std::ifstream in_;
  std::uint64_t offset_, bytes_;
  std::string what_;
  z_stream z_;
  std::vector<unsigned char> input_;
  std::uint64_t fed_ = 0, position_ = 0;
  bool ended_ = false;
};

// ---------------------------------------------------------------------------
// The v5 element walk.

struct V5Variable {
  std::string name;
  int cls = 0;
  bool complex = false, logical = false;
  std::vector<std::uint64_t> dims;
  std::uint64_t offset = 0;  // the element's tag in the file
  std::uint64_t bytes = 0;   // its body after the tag
  bool compressed = false;
  std::optional<Kind> stored;    // numeric arrays: the real part's type
  std::uint64_t data = 0;        // its first value: in the file, or in the inflated stream
  std::uint64_t data_bytes = 0;
};

// A little cursor over the start of a matrix element (tag included).
class SubElements {
 public:
  SubElements(const std::vector<unsigned char>& b, bool swap) : b_(b), swap_(swap) {}
  struct Sub {
    std::uint32_t type;
    std::uint64_t bytes, at, next;
  };
  // The subelement at `pos`, normal or small (<= 4 bytes packed into the tag).
  [[nodiscard]] std::optional<Sub> at(std::uint64_t pos) const {
    if (pos + 8 > b_.size()) return std::nullopt;
    const auto first = load<std::uint32_t>(b_.data() + pos, swap_);
    if (first >> 16) return Sub{first & 0xFFFFu, first >> 16, pos + 4, pos + 8};
    const std::uint64_t bytes = load<std::uint32_t>(b_.data() + pos + 4, swap_);
    return Sub{first, bytes, pos + 8, pos + 8 + (bytes + 7) / 8 * 8};
  }
  [[nodiscard]] bool holds(std::uint64_t pos, std::uint64_t n) const { return pos <= b_.size() && n <= b_.size() - pos; }
  [[nodiscard]] std::uint32_t u32(std::uint64_t pos) const { return load<std::uint32_t>(b_.data() + pos, swap_); }
  [[nodiscard]] std::int32_t i32(std::uint64_t pos) const { return load<std::int32_t>(b_.data() + pos, swap_); }
  [[nodiscard]] const std::vector<unsigned char>& bytes() const { return b_; }

 private:
  const std::vector<unsigned char>& b_;
  bool swap_;
};

enum class Parse { done, short_buffer };

// Flags, dimensions, name and the real part's tag of the matrix element in
// `b` (from its tag). short_buffer: `b` ends inside them.
Parse parse_matrix(const fs::path& path, const std::vector<unsigned char>& b, bool swap, V5Variable& v,
                   const std::string& where) {
  const SubElements s(b, swap);
  auto bad = [&](const std::string& what) {
    reader_fail(path, fmt::format("{}: {}: the file is damaged, or not a MAT-file", where, what));
  };
  if (b.size() < 8) return Parse::short_buffer;
  const std::uint32_t type = s.u32(0);
  if (type != miMATRIX) bad(fmt::format("the element's data type is {}, not miMATRIX (14)", type));
  const std::uint64_t end = 8 + std::uint64_t{s.u32(4)};  // the matrix element's last byte + 1
  if (end == 8) {
    v.cls = MAT_C_EMPTY;  // an empty array may be written as an empty element
    v.dims = {0, 0};
    return Parse::done;
  }
  const auto flags = s.at(8);
  if (!flags || !s.holds(flags->at, 8)) return Parse::short_buffer;
  if (flags->type != miUINT32 || flags->bytes != 8) bad("its array flags are not two uint32");
  const std::uint32_t word = s.u32(flags->at);
  v.cls = static_cast<int>(word & 0xFFu);
  v.complex = (word & MAT_F_COMPLEX) != 0;
  v.logical = (word & MAT_F_LOGICAL) != 0;
  if (v.cls == MAT_C_FUNCTION || v.cls == MAT_C_OPAQUE) {
    return Parse::done;  // no dimensions where numeric arrays have them
  }
  const auto dims = s.at(flags->next);
  if (!dims) return Parse::short_buffer;
  if (dims->type != miINT32 || dims->bytes % 4 != 0 || dims->bytes < 8 || dims->bytes > 4 * 64) {
    bad(fmt::format("its dimensions subelement (type {}, {} bytes) is not 2 to 64 int32", dims->type, dims->bytes));
  }
  if (!s.holds(dims->at, dims->bytes)) return Parse::short_buffer;
  v.dims.clear();
  for (std::uint64_t k = 0; k < dims->bytes / 4; ++k) {
    const std::int32_t d = s.i32(dims->at + 4 * k);
    if (d < 0) bad(fmt::format("dimension {} is {}", k + 1, d));
    v.dims.push_back(static_cast<std::uint64_t>(d));
  }
  const auto name = s.at(dims->next);
  if (!name) return Parse::short_buffer;
  if ((name->type != miINT8 && name->type != miUINT8) || name->bytes > 4096) {
    bad(fmt::format("its name subelement (type {}, {} bytes) is not a name", name->type, name->bytes));
  }
  if (!s.holds(name->at, name->bytes)) return Parse::short_buffer;
  v.name.assign(reinterpret_cast<const char*>(b.data() + name->at), static_cast<std::size_t>(name->bytes));
  if (name->next > end) bad("its name runs past the element");
  if (!kind_of_class(v.cls) || v.cls == MAT_C_SPARSE) return Parse::done;
  const auto real = s.at(name->next);
  if (!real) return Parse::short_buffer;
  v.stored = kind_of_stored(real->type);
  if (!v.stored) bad(fmt::format("variable '{}' stores its values as data type {}, not a number", v.name, real->type));
  v.data = real->at;
  v.data_bytes = real->bytes;
  const auto n = product(v.dims);
  if (!n) bad(fmt::format("variable '{}' claims {} values", v.name, size_text(v.dims)));
  if (real->bytes / size_of(*v.stored) < *n) {
    reader_fail(path, fmt::format("{}: variable '{}' claims {} values ({}) but its data hold {} bytes, {} values: the "
                                  "file is damaged",
                                  where, v.name, *n, size_text(v.dims), real->bytes, real->bytes / size_of(*v.stored)));
  }
  if (real->at + real->bytes > end) {
    bad(fmt::format("the values of variable '{}' ({} bytes) run past its element ({} bytes)", v.name, real->bytes, end - 8));
  }
  return Parse::done;
}

std::vector<V5Variable> walk_v5(const fs::path& path, std::uint64_t size, bool swap) {
  std::ifstream in(path, std::ios::binary);
  std::vector<V5Variable> out;
  std::uint64_t at = 128;
  while (at < size) {
    const std::uint64_t left = size - at;
    unsigned char tag[8] = {};
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    in.read(reinterpret_cast<char*>(tag), static_cast<std::streamsize>(std::min<std::uint64_t>(left, 8)));
    if (left < 8) {
      if (std::all_of(tag, tag + left, [](unsigned char c) { return c == 0; })) break;  // padding
      reader_fail(path, fmt::format("{} stray bytes follow the last variable: the file is truncated or damaged", left));
    }
    const auto type = load<std::uint32_t>(tag, swap);
    const std::uint64_t bytes = load<std::uint32_t>(tag + 4, swap);
    const std::string where = fmt::format("variable {} (the element at byte {})", out.size() + 1, at);
    if (type != miMATRIX && type != miCOMPRESSED) {
      reader_fail(path, fmt::format("{} has data type {}, where a variable (miMATRIX 14, miCOMPRESSED 15) belongs: the "
                                    "file is damaged, or not a MAT-file",
                                    where, type));
    }
    if (bytes > left - 8) {
      reader_fail(path, fmt::format("{} claims {} bytes but the file ends {} bytes later: it is truncated (a copy cut "
                                    "short?); copy the whole file again",
                                    where, bytes, left - 8));
    }
    V5Variable v;
    v.offset = at;
    v.bytes = bytes;
    v.compressed = type == miCOMPRESSED;
    // The header (flags, dimensions, name, the values' tag) fits in a few
    // hundred bytes; a long name or many dimensions take a second look.
    for (std::size_t look : {std::size_t{512}, std::size_t{1} << 16}) {
      std::vector<unsigned char> head;
      if (v.compressed) {
        Inflater z(path, at + 8, bytes, where);
        head.resize(look);
        head.resize(z.read_some(head.data(), look));
      } else {
        head.resize(static_cast<std::size_t>(std::min<std::uint64_t>(bytes + 8, look)));
        in.clear();
        in.seekg(static_cast<std::streamoff>(at));
        in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
      }
      if (parse_matrix(path, head, swap, v, where) == Parse::done) break;
      if (look > 512 || head.size() < look) {
        reader_fail(path, fmt::format("{}: its header runs past the element: the file is damaged", where));
      }
    }
    if (v.stored) {
      const auto n = *product(v.dims);
      if (v.compressed) {
        // zlib inflates at most 1032 bytes from one.
        if (n * size_of(*v.stored) / 1032 > bytes + 64) {
          reader_fail(path, fmt::format("{}: variable '{}' claims {} values ({}) in {} compressed bytes, more than zlib "
                                        "can inflate from them: the file is damaged",
                                        where, v.name, n, size_text(v.dims), bytes));
        }
      } else {
        v.data += at;  // from the element's tag to the file
      }
    }
    out.push_back(std::move(v));
    at += 8 + bytes;
  }
  return out;
}

// A v4 MAT-file has no text header: its first matrix header is five int32
// (type MOPT, rows, columns, imaginary flag, name length) and the name.
bool looks_like_v4(const unsigned char* h, std::size_t n) {
  if (n < 21) return false;
  for (bool swap : {false, true}) {
    const auto type = load<std::int32_t>(h, swap), rows = load<std::int32_t>(h + 4, swap),
               cols = load<std::int32_t>(h + 8, swap), imag = load<std::int32_t>(h + 12, swap),
               namelen = load<std::int32_t>(h + 16, swap);
    const int m = type / 1000, o = type / 100 % 10, p = type / 10 % 10, t = type % 10;
    if (type < 0 || m > 4 || o != 0 || p > 5 || t > 2 || rows < 0 || cols < 0 || (imag != 0 && imag != 1) ||
        namelen < 2 || namelen > 64 || static_cast<std::size_t>(20 + namelen) > n || h[20 + namelen - 1] != 0) {
      continue;
    }
    if (std::all_of(h + 20, h + 20 + namelen - 1, [](unsigned char c) { return c >= 32 && c < 127; })) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------
// The variables as matio lists them.

struct Variable {
  std::string name;
  int cls = 0;
  bool complex = false, logical = false;
  std::vector<std::uint64_t> dims;

  [[nodiscard]] std::uint64_t elements() const { return product(dims).value_or(0); }
  [[nodiscard]] bool numeric() const { return kind_of_class(cls) && !complex; }
  [[nodiscard]] bool matrix2d() const { return dims.size() == 2; }
  [[nodiscard]] bool vector() const {
    return matrix2d() && (dims[0] == 1 || dims[1] == 1) && elements() > 1;
  }
  [[nodiscard]] std::string describe() const {
    return fmt::format("{} ({} {})", name, size_text(dims), class_name(cls, logical, complex));
  }
};

std::string listing(const std::vector<Variable>& vars, bool numeric_only) {
  std::string s;
  for (const auto& v : vars) {
    if (numeric_only && !v.numeric()) continue;
    s += (s.empty() ? "" : ", ") + v.describe();
  }
  if (s.empty() && numeric_only) return "none (its other variables: " + listing(vars, false) + ")";
  return s.empty() ? "none" : s;
}

// ---------------------------------------------------------------------------
// Where a variable's values come from.

class Source {
 public:
  virtual ~Source() = default;
  // `count` values from element `first` (column-major order), converted.
  virtual void get(std::uint64_t first, std::size_t count, double* out) = 0;
  virtual void get(std::uint64_t first, std::size_t count, std::int16_t* out) = 0;
};

// v7.3 and uncompressed v5: matio's slab reads, in the class's own type.
class MatioSource final : public Source {
 public:
  MatioSource(const fs::path& path, mat_t* mat, const Variable& v, bool v73) : path_(path), mat_(mat), v73_(v73) {
    name_ = v.name;
    kind_ = *kind_of_class(v.cls);
    rows_ = v.dims[0];
    matvar_t* raw = nullptr;
    std::string why;
    {
      MatioLock lock;
      raw = Mat_VarReadInfo(mat_, v.name.c_str());
      if (!raw) why = MatioLock::said();
    }
    var_.reset(raw);
    if (!var_) reader_fail(path_, fmt::format("variable '{}' cannot be opened{}: the file is damaged", v.name, why));
  }

  void get(std::uint64_t first, std::size_t count, double* out) override {
    fetch(first, count);
    convert(bytes_.data(), kind_, count, false, out);
  }
  void get(std::uint64_t first, std::size_t count, std::int16_t* out) override {
    fetch(first, count);
    convert(bytes_.data(), kind_, count, false, out);
  }

 private:
  void fetch(std::uint64_t first, std::size_t count) {
    bytes_.resize(count * size_of(kind_));
    int rc = 0;
    std::string why;
    {
      MatioLock lock;
      const std::uint64_t column = first / rows_, last_column = (first + count - 1) / rows_;
      if (!v73_) {
        // v5: one contiguous run, read as fast as the file allows.
        rc = Mat_VarReadDataLinear(mat_, var_.get(), bytes_.data(), static_cast<int>(first), 1, static_cast<int>(count));
      } else if (column == last_column || (first % rows_ == 0 && count % rows_ == 0)) {
        // v7.3: a 2-D hyperslab (matio's linear reads select point by point, 30 times slower).
        const bool within = column == last_column;
        int start[2] = {static_cast<int>(first % rows_), static_cast<int>(column)};
        int stride[2] = {1, 1};
        int edge[2] = {within ? static_cast<int>(count) : static_cast<int>(rows_),
                       within ? 1 : static_cast<int>(count / rows_)};
        rc = Mat_VarReadData(mat_, var_.get(), bytes_.data(), start, stride, edge);
      } else {
        rc = Mat_VarReadDataLinear(mat_, var_.get(), bytes_.data(), static_cast<int>(first), 1, static_cast<int>(count));
      }
      if (rc != 0) why = MatioLock::said();
    }
    if (rc != 0) {
      // Counted from 1, as MATLAB counts.
      const auto which = count == 1 ? fmt::format("value {}", first + 1)
                                    : fmt::format("values {} to {}", first + 1, first + count);
      reader_fail(path_, fmt::format("{} of variable '{}' cannot be read{}: the file is damaged", which, name_, why));
    }
  }

  fs::path path_;
  mat_t* mat_;
  bool v73_;
  std::string name_;
  Kind kind_ = Kind::f64;
  std::uint64_t rows_ = 1;
  MatVar var_;
  std::vector<unsigned char> bytes_;
};

// Compressed v5: inflated here, forward only. One stream per channel of a
// matrix (its columns lie one after another in the stream), each reused
// from where it stopped; a stream behind is restarted from the top.
class InflateSource final : public Source {
 public:
  InflateSource(const fs::path& path, const V5Variable& v, bool swap, std::size_t streams)
      : path_(path), v_(v), swap_(swap), streams_(std::max<std::size_t>(streams, 1)) {}

  void get(std::uint64_t first, std::size_t count, double* out) override {
    fetch(first, count);
    convert(bytes_.data(), *v_.stored, count, swap_, out);
  }
  void get(std::uint64_t first, std::size_t count, std::int16_t* out) override {
    fetch(first, count);
    convert(bytes_.data(), *v_.stored, count, swap_, out);
  }

 private:
  void fetch(std::uint64_t first, std::size_t count) {
    const auto width = size_of(*v_.stored);
    const std::uint64_t target = v_.data + first * width;
    Inflater* best = nullptr;
    for (auto& z : inflaters_) {
      if (z->position() <= target && (!best || z->position() > best->position())) best = z.get();
    }
    if (!best) {
      if (inflaters_.size() < streams_) {
        inflaters_.push_back(std::make_unique<Inflater>(path_, v_.offset + 8, v_.bytes, fmt::format("variable '{}'", v_.name)));
        best = inflaters_.back().get();
      } else {
        best = std::max_element(inflaters_.begin(), inflaters_.end(), [](const auto& a, const auto& b) {
                 return a->position() < b->position();
               })->get();
        best->restart();
      }
    }
    best->skip(target - best->position());
    bytes_.resize(count * width);
    best->read(bytes_.data(), bytes_.size());
    if (target + bytes_.size() == v_.data + *product(v_.dims) * width) best->finish(8);
  }

  fs::path path_;
  V5Variable v_;
  bool swap_;
  std::size_t streams_;
  std::vector<std::unique_ptr<Inflater>> inflaters_;
  std::vector<unsigned char> bytes_;
};

// ---------------------------------------------------------------------------

constexpr std::array<std::string_view, 6> kRateNames{"fs", "Fs", "FS", "sampling_rate", "sample_rate", "sampling_frequency"};
constexpr std::array<std::string_view, 2> kIntervalNames{"dt", "Ts"};
constexpr std::array<std::string_view, 3> kTimeNames{"t", "time", "Time"};

// HDF5's innermost complaint on its error stack.
herr_t keep_innermost(unsigned, const H5E_error2_t* e, void* data) {
  if (e && e->desc) *static_cast<std::string*>(data) = e->desc;
  return 0;
}

class MatRecording final : public Recording {
 public:
  MatRecording(const fs::path& path, const ReaderOptions& options) {
    info_.path = path;
    std::error_code ec;
    const std::uint64_t size = fs::file_size(path, ec);
    if (ec) reader_fail(path, fmt::format("cannot read: {}", ec.message()));
    std::ifstream in(path, std::ios::binary);
    if (!in) reader_fail(path, "cannot open for reading");
    std::array<unsigned char, 128> header{};
    in.read(reinterpret_cast<char*>(header.data()), 128);
    const auto got = static_cast<std::size_t>(in.gcount());
    read_header(path, header.data(), got);
    if (v73_) {
      check_hdf5(path);
    } else {
      v5_ = walk_v5(path, size, swap_);
    }
    list_variables(path);
    choose_channels(path, options);
    open_sources(path);
    choose_rate(path, options);
    describe(options);
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    const std::int64_t n = std::min<std::int64_t>(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    const auto frames = static_cast<std::size_t>(n);
    const auto channels = static_cast<std::size_t>(info_.channels);
    values_.resize(frames * channels);
    gather(values_.data(), frames);
    for (std::size_t i = 0; i < frames * channels; ++i) {
      const double v = values_[i] * scale_;
      const auto f = static_cast<float>(v);
      if (!std::isfinite(f)) [[unlikely]] {
        reader_fail(info_.path, fmt::format("sample {} of channel {} ({}) is {}: the recording is damaged; repair or "
                                            "cut it before processing",
                                            position_ + static_cast<std::int64_t>(i / channels), i % channels,
                                            info_.channel_names[i % channels],
                                            std::isnan(v) ? "NaN" : (std::isinf(v) ? "infinite" : "beyond float range")));
      }
      out[i] = f;
    }
    position_ += n;
    return n;
  }

  void rewind() override { position_ = 0; }

  [[nodiscard]] bool has_int16() const override { return int16_; }

  std::int64_t read_int16(std::span<std::int16_t> out, std::int64_t max_frames) override {
    if (!int16_) return Recording::read_int16(out, max_frames);
    const std::int64_t n = std::min<std::int64_t>(max_frames, info_.frames - position_);
    if (n <= 0) return 0;
    gather(out.data(), static_cast<std::size_t>(n));
    position_ += n;
    return n;
  }

 private:
  enum class Layout { matrix, transposed, vectors };

  void read_header(const fs::path& path, const unsigned char* h, std::size_t n) {
    const std::string_view text(reinterpret_cast<const char*>(h), std::min<std::size_t>(n, 19));
    if (text != "MATLAB 5.0 MAT-file" && text != "MATLAB 7.3 MAT-file") {
      if (looks_like_v4(h, n)) {
        reader_fail(path, "a MATLAB v4 MAT-file (no 128-byte text header): only v5 and later are read; save it again "
                          "in MATLAB with save(..., '-v7') or '-v7.3'");
      }
      reader_fail(path, "not a MAT-file: it does not start with the text 'MATLAB 5.0 MAT-file' or 'MATLAB 7.3 "
                        "MAT-file'; check the file, or state its format", "format");
    }
    if (n < 128) reader_fail(path, fmt::format("the MAT-file header is cut short ({} of 128 bytes): the file is truncated", n));
    if (h[126] == 'I' && h[127] == 'M') {
      swap_ = std::endian::native == std::endian::big;
    } else if (h[126] == 'M' && h[127] == 'I') {
      swap_ = std::endian::native == std::endian::little;
    } else {
      reader_fail(path, "the MAT-file header's byte-order mark (bytes 126-127) is neither 'IM' nor 'MI': the file is damaged");
    }
    const auto version = load<std::uint16_t>(h + 124, swap_);
    if (version == 0x0200) {
      v73_ = true;
    } else if (version != 0x0100) {
      reader_fail(path, fmt::format("the MAT-file header gives version {:#06x}, neither 0x0100 (v5, v7) nor 0x0200 "
                                    "(v7.3): the file is damaged or of a newer kind",
                                    version));
    }
  }

  void check_hdf5(const fs::path& path) {
    std::string why;
    {
      MatioLock lock;
      const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
      if (f >= 0) {
        H5Fclose(f);
        return;
      }
      H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, &keep_innermost, &why);
      H5Eclear2(H5E_DEFAULT);
    }
    reader_fail(path, fmt::format("a v7.3 MAT-file whose HDF5 part cannot be opened (HDF5: {}): the file is truncated "
                                  "or damaged; copy the whole file again",
                                  why.empty() ? "no reason given" : why));
  }

  void list_variables(const fs::path& path) {
    mat_t* raw = nullptr;
    std::string why;
    {
      MatioLock lock;
      raw = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
      if (!raw) why = MatioLock::said();
    }
    mat_.reset(raw);
    if (!mat_) reader_fail(path, fmt::format("matio cannot open the MAT-file{}: the file is damaged", why));
    for (;;) {
      MatioLock lock;
      matvar_t* v = Mat_VarReadNextInfo(mat_.get());
      if (!v) break;
      Variable var;
      var.name = v->name ? v->name : "";
      var.cls = v->class_type;
      var.complex = v->isComplex != 0;
      var.logical = v->isLogical != 0;
      for (int k = 0; k < v->rank && v->dims; ++k) var.dims.push_back(v->dims[k]);
      Mat_VarFree(v);
      // v7.3 keeps the contents of cells and the like in groups named #...#.
      if (!var.name.empty() && var.name.front() != '#') vars_.push_back(std::move(var));
    }
    if (!v73_) {
      // matio stops at the first variable it cannot read (the walk found it whole).
      for (const auto& w : v5_) {
        const bool listed = std::any_of(vars_.begin(), vars_.end(), [&](const Variable& v) { return v.name == w.name; });
        if (!listed && !w.name.empty()) {
          reader_fail(path, fmt::format("matio cannot read variable '{}' (the element at byte {}): the file is damaged",
                                        w.name, w.offset));
        }
      }
    }
    if (vars_.empty()) reader_fail(path, "the MAT-file holds no variables", "variable");
  }

  const Variable* find(const std::string& name) const {
    for (const auto& v : vars_) {
      if (v.name == name) return &v;
    }
    return nullptr;
  }

  // The class a signal may have; refusal otherwise.
  void check_signal_class(const fs::path& path, const Variable& v) const {
    if (v.numeric()) {
      if (v.matrix2d()) return;
      reader_fail(path, fmt::format("variable '{}' is {}-dimensional ({}): save the channels as a matrix samples x "
                                    "channels, or as one vector each",
                                    v.name, v.dims.size(), size_text(v.dims)), "variable");
    }
    std::string what = class_name(v.cls, v.logical, v.complex);
    if (v.cls == MAT_C_SPARSE) what += " (convert it with full())";
    else if (v.complex) what += " (save its real part, or abs(), as the signal)";
    else if (v.cls == MAT_C_STRUCT || v.cls == MAT_C_CELL) what += " (save the field or cell holding the signal as its own variable)";
    reader_fail(path, fmt::format("variable '{}' is a {} {}, not a real numeric array: only double, single, int8 to "
                                  "uint64 and logical arrays hold signals",
                                  v.name, size_text(v.dims), what), "variable");
  }

  void use_matrix(const fs::path& path, const Variable& v) {
    const auto rows = v.dims[0], cols = v.dims[1];
    vars_used_ = {&v};
    const auto shape = column_layout(rows, cols);
    if (!shape) {
      reader_fail(path, fmt::format("variable '{}' is {} x {}: more columns than rows, but too many rows (more than {}) "
                                    "to be channels; save it samples x channels",
                                    v.name, rows, cols, kMaxStackedChannels), "variable");
    }
    layout_ = shape->transposed ? Layout::transposed : Layout::matrix;
    info_.frames = static_cast<std::int64_t>(shape->frames);
    info_.channels = static_cast<int>(std::min<std::uint64_t>(shape->channels, INT_MAX));
    for (std::uint64_t k = 1; k <= shape->channels && k <= 1024; ++k) {
      info_.channel_names.push_back(shape->transposed ? fmt::format("{}({},:)", v.name, k)
                                                      : fmt::format("{}(:,{})", v.name, k));
    }
    if (info_.channels > 1024) {
      reader_fail(path, fmt::format("variable '{}' ({}) would be {} channels: not a probe recording; name the "
                                    "variable(s) holding the channels",
                                    v.name, size_text(v.dims), info_.channels), "variable");
    }
  }

  void choose_channels(const fs::path& path, const ReaderOptions& options) {
    if (options.variables.empty()) {
      std::vector<const Variable*> found;
      for (const auto& v : vars_) {
        if (v.numeric() && v.matrix2d() && v.dims[0] >= 2 && v.dims[1] >= 2) found.push_back(&v);
      }
      if (found.size() != 1) {
        reader_fail(path, fmt::format("{} numeric matrix with two or more columns (or rows) to take the channels "
                                      "from; the file's numeric variables: {}. Name the variable holding the channels "
                                      "(a matrix samples x channels, or one vector per channel)",
                                      found.empty() ? "no" : "more than one", listing(vars_, true)),
                    "variable");
      }
      check_signal_class(path, *found.front());
      use_matrix(path, *found.front());
      return;
    }
    std::vector<const Variable*> named;
    for (const auto& name : options.variables) {
      const Variable* v = find(name);
      if (!v) {
        reader_fail(path, fmt::format("no variable '{}'; the file holds: {}", name, listing(vars_, false)), "variable");
      }
      if (std::find(named.begin(), named.end(), v) != named.end()) {
        reader_fail(path, fmt::format("variable '{}' is named twice", name), "variable");
      }
      check_signal_class(path, *v);
      if (v->elements() < 2) {
        reader_fail(path, fmt::format("variable '{}' ({}) holds {} value{}, not a signal", name, size_text(v->dims),
                                      v->elements(), v->elements() == 1 ? "" : "s"), "variable");
      }
      named.push_back(v);
    }
    if (named.size() == 1 && !named.front()->vector()) {
      use_matrix(path, *named.front());
      return;
    }
    const Variable& first = *named.front();
    for (const auto* v : named) {
      if (!v->vector()) {
        reader_fail(path, fmt::format("variable '{}' is a {} matrix: name one matrix alone, or one vector per channel",
                                      v->name, size_text(v->dims)), "variable");
      }
      if (v->elements() != first.elements()) {
        reader_fail(path, fmt::format("variables '{}' and '{}' hold {} and {} values: the channels must be recorded "
                                      "together, sample for sample",
                                      first.name, v->name, first.elements(), v->elements()), "variable");
      }
      if (v->cls != first.cls || v->logical != first.logical) {
        reader_fail(path, fmt::format("variables '{}' ({}) and '{}' ({}) are of different classes: save the channels "
                                      "in one class",
                                      first.name, class_name(first.cls, first.logical, false), v->name,
                                      class_name(v->cls, v->logical, false)), "variable");
      }
      info_.channel_names.push_back(v->name);
    }
    layout_ = Layout::vectors;
    vars_used_ = named;
    info_.frames = static_cast<std::int64_t>(first.elements());
    info_.channels = static_cast<int>(named.size());
  }

  // The walk's record of a variable matio listed (v5).
  const V5Variable& walked(const fs::path& path, const Variable& v) const {
    for (const auto& w : v5_) {
      if (w.name != v.name) continue;
      if (w.dims != v.dims || w.cls != v.cls || !w.stored) {
        reader_fail(path, fmt::format("variable '{}': matio reads it as {} {} but its element says {} {}: the file is "
                                      "damaged",
                                      v.name, size_text(v.dims), class_name(v.cls, v.logical, v.complex),
                                      size_text(w.dims), class_name(w.cls, w.logical, w.complex)));
      }
      return w;
    }
    reader_fail(path, fmt::format("variable '{}' is not among the file's elements: the file is damaged", v.name));
  }

  std::unique_ptr<Source> source_for(const fs::path& path, const Variable& v, std::size_t streams) {
    if (!v73_) {
      const auto& w = walked(path, v);
      if (w.compressed) return std::make_unique<InflateSource>(path, w, swap_, streams);
      if (v.elements() > static_cast<std::uint64_t>(INT_MAX)) {
        reader_fail(path, fmt::format("variable '{}' holds {} values, more than matio can address in one variable "
                                      "(2^31 - 1): save the channels as separate variables",
                                      v.name, v.elements()));
      }
    } else {
      for (auto d : v.dims) {
        if (d > static_cast<std::uint64_t>(INT_MAX)) {
          reader_fail(path, fmt::format("variable '{}' ({}) has a dimension beyond matio's 2^31 - 1", v.name,
                                        size_text(v.dims)));
        }
      }
    }
    auto source = std::make_unique<MatioSource>(path, mat_.get(), v, v73_);
    if (v73_) {
      // HDF5 holds the dimensions apart from the data: a dataset claiming more
      // than it stores fails here rather than in the middle of a pass.
      double last = 0.0;
      source->get(v.elements() - 1, 1, &last);
    }
    return source;
  }

  void open_sources(const fs::path& path) {
    const auto streams = layout_ == Layout::matrix ? static_cast<std::size_t>(info_.channels) : std::size_t{1};
    for (const auto* v : vars_used_) sources_.push_back(source_for(path, *v, streams));
    const Variable& v = *vars_used_.front();
    int16_ = v.cls == MAT_C_INT16 && !v.logical;
    rows_ = v.dims[0];
  }

  // A scalar's value (nullopt: not one positive finite real number).
  std::optional<double> scalar(const Variable& v) {
    if (!v.numeric() || v.elements() != 1 || v.logical) return std::nullopt;
    double value = std::numeric_limits<double>::quiet_NaN();
    {
      MatioLock lock;
      matvar_t* m = Mat_VarRead(mat_.get(), v.name.c_str());
      if (m && m->data && !m->isComplex && kind_of_class(m->class_type)) {
        convert(static_cast<const unsigned char*>(m->data), *kind_of_class(m->class_type), 1, false, &value);
      }
      Mat_VarFree(m);
    }
    if (!(std::isfinite(value) && value > 0.0)) return std::nullopt;
    return value;
  }

  bool used(const Variable& v) const {
    return std::find(vars_used_.begin(), vars_used_.end(), &v) != vars_used_.end();
  }

  void choose_rate(const fs::path& path, const ReaderOptions& options) {
    if (options.fs > 0.0 && options.override_fs) {
      info_.fs = options.fs;
      return;
    }
    // Scalars: every one present must agree with the first.
    std::optional<std::pair<std::string, double>> rate;
    auto consider = [&](std::string_view name, bool interval) {
      const Variable* v = find(std::string(name));
      if (!v || used(*v)) return;
      const auto value = scalar(*v);
      if (!value) {
        const std::string what = fmt::format("variable '{}' ({}) is not one positive number, so it gives no {}",
                                             v->name, v->describe(), interval ? "sampling interval" : "sampling rate");
        if (options.fs > 0.0) {
          info_.warnings.push_back(what + "; the stated rate is used");
          return;
        }
        reader_fail(path, what + "; state the sampling rate", "fs");
      }
      const double hz = interval ? 1.0 / *value : *value;
      if (!rate) {
        rate = {std::string(name), hz};
      } else if (std::fabs(hz - rate->second) > 1e-6 * rate->second) {
        reader_fail(path, fmt::format("variables '{}' ({}) and '{}' ({}) give different sampling rates; state the "
                                      "right one and force it",
                                      rate->first, format_quantity(rate->second, Dimension::frequency), name,
                                      format_quantity(hz, Dimension::frequency)), "override-fs");
      }
    };
    for (auto name : kRateNames) consider(name, false);
    for (auto name : kIntervalNames) consider(name, true);
    if (rate) {
      info_.fs = stated_rate(path, options, rate->second, fmt::format("its variable '{}'", rate->first));
      rate_source_ = fmt::format("rate from '{}'", rate->first);
      return;
    }
    for (auto name : kTimeNames) {
      const Variable* v = find(std::string(name));
      if (!v || used(*v)) continue;
      if (!v->numeric() || !v->vector() || v->elements() != static_cast<std::uint64_t>(info_.frames)) {
        const std::string what = fmt::format("variable '{}' ({}) is not a time vector of the channels' {} samples",
                                             v->name, v->describe(), info_.frames);
        if (options.fs > 0.0) {
          info_.warnings.push_back(what + "; the stated rate is used");
          break;
        }
        reader_fail(path, what + "; state the sampling rate", "fs");
      }
      const auto timed = rate_from_time(path, options, *v);
      info_.fs = stated_rate(path, options, timed.fs, fmt::format("its time variable '{}'", name), timed.tolerance);
      rate_source_ = fmt::format("rate from time vector '{}'", name);
      return;
    }
    if (options.fs > 0.0) {
      info_.fs = options.fs;
      return;
    }
    reader_fail(path, "the MAT-file records no sampling rate (no scalar fs, Fs, FS, sampling_rate, sample_rate or "
                      "sampling_frequency in Hz, dt or Ts in s, nor a time vector t, time or Time): state it",
                "fs");
  }

  // The rate of a time vector by the time-base rule (awcc/detail/time_base.hpp).
  TimeBaseRate rate_from_time(const fs::path& path, const ReaderOptions& options, const Variable& v) {
    auto source = source_for(path, v, 1);
    const std::uint64_t n = v.elements();
    const Kind kind = *kind_of_class(v.cls);
    const bool floating = kind == Kind::f32 || kind == Kind::f64;
    TimeBase base;
    base.path = path;
    base.name = fmt::format("time variable '{}'", v.name);
    // Counted from 1, as MATLAB counts.
    base.where = [](std::uint64_t index) { return fmt::format("value {}", index + 1); };
    base.float_bits = kind == Kind::f32 ? 24 : (floating ? 53 : 0);
    base.fix = options.fs > 0.0 ? "force the stated rate if the samples are evenly spaced"
                                : "state the sampling rate if the samples are evenly spaced";
    base.quantity = options.fs > 0.0 ? "override-fs" : "fs";
    base.scan = [&](const TimeBase::Sink& sink) {
      std::vector<double> block;
      for (std::uint64_t at = 0; at < n; at += block.size()) {
        block.resize(static_cast<std::size_t>(std::min<std::uint64_t>(n - at, 1 << 16)));
        source->get(at, block.size(), block.data());
        sink(at, block);
      }
      // Integers count whole units of the time base.
      return TimeBaseScan{n, floating ? 0.0 : 1.0};
    };
    return time_base_rate(base);
  }

  void describe(const ReaderOptions& options) {
    const Variable& v = *vars_used_.front();
    const bool integer = v.cls != MAT_C_DOUBLE && v.cls != MAT_C_SINGLE;
    const std::string cls = class_name(v.cls, v.logical, false);
    if (v.logical) {
      // 0 and 1: binarisation takes two levels as the air/water signal itself.
      scale_ = 1.0;
      info_.quantum = 1.0;
      info_.volts_known = false;
    } else if (integer) {
      scale_ = options.volts_per_count > 0.0 ? options.volts_per_count : 1.0;
      info_.quantum = scale_;
      info_.volts_known = options.volts_per_count > 0.0;
      if (!info_.volts_known) {
        info_.warnings.push_back(fmt::format("{} values without a stated volts per count: they are read as counts", cls));
      }
    } else {
      scale_ = 1.0;
      info_.quantum = 0.0;
      info_.volts_known = true;
      if (options.volts_per_count > 0.0) {
        info_.warnings.push_back(fmt::format("{} values are taken as volts: the volts per count applies to integer "
                                             "classes only",
                                             cls));
      }
    }
    std::string what;
    switch (layout_) {
      case Layout::matrix: what = fmt::format("'{}' {} {} (samples x channels)", v.name, size_text(v.dims), cls); break;
      case Layout::transposed:
        what = fmt::format("'{}' {} {}, channels in rows: read transposed", v.name, size_text(v.dims), cls);
        break;
      case Layout::vectors: {
        std::string names;
        for (const auto* u : vars_used_) names += (names.empty() ? "'" : ", '") + u->name + "'";
        what = fmt::format("vectors {} ({} {} each)", names, v.elements(), cls);
        break;
      }
    }
    const bool compressed = !v73_ && walked(info_.path, v).compressed;
    info_.description = fmt::format("MATLAB {} MAT-file{}, {}{}{}", v73_ ? "v7.3" : "v5",
                                    compressed ? " (compressed, inflated as read)" : "", what,
                                    rate_source_.empty() ? "" : ", " + rate_source_,
                                    v.logical ? ", 0/1" : (info_.volts_known ? "" : ", counts"));
  }

  // `frames` frames from position_, interleaved, as doubles or raw int16.
  template <class T>
  void gather(T* out, std::size_t frames) {
    const auto channels = static_cast<std::size_t>(info_.channels);
    const auto pos = static_cast<std::uint64_t>(position_);
    switch (layout_) {
      case Layout::transposed: sources_[0]->get(pos * rows_, frames * channels, out); return;
      case Layout::matrix:
      case Layout::vectors: {
        auto& column = column_buffer<T>();
        column.resize(frames);
        // One channel at a time: a compressed matrix inflates one stream per channel.
        for (std::size_t c = 0; c < channels; ++c) {
          if (layout_ == Layout::matrix) sources_[0]->get(c * rows_ + pos, frames, column.data());
          else sources_[c]->get(pos, frames, column.data());
          interleave(frames, 1, false, [&column](std::size_t k) { return column[k]; }, std::span<T>(out, frames * channels),
                     channels, c, [](T v, std::size_t, std::size_t) { return v; });
        }
        return;
      }
    }
  }
  template <class T>
  std::vector<T>& column_buffer() {
    if constexpr (std::is_same_v<T, double>) return column_;
    else return column16_;
  }

  bool v73_ = false, swap_ = false, int16_ = false;
  std::vector<V5Variable> v5_;
  MatFile mat_;
  std::vector<Variable> vars_;
  std::vector<const Variable*> vars_used_;
  Layout layout_ = Layout::matrix;
  std::uint64_t rows_ = 0;
  std::vector<std::unique_ptr<Source>> sources_;
  std::string rate_source_;
  double scale_ = 1.0;
  std::int64_t position_ = 0;
  std::vector<double> values_, column_;
  std::vector<std::int16_t> column16_;
};

}  // namespace

bool matlab_magic(const fs::path& path) {
  const std::string text = leading_bytes(path, 19);
  return text == "MATLAB 5.0 MAT-file" || text == "MATLAB 7.3 MAT-file";
}

std::unique_ptr<Recording> open_matlab(const fs::path& path, const ReaderOptions& options) {
  return std::make_unique<MatRecording>(path, options);
}

}  // namespace awcc::detail
