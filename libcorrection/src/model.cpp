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

// What a value outside its training range means, in the field's words
// where the flow itself is outside what the simulator models.
std::string out_of_range_meaning(const FeatureRange& r, double v) {
  if (r.name == "void_fraction" && v > 0.5) {
    return ": above c = 0.5 the flow is droplets in air, which this model was not trained on (its campaigns stop at c = 0.6; the synthetic probe models the spray region since issue 31)";
  }
  if (r.name == "duration" && v < r.min) return ": a shorter record holds less than any the model learnt from";
  return {};
}

std::string out_of_range_reason(const FeatureRange& r, double v) {
  return fmt::format("{} is outside the training range {}{}", feature_value_text(r.name, v),
                     feature_range_text(r.name, r.min, r.max), out_of_range_meaning(r, v));
}

// A forest's features of a row: x, or why the row cannot be corrected (a
// feature not known, or outside the training range). A record longer than
// the longest training record is held at that length, with a note (the
// model's header says why duration alone is held).
struct FeatureVector {
  std::vector<double> x;
  CorrectionStatus status = CorrectionStatus::corrected;
  std::string message;
  std::vector<std::string> notes;
  const FeatureRange* refused = nullptr;  ///< the feature outside its range
  [[nodiscard]] bool ok() const { return status == CorrectionStatus::corrected; }
};

}  // namespace

FeatureRange accepted_range(const FeatureRange& training, double margin) {
  FeatureRange r = training;
  const double pad = margin * (training.max - training.min);
  r.min = training.min - pad;
  r.max = training.max + pad;
  if (Features::on_log_scale(training.name) && training.min > 0.0) {
    r.min = training.min * std::pow(training.max / training.min, -margin);
  }
  return r;
}

namespace {

FeatureVector feature_vector(const std::vector<FeatureRange>& ranges, double margin, const Features& f) {
  FeatureVector out;
  out.x.resize(ranges.size());
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    const auto v = f.value(ranges[j].name);
    if (!v) {
      out.status = CorrectionStatus::missing_feature;
      out.message = fmt::format("the model takes the record's {} as a feature, and it is not known for this row; give it "
                                "({})",
                                ranges[j].name, how_to_give(ranges[j].name));
      return out;
    }
    out.x[j] = *v;
  }
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    const auto& r = ranges[j];
    const auto accepted = accepted_range(r, margin);
    if (r.name == "duration" && out.x[j] > accepted.max) {
      out.notes.push_back(fmt::format("duration {} s is beyond the training range ({}): corrected as {:.4g} s",
                                      fmt::format("{:.4g}", out.x[j]), feature_range_text(r.name, r.min, r.max), r.max));
      out.x[j] = r.max;
    } else if (!(out.x[j] >= accepted.min && out.x[j] <= accepted.max)) {
      out.status = CorrectionStatus::outside_training_range;
      out.message = out_of_range_reason(r, out.x[j]);
      out.refused = &r;
      return out;
    }
  }
  return out;
}

// The offsets or envelope of a row's group (Calibration::offsets).
template <std::size_t N>
std::array<double, N> group_value(const Calibration& c, const std::vector<std::array<double, N>>& groups,
                                  std::int64_t windows, double tu_median) {
  const auto h = static_cast<std::size_t>(c.tu_band(tu_median));
  const int w = c.band(windows);
  if (w >= 0) return groups[static_cast<std::size_t>(w) * c.tu_bands() + h];
  std::array<double, N> o;
  o.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t b = 0; b <= c.window_edges.size(); ++b)
    for (std::size_t k = 0; k < N; ++k) o[k] = std::max(o[k], groups[b * c.tu_bands() + h][k]);
  return o;
}

// A shift of a quantity's target from the measurement, in words: "+136 %"
// for a ratio, "+0.45" (Tu) or "+1.2 m/s" otherwise.
std::string shift_text(TargetForm form, double shift, std::string_view unit) {
  if (form == TargetForm::ratio) {
    const double percent = 100.0 * shift;
    return std::fabs(percent) >= 100.0 ? fmt::format("{:+.0f} %", percent) : fmt::format("{:+.3g} %", percent);
  }
  return unit.empty() ? fmt::format("{:+.3g}", shift) : fmt::format("{:+.3g} {}", shift, unit);
}

// One corrected quantity, the forest's distribution at the row and what the
// trust rules need to say about it.
struct Quantity {
  const char* forest;      // "AWCC forest's", "FSCC forest's"
  const char* name;        // "velocity", "Tu"
  const char* unit;        // "m/s", "" (dimensionless)
  const char* source;      // "AWCC's", "FSCC's"
  TargetForm form;
  double measured;
  bool nonnegative;
};

std::string value_text(const Quantity& q, double v) {
  return *q.unit ? fmt::format("{:.3g} {}", v, q.unit) : fmt::format("{:.3g}", v);
}

// Rule (a) and rule (b) of the trust rules (the model's header) for one
// quantity: the reasons it breaks, empty when it holds. `envelope_runs`
// says where the envelope was measured.
// What the trust rules find, rule by rule, each quantity's clause apart so
// that a rule both quantities break is named once.
struct Verdict {
  std::vector<std::string> envelope, modes, lag, yield;
  void add(const Verdict& v) {
    envelope.insert(envelope.end(), v.envelope.begin(), v.envelope.end());
    modes.insert(modes.end(), v.modes.begin(), v.modes.end());
    lag.insert(lag.end(), v.lag.begin(), v.lag.end());
    yield.insert(yield.end(), v.yield.begin(), v.yield.end());
  }
};

// Rule (d) (the model's header): AWCC's data yield; silent when the windows
// are not known.
Verdict chance_yield(const Features& f) {
  Verdict verdict;
  if (f.windows_accepted < 0 || f.windows_total <= 0) return verdict;
  const double yield = static_cast<double>(f.windows_accepted) / static_cast<double>(f.windows_total);
  if (yield >= awcc::chance_data_yield) return verdict;
  verdict.yield.push_back(fmt::format(
      "AWCC accepted {} of {} windows ({:.3g} %, below {:g} %), about what signals that share no bubble give by "
      "chance, so the measurement corrected may be chance peaks rather than the flow's",
      f.windows_accepted, f.windows_total, 100.0 * yield, 100.0 * awcc::chance_data_yield));
  return verdict;
}

// Rule (c) (the model's header): the measurement's lag in samples, from
// `source`'s velocity; silent when fs is not known.
Verdict unresolved_lag(const char* source, double velocity, double dx, double fs) {
  Verdict verdict;
  if (!(fs > 0.0) || !(dx > 0.0) || !(velocity > 0.0)) return verdict;
  const double lag = dx * fs / velocity;
  if (lag >= awcc::least_resolved_lag_samples) return verdict;
  const auto [lo, hi] = awcc::one_sample_velocity_bounds(dx, fs);
  verdict.lag.push_back(fmt::format(
      "{} velocity {:.3g} m/s is a lag of {:.2f} samples (dx fs / u, below {:g}), and every delay of 0.5-1.5 samples "
      "reads as one, so the record bounds the velocity ({:.4g}-{:.4g} m/s) and no forest's median measures it "
      "(sample faster or move the tips apart)",
      source, velocity, lag, awcc::least_resolved_lag_samples, lo, hi));
  return verdict;
}

// Rule (e) (the model's header): Tu of bubbles far larger than the tip
// separation; silent when d32 or dx is not known.
void judge_turbulence(Correction& c, const Features& f) {
  if (!c.turbulence_intensity || !(f.d32 > 0.0) || !(f.dx > 0.0)) return;
  const double ratio = f.d32 / f.dx;
  if (ratio <= largest_tu_size_ratio) return;
  c.large_bubbles = true;
  c.turbulence_message = fmt::format(
      "Tu not corrected: the Sauter diameter d32 {:.4g} mm is {:.3g} times the tip separation dx {:.4g} mm (above "
      "{:g}), so the tips meet each interface almost together and a window's delay follows the interface's tilt "
      "more than the flow; AWCC's Tu reads high there by more than the forest corrects, and its intervals do not "
      "hold (the quantiles are kept, the median is not a corrected value; move the tips apart to measure Tu)",
      1e3 * f.d32, ratio, 1e3 * f.dx, largest_tu_size_ratio);
}

Verdict untrusted_reasons(const Quantity& q, const WeightedDistribution& d,
                          const std::optional<std::array<double, 2>>& envelope, const std::string& envelope_runs) {
  Verdict verdict;
  const double identity = to_target(q.form, q.measured, q.measured);
  const double shift = d.quantile(0.5) - identity;
  if (envelope && !(shift >= -(*envelope)[0] && shift <= (*envelope)[1])) {
    const double median = from_target(q.form, d.quantile(0.5), q.measured);
    verdict.envelope.push_back(fmt::format(
        "the {} {} median {} is {} from {} {}; on {} the truth lay within {} to {} of the measurement for {:g} % of "
        "them",
        q.forest, q.name, value_text(q, q.nonnegative ? std::max(0.0, median) : median), shift_text(q.form, shift, q.unit),
        q.source, value_text(q, q.measured), envelope_runs, shift_text(q.form, -(*envelope)[0], q.unit),
        shift_text(q.form, (*envelope)[1], q.unit), 100.0 * envelope_coverage));
  }
  const bool log_scale = q.form == TargetForm::ratio && !d.values.empty() && d.values.front() > 0.0;
  const auto m = dip(d, log_scale);
  if (m.ratio < multimodal_dip_limit) {
    const auto lo = from_target(q.form, m.quantiles[m.interval], q.measured);
    const auto hi = from_target(q.form, m.quantiles[m.interval + 1], q.measured);
    const std::string range = *q.unit ? fmt::format("{:.3g}-{:.3g} {}", lo, hi, q.unit) : fmt::format("{:.3g}-{:.3g}", lo, hi);
    verdict.modes.push_back(fmt::format(
        "the {} {} distribution is {:.2f} times as dense between its {:g} and {:g} quantiles ({}) as in the densest "
        "interval on each side (one mode gives at least 1; the limit is {:g})",
        q.forest, q.name, m.ratio, modality_levels[m.interval], modality_levels[m.interval + 1], range,
        multimodal_dip_limit));
  }
  return verdict;
}

CorrectedQuantity corrected_quantity(const Quantity& q, const std::vector<double>& t) {
  CorrectedQuantity c;
  c.measured = q.measured;
  for (std::size_t k = 0; k < t.size(); ++k) {
    c.quantiles[k] = from_target(q.form, t[k], q.measured);
    if (q.nonnegative) c.quantiles[k] = std::max(0.0, c.quantiles[k]);
  }
  return c;
}

std::vector<double> quantiles_of(const WeightedDistribution& d) {
  std::vector<double> t;
  for (double a : correction_levels) t.push_back(d.quantile(a));
  return t;
}

// The trust rules' verdict on a correction (the model's header): each rule
// named once, with the clauses of the quantities that break it.
void judge(Correction& c, const Verdict& v) {
  c.outside_envelope = !v.envelope.empty();
  c.multimodal = !v.modes.empty();
  c.one_sample_lag = !v.lag.empty();
  c.chance_yield = !v.yield.empty();
  if (!c.outside_envelope && !c.multimodal && !c.one_sample_lag && !c.chance_yield) return;
  c.status = CorrectionStatus::untrusted;
  std::vector<std::string> rules;
  if (c.chance_yield) rules.push_back(fmt::format("a chance yield: {}", fmt::join(v.yield, "; ")));
  if (c.one_sample_lag) rules.push_back(fmt::format("a lag of one sample: {}", fmt::join(v.lag, "; ")));
  if (c.outside_envelope) rules.push_back(fmt::format("outside the envelope: {}", fmt::join(v.envelope, "; ")));
  if (c.multimodal) rules.push_back(fmt::format("multimodal: {}", fmt::join(v.modes, "; ")));
  c.message = fmt::format("{}", fmt::join(rules, "; "));
}

// A forest's envelope when the file stores none: its training targets'
// shifts from the measurement, pooled (the model's header). None for the
// value form, whose shift needs the measurement the targets do not keep.
std::vector<std::array<double, 2>> training_envelope(const QuantileForest& forest, TargetForm form) {
  if (form == TargetForm::value || forest.target_count() == 0) return {};
  const double identity = form == TargetForm::ratio ? 1.0 : 0.0;
  auto shifts = forest.targets();
  for (double& t : shifts) t -= identity;
  const auto e = envelope_of(std::move(shifts));
  if (!e) return {};
  return {*e};
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
  return group_value(*this, groups, windows, tu_median);
}

std::optional<std::array<double, 2>> Calibration::envelope(const std::vector<std::array<double, 2>>& groups,
                                                           std::int64_t windows, double tu_median) const {
  if (groups.empty()) return std::nullopt;
  if (groups.size() == 1) return groups.front();
  return group_value(*this, groups, windows, tu_median);
}

std::string Calibration::group_text(std::int64_t windows, double tu_median) const {
  std::string out;
  const int w = band(windows);
  if (window_edges.empty()) {
    out = "all windows";
  } else if (w < 0) {
    out = "windows unknown: the widest band";
  } else if (w == 0) {
    out = fmt::format("windows up to {}", window_edges.front() - 1);
  } else if (w == static_cast<int>(window_edges.size())) {
    out = fmt::format("windows {}+", window_edges.back());
  } else {
    out = fmt::format("windows {}-{}", window_edges[static_cast<std::size_t>(w) - 1],
                      window_edges[static_cast<std::size_t>(w)] - 1);
  }
  if (tu_edges.empty()) return out;
  const auto h = static_cast<std::size_t>(tu_band(tu_median));
  if (h == 0) return fmt::format("{}, model Tu below {:g}", out, tu_edges.front());
  if (h == tu_edges.size()) return fmt::format("{}, model Tu {:g}+", out, tu_edges.back());
  return fmt::format("{}, model Tu {:g}-{:g}", out, tu_edges[h - 1], tu_edges[h]);
}

std::optional<std::array<double, 2>> envelope_of(std::vector<double> shifts, double coverage) {
  const auto n = static_cast<double>(shifts.size());
  // (The rank of an exact product must not round up: 400 x 0.9975 is 399.)
  const auto k = static_cast<std::size_t>(std::ceil((n + 1.0) * (1.0 + coverage) / 2.0 - 1e-9));
  if (shifts.empty() || k > shifts.size()) return std::nullopt;
  std::sort(shifts.begin(), shifts.end());
  // The rule bounds how far from the measurement a median may move: a
  // median nearer to it than the truths lay is not farther, so 0 is inside.
  return std::array<double, 2>{std::max(0.0, -shifts[shifts.size() - k]), std::max(0.0, shifts[k - 1])};
}

std::string Correction::why_not() const {
  if (corrected()) return {};
  return status == CorrectionStatus::untrusted ? "untrusted: " + message : message;
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

namespace {

// A forest's correction of a row, and the feature that kept it from the row
// (to say once what both forests refuse).
struct Attempt {
  Correction correction;
  const FeatureRange* refused = nullptr;
  double value = 0.0;
};

Attempt refused(const FeatureVector& x, const Features& f) {
  Attempt a{not_corrected(x.status, x.message), x.refused, 0.0};
  if (x.refused) a.value = f.value(x.refused->name).value_or(0.0);
  return a;
}

Attempt awcc_attempt(const CorrectionModel& m, const Features& f);

// A row without the record's features, by the reduced model (its forest named).
Attempt reduced_attempt(const CorrectionModel& m, const Features& f) {
  std::vector<std::string> missing;
  for (const auto& r : m.ranges)
    if (!f.value(r.name) && r.name != Features::weighting_name) missing.push_back(r.name);
  Attempt a = awcc_attempt(*m.reduced, f);
  auto& c = a.correction;
  if (c.velocity) {
    c.forest = "awcc-reduced";
    // A file of an earlier pdp lacks only the time scale: the recording,
    // processed again, gives it and the full forest.
    const bool only_scale = missing.size() == 1 && missing.front() == Features::scale_name;
    c.notes.insert(c.notes.begin(),
                   fmt::format("{} not known for this row: corrected by the reduced forest (u, Tu, c, d32, dx, dy, "
                               "Np), trained over every record length and rate, whose intervals are wider{}",
                               fmt::join(missing, ", "),
                               only_scale ? " (pdp process writes it as awcc.time_scale_ratio: process the "
                                            "recording again for the full forest)"
                                          : ""));
  }
  return a;
}

Attempt awcc_attempt(const CorrectionModel& m, const Features& f) {
  if (f.windows_accepted >= 0 && f.windows_accepted < m.min_windows) {
    return {not_corrected(CorrectionStatus::too_few_windows,
                          fmt::format("{} accepted windows; the model was trained on runs with at least {}",
                                      f.windows_accepted, m.min_windows))};
  }
  // A row whose weighting is not known, for a model that takes it: both
  // answers, equally weighted (correction/features.hpp).
  const bool mixed = m.takes_weighting() && f.awcc_unweighted < 0;
  Features known = f;
  if (mixed) known.awcc_unweighted = 0;
  const auto x = feature_vector(m.ranges, m.range_margin, known);
  if (x.status == CorrectionStatus::missing_feature && m.reduced) return reduced_attempt(m, f);
  if (!x.ok()) return refused(x, f);
  const auto& cal = m.calibration;
  auto velocity_d = m.velocity.distribution(x.x);
  auto tu_d = m.turbulence_intensity.distribution(x.x);
  if (mixed) {
    auto other = x.x;
    other[m.weighting_feature()] = 1.0;
    velocity_d = mixture(velocity_d, m.velocity.distribution(other));
    tu_d = mixture(tu_d, m.turbulence_intensity.distribution(other));
  }
  auto velocity_t = quantiles_of(velocity_d);
  auto tu_t = quantiles_of(tu_d);
  // The group's Tu band: the Tu forest's own median, before calibration.
  const double tu_median = from_target(m.turbulence_form, tu_t[3], f.turbulence_intensity);
  if (!cal.empty()) {
    Calibration::apply(cal.offsets(cal.velocity, f.windows_accepted, tu_median), velocity_t);
    Calibration::apply(cal.offsets(cal.turbulence_intensity, f.windows_accepted, tu_median), tu_t);
  }
  const Quantity u{"AWCC forest's", "velocity", "m/s", "AWCC's", m.velocity_form, f.velocity, false};
  const Quantity tu{"AWCC forest's", "Tu", "", "AWCC's", m.turbulence_form, f.turbulence_intensity, true};
  Correction c;
  c.status = CorrectionStatus::corrected;
  c.forest = "awcc";
  c.velocity = corrected_quantity(u, velocity_t);
  c.turbulence_intensity = corrected_quantity(tu, tu_t);
  c.notes = x.notes;
  if (mixed) {
    c.notes.push_back("how AWCC's moments were taken is not known for this row: the answers for duration-weighted "
                      "and unweighted moments are mixed, equally weighted (state it: the setting weighting)");
  }
  const std::string runs = cal.envelope_from_training
                               ? "the forest's training runs"
                               : fmt::format("runs the model was not trained on ({})",
                                             cal.group_text(f.windows_accepted, tu_median));
  auto verdict =
      untrusted_reasons(u, velocity_d, cal.envelope(cal.velocity_envelope, f.windows_accepted, tu_median), runs);
  verdict.add(untrusted_reasons(tu, tu_d, cal.envelope(cal.turbulence_envelope, f.windows_accepted, tu_median), runs));
  verdict.add(unresolved_lag("AWCC's", f.velocity, f.dx, f.fs));
  verdict.add(chance_yield(f));
  judge(c, verdict);
  judge_turbulence(c, f);
  return {c};
}

Attempt fscc_attempt(const CorrectionModel& m, const Features& f) {
  if (!m.fscc) return {not_corrected(CorrectionStatus::no_awcc_velocity, "the model has no FSCC forest")};
  if (const auto why = fscc_unusable(f); !why.empty()) return {not_corrected(CorrectionStatus::no_awcc_velocity, why)};
  const auto& forest = *m.fscc;
  const auto x = feature_vector(forest.ranges, m.range_margin, f);
  if (!x.ok()) return refused(x, f);
  const auto d = forest.velocity.distribution(x.x);
  auto t = quantiles_of(d);
  const auto& cal = forest.calibration;
  if (!cal.empty()) Calibration::apply(cal.velocity.front(), t);
  const Quantity u{"FSCC forest's", "velocity", "m/s", "FSCC's", forest.form, f.fscc_velocity, false};
  Correction c;
  c.status = CorrectionStatus::corrected;
  c.forest = "fscc";
  c.velocity = corrected_quantity(u, t);
  c.notes = x.notes;
  auto verdict = untrusted_reasons(u, d, cal.envelope(cal.velocity_envelope, -1, 0.0),
                                   cal.envelope_from_training ? "the FSCC forest's training runs"
                                                              : "the FSCC forest's calibration runs");
  verdict.add(unresolved_lag("FSCC's", f.fscc_velocity, f.dx, f.fs));
  judge(c, verdict);
  return {c};
}

// The FSCC forest's answer when the AWCC forest's is not a correction: its
// correction or its untrusted quantiles, else AWCC's status with both
// reasons, each said once (a feature both forests refuse is named once).
Correction after_awcc(const Attempt& first, const Attempt& fscc) {
  const auto& c = fscc.correction;
  if (c.corrected() || c.status == CorrectionStatus::untrusted) {
    // Why the AWCC forest did not answer, first: a row the AWCC forest
    // refuses for a feature (a dx or fs typed wrong puts the lag outside its
    // range) is corrected from FSCC's velocity, and says so.
    Correction out = c;
    out.notes.insert(out.notes.begin(),
                     fmt::format("AWCC forest: {}; corrected from FSCC's velocity by the FSCC forest, which gives no Tu",
                                 first.correction.message));
    return out;
  }
  Correction awcc = first.correction;
  const auto* a = first.refused;
  const auto* b = fscc.refused;
  if (a && b && a->name == b->name) {
    awcc.message = fmt::format("{} is outside the training ranges of both forests (AWCC forest {}, FSCC forest {}){}",
                               feature_value_text(a->name, first.value), feature_range_text(a->name, a->min, a->max),
                               feature_range_text(b->name, b->min, b->max), out_of_range_meaning(*a, first.value));
  } else {
    awcc.message = fmt::format("{}; FSCC forest: {}", awcc.message, c.message);
  }
  return awcc;
}

}  // namespace

Correction CorrectionModel::correct(const Features& f) const { return awcc_attempt(*this, f).correction; }

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

Correction CorrectionModel::correct_fscc(const Features& f) const { return fscc_attempt(*this, f).correction; }

Correction CorrectionModel::correct(const Measurement& m) const {
  const auto f = make_features(m);
  const Attempt awcc = f.ok() ? awcc_attempt(*this, f.features) : Attempt{not_corrected(f.status, f.message)};
  if (awcc.correction.corrected() || !fscc || !fscc_may_follow(awcc.correction.status)) return awcc.correction;
  return after_awcc(awcc, fscc_attempt(*this, f.features));
}

Correction CorrectionModel::correct(const MeasurementResult& m) const {
  if (m.status == CorrectionStatus::corrected) return correct(m.measurement);
  const Attempt awcc{not_corrected(m.status, m.message)};
  if (!fscc || !fscc_may_follow(m.status)) return awcc.correction;
  return after_awcc(awcc, fscc_attempt(*this, make_features(m.measurement).features));
}

void CorrectionModel::use_training_envelopes() {
  if (calibration.velocity_envelope.empty()) {
    calibration.velocity_envelope = training_envelope(velocity, velocity_form);
    calibration.turbulence_envelope = training_envelope(turbulence_intensity, turbulence_form);
    calibration.envelope_from_training = true;
  }
  if (fscc && fscc->calibration.velocity_envelope.empty()) {
    fscc->calibration.velocity_envelope = training_envelope(fscc->velocity, fscc->form);
    fscc->calibration.envelope_from_training = true;
  }
}

std::string CorrectionModel::mismatch(const Processing& results) const {
  Processing compared = results;
  if (takes_weighting()) compared.weighting = processing.weighting;  // a feature, not a mismatch
  return processing_mismatch(processing, compared);
}

std::size_t CorrectionModel::weighting_feature() const {
  for (std::size_t j = 0; j < ranges.size(); ++j)
    if (ranges[j].name == Features::weighting_name) return j;
  return ranges.size();
}

bool CorrectionModel::takes_weighting() const { return weighting_feature() < ranges.size(); }

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
        for (auto& band : *b)
          for (double& o : band) {
            o = r.f64();
            if (!std::isfinite(o)) r.damaged("a calibration offset is not finite");
          }
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
        f.calibration.velocity.resize(1);
        for (double& o : f.calibration.velocity.front()) {
          o = r.f64();
          if (!std::isfinite(o)) r.damaged("a calibration offset is not finite");
        }
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

std::span<const awcc::ProfileColumn> correction_csv_columns() {
  // Built once from the levels; the strings live as long as the program.
  static const auto columns = [] {
    static std::deque<std::string> text;
    auto keep = [](std::string s) -> std::string_view { return text.emplace_back(std::move(s)); };
    std::vector<awcc::ProfileColumn> out{
        {"correction_in_range", "", "/correction/in_range", "1 when the row was corrected"},
        {"correction_reason", "", "/correction/reason",
         "why the row was not corrected (untrusted: which trust rule its quantiles break, with the numbers)"},
        {correction_column::forest, "", "/correction/forest",
         "the forest that gave the quantiles: awcc, or fscc (velocity only)"}};
    for (const char* q : {"velocity", "turbulence_intensity"}) {
      const bool u = std::string_view(q) == "velocity";
      const char* unit = u ? "m/s" : "-";
      const char* what = u ? "velocity" : "turbulence intensity";
      out.push_back({keep(fmt::format("corrected_{}", q)), unit, keep(fmt::format("/correction/{}/median", q)),
                     keep(fmt::format("corrected {} (median of the truth given the measurement; empty when not "
                                      "corrected, untrusted included)",
                                      what))});
      for (const char* l : correction_level_names) {
        out.push_back({keep(fmt::format("corrected_{}_q{}", q, l)), unit,
                       keep(fmt::format("/correction/{}/quantiles/{}", q, l)),
                       keep(fmt::format("quantile {} of the true {} (of an untrusted row too: not a corrected value)",
                                        l, what))});
      }
    }
    out.push_back({correction_column::status, "", "/correction/status", "corrected, untrusted, or why not"});
    out.push_back({"correction_notes", "", "/correction/notes",
                   "what to know of the correction (a record longer than the training records, held at their "
                   "length), joined by '; '"});
    out.push_back({correction_column::turbulence_reason, "", "/correction/turbulence_intensity/reason",
                   "why the corrected Tu is empty on a row whose velocity stands (trust rule (e): bubbles far larger "
                   "than the tip separation); empty otherwise"});
    return out;
  }();
  return columns;
}

std::string correction_csv_header() {
  std::string out;
  for (const auto& c : correction_csv_columns()) out += (out.empty() ? "" : ",") + std::string(c.name);
  return out;
}

std::string quantile_cells(const Correction& c) {
  std::string out;
  for (const auto* q : {&c.velocity, &c.turbulence_intensity}) {
    if (*q) {
      // An untrusted row's median is not a corrected value: its quantiles
      // only; nor is a Tu that rule (e) leaves uncorrected.
      const bool stands = q == &c.velocity ? c.corrected() : c.turbulence_corrected();
      out += stands ? fmt::format(",{:.10g}", (*q)->median()) : ",";
      for (double v : (*q)->quantiles) out += fmt::format(",{:.10g}", v);
    } else {
      out += std::string(1 + correction_levels.size(), ',');
    }
  }
  return out;
}

std::string notes_text(const Correction& c) {
  std::string notes;
  for (const auto& n : c.notes) notes += (notes.empty() ? "" : "; ") + n;
  return notes;
}

std::string correction_csv_cells(const Correction& c) {
  return fmt::format("{},{},{}{},{},{},{}", c.corrected() ? 1 : 0,
                     awcc::csv_cell(c.corrected() ? std::string() : c.message), c.forest, quantile_cells(c),
                     to_string(c.status), awcc::csv_cell(notes_text(c)), awcc::csv_cell(c.turbulence_message));
}

nlohmann::json to_json(const Correction& c) {
  using nlohmann::json;
  // An untrusted row's median is not a corrected value: null, its quantiles kept.
  // So is a Tu that rule (e) leaves uncorrected, its reason given.
  auto quantity = [](const std::optional<CorrectedQuantity>& q, bool stands) {
    if (!q) return json(nullptr);
    json levels = json::object();
    for (std::size_t k = 0; k < correction_levels.size(); ++k) levels[correction_level_names[k]] = q->quantiles[k];
    return json{{"measured", q->measured}, {"median", stands ? json(q->median()) : json(nullptr)},
                {correction_key::quantiles, levels}};
  };
  json tu = quantity(c.turbulence_intensity, c.turbulence_corrected());
  if (tu.is_object()) {
    tu[correction_key::reason] = c.turbulence_message.empty() ? json(nullptr) : json(c.turbulence_message);
  }
  return json{{correction_key::status, to_string(c.status)},
              {"in_range", c.corrected()},
              {correction_key::forest, c.forest.empty() ? json(nullptr) : json(c.forest)},
              {"reason", c.corrected() ? json(nullptr) : json(c.message)},
              {"notes", c.notes},
              {correction_key::velocity, quantity(c.velocity, c.corrected())},
              {correction_key::turbulence_intensity, tu}};
}

}  // namespace correction
