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
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/read_back.hpp"

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

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  // crc32_z, not crc32: its length is a size_t, not a 32-bit uInt.
  return static_cast<std::uint32_t>(::crc32_z(0UL, data, size));
}

std::string_view to_string(TargetForm f) {
  switch (f) {
    case TargetForm::value: return "value";
    case TargetForm::ratio: return "ratio";
    case TargetForm::difference: return "difference";
  }
  return "unknown";
}

double to_target(TargetForm form, double truth, double measured) {
  switch (form) {
    case TargetForm::value: return truth;
    case TargetForm::ratio: return truth / measured;
    case TargetForm::difference: return truth - measured;
  }
  return truth;
}

double from_target(TargetForm form, double target, double measured) {
  switch (form) {
    case TargetForm::value: return target;
    case TargetForm::ratio: return target * measured;
    case TargetForm::difference: return target + measured;
  }
  return target;
}

Correction not_corrected(CorrectionStatus status, std::string message) {
  Correction c;
  c.status = status;
  c.message = std::move(message);
  return c;
}

namespace {

// Where a row's missing record feature comes from: the columns pdp process
// writes (read from any CSV), or the setting stated for a whole file (pdp correct --fs, --duration).
std::string how_to_give(const std::string& feature) {
  if (feature == "fs" || feature == "duration") {
    return fmt::format("a column '{}', or the {} stated for the whole file", feature, feature);
  }
  namespace column = awcc::profile_column;
  if (feature == "windows_accepted") {
    return fmt::format("a column '{}': AWCC's accepted windows of the row", column::awcc_windows_accepted);
  }
  if (feature == "data_yield") {
    return fmt::format("columns '{}' and '{}': AWCC's accepted and formed windows of the row",
                       column::awcc_windows_accepted, column::awcc_windows_total);
  }
  return fmt::format("a column '{}'", feature);
}

// Why a feature value is outside its training range, in the field's words
// where the flow itself is outside what the simulator models.
std::string out_of_range_reason(const FeatureRange& r, double v) {
  std::string why = fmt::format("{} = {:.6g} is outside the training range [{:.6g}, {:.6g}]", r.name, v, r.min, r.max);
  if (r.name == "void_fraction" && v > 0.6) {
    why += ": above c = 0.6 the flow is droplets in air, which the synthetic probe the model learnt from does not model";
  }
  return why;
}

}  // namespace

int Calibration::band(std::int64_t windows) const {
  if (windows < 0) return -1;
  int b = 0;
  while (b < static_cast<int>(window_edges.size()) && windows >= window_edges[static_cast<std::size_t>(b)]) ++b;
  return b;
}

int Calibration::tu_band(double tu_median) const {
  int h = 0;
  while (h < static_cast<int>(tu_edges.size()) && tu_median >= tu_edges[static_cast<std::size_t>(h)]) ++h;
  return h;
}

std::array<double, 3> Calibration::offsets(const std::vector<std::array<double, 3>>& groups, std::int64_t windows,
                                           double tu_median) const {
  const auto h = static_cast<std::size_t>(tu_band(tu_median));
  const int w = band(windows);
  if (w >= 0) return groups[static_cast<std::size_t>(w) * tu_bands() + h];
  std::array<double, 3> o;
  o.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t b = 0; b <= window_edges.size(); ++b)
    for (std::size_t k = 0; k < 3; ++k) o[k] = std::max(o[k], groups[b * tu_bands() + h][k]);
  return o;
}

void Calibration::apply(const std::array<double, 3>& offsets, std::vector<double>& t) {
  // Levels 0.025 0.1 0.25 0.5 0.75 0.9 0.975: pairs (2, 4), (1, 5), (0, 6).
  for (std::size_t k = 0; k < 3; ++k) {
    t[2 - k] -= offsets[k];
    t[4 + k] += offsets[k];
  }
  // A narrowed interval may not cross a narrower one or the median.
  for (std::size_t k = 3; k-- > 0;) t[k] = std::min(t[k], t[k + 1]);
  for (std::size_t k = 4; k < 7; ++k) t[k] = std::max(t[k], t[k - 1]);
}

Correction CorrectionModel::correct(const Features& f) const {
  if (f.windows_accepted >= 0 && f.windows_accepted < min_windows) {
    return not_corrected(CorrectionStatus::too_few_windows,
                         fmt::format("{} accepted windows; the model was trained on runs with at least {}",
                                     f.windows_accepted, min_windows));
  }
  std::vector<double> x(ranges.size());
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    const auto v = f.value(ranges[j].name);
    if (!v) {
      return not_corrected(CorrectionStatus::missing_feature,
                           fmt::format("the model takes the record's {} as a feature, and it is not known for this row; "
                                       "give it ({})",
                                       ranges[j].name, how_to_give(ranges[j].name)));
    }
    x[j] = *v;
  }
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    const auto& r = ranges[j];
    const double pad = range_margin * (r.max - r.min);
    if (!(x[j] >= r.min - pad && x[j] <= r.max + pad)) {
      return not_corrected(CorrectionStatus::outside_training_range, out_of_range_reason(r, x[j]));
    }
  }
  Correction c;
  c.status = CorrectionStatus::corrected;
  auto velocity_t = velocity.quantiles(x, correction_levels);
  auto tu_t = turbulence_intensity.quantiles(x, correction_levels);
  if (!calibration.empty()) {
    // The group's Tu band: the Tu forest's own median, before calibration.
    const double tu_median = from_target(turbulence_form, tu_t[3], f.turbulence_intensity);
    Calibration::apply(calibration.offsets(calibration.velocity, f.windows_accepted, tu_median), velocity_t);
    Calibration::apply(calibration.offsets(calibration.turbulence_intensity, f.windows_accepted, tu_median), tu_t);
  }
  auto one = [&](const std::vector<double>& t, TargetForm form, double measured, bool nonnegative) {
    CorrectedQuantity q;
    q.measured = measured;
    for (std::size_t k = 0; k < t.size(); ++k) {
      q.quantiles[k] = from_target(form, t[k], measured);
      if (nonnegative) q.quantiles[k] = std::max(0.0, q.quantiles[k]);
    }
    return q;
  };
  c.forest = "awcc";
  c.velocity = one(velocity_t, velocity_form, f.velocity, false);
  c.turbulence_intensity = one(tu_t, turbulence_form, f.turbulence_intensity, true);
  return c;
}

namespace {

// AWCC statuses after which the FSCC forest may correct the velocity.
bool fscc_may_follow(CorrectionStatus s) {
  switch (s) {
    case CorrectionStatus::awcc_not_run:
    case CorrectionStatus::no_awcc_velocity:
    case CorrectionStatus::too_few_windows:
    case CorrectionStatus::outside_training_range: return true;
    default: return false;
  }
}

}  // namespace

bool CorrectionModel::falls_back_to_fscc(CorrectionStatus awcc_status) const {
  return fscc.has_value() && fscc_may_follow(awcc_status);
}

Correction CorrectionModel::correct_fscc(const Features& f) const {
  if (!fscc) return not_corrected(CorrectionStatus::no_awcc_velocity, "the model has no FSCC forest");
  if (const auto why = fscc_unusable(f); !why.empty()) return not_corrected(CorrectionStatus::no_awcc_velocity, why);
  std::vector<double> x(fscc->ranges.size());
  for (std::size_t j = 0; j < x.size(); ++j) {
    const auto& r = fscc->ranges[j];
    const auto v = f.value(r.name);
    if (!v) {
      return not_corrected(CorrectionStatus::missing_feature,
                           fmt::format("the FSCC forest takes the record's {}, which is not known for this row; give it ({})",
                                       r.name, how_to_give(r.name)));
    }
    const double pad = range_margin * (r.max - r.min);
    if (!(*v >= r.min - pad && *v <= r.max + pad)) {
      return not_corrected(CorrectionStatus::outside_training_range, "FSCC forest: " + out_of_range_reason(r, *v));
    }
    x[j] = *v;
  }
  auto t = fscc->velocity.quantiles(x, correction_levels);
  if (!fscc->calibration.empty()) Calibration::apply(fscc->calibration.velocity.front(), t);
  CorrectedQuantity q;
  q.measured = f.fscc_velocity;
  for (std::size_t k = 0; k < t.size(); ++k) q.quantiles[k] = from_target(fscc->form, t[k], f.fscc_velocity);
  Correction c;
  c.status = CorrectionStatus::corrected;
  c.forest = "fscc";
  c.velocity = q;
  return c;
}

Correction CorrectionModel::correct(const Measurement& m) const {
  const auto f = make_features(m);
  Correction awcc = f.ok() ? correct(f.features) : not_corrected(f.status, f.message);
  if (awcc.corrected() || !fscc || !fscc_may_follow(awcc.status)) return awcc;
  auto c = correct_fscc(f.features);
  if (!c.corrected()) {
    // Neither forest: AWCC's status, with both reasons.
    c.status = awcc.status;
    c.message = fmt::format("{}; FSCC forest: {}", awcc.message, c.message);
  }
  return c;
}

Correction CorrectionModel::correct(const MeasurementResult& m) const {
  if (m.status == CorrectionStatus::corrected) return correct(m.measurement);
  Correction awcc = not_corrected(m.status, m.message);
  if (!fscc || !fscc_may_follow(m.status)) return awcc;
  auto c = correct_fscc(make_features(m.measurement).features);
  if (!c.corrected()) {
    c.status = awcc.status;
    c.message = fmt::format("{}; FSCC forest: {}", awcc.message, c.message);
  }
  return c;
}

std::string CorrectionModel::mismatch(const Processing& results) const {
  return processing_mismatch(processing, results);
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
  payload.u8(processing.subsample == awcc::Subsample::parabolic ? 1 : 0);
  payload.u32(calibration.empty() ? 0 : static_cast<std::uint32_t>(calibration.window_edges.size() + 1));
  if (!calibration.empty()) {
    for (auto e : calibration.window_edges) payload.i64(e);
    payload.u32(static_cast<std::uint32_t>(calibration.tu_bands()));
    for (double e : calibration.tu_edges) payload.f64(e);
    for (const auto* bands : {&calibration.velocity, &calibration.turbulence_intensity})
      for (const auto& b : *bands)
        for (double o : b) payload.f64(o);
  }
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
    write_forest(payload, "fscc_velocity", fscc->form, fscc->velocity);
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
    m.processing.subsample = flag("peak refinement") ? awcc::Subsample::parabolic : awcc::Subsample::none;
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
        for (auto& band : *b)
          for (double& o : band) {
            o = r.f64();
            if (!std::isfinite(o)) r.damaged("a calibration offset is not finite");
          }
      }
    }
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
      const auto fscc_names = feature_set_names("fscc");
      f.ranges.resize(r.count(r.u32(), 20));
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
        f.calibration.velocity.resize(1);
        for (double& o : f.calibration.velocity.front()) {
          o = r.f64();
          if (!std::isfinite(o)) r.damaged("a calibration offset is not finite");
        }
      }
      f.velocity = forest("fscc_velocity", f.form, static_cast<std::uint32_t>(fscc_names.size()));
      m.fscc = std::move(f);
    }
  }
  if (!r.done()) r.damaged("bytes after the last forest");
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

std::span<const awcc::ProfileColumn> correction_csv_columns() {
  // Built once from the levels; the strings live as long as the program.
  static const auto columns = [] {
    static std::deque<std::string> text;
    auto keep = [](std::string s) -> std::string_view { return text.emplace_back(std::move(s)); };
    std::vector<awcc::ProfileColumn> out{
        {"correction_in_range", "", "/correction/in_range", "1 when the row was corrected"},
        {"correction_reason", "", "/correction/reason", "why the row was not corrected"},
        {"correction_forest", "", "/correction/forest", "the forest that corrected the row: awcc, or fscc (velocity only)"}};
    for (const char* q : {"velocity", "turbulence_intensity"}) {
      const bool u = std::string_view(q) == "velocity";
      const char* unit = u ? "m/s" : "-";
      const char* what = u ? "velocity" : "turbulence intensity";
      out.push_back({keep(fmt::format("corrected_{}", q)), unit, keep(fmt::format("/correction/{}/median", q)),
                     keep(fmt::format("corrected {} (median of the truth given the measurement)", what))});
      for (const char* l : correction_level_names) {
        out.push_back({keep(fmt::format("corrected_{}_q{}", q, l)), unit,
                       keep(fmt::format("/correction/{}/quantiles/{}", q, l)),
                       keep(fmt::format("quantile {} of the true {}", l, what))});
      }
    }
    out.push_back({"correction_status", "", "/correction/status", "corrected, or why not"});
    return out;
  }();
  return columns;
}

std::string correction_csv_header() {
  std::string out;
  for (const auto& c : correction_csv_columns()) out += (out.empty() ? "" : ",") + std::string(c.name);
  return out;
}

std::string correction_csv_cells(const Correction& c) {
  std::string out = fmt::format("{},{},{}", c.corrected() ? 1 : 0,
                                awcc::csv_cell(c.corrected() ? std::string() : c.message), c.forest);
  for (const auto* q : {&c.velocity, &c.turbulence_intensity}) {
    if (*q) {
      out += fmt::format(",{:.10g}", (*q)->median());
      for (double v : (*q)->quantiles) out += fmt::format(",{:.10g}", v);
    } else {
      out += std::string(1 + correction_levels.size(), ',');
    }
  }
  return out + "," + std::string(to_string(c.status));
}

nlohmann::json to_json(const Correction& c) {
  using nlohmann::json;
  auto quantity = [](const std::optional<CorrectedQuantity>& q) {
    if (!q) return json(nullptr);
    json levels = json::object();
    for (std::size_t k = 0; k < correction_levels.size(); ++k) levels[correction_level_names[k]] = q->quantiles[k];
    return json{{"measured", q->measured}, {"median", q->median()}, {"quantiles", levels}};
  };
  return json{{"status", to_string(c.status)},
              {"in_range", c.corrected()},
              {"forest", c.forest.empty() ? json(nullptr) : json(c.forest)},
              {"reason", c.corrected() ? json(nullptr) : json(c.message)},
              {"velocity", quantity(c.velocity)},
              {"turbulence_intensity", quantity(c.turbulence_intensity)}};
}

}  // namespace correction
