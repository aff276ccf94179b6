// The model file (model.hpp, CorrectionModel::serialise and parse): its
// little-endian layout, the forests read in place, and its checks.

#include "correction/model.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <deque>
#include <fstream>
#include <iterator>

#include <cerrno>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <stdexcept>
#include <zlib.h>

#include "awcc/atomic_output.hpp"
#include "awcc/awcc.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/read_back.hpp"
#include "correction/modality.hpp"

namespace correction {

namespace {

constexpr char magic[8] = {'p', 'd', 'p', '-', 'q', 'r', 'f', '\n'};

// Little-endian writer and a bounds-checked reader: the file's byte order
// does not depend on the machine's.
class Writer {
 public:
  void u8(std::uint8_t v) { raw(&v, 1); }
  void u32(std::uint32_t v) {
    std::uint8_t b[4];
    for (int i = 0; i < 4; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
    raw(b, 4);
  }
  void u64(std::uint64_t v) {
    std::uint8_t b[8];
    for (int i = 0; i < 8; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
    raw(b, 8);
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void text(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  void raw(const void* data, std::size_t n) {
    if (n == 0) return;
    const auto at = bytes.size();
    bytes.resize(at + n);
    std::memcpy(bytes.data() + at, data, n);
  }
  std::vector<std::uint8_t> bytes;
};

// The file's little-endian bytes as a number on this machine.
template <typename T>
T little(const std::uint8_t* b) {
  T v;
  std::memcpy(&v, b, sizeof v);
  if constexpr (std::endian::native == std::endian::big) {  // C++20 has no std::byteswap
    T r = 0;
    for (std::size_t i = 0; i < sizeof v; ++i) r |= static_cast<T>(b[i]) << (8 * i);
    v = r;
  }
  return v;
}

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size, const std::string& name) : p_(data), end_(data + size), name_(name) {}
  std::uint8_t u8() { return *take(1); }
  std::uint32_t u32() { return little<std::uint32_t>(take(4)); }
  std::uint64_t u64() { return little<std::uint64_t>(take(8)); }
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64() { return std::bit_cast<double>(u64()); }
  std::string text() {
    const auto n = u32();
    const auto* b = take(n);
    return {reinterpret_cast<const char*>(b), n};
  }
  /// A count of items of `item_bytes` each that must fit in what is left.
  std::size_t count(std::uint64_t n, std::size_t item_bytes) {
    if (n > static_cast<std::uint64_t>(end_ - p_) / std::max<std::size_t>(item_bytes, 1)) damaged("a count exceeds the file");
    return static_cast<std::size_t>(n);
  }
  [[nodiscard]] bool done() const { return p_ == end_; }
  /// The next n bytes, in place.
  std::span<const std::uint8_t> bytes(std::size_t n) { return {take(n), n}; }
  [[noreturn]] void damaged(const std::string& what) const {
    throw awcc::InputError(fmt::format("{}: damaged model file ({}); retrain it with pdp train or fetch it again", name_, what));
  }

 private:
  const std::uint8_t* take(std::size_t n) {
    if (static_cast<std::size_t>(end_ - p_) < n) damaged("it ends early");
    const auto* b = p_;
    p_ += n;
    return b;
  }
  const std::uint8_t* p_;
  const std::uint8_t* end_;
  const std::string& name_;
};

void write_forest(Writer& w, const std::string& name, TargetForm form, const QuantileForest& f) {
  w.text(name);
  w.u8(static_cast<std::uint8_t>(form));
  const auto block = f.bytes();
  w.u64(block.size());
  w.raw(block.data(), block.size());
}

// Format 3: the forest's block (quantile_forest.hpp), read in place.
QuantileForest view_forest(Reader& r, const std::shared_ptr<const void>& owner, const std::string& expected,
                           TargetForm& form, std::uint32_t expected_features) {
  if (const auto name = r.text(); name != expected) r.damaged(fmt::format("forest '{}' where '{}' belongs", name, expected));
  const auto f = r.u8();
  if (f > 2) r.damaged(fmt::format("unknown target form {}", f));
  form = static_cast<TargetForm>(f);
  const auto block = r.bytes(r.count(r.u64(), 1));
  try {
    auto forest = QuantileForest::view(owner, block);
    if (forest.features() != static_cast<int>(expected_features)) {
      r.damaged(fmt::format("{} features, expected {}", forest.features(), expected_features));
    }
    return forest;
  } catch (const std::invalid_argument& e) {
    r.damaged(e.what());
  }
}

// Formats 1 and 2: variable-size nodes, decoded and assembled.
QuantileForest read_forest_v2(Reader& r, const std::string& expected, TargetForm& form, std::uint32_t expected_features) {
  if (const auto name = r.text(); name != expected) r.damaged(fmt::format("forest '{}' where '{}' belongs", name, expected));
  const auto f = r.u8();
  if (f > 2) r.damaged(fmt::format("unknown target form {}", f));
  form = static_cast<TargetForm>(f);
  const auto features = r.u32();
  if (features != expected_features) r.damaged(fmt::format("{} features, expected {}", features, expected_features));
  std::vector<double> targets(r.count(r.u64(), 8));
  for (auto& y : targets) y = r.f64();
  std::vector<RegressionTree> trees(r.count(r.u32(), 12));
  const auto row_bytes = r.u8();
  if (row_bytes != 2 && row_bytes != 4) r.damaged(fmt::format("held rows of {} bytes", row_bytes));
  for (auto& t : trees) {
    t.nodes.resize(r.count(r.u32(), 9));
    for (auto& n : t.nodes) {
      const auto feature = r.u8();
      if (feature == 0xff) {
        n.feature = -1;
        n.left = r.u32();
        n.right = r.u32();
      } else {
        n.feature = feature;
        n.threshold = r.f64();
        n.left = r.u32();
        n.right = n.left + 1;
      }
    }
    t.leaf_rows.resize(r.count(r.u64(), row_bytes));
    for (auto& row : t.leaf_rows) {
      if (row_bytes == 2) {
        row = r.u8();
        row |= static_cast<std::uint32_t>(r.u8()) << 8;
      } else {
        row = r.u32();
      }
    }
  }
  try {
    return QuantileForest::assemble(static_cast<int>(features), std::move(targets), std::move(trees));
  } catch (const std::invalid_argument& e) {
    r.damaged(e.what());
  }
}

// The offsets of one calibration group. Format 7 stores the four intervals
// of interval_coverages; older formats the 50, 80 and 95 % ones, and their
// 90 % offset is interpolated between the 80 and 95 % ones linearly in the
// normal score z((1 + coverage) / 2): exact for normal forest errors, not a
// conformal guarantee (model.hpp, Calibration).
IntervalOffsets read_offsets(Reader& r, std::uint32_t version) {
  IntervalOffsets o{};
  for (std::size_t k = 0; k < interval_count; ++k) {
    if (version < 7 && k == interval90) continue;
    o[k] = r.f64();
    if (!std::isfinite(o[k])) r.damaged("a calibration offset is not finite");
  }
  if (version < 7) {
    constexpr double z80 = 1.2815515655446004, z90 = 1.6448536269514722, z95 = 1.959963984540054;
    o[interval90] = o[interval80] + (o[interval95] - o[interval80]) * (z90 - z80) / (z95 - z80);
  }
  return o;
}

// Format 5: u32 E, then E x 2 values per quantity (the model's header).
void write_envelopes(Writer& w, const Calibration& c,
                     std::initializer_list<const std::vector<std::array<double, 2>>*> quantities) {
  const auto count = c.envelope_from_training ? 0 : (*quantities.begin())->size();
  w.u32(static_cast<std::uint32_t>(count));
  if (count == 0) return;
  for (const auto* q : quantities)
    for (const auto& e : *q)
      for (double v : e) w.f64(v);
}

void read_envelopes(Reader& r, std::size_t groups, std::initializer_list<std::vector<std::array<double, 2>>*> quantities) {
  const auto count = r.count(r.u32(), 16);
  if (count != 0 && count != 1 && count != groups) r.damaged(fmt::format("{} envelopes for {} groups", count, groups));
  for (auto* q : quantities) {
    q->resize(count);
    for (auto& e : *q)
      for (double& v : e) {
        v = r.f64();
        if (!(v >= 0.0 || std::isinf(v))) r.damaged("an envelope is negative or not a number");
      }
  }
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  // crc32_z, not crc32: its length is a size_t, not a 32-bit uInt.
  return static_cast<std::uint32_t>(::crc32_z(0UL, data, size));
}

std::vector<std::uint8_t> CorrectionModel::serialise() const {
  Writer payload;
  payload.text(provenance);
  payload.u32(static_cast<std::uint32_t>(ranges.size()));
  for (const auto& r : ranges) {
    payload.text(r.name);
    payload.f64(r.min);
    payload.f64(r.max);
  }
  payload.f64(range_margin);
  payload.i64(min_windows);
  payload.f64(processing.filter_a);
  payload.u8(processing.roc ? 1 : 0);
  payload.u8(processing.weighting == awcc::Weighting::none ? 1 : 0);
  payload.u8(processing.signal == awcc::CorrelationSignal::raw ? 1 : 0);
  payload.u8(static_cast<std::uint8_t>(processing.subsample));  // awcc::Subsample's order is the code
  payload.u32(calibration.empty() ? 0 : static_cast<std::uint32_t>(calibration.window_edges.size() + 1));
  if (!calibration.empty()) {
    for (auto e : calibration.window_edges) payload.i64(e);
    payload.u32(static_cast<std::uint32_t>(calibration.tu_bands()));
    for (double e : calibration.tu_edges) payload.f64(e);
    for (const auto* bands : {&calibration.velocity, &calibration.turbulence_intensity})
      for (const auto& b : *bands)
        for (double o : b) payload.f64(o);
  }
  // Envelopes taken from the training targets are not stored: a reader takes them again.
  write_envelopes(payload, calibration, {&calibration.velocity_envelope, &calibration.turbulence_envelope});
  payload.u32(2);
  write_forest(payload, "velocity", velocity_form, velocity);
  write_forest(payload, "turbulence_intensity", turbulence_form, turbulence_intensity);
  payload.u32(fscc ? 1 : 0);
  if (fscc) {
    payload.u32(static_cast<std::uint32_t>(fscc->ranges.size()));
    for (const auto& r : fscc->ranges) {
      payload.text(r.name);
      payload.f64(r.min);
      payload.f64(r.max);
    }
    payload.u32(fscc->calibration.empty() ? 0 : 1);
    if (!fscc->calibration.empty())
      for (double o : fscc->calibration.velocity.front()) payload.f64(o);
    write_envelopes(payload, fscc->calibration, {&fscc->calibration.velocity_envelope});
    write_forest(payload, "fscc_velocity", fscc->form, fscc->velocity);
  }
  payload.u32(reduced ? 1 : 0);
  if (reduced) {
    const auto nested = reduced->serialise();
    payload.u64(nested.size());
    payload.raw(nested.data(), nested.size());
  }
  Writer w;
  w.raw(magic, sizeof magic);
  w.u32(format_version);
  w.u64(payload.bytes.size());
  w.raw(payload.bytes.data(), payload.bytes.size());
  w.u32(crc32(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

CorrectionModel CorrectionModel::parse(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  auto owned = std::make_shared<const std::vector<std::uint8_t>>(bytes);
  const std::span<const std::uint8_t> view(owned->data(), owned->size());
  return parse(std::move(owned), view, name);
}

CorrectionModel CorrectionModel::parse(std::shared_ptr<const void> owner, std::span<const std::uint8_t> bytes,
                                       const std::string& name) {
  if (bytes.size() < sizeof magic || std::memcmp(bytes.data(), magic, sizeof magic) != 0) {
    throw awcc::InputError(fmt::format("{}: not a pdp model file (it does not start with \"pdp-qrf\"); give a file "
                                       "written by pdp train",
                                       name));
  }
  Reader head(bytes.data() + sizeof magic, bytes.size() - sizeof magic, name);
  const auto version = head.u32();
  if (version < 1 || version > format_version) {
    throw awcc::InputError(fmt::format("{}: model file format version {}; this pdp reads versions 1 to {}; retrain the "
                                       "model with this pdp train",
                                       name, version, format_version));
  }
  const auto length = head.u64();
  const std::size_t header = sizeof magic + 4 + 8;
  if (length > bytes.size() || bytes.size() - header - 4 != length) {
    head.damaged(fmt::format("{} bytes where the header announces {}", bytes.size(), header + length + 4));
  }
  Reader tail(bytes.data() + header + length, 4, name);
  if (tail.u32() != crc32(bytes.data(), header + length)) head.damaged("checksum mismatch");
  Reader r(bytes.data() + header, length, name);
  CorrectionModel m;
  m.provenance = r.text();
  m.ranges.resize(r.count(r.u32(), 20));
  // Format 1 and 2 models take the measured features; format 3 also an extended set.
  std::vector<std::string> names;
  for (auto& fr : m.ranges) {
    fr.name = r.text();
    fr.min = r.f64();
    fr.max = r.f64();
    names.push_back(fr.name);
    if (!(std::isfinite(fr.min) && std::isfinite(fr.max) && fr.min <= fr.max)) r.damaged("a feature range is not finite");
  }
  const auto set = feature_set_of(names);
  if (set.empty() || (version < 3 && set != "measured")) {
    r.damaged(fmt::format("features ({}) are not a feature set this pdp knows", fmt::join(names, ", ")));
  }
  m.range_margin = r.f64();
  if (!(m.range_margin >= 0.0 && m.range_margin <= 1.0)) r.damaged("range margin outside [0, 1]");
  m.min_windows = r.i64();
  if (version >= 2) {
    auto flag = [&](const char* what) {
      const auto v = r.u8();
      if (v > 1) r.damaged(fmt::format("{} code {}", what, v));
      return v == 1;
    };
    m.processing.filter_a = r.f64();
    if (!(m.processing.filter_a >= 0.0 && m.processing.filter_a <= 1.0)) r.damaged("filter A outside [0, 1]");
    m.processing.roc = flag("outlier cutoff");
    m.processing.weighting = flag("weighting") ? awcc::Weighting::none : awcc::Weighting::duration;
    m.processing.signal = flag("signal") ? awcc::CorrelationSignal::raw : awcc::CorrelationSignal::binary;
    const auto refinement = r.u8();
    if (refinement >= std::size(awcc::values::subsample)) r.damaged(fmt::format("peak refinement code {}", refinement));
    m.processing.subsample = awcc::values::subsample[refinement];
  }
  if (version >= 3) {
    const auto bands = r.count(r.u32(), 48);
    if (bands > 0) {
      auto& c = m.calibration;
      c.window_edges.resize(bands - 1);
      for (auto& e : c.window_edges) {
        e = r.i64();
        if (e < 0 || (&e != c.window_edges.data() && e <= *(&e - 1))) r.damaged("calibration band edges not increasing");
      }
      const auto tu_bands = version >= 4 ? r.count(r.u32(), 48) : std::size_t{1};
      if (tu_bands < 1) r.damaged("no Tu band in the calibration");
      c.tu_edges.resize(tu_bands - 1);
      for (auto& e : c.tu_edges) {
        e = r.f64();
        if (!std::isfinite(e) || (&e != c.tu_edges.data() && e <= *(&e - 1))) r.damaged("calibration Tu edges not increasing");
      }
      for (auto* b : {&c.velocity, &c.turbulence_intensity}) {
        b->resize(bands * tu_bands);
        for (auto& band : *b) band = read_offsets(r, version);
      }
    }
  }
  if (version >= 5) {
    read_envelopes(r, std::max<std::size_t>(m.calibration.velocity.size(), 1),
                   {&m.calibration.velocity_envelope, &m.calibration.turbulence_envelope});
  }
  if (r.u32() != 2) r.damaged("the model holds other than two forests");
  const auto p = static_cast<std::uint32_t>(m.ranges.size());
  auto forest = [&](const std::string& forest_name, TargetForm& form, std::uint32_t features) {
    return version >= 3 ? view_forest(r, owner, forest_name, form, features) : read_forest_v2(r, forest_name, form, features);
  };
  m.velocity = forest("velocity", m.velocity_form, p);
  m.turbulence_intensity = forest("turbulence_intensity", m.turbulence_form, p);
  if (version >= 3) {
    const auto extra = r.u32();
    if (extra > 1) r.damaged(fmt::format("{} FSCC forests", extra));
    if (extra == 1) {
      FsccForest f;
      f.ranges.resize(r.count(r.u32(), 20));
      // Set 2 from format 6 on; the names say which.
      const auto fscc_names =
          feature_set_names(version >= 6 && f.ranges.size() == Features::fscc2_names.size() ? "fscc-2" : "fscc");
      if (f.ranges.size() != fscc_names.size()) r.damaged(fmt::format("{} FSCC feature ranges", f.ranges.size()));
      for (std::size_t j = 0; j < f.ranges.size(); ++j) {
        auto& fr = f.ranges[j];
        fr.name = r.text();
        fr.min = r.f64();
        fr.max = r.f64();
        if (fr.name != fscc_names[j]) r.damaged(fmt::format("FSCC feature {} is '{}', expected '{}'", j, fr.name, fscc_names[j]));
        if (!(std::isfinite(fr.min) && std::isfinite(fr.max) && fr.min <= fr.max)) r.damaged("a feature range is not finite");
      }
      const auto calibrated = r.u32();
      if (calibrated > 1) r.damaged("FSCC calibration flag");
      if (calibrated == 1) {
        f.calibration.velocity = {read_offsets(r, version)};
      }
      if (version >= 5) read_envelopes(r, 1, {&f.calibration.velocity_envelope});
      f.velocity = forest("fscc_velocity", f.form, static_cast<std::uint32_t>(fscc_names.size()));
      m.fscc = std::move(f);
    }
  }
  if (version >= 6) {
    const auto nested = r.u32();
    if (nested > 1) r.damaged(fmt::format("{} reduced models", nested));
    if (nested == 1) {
      const auto block = r.bytes(r.count(r.u64(), 1));
      auto reduced = parse(owner, block, name + " (its reduced model)");
      std::vector<std::string> reduced_names;
      for (const auto& fr : reduced.ranges) reduced_names.push_back(fr.name);
      const auto reduced_set = feature_set_of(reduced_names);
      if ((reduced_set != "measured" && reduced_set != "measured+weighting") || reduced.fscc || reduced.reduced) {
        r.damaged("the reduced model is not one of the measured features alone");
      }
      m.reduced = std::make_shared<const CorrectionModel>(std::move(reduced));
    }
  }
  if (!r.done()) r.damaged("bytes after the last forest");
  m.use_training_envelopes();
  return m;
}

void CorrectionModel::save(const std::filesystem::path& path) const {
  const auto bytes = serialise();
  awcc::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw awcc::OutputError(fmt::format("{}: cannot write the model", path.string()));
  });
}

CorrectionModel CorrectionModel::load(const std::filesystem::path& path) {
  // Read into memory once (not mapped: a file replaced in place while a run
  // uses the model must not change or truncate the forests under it). The
  // memory is taken with its pages in place (MAP_POPULATE): faulting them in
  // one by one cost more than reading the file.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw awcc::InputError(fmt::format("{}: cannot open the model file; check the path", path.string()));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw awcc::InputError(fmt::format("{}: not a regular file; give a model file written by pdp train", path.string()));
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  void* memory = ::mmap(nullptr, std::max<std::size_t>(size, 1), PROT_READ | PROT_WRITE,
                        MAP_PRIVATE | MAP_ANONYMOUS | MAP_POPULATE, -1, 0);
  if (memory == MAP_FAILED) {
    ::close(fd);
    throw awcc::InputError(fmt::format("{}: no memory to read the model file ({} bytes)", path.string(), size));
  }
  std::shared_ptr<std::uint8_t> bytes(static_cast<std::uint8_t*>(memory),
                                      [n = std::max<std::size_t>(size, 1)](std::uint8_t* q) { ::munmap(q, n); });
  std::size_t done = 0;
  while (done < size) {
    const auto got = ::read(fd, bytes.get() + done, size - done);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    done += static_cast<std::size_t>(got);
  }
  ::close(fd);
  if (done != size) throw awcc::InputError(fmt::format("{}: cannot read the model file", path.string()));
  const std::span<const std::uint8_t> view(bytes.get(), size);
  return parse(std::move(bytes), view, path.string());
}

}  // namespace correction
